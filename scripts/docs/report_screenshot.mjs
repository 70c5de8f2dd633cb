// A screenshot of a vgpu-rt HTML report in headless chromium (the one in docs/ comes from here):
//   node scripts/docs/report_screenshot.mjs REPORT.html OUT.png [--pixel X,Y] [--trace N] [--hide-idle] [--height PX]
//                                           [--element SELECTOR]
// --trace N zooms the timeline to trace N (0-based), --hide-idle hides the idle bars, --height
// cuts the page to its first PX pixels (default: the whole page), --element shoots one element
// alone (e.g. "#beams", the tile map's section). Needs scripts/setup.sh's JS.
import path from "node:path";
import { createRequire } from "node:module";

const here = path.dirname(new URL(import.meta.url).pathname);
const { chromium } = createRequire(import.meta.url)(path.join(here, "../../host/report/node_modules/playwright-core"));
const args = process.argv.slice(2);
const opt = name => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : undefined; };
const [file, out] = args;
if (!file || !out) { console.error("usage: node scripts/docs/report_screenshot.mjs REPORT.html OUT.png [options]"); process.exit(2); }
const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
try {
  const page = await browser.newPage({ viewport: { width: 1320, height: 1000 } });
  let failed = false;
  page.on("pageerror", e => { failed = true; console.error("page error:", e.message); });
  await page.goto("file://" + path.resolve(file));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  if (opt("--pixel")) await page.evaluate(p => window.report.showHistory(...p.split(",").map(Number), false), opt("--pixel"));
  if (opt("--trace")) await page.selectOption("#t-trace", opt("--trace"));
  if (args.includes("--hide-idle")) await page.evaluate(() => window.report.hideIdle());
  const h = opt("--height");
  if (opt("--element")) await page.locator(opt("--element")).screenshot({ path: out });
  else await page.screenshot({ path: out, fullPage: true, clip: h ? { x: 0, y: 0, width: 1320, height: +h } : undefined });
  if (failed) process.exitCode = 1;
} finally {
  await browser.close();
}
