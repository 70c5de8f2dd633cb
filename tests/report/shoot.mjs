// Screenshots of a report (for the docs and for looking at it): node shoot.mjs REPORT.html OUT.png [x,y]
import { createRequire } from "node:module";
import path from "node:path";
const require = createRequire(import.meta.url);
const { chromium } = require(path.resolve(path.dirname(new URL(import.meta.url).pathname), "../../host/report/node_modules/playwright-core"));
const [file, out, pick] = process.argv.slice(2);
const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
const page = await browser.newPage({ viewport: { width: 1320, height: 1000 } });
page.on("pageerror", e => console.error("pageerror:", e.message));
page.on("console", m => { if (m.type() === "error") console.error("console:", m.text()); });
const t0 = Date.now();
await page.goto("file://" + path.resolve(file));
await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
console.log("ready in", Date.now() - t0, "ms", await page.evaluate(() => document.body.dataset.error || "no error"));
if (pick) { const [x, y] = pick.split(",").map(Number); await page.evaluate(([x, y]) => window.report.showHistory(x, y, false), [x, y]); }
await page.screenshot({ path: out, fullPage: true });
await browser.close();
