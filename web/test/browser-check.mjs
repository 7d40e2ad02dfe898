// Opens a page bouncecheck wrote (report.html or sweep.html) from disk in
// headless Chromium, the way a reader would, and fails if:
//   - the page logs a console error or throws,
//   - the page requests anything but itself (it must work offline),
//   - a plot is missing, or has another number of traces than the run's
//     JSON (report.json or sweep.json, read here independently) implies.
// It saves a screenshot of what a reader sees first.
//
// usage: node browser-check.mjs PAGE.html JSON SCREENSHOT.png
import { chromium } from "playwright-core";
import { readFileSync } from "node:fs";
import { resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [pagePath, jsonPath, screenshotPath] = process.argv.slice(2);
if (!pagePath || !jsonPath || !screenshotPath) {
  console.error("usage: node browser-check.mjs PAGE.html JSON SCREENSHOT.png");
  process.exit(2);
}
const pageUrl = pathToFileURL(resolve(pagePath)).href;
const expected = expectedPlots(JSON.parse(readFileSync(jsonPath, "utf8")));
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

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  // --no-sandbox: CI runs as root. SwiftShader: WebGL for the 3D path on a
  // machine without a GPU.
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  page.on("console", (m) => {
    if (m.type() === "error") problems.push("console error: " + m.text());
  });
  page.on("pageerror", (e) => problems.push("page error: " + e.message));
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
    ids, { timeout: 60000 }).catch(() => problems.push("timed out waiting for the plots to render"));
  const seen = await page.evaluate(() => Array.from(document.querySelectorAll(".plot")).map((gd) => ({
    id: gd.id,
    traces: gd.data ? gd.data.length : -1,
    drawn: !!gd.querySelector(".main-svg") && (!gd._fullLayout.scene || !!gd.querySelector("canvas")),
  })));
  const seenIds = new Set(seen.map((p) => p.id));
  for (const id of ids) if (!seenIds.has(id)) problems.push(id + ": missing");
  for (const p of seen) {
    if (!(p.id in expected)) problems.push(p.id + ": not expected");
    else if (p.traces !== expected[p.id]) problems.push(p.id + ": " + p.traces + " traces, expected " + expected[p.id]);
    if (!p.drawn) problems.push(p.id + ": not drawn");
  }
  await page.screenshot({ path: screenshotPath, fullPage: true });
  console.log("checked " + seen.length + " plots in " + pagePath + "; screenshot " + screenshotPath);
} finally {
  await browser.close();
}
if (problems.length) {
  for (const p of problems) console.error("FAIL " + p);
  process.exit(1);
}
