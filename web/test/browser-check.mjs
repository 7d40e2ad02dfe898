// Opens a page bouncecheck wrote (report.html or sweep.html) from disk in
// headless Chromium, the way a reader would, at 1280 and 1920 px wide, and
// fails if:
//   - the page logs a console error or throws,
//   - the page requests anything but itself (it must work offline),
//   - a plot is missing, or has another number of traces than the run's
//     JSON (report.json or sweep.json, read here independently) implies,
//   - a plot draws a trace point outside its frame (its axis ranges),
//   - (report.html) a scenario's animation does not play (the time shown
//     does not advance, or the picture does not change), or, scrubbed to a
//     time, does not draw each ball, alone, centred within a pixel of where
//     the page's own path data puts it at that time (interpolated here, not
//     by the page), or draws a ball outside its room.
// It saves a screenshot of the page at each width, and of seed-3d's
// animation at t = 0, 10 and 30 s.
//
// usage: node browser-check.mjs PAGE.html JSON SCREENSHOT.png
import { chromium } from "playwright-core";
import { readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [pagePath, jsonPath, screenshotPath] = process.argv.slice(2);
if (!pagePath || !jsonPath || !screenshotPath) {
  console.error("usage: node browser-check.mjs PAGE.html JSON SCREENSHOT.png");
  process.exit(2);
}
const pageUrl = pathToFileURL(resolve(pagePath)).href;
const runJson = JSON.parse(readFileSync(jsonPath, "utf8"));
const expected = expectedPlots(runJson);
const expectedJsonKind = runJson.schema && runJson.schema.startsWith("bouncecheck-report/") ? "report" : "sweep";
const problems = [];

// The trace layout page.js documents, counted from the run's own JSON.
function expectedPlots(json) {
  const plots = {};
  if (json.schema && json.schema.startsWith("bouncecheck-report/")) {
    json.scenarios.forEach((entry, index) => {
      const ran = entry.simulators.filter((r) => r.status !== "skipped").map((r) => r.simulator);
      const n = ran.length;
      const has = (name) => (ran.includes(name) ? 1 : 0);
      const id = (kind) => "plot-" + index + "-" + kind;
      plots[id("path")] = n + 1;
      plots[id("height")] = 2 * n;
      plots[id("apex")] = n - has("exact") + 1;
      plots[id("divergence")] = n - has("reference");
      plots[id("error")] = n - has("exact");
      plots[id("normal")] = n + 1;
      plots[id("tangential")] = n + 1;
    });
  } else if (json.schema && json.schema.startsWith("bouncecheck-sweep/")) {
    const simulators = new Set(json.rows.map((r) => r.engine));
    plots["plot-sweep-work-precision"] = simulators.size + 1;
  } else {
    throw new Error(jsonPath + ": neither a report nor a sweep");
  }
  return plots;
}

const isReport = expectedJsonKind === "report";

// In the page: every trace point a plot draws that falls outside its axis
// ranges (log axes compare log10 of the value; bars, their tops).
function pointsOutsideFrames() {
  const out = [];
  for (const gd of document.querySelectorAll(".plot")) {
    const layout = gd._fullLayout;
    if (!layout || !gd._fullData) continue;
    const inside = (axis, v) => {
      if (v === null || v === undefined || !Number.isFinite(v)) return true;  // a gap, not a point
      if (axis.type === "log") { if (v <= 0) return true; v = Math.log10(v); }
      const [a, b] = axis.range, lo = Math.min(a, b), hi = Math.max(a, b), slack = 1e-9 * (hi - lo || 1);
      return v >= lo - slack && v <= hi + slack;
    };
    for (const trace of gd._fullData) {
      if (trace.visible !== true) continue;
      if (trace.type === "scatter3d") {
        const scene = layout[trace.scene || "scene"];
        for (const k of ["x", "y", "z"]) {
          const axis = scene[k + "axis"];
          const bad = (trace[k] || []).filter((v) => !inside(axis, v));
          if (bad.length) out.push(gd.id + ": " + trace.name + " has " + bad.length + " " + k + " outside " + JSON.stringify(axis.range));
        }
        continue;
      }
      const xaxis = layout[(trace.xaxis || "x").replace("x", "xaxis")], yaxis = layout[(trace.yaxis || "y").replace("y", "yaxis")];
      const xs = trace.x || [], ys = trace.y || [];
      let bad = 0;
      for (let i = 0; i < Math.max(xs.length, ys.length); ++i) if (!inside(xaxis, xs[i]) || !inside(yaxis, ys[i])) ++bad;
      if (bad) out.push(gd.id + ": " + trace.name + " has " + bad + " point(s) outside its frame");
    }
  }
  return out;
}

// The centre at t, linear between the path's kept samples: the test's own
// reading of the page's data, not the page's code.
function centreAt(path, t) {
  const ts = path.t;
  let i = 0;
  while (i + 1 < ts.length && ts[i + 1] <= t) ++i;
  const j = Math.min(i + 1, ts.length - 1), span = ts[j] - ts[i];
  const f = span > 0 ? Math.min(Math.max((t - ts[i]) / span, 0), 1) : 0;
  return ["x", "y", "z"].map((k) => (path[k] ? path[k][i] + f * (path[k][j] - path[k][i]) : 0));
}

// The centroid of the canvas pixels of one colour near an expected point.
function centroidOfColour([index, colour, near, reach]) {
  const api = window.bouncecheckAnimations[index];
  const canvas = api.canvas, ratio = canvas.width / canvas.clientWidth;
  const g = canvas.getContext("2d");
  const x0 = Math.max(0, Math.floor((near.x - reach) * ratio)), y0 = Math.max(0, Math.floor((near.y - reach) * ratio));
  const w = Math.min(canvas.width - x0, Math.ceil(2 * reach * ratio)), h = Math.min(canvas.height - y0, Math.ceil(2 * reach * ratio));
  if (w <= 0 || h <= 0) return null;
  const px = g.getImageData(x0, y0, w, h).data;
  const want = [1, 3, 5].map((k) => parseInt(colour.slice(k, k + 2), 16));
  let n = 0, sx = 0, sy = 0;
  for (let y = 0; y < h; ++y) for (let x = 0; x < w; ++x) {
    const k = 4 * (y * w + x);
    if (Math.abs(px[k] - want[0]) <= 3 && Math.abs(px[k + 1] - want[1]) <= 3 && Math.abs(px[k + 2] - want[2]) <= 3) {
      ++n; sx += x + 0.5; sy += y + 0.5;
    }
  }
  return n ? { x: (x0 + sx / n) / ratio, y: (y0 + sy / n) / ratio, pixels: n } : null;
}

async function checkAnimations(page, width, at) {
  const data = await page.evaluate(() => JSON.parse(document.getElementById("bouncecheck-data").textContent));
  for (let index = 0; index < data.report.scenarios.length; ++index) {
    const entry = data.report.scenarios[index], plots = data.plots[index], name = entry.scenario.name;
    const where = "animation of " + name + at;
    const present = await page.evaluate((i) => !!(window.bouncecheckAnimations && window.bouncecheckAnimations[i]), index);
    if (!plots) continue;
    if (!present) { problems.push(where + ": missing"); continue; }
    const box = await page.$("#animation-" + index);
    await box.scrollIntoViewIfNeeded();

    // Play: the time shown advances and the picture changes.
    await page.evaluate((i) => window.bouncecheckAnimations[i].seek(0), index);
    const before = await box.screenshot();
    const t0 = await page.evaluate((i) => window.bouncecheckAnimations[i].time(), index);
    await page.click("#animation-" + index + " button.play");
    await page.waitForTimeout(600);
    await page.click("#animation-" + index + " button.play");  // pause
    const t1 = await page.evaluate((i) => window.bouncecheckAnimations[i].time(), index);
    if (!(t1 > t0)) problems.push(where + ": play did not advance the time (" + t0 + " -> " + t1 + ")");
    if (Buffer.compare(before, await box.screenshot()) === 0) problems.push(where + ": the picture did not change while playing");

    // Scrub, then each ball alone: drawn where the data puts it.
    const balls = entry.simulators.map((r, i) => ({ r: r, plot: plots.simulators[i] }))
      .filter((b) => b.r.status === "ok" && b.plot && b.plot.path.t.length);
    const names = await page.evaluate((i) => window.bouncecheckAnimations[i].names(), index);
    if (names.join() !== balls.map((b) => b.r.simulator).join())
      problems.push(where + ": balls " + names.join() + ", expected " + balls.map((b) => b.r.simulator).join());
    const duration = entry.scenario.duration;
    const times = name === "seed-3d" ? [0, 10, 30] : [0, 0.37 * duration, 0.81 * duration];
    for (const t of times) {
      await page.$eval("#animation-" + index + " input[type=range]", (input, t) => {
        input.value = String(t);
        input.dispatchEvent(new Event("input"));
      }, t);
      const shownT = await page.evaluate((i) => window.bouncecheckAnimations[i].time(), index);
      if (name === "seed-3d")
        await box.screenshot({ path: join(dirname(screenshotPath), "animation-seed-3d-t" + t + "-" + width + ".png") });
      for (const b of balls) {
        const expectedCentre = centreAt(b.plot.path, shownT);
        const s = entry.scenario, tolerance = 0.02 * Math.max(...s.room);
        for (let k = 0; k < s.dim; ++k)
          if (expectedCentre[k] < -tolerance || expectedCentre[k] > s.room[k] + tolerance)
            problems.push(where + ": " + b.r.simulator + " outside the room at t = " + shownT);
        const found = await page.evaluate(([i, ball, centre, all]) => {
          const api = window.bouncecheckAnimations[i];
          for (const other of all) api.setVisible(other, other === ball);
          const near = api.project(centre);
          return { near: near, radius: api.radiusPixels(),
                   colour: getComputedStyle(document.querySelector("#animation-" + i + " .legend-entry[data-name='" + ball + "'] .swatch")).backgroundColor };
        }, [index, b.r.simulator, expectedCentre, names]);
        const rgb = found.colour.match(/\d+/g).slice(0, 3).map(Number);
        const hex = "#" + rgb.map((v) => v.toString(16).padStart(2, "0")).join("");
        const centroid = await page.evaluate(centroidOfColour, [index, hex, found.near, found.radius + 4]);
        if (!centroid) problems.push(where + ": " + b.r.simulator + " not drawn near its centre at t = " + shownT);
        else {
          const off = Math.hypot(centroid.x - found.near.x, centroid.y - found.near.y);
          if (off > 1) problems.push(where + ": " + b.r.simulator + " drawn " + off.toFixed(2) + " px from its centre at t = " + shownT);
        }
      }
      await page.evaluate(([i, all]) => { for (const other of all) window.bouncecheckAnimations[i].setVisible(other, true); }, [index, names]);
    }
  }
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  // --no-sandbox: CI runs as root. SwiftShader: WebGL for the 3D path on a
  // machine without a GPU.
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
const WIDTHS = [1280, 1920];
try {
  for (const width of WIDTHS) {
    const page = await browser.newPage({ viewport: { width: width, height: 1000 } });
    const at = " (" + width + " px)";
    page.on("console", (m) => {
      if (m.type() === "error") problems.push("console error" + at + ": " + m.text());
    });
    page.on("pageerror", (e) => problems.push("page error" + at + ": " + e.message));
    page.on("request", (r) => {
      if (r.url() !== pageUrl && !r.url().startsWith("data:") && !r.url().startsWith("blob:"))
        problems.push("network request: " + r.url());
    });
    await page.goto(pageUrl, { waitUntil: "load" });
    // Plotly draws asynchronously (3D scenes especially): wait until every
    // expected plot has its full layout, or time out with the state seen.
    const ids = Object.keys(expected);
    await page.waitForFunction(
      (ids) => ids.every((id) => { const gd = document.getElementById(id); return gd && gd._fullLayout && gd._fullData; }),
      ids, { timeout: 60000 }).catch(() => problems.push("timed out waiting for the plots to render" + at));
    const seen = await page.evaluate(() => Array.from(document.querySelectorAll(".plot")).map((gd) => ({
      id: gd.id,
      traces: gd.data ? gd.data.length : -1,
      drawn: !!gd.querySelector(".main-svg") && (!gd._fullLayout.scene || !!gd.querySelector("canvas")),
    })));
    const seenIds = new Set(seen.map((p) => p.id));
    for (const id of ids) if (!seenIds.has(id)) problems.push(id + ": missing" + at);
    for (const p of seen) {
      if (!(p.id in expected)) problems.push(p.id + ": not expected");
      else if (p.traces !== expected[p.id]) problems.push(p.id + ": " + p.traces + " traces, expected " + expected[p.id]);
      if (!p.drawn) problems.push(p.id + ": not drawn" + at);
    }
    for (const p of await page.evaluate(pointsOutsideFrames)) problems.push(p + at);
    if (isReport) await checkAnimations(page, width, at);
    await page.screenshot({ path: width === WIDTHS[0] ? screenshotPath : screenshotPath.replace(/\.png$/, "-" + width + ".png"),
                            fullPage: true });
    console.log("checked " + seen.length + " plots in " + pagePath + at);
    await page.close();
  }
} finally {
  await browser.close();
}
if (problems.length) {
  for (const p of problems) console.error("FAIL " + p);
  process.exit(1);
}
