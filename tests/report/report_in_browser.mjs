// The HTML report as a person would check it: vgpu-rt writes a report, headless chromium (driven
// by playwright-core) opens it from disk; the test fails on any page script error, clicks a
// pixel of the image and compares the history the page shows with that pixel's --trace-pixel
// output, line by line, and compares the timeline's sums with the --stats-json totals; the
// predicted-time table shows the statistics' predictions, the looping passes' longest lanes on
// the h200 in a looping frame; a frame with beams draws its tile map where the image has its
// tiles (grey where a tile missed the grid and none of its pixels hits).
// Usage: node report_in_browser.mjs VGPU_RT WORK_DIR
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";

const here = path.dirname(new URL(import.meta.url).pathname);
const require = createRequire(import.meta.url);
const { chromium } = require(path.join(here, "../../host/report/node_modules/playwright-core"));
const [vgpu, work] = process.argv.slice(2);
fs.mkdirSync(work, { recursive: true });
const html = path.join(work, "sphere.html"), stats = path.join(work, "sphere.json");
const [px, py] = [37, 29];  // on the sphere; off the 16-pixel sample grid (kept: it is traced)
const trace = execFileSync(vgpu, ["render", "sphere", "--size", "64x48", "--quiet", "--stats", "none",
  "--threads", "2", "--report", html, "--stats-json", stats, "--trace-pixel", `${px},${py}`], { encoding: "utf8" });
// The pass lines of the trace (not "pixel x,y:" or "iteration n:").
const expected = trace.split("\n").filter(l => l.startsWith("  "));

let failed = 0, passed = 0;
const check = (ok, what) => { if (ok) ++passed; else { ++failed; console.error("FAILED: " + what); } };

const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--no-sandbox",
  "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
  "--disable-component-update", "--disable-sync"] });
