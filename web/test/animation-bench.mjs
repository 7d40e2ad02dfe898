// The animation's frame cost with twenty balls, in headless Chromium: a
// benchmark, not a test (it asserts nothing). It opens a report.html,
// builds one more animation of the seed-3d scenario's (or the first
// scenario's) balls, repeated to twenty with the page's own
// BouncecheckAnimation.create, and times `frames` redraws at times spread
// over the run (seek, the same draw a playing frame makes). Prints the
// median and the 95th percentile in ms; 60 frames a second leaves 16.7 ms.
//
// usage: node animation-bench.mjs REPORT.html [frames]
import { chromium } from "playwright-core";
import { resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [pagePath, framesArg] = process.argv.slice(2);
if (!pagePath) {
  console.error("usage: node animation-bench.mjs REPORT.html [frames]");
  process.exit(2);
}
const frames = Number(framesArg || 600);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1920, height: 1000 } });
  await page.goto(pathToFileURL(resolve(pagePath)).href, { waitUntil: "load" });
  const result = await page.evaluate((frames) => {
    const data = JSON.parse(document.getElementById("bouncecheck-data").textContent);
    let index = data.report.scenarios.findIndex((s) => s.scenario.name === "seed-3d");
    if (index < 0) index = 0;
    const entry = data.report.scenarios[index], plots = data.plots[index];
    const ran = entry.simulators.map((r, i) => ({ r, p: plots.simulators[i] })).filter((x) => x.r.status === "ok" && x.p);
    const balls = [];
    for (let k = 0; balls.length < 20; ++k) {
      const x = ran[k % ran.length];
      balls.push({ name: x.r.simulator + " " + k, colour: "#1f77b4", path: x.p.path, contacts: x.p.contacts });
    }
    const box = document.createElement("div");
    document.getElementById("page").prepend(box);
    const api = BouncecheckAnimation.create(box, { scenario: entry.scenario, balls, absent: [] });
    const times = [];
    for (let f = 0; f < frames; ++f) {
      const start = performance.now();
      api.seek((api.duration * f) / frames);
      times.push(performance.now() - start);
    }
    times.sort((a, b) => a - b);
    return { scenario: entry.scenario.name, balls: balls.length, median: times[frames >> 1],
             p95: times[Math.floor(0.95 * frames)] };
  }, frames);
  console.log(`${result.scenario}, ${result.balls} balls, ${frames} frames at 1920 px: median ${result.median.toFixed(3)} ms, ` +
              `95th percentile ${result.p95.toFixed(3)} ms per frame (16.7 ms at 60 frames a second)`);
} finally {
  await browser.close();
}