try {
  const page = await browser.newPage({ viewport: { width: 1320, height: 1000 } });
  const errors = [];
  page.on("pageerror", e => errors.push(e.message));
  page.on("console", m => { if (m.type() === "error") errors.push(m.text()); });
  page.on("request", r => { if (!r.url().startsWith("file:") && !r.url().startsWith("data:")) errors.push("network request: " + r.url()); });
  await page.goto("file://" + path.resolve(html));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  check(errors.length === 0 && !(await page.evaluate(() => document.body.dataset.error)), `no script errors (${errors.join("; ")})`);

  // Click the pixel on the image as a person would: the canvas is scaled up.
  const box = await page.locator("#img").boundingBox();
  await page.mouse.click(box.x + (px + 0.5) * box.width / 64, box.y + (py + 0.5) * box.height / 48);
  check(await page.evaluate(() => document.body.dataset.historyPixel) === `${px},${py}`, "the click picks the pixel");
  // A long history is shown a page at a time: all of it, as a person would ask for it.
  if (!(await page.isDisabled("#h-all"))) await page.click("#h-all");
  const rows = await page.$$eval("#history tr", trs => trs.slice(1).map(tr => Array.from(tr.children, td => td.textContent)));
  // Columns: #, pass, iteration, trace, paper name, kernel, writes, state/query. Printed as
  // PassRunner::pass and ::count (host/trace/passes.cpp) print them.
  const shown = rows.map(r => r[7].startsWith("query:")
    ? `  ${r[4].padEnd(22)} ${r[5].padEnd(24)}    ${r[7]}`
    : `  ${r[4].padEnd(22)} ${r[5].padEnd(24)} -> ${r[6].padEnd(14)} ${r[7]}`);
  check(shown.length === expected.length, `the page lists ${shown.length} passes for the pixel, --trace-pixel ${expected.length}`);
  let first = -1;
  for (let i = 0; i < Math.min(shown.length, expected.length); ++i) if (shown[i] !== expected[i]) { first = i; break; }
  check(first < 0, first < 0 ? "" : `history row ${first + 1}:\n  page:  ${shown[first]}\n  trace: ${expected[first]}`);
  check(shown.length > 10 && shown[0].includes("generadorRayos") && shown[1].includes("initTraversal"), "the known first passes: generadorRayos, initTraversal");

  const totals = JSON.parse(fs.readFileSync(stats, "utf8")).totals;
  const sums = await page.evaluate(() => window.report.timelineTotals());
  for (const [k, v] of Object.entries(sums)) check(totals[k] === v, `timeline sum of ${k}: ${v}, statistics ${totals[k]}`);

  // The predicted-time table: one column per card, its total the statistics' predicted_ms.
  const cell = (key, card) => page.$eval(`#predicted tr[data-key="${key}"] td[data-card="${card}"]`, td => +td.textContent);
  const predicted = JSON.parse(fs.readFileSync(stats, "utf8")).predicted_ms;
  for (const [card, ms] of Object.entries(predicted))
    if (ms !== null) check(Math.abs((await cell("total_ms", card)) - ms) < 0.001, `predicted total on ${card}: ${ms}`);
  check(await cell("latency_ms", "h200") === 0, "no longest-lane latency in a multipass frame");

  // A looping frame on the h200: its longest lanes are priced, on the h200 alone.
  const lhtml = path.join(work, "looping.html"), lstats = path.join(work, "looping.json");
  execFileSync(vgpu, ["render", "sphere", "--size", "32x32", "--quiet", "--stats", "none", "--threads", "2",
    "--kernels", "looping", "--profile", "h200", "--bounces", "0", "--report", lhtml, "--stats-json", lstats]);
  await page.goto("file://" + path.resolve(lhtml));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  check(errors.length === 0 && !(await page.evaluate(() => document.body.dataset.error)), `no script errors in the looping frame's report (${errors.join("; ")})`);
  const lb = JSON.parse(fs.readFileSync(lstats, "utf8")).predicted_breakdown;
  check(lb.h200.latency_ms > 0 && Math.abs((await cell("latency_ms", "h200")) - lb.h200.latency_ms) < 0.001, `the h200's longest lanes: ${lb.h200.latency_ms} ms`);
  check(await cell("latency_ms", "gf6600") === 0, "no latency on gf6600, whose latencies are not modeled");

  // A frame with beams: the tile map's squares, as the page drew them, against the image's own
  // hits and depths (48x32 in 8x8 tiles: 6 across, 4 down, so a map drawn down its columns
  // fails). A grey square's tile missed the grid: none of its pixels hits; any other square's
  // rays start no farther than its nearest hit; the grey squares are the JSON's missed tiles.
  const bhtml = path.join(work, "beams.html"), bstats = path.join(work, "beams.json");
  execFileSync(vgpu, ["render", "bunny-low", "--size", "48x32", "--quiet", "--stats", "none", "--threads", "2",
    "--bounces", "0", "--shadows", "off", "--beams", "on", "--report", bhtml, "--stats-json", bstats]);
  await page.goto("file://" + path.resolve(bhtml));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  check(errors.length === 0 && !(await page.evaluate(() => document.body.dataset.error)), `no script errors in the beams frame's report (${errors.join("; ")})`);
  check(await page.isVisible("#beams"), "the tile map's section is shown for a frame with beams");
  const tiles = await page.evaluate(async () => {
    const c = document.getElementById("beam-map"), px = +c.dataset.tilePx, ctx = c.getContext("2d");
    const hit = await unpack(D.hit, Float32Array), depth = await unpack(D.depth, Float32Array);
    const start = await unpack(D.beam_map.start, Float32Array);
    const out = [];
    for (let ty = 0; ty < 4; ++ty)
      for (let tx = 0; tx < 6; ++tx) {
        const p = ctx.getImageData(tx * px + 1, ty * px + 1, 1, 1).data;
        let hits = 0, nearest = Infinity;
        for (let y = ty * 8; y < ty * 8 + 8; ++y)
          for (let x = tx * 8; x < tx * 8 + 8; ++x)
            if (hit[y * W + x] >= 0) { ++hits; nearest = Math.min(nearest, depth[y * W + x]); }
        out.push({ tx, ty, grey: p[0] === 200 && p[1] === 200 && p[2] === 200, hits, nearest, start: start[ty * 6 + tx] });
      }
    return { dims: c.dataset.tiles, out };
  });
  check(tiles.dims === "6x4", `the map is 6x4 tiles (${tiles.dims})`);
  const greys = tiles.out.filter(t => t.grey);
  const bj = JSON.parse(fs.readFileSync(bstats, "utf8")).beams;
  check(greys.length === bj.tiles_missed && greys.length > 0 && greys.length < 24, `${greys.length} grey tiles, ${bj.tiles_missed} missed`);
  for (const t of tiles.out) {
    if (t.grey) check(t.hits === 0, `grey tile ${t.tx},${t.ty} has no hit (${t.hits})`);
    else check(t.start <= t.nearest, `tile ${t.tx},${t.ty}: rays start at ${t.start}, before the nearest hit ${t.nearest}`);
  }

  // Beams through the kd-tree: the map shades each tile by the depth of the node its rays start
  // at; a grey square's tile missed the tree's box (none of its pixels hits); every other one
  // names a node of the tree no deeper than the tree, and the deepest tile is drawn yellow.
  const khtml = path.join(work, "kd-beams.html"), kstats = path.join(work, "kd-beams.json");
  execFileSync(vgpu, ["render", "bunny-low", "--size", "48x32", "--quiet", "--stats", "none", "--threads", "2",
    "--bounces", "0", "--shadows", "off", "--accel", "kdtree", "--beams", "on", "--beam-tile", "4", "--report", khtml, "--stats-json", kstats]);
  await page.goto("file://" + path.resolve(khtml));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  check(errors.length === 0 && !(await page.evaluate(() => document.body.dataset.error)), `no script errors in the kd-tree beams frame's report (${errors.join("; ")})`);
  const kd = await page.evaluate(async () => {
    const c = document.getElementById("beam-map"), px = +c.dataset.tilePx, ctx = c.getContext("2d");
    const hit = await unpack(D.hit, Float32Array);
    const node = await unpack(D.beam_map.start, Float32Array), depth = await unpack(D.beam_map.steps, Float32Array);
    const out = [];
    for (let ty = 0; ty < 8; ++ty)
      for (let tx = 0; tx < 12; ++tx) {
        const p = ctx.getImageData(tx * px + 1, ty * px + 1, 1, 1).data;
        let hits = 0;
        for (let y = ty * 4; y < ty * 4 + 4; ++y)
          for (let x = tx * 4; x < tx * 4 + 4; ++x) if (hit[y * W + x] >= 0) ++hits;
        out.push({ tx, ty, rgb: [p[0], p[1], p[2]], grey: p[0] === 200 && p[1] === 200 && p[2] === 200, hits, node: node[ty * 12 + tx], depth: depth[ty * 12 + tx] });
      }
    return { tree: D.beam_map.tree, legend: document.getElementById("beam-legend").textContent, out };
  });
  const kj = JSON.parse(fs.readFileSync(kstats, "utf8"));
  check(kd.tree === true, "the kd-tree frame's map is a tree's");
  check(kd.legend.includes("missed the kd-tree"), `the legend names the kd-tree (${kd.legend})`);
  const kgreys = kd.out.filter(t => t.grey);
  check(kgreys.length === kj.beams.tiles_missed && kgreys.length > 0, `${kgreys.length} grey tiles, ${kj.beams.tiles_missed} missed`);
  const deepest = Math.max(...kd.out.filter(t => !t.grey).map(t => t.depth));
  for (const t of kd.out) {
    if (t.grey) { check(t.hits === 0, `grey tile ${t.tx},${t.ty} has no hit (${t.hits})`); continue; }
    check(t.node >= 0 && t.node < kj.accel.nodes && t.depth <= kj.accel.depth, `tile ${t.tx},${t.ty}: node ${t.node} at depth ${t.depth}`);
    // viridis ends in yellow (red and green high, blue low).
    if (t.depth === deepest) check(t.rgb[0] > 200 && t.rgb[1] > 200 && t.rgb[2] < 100, `the deepest tile ${t.tx},${t.ty} is yellow (${t.rgb})`);
  }
  check(deepest > 0, `some tile starts below the root (deepest ${deepest})`);

  // An adaptive frame (the budget criterion, the default): the search's section, one table row
  // per level of the JSON, one point per counting pass (the first level's first count, every
  // pixel that hits, is the budget's base, not a step), and the pixels marked within budget.
  const ahtml = path.join(work, "budget.html"), astats = path.join(work, "budget.json");
  execFileSync(vgpu, ["render", "bunny-refl", "--size", "24x24", "--quiet", "--stats", "none", "--threads", "2",
    "--bounces", "1", "--aa", "adaptive", "--spp", "16", "--report", ahtml, "--stats-json", astats]);
  await page.goto("file://" + path.resolve(ahtml));
  await page.waitForFunction(() => document.body.dataset.ready === "1" || document.body.dataset.error, null, { timeout: 60000 });
  check(errors.length === 0 && !(await page.evaluate(() => document.body.dataset.error)), `no script errors in the adaptive frame's report (${errors.join("; ")})`);
  check(await page.isVisible("#budget"), "the budget's section is shown for an adaptive frame");
  // This frame's 74k passes: the centre pixel's history is shown 2,000 rows at a time.
  const paging = await page.evaluate(() => {
    const first = () => +document.querySelector("#history tr:nth-child(2) td").textContent;
    const n = () => document.querySelectorAll("#history tr").length - 1;
    const [x, y] = document.body.dataset.historyPixel.split(",").map(Number);
    const total = window.report.historyRows(x, y).length, out = { total, range: document.getElementById("h-range").textContent, rows: n(), first: first() };
    document.getElementById("h-next").click();
    Object.assign(out, { nextFirst: first(), nextRows: n() });
    document.getElementById("h-all").click();
    return Object.assign(out, { allRows: n(), allDisabled: document.getElementById("h-all").disabled });
  });
  check(paging.total > 4000 && paging.rows === 2000 && paging.first === 1 && paging.range === `rows 1 to 2,000 of ${paging.total.toLocaleString("en-US")}`,
        `the long history's first page: ${paging.rows} rows from ${paging.first}, "${paging.range}" (${paging.total} in all)`);
  check(paging.nextFirst === 2001 && paging.nextRows === 2000, `the next page starts at row ${paging.nextFirst} (${paging.nextRows} rows)`);
  check(paging.allRows === paging.total && paging.allDisabled, `all rows: ${paging.allRows} of ${paging.total}`);
  const levels = JSON.parse(fs.readFileSync(astats, "utf8")).sampling.budget_levels;
  const drawn = await page.evaluate(() => {
    const rows = [...document.querySelectorAll("#budget-levels tbody tr")].map(tr => [...tr.cells].map(td => td.textContent));
    const chart = Chart.getChart("budget-chart");
    return { rows, points: chart.data.datasets.filter((d, i) => i % 2 === 0).map(d => d.data.length) };
  });
  check(drawn.rows.length === levels.length && levels.length === 2, `${drawn.rows.length} table rows, ${levels.length} levels`);
  levels.forEach((l, i) => {
    const row = drawn.rows[i] || [];
    check(+row[1].replace(/,/g, "") === l.budget_pixels, `level ${i + 1}: budget ${row[1]} (${l.budget_pixels})`);
    check(Math.abs(+row[2] - l.threshold) <= 1e-5 * l.threshold, `level ${i + 1}: threshold ${row[2]} (${l.threshold})`);
    check(drawn.points[i] === l.counting_passes - (i === 0 ? 1 : 0), `level ${i + 1}: ${drawn.points[i]} points, ${l.counting_passes} counting passes`);
    const marked = +row[4].replace(/,/g, "");
    check(marked > 0 && marked <= l.budget_pixels, `level ${i + 1}: ${marked} pixels that hit marked, budget ${l.budget_pixels}`);
  });
} finally {
  await browser.close();
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
