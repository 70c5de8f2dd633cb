#!/usr/bin/python3
"""Speed vs accuracy sweep of the stream tracer.

For each scene (sphere, bunny, bunny-refl, classic), grid resolution (auto, 8, 16, 32 by default)
and bounce count (0, 2): one CPU reference render (--engine cpu, double precision) and one stream
render per precision (fp32, fp24, fp16, auto), all at 128x128, one host thread each. Per run it
records render_ms (host time, --stats-json), the cost model's modeled GPU time on each 2004 part
(gf5700, r300, gf6600: predicted_ms from the same counters, each format charged at the part's
rate for it) and, against the CPU reference at the same grid and bounces, the pixels rendered
wrong by three criteria (all through `vgpu-rt compare`, i.e. OpenImageIO):

  hit:    the primary hit's triangle id differs (hit AOVs, threshold 0.5);
  depth:  the distance to the primary hit differs by more than DEPTH_TOL scene units (depth AOVs;
          a hit against a miss always counts);
  colour: some channel of the linear colour differs by more than COLOUR_TOL (one 8-bit step);

plus the PSNR of the colour image. A grid the profile refuses (the render fails) is recorded with
its message and left out of the chart; a run over --timeout seconds likewise.

Writes results/sweep/sweep.csv, docs/studies/speed_vs_accuracy.png and docs/studies/accuracy.md.
Usage: /usr/bin/python3 scripts/docs/sweep.py [--grids auto,8,16,32] [--jobs 2] [--timeout 300]
                                         [--reuse WORKDIR]
       /usr/bin/python3 scripts/docs/sweep.py --plot-only   (chart and report from results/sweep/sweep.csv)
"""
import argparse
import concurrent.futures as cf
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = ["sphere", "bunny", "bunny-refl", "classic"]
PRECISIONS = ["fp32", "fp24", "fp16", "auto"]
PARTS = ["gf5700", "r300", "gf6600"]  # the 2004 profiles, modeled time of each
BOUNCES = [0, 2]
# Stated tolerances of the wrong-pixel counts (see the docstring).
DEPTH_TOL = 1e-3  # scene units: the scenes span 3 to 16 units, cameras stand 7 to 9 units away
COLOUR_TOL = 1.0 / 255.0
CRITERIA = [("hit", "wrong primary hit id"), ("depth", f"depth error > {DEPTH_TOL:g}"),
            ("colour", "colour difference > 1/255")]


def render(exe, work, scene, grid, engine, precision, bounces, size, timeout, reuse=False):
    tag = f"{scene}_{grid}_{engine}_{precision}_b{bounces}"
    out = {k: os.path.join(work, tag + s) for k, s in
           [("rgb", ".exr"), ("hit", "_hit.exr"), ("depth", "_depth.exr"), ("json", ".json")]}
    if reuse and all(os.path.exists(p) for p in out.values()):
        with open(out["json"]) as f:
            return tag, out, json.load(f), ""
    args = ["--engine", engine, "--grid", grid, "--bounces", str(bounces), "--size", size,
            "--threads", "1"] + (["--precision", precision] if engine == "stream" else [])
    t0 = time.time()
    try:
        stats = vgpurt.render(exe, scene, args, stats_json=out["json"], out=out["rgb"],
                              aovs={"hit": out["hit"], "depth": out["depth"]}, timeout=timeout)
    except subprocess.TimeoutExpired:
        return tag, out, None, f"timeout after {timeout} s"
    except vgpurt.Failed as e:
        return tag, out, None, "refused: " + e.message
    stats["_wall_s"] = time.time() - t0
    return tag, out, stats, ""


def compare(exe, a, b, threshold=None):
    share, psnr, _, _ = vgpurt.compare(exe, a, b, threshold if threshold else None)
    return share, psnr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--grids", default="auto,8,16,32")
    ap.add_argument("--out-dir", default=os.path.join(ROOT, "docs", "studies"),
                    help="where sweep.csv, speed_vs_accuracy.png and accuracy.md go")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--results-dir", default=os.path.join(ROOT, "results", "sweep"),
                    help="where sweep.csv, the raw figures, goes")
    ap.add_argument("--build", default=os.path.join(ROOT, "build-stab"))
    ap.add_argument("--plot-only", action="store_true", help="redraw the chart from results/sweep/sweep.csv")
    ap.add_argument("--reuse", metavar="DIR",
                    help="work directory of an earlier sweep: keep the renders it finished")
    args = ap.parse_args()
    SCENES[:] = args.scenes.split(",")
    if args.plot_only:
        with open(os.path.join(args.results_dir, "sweep.csv")) as f:
            rows = [dict(r, bounces=int(r["bounces"])) for r in csv.DictReader(f)]
        plot(rows, os.path.join(args.out_dir, "speed_vs_accuracy.png"), args.size)
        report(rows, os.path.join(args.out_dir, "accuracy.md"), args.size)
        return 0
    exe = os.path.join(args.build, "host", "vgpu-rt")
    grids = args.grids.split(",")
    work = args.reuse or tempfile.mkdtemp(prefix="vgpu-sweep-")
    jobs = []
    for scene in SCENES:
        for grid in grids:
            for b in BOUNCES:
                jobs.append((scene, grid, "cpu", "fp64", b))
                for prec in PRECISIONS:
                    jobs.append((scene, grid, "stream", prec, b))
    # Slow ones first so the pool drains evenly.
    order = {"fp16": 0, "fp24": 1, "fp32": 2, "auto": 2, "fp64": 3}
    jobs.sort(key=lambda j: (order[j[3]], j[0] != "bunny-refl"))
    results = {}
    t0 = time.time()
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        futs = {pool.submit(render, exe, work, j[0], j[1], j[2], j[3], j[4], args.size,
                            args.timeout, bool(args.reuse)): j for j in jobs}
        for n, fut in enumerate(cf.as_completed(futs), 1):
            j = futs[fut]
            results[j] = fut.result()
            _, _, stats, err = results[j]
            ms = f"{stats['render_ms']:.0f} ms" if stats else err
            print(f"[{n}/{len(jobs)} {time.time() - t0:5.0f} s] {' '.join(map(str, j))}: {ms}",
                  flush=True)

    rows = []
    for (scene, grid, engine, prec, b), (tag, out, stats, err) in sorted(results.items()):
        row = {"scene": scene, "grid": grid, "engine": engine, "precision": prec, "bounces": b,
               "grid_res": "", "render_ms": "", "pixels": "", "wrong_hit_px": "",
               "wrong_depth_px": "", "wrong_colour_px": "", "wrong_hit_share": "", "psnr_db": "",
               "rays_unfinished": "", "voxel_format": "", "voxel_why": "",
               "status": err or "ok"}
        for part in PARTS:
            row[f"modeled_{part}_ms"] = ""
        if stats:
            row["grid_res"] = "x".join(map(str, stats.get("grid", [])))
            row["render_ms"] = f"{stats['render_ms']:.3f}"
            row["rays_unfinished"] = stats.get("rays_unfinished", 0)
            for part in PARTS:
                if part in (stats.get("predicted_ms") or {}):
                    row[f"modeled_{part}_ms"] = f"{stats['predicted_ms'][part]:.3f}"
            if "formats" in stats:
                row["voxel_format"] = stats["formats"]["voxel"]["texels"]
                row["voxel_why"] = stats["formats"]["voxel"]["why"]
            pixels = stats["size"][0] * stats["size"][1]
            row["pixels"] = pixels
            ref = results.get((scene, grid, "cpu", "fp64", b))
            if ref and ref[2]:
                if engine == "cpu":
                    row.update(wrong_hit_px=0, wrong_depth_px=0, wrong_colour_px=0,
                               wrong_hit_share="0", psnr_db="inf")
                else:
                    hit, _ = compare(exe, out["hit"], ref[1]["hit"], 0.5)
                    depth, _ = compare(exe, out["depth"], ref[1]["depth"], DEPTH_TOL)
                    colour, psnr = compare(exe, out["rgb"], ref[1]["rgb"], COLOUR_TOL)
                    row["wrong_hit_px"] = round(hit * pixels)
                    row["wrong_depth_px"] = round(depth * pixels)
                    row["wrong_colour_px"] = round(colour * pixels)
                    row["wrong_hit_share"] = f"{hit:.6f}"
                    row["psnr_db"] = "inf" if math.isinf(psnr) else f"{psnr:.2f}"
            elif engine != "cpu":
                row["status"] += " (no cpu reference)"
        rows.append(row)

    os.makedirs(args.out_dir, exist_ok=True)
    os.makedirs(args.results_dir, exist_ok=True)
    csv_path = os.path.join(args.results_dir, "sweep.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {csv_path} ({len(rows)} runs, {time.time() - t0:.0f} s)")
    plot(rows, os.path.join(args.out_dir, "speed_vs_accuracy.png"), args.size)
    report(rows, os.path.join(args.out_dir, "accuracy.md"), args.size)


def num(r, key):
    return float(r[key]) if r.get(key, "") not in ("", None) else None


def pareto(points):
    """The points no other beats in both time and error (lower is better in both)."""
    front, best = [], math.inf
    for x, y in sorted(points):
        if y < best:
            front.append((x, y))
            best = y
    return front


def plot(rows, path, size):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"fp64": "black", "fp32": "tab:blue", "fp24": "tab:green", "fp16": "tab:red",
               "auto": "tab:purple"}
    markers = {0: "o", 2: "^"}
    psnr_cap = 120.0
    # (error key, time column, x label): the speed axis is the modeled GPU time of a 2004 part;
    # the emulator's host time has its own panel (it charges fp16 for emulating its rounding).
    panels = [("hit", "modeled_gf5700_ms", "modeled GeForce FX 5700 time [ms]"),
              ("psnr", "modeled_gf5700_ms", "modeled GeForce FX 5700 time [ms]"),
              ("hit", "modeled_r300_ms", "modeled Radeon 9700 Pro time [ms]"),
              ("hit", "render_ms", "host (emulator) time [ms], 1 thread")]
    ylabels = {"hit": "wrong primary hit id\n[% of pixels, symlog]",
               "psnr": f"PSNR vs CPU fp64 [dB]\n(inf drawn at {psnr_cap:.0f}; higher is better)"}
    fig, axes = plt.subplots(len(panels), len(SCENES), figsize=(4.2 * len(SCENES), 15),
                             squeeze=False)
    for c, scene in enumerate(SCENES):
        for k, (key, tcol, xlabel) in enumerate(panels):
            ax = axes[k][c]
            pts = []
            for r in rows:
                if (r["scene"] != scene or r["engine"] != "stream" or r.get(tcol, "") == ""
                        or r["psnr_db"] == ""):
                    continue
                x = float(r[tcol])
                if key == "psnr":
                    y = min(float(r["psnr_db"]), psnr_cap)
                else:
                    y = 100.0 * float(r["wrong_hit_px"]) / float(r["pixels"])
                ax.scatter(x, y, color=colours[r["precision"]], marker=markers[r["bounces"]],
                           s=36, alpha=0.85, edgecolors="none")
                ax.annotate(r["grid"], (x, y), fontsize=6, xytext=(3, 2),
                            textcoords="offset points")
                pts.append((x, -y if key == "psnr" else y))
                if r["precision"] == "fp32" and r["grid"] == "auto" and r["bounces"] == 2:
                    ax.scatter(x, y, s=160, facecolors="none", edgecolors="black",
                               linewidths=1.2, zorder=3)  # the CLI's defaults
            front = pareto(pts)
            if front:
                fx = [p[0] for p in front]
                fy = [-p[1] if key == "psnr" else p[1] for p in front]
                ax.step(fx, fy, where="post", color="gray", linewidth=1, linestyle="--",
                        zorder=1)
            ax.set_xscale("log")
            if key == "hit":
                ax.set_yscale("symlog", linthresh=0.01)
                ax.set_ylim(-0.002, 100)
            ax.grid(True, which="both", alpha=0.3)
            ax.set_xlabel(xlabel, fontsize=8)
            if c == 0:
                ax.set_ylabel(ylabels[key])
        axes[0][c].set_title(scene)
    handles = [plt.Line2D([], [], color=colours[p], marker="s", linestyle="", label=p)
               for p in PRECISIONS]
    handles += [plt.Line2D([], [], color="gray", marker=markers[b], linestyle="",
                           label=f"{b} bounces") for b in BOUNCES]
    handles += [plt.Line2D([], [], color="gray", linestyle="--", label="Pareto front"),
                plt.Line2D([], [], marker="o", markersize=10, markerfacecolor="none",
                           markeredgecolor="black", linestyle="",
                           label="defaults (fp32, grid auto, 2 bounces)")]
    fig.suptitle(f"Stream tracer, {size}: modeled 2004 GPU time vs accuracy against the CPU fp64 "
                 "reference (labels = grid; fp24 on the FX 5700 runs on its fp32 units; "
                 "timed-out runs omitted)", y=0.995, fontsize=10)
    fig.legend(handles=handles, loc="upper center", ncol=9, frameon=False,
               bbox_to_anchor=(0.5, 0.978), fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.955))
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


def report(rows, path, size):
    """docs/studies/accuracy.md: wrong pixels per precision mode, by criterion."""
    ok = [r for r in rows if r["render_ms"] != "" and r["wrong_hit_px"] != ""]
    grids = sorted({r["grid"] for r in rows}, key=lambda g: (g != "auto", g.zfill(4)))
    pixels = int(ok[0]["pixels"]) if ok else 0
    L = []
    L.append("# Accuracy per precision mode: wrong pixels against the CPU reference\n")
    L.append("Written by `/usr/bin/python3 scripts/docs/sweep.py` (do not edit by hand; the same runs "
             "as `results/sweep/sweep.csv` and `docs/studies/speed_vs_accuracy.png`).\n")
    L.append(f"Every stream render (`--engine stream --precision P`) is compared with the CPU "
             f"tracer (`--engine cpu`, double precision) at the same scene, grid and bounce "
             f"count, {size} ({pixels} pixels), through `vgpu-rt compare` (OpenImageIO). A pixel "
             f"is wrong by:\n")
    L.append("- **hit**: its primary hit's triangle id differs (a hit against a miss included);")
    L.append(f"- **depth**: its distance to the primary hit differs by more than "
             f"**{DEPTH_TOL:g} scene units** (the scenes span 3 to 16 units and the cameras "
             f"stand 7 to 9 units from their targets, so about 1e-4 of the viewing distance; "
             f"a hit against a miss counts);")
    L.append(f"- **colour**: some channel of the linear colour differs by more than "
             f"**1/255** (one 8-bit step of the PNG output).\n")
    L.append("## Per precision mode, all scenes and grids\n")
    L.append("Sums over every run that finished (scenes x grids x bounces); *runs* counts them, "
             "*timed out / refused* the ones left out.\n")
    L.append("*auto* is `--precision auto`: per group of textures and kernels, the fewest bits "
             "the part has that keep the scene's integers exact (see the last section). Modeled "
             "times are the cost model's (docs/studies/table1.md) on each 2004 part, medians over the "
             "runs; fp24 on the FX 5700 and 6600 runs on their fp32 units, fp32 and fp16 on the "
             "R300 on its fp24 units.\n")
    L.append("| precision | runs | timed out / refused | pixels compared | wrong hit | wrong depth "
             "| wrong colour | median PSNR [dB] | " +
             " | ".join(f"median modeled {p} [ms]" for p in PARTS) + " | median host [ms] |")
    L.append("|---|---:|---:|---:|---:|---:|---:|---:|" + "---:|" * (len(PARTS) + 1))
    for prec in PRECISIONS:
        rs = [r for r in ok if r["precision"] == prec]
        bad = [r for r in rows if r["precision"] == prec and r["render_ms"] == ""]
        tot = sum(int(r["pixels"]) for r in rs)
        cells = []
        for key, _ in CRITERIA:
            n = sum(int(r[f"wrong_{key}_px"]) for r in rs)
            cells.append(f"{n} ({100.0 * n / tot:.3g}%)" if tot else "")
        med = statistics.median(float(r["psnr_db"]) for r in rs) if rs else None
        times = []
        for col in [f"modeled_{p}_ms" for p in PARTS] + ["render_ms"]:
            v = [float(r[col]) for r in rs if r.get(col, "") != ""]
            times.append(f"{statistics.median(v):.0f}" if v else "")
        L.append(f"| {prec} | {len(rs)} | {len(bad)} | {tot} | " + " | ".join(cells) +
                 f" | {'' if med is None else 'inf' if med == math.inf else f'{med:.1f}'} | " +
                 " | ".join(times) + " |")
    L.append("")
    L.append("## Per scene and grid\n")
    L.append("Wrong pixels as *hit / depth / colour* (of " + str(pixels) + "), for 0 and 2 "
             "bounces; *t/o*: over the time limit (fp16 rays that never leave the grid run the "
             "pass loop to its cap).\n")
    head = "| scene | grid | bounces | " + " | ".join(PRECISIONS) + " |"
    L.append(head)
    L.append("|---|---|---:|" + "---:|" * len(PRECISIONS))
    index = {(r["scene"], r["grid"], r["precision"], int(r["bounces"])): r for r in rows}
    for scene in [s for s in SCENES if any(r["scene"] == s for r in rows)]:
        for grid in grids:
            for b in BOUNCES:
                cells = []
                for prec in PRECISIONS:
                    r = index.get((scene, grid, prec, b))
                    if not r:
                        cells.append("")
                    elif r["wrong_hit_px"] == "":
                        cells.append("t/o" if "timeout" in r["status"] else "refused")
                    else:
                        cells.append(f"{r['wrong_hit_px']} / {r['wrong_depth_px']} / "
                                     f"{r['wrong_colour_px']}")
                res = next((r["grid_res"] for p in ["fp64"] + PRECISIONS
                            for r in [index.get((scene, grid, p, b))] if r and r["grid_res"]), "")
                L.append(f"| {scene} | {grid}" + (f" ({res})" if grid == "auto" and res else "") +
                         f" | {b} | " + " | ".join(cells) + " |")
    L.append("")
    L.append("## What breaks first at fp16 and at fp24\n")
    L.append("Integers the kernels address texels with (list positions, triangle ids, voxel "
             "pointer texels) are exact in a format only while the texel centre id + 1/2 is: "
             "below **1024 in fp16** and **65536 in fp24** (host/model/formats.h). *largest integer* is "
             "what `--precision auto` reports for the scene's voxel state at the auto grid; "
             "*wrong hit* sums over every grid and bounce count. Where the integers fit, the "
             "first to break are the floating-point quantities: t and the barycentrics at "
             "triangle edges and voxel boundaries.\n")
    L.append("| scene | largest integer (auto grid) | fp16 | wrong hit fp16 | fp24 | wrong hit fp24 "
             "| wrong hit auto |")
    L.append("|---|---|---|---:|---|---:|---:|")
    for scene in [s for s in SCENES if any(r["scene"] == s for r in rows)]:
        a = index.get((scene, "auto", "auto", 2)) or index.get((scene, "auto", "auto", 0))
        why = a["voxel_why"] if a and a.get("voxel_why") else ""
        m = re.search(r"(list positions|triangle ids|voxel pointer texels|voxel indices) reach "
                      r"(\d+)", why)
        need = int(m.group(2)) if m else None
        def wrong(prec):
            return sum(int(r["wrong_hit_px"]) for r in ok
                       if r["scene"] == scene and r["precision"] == prec)
        def first(limit):
            if need is None:
                return ""
            if need > limit:
                return f"{m.group(1)} first ({need} > {limit})"
            return f"integers fit ({need} <= {limit}); t and barycentrics first"
        L.append(f"| {scene} | {m.group(1) + ' ' + str(need) if m else ''} | {first(1023)} | "
                 f"{wrong('fp16')} | {first(65535)} | {wrong('fp24')} | {wrong('auto')} |")
    L.append("")
    with open(path, "w") as f:
        f.write("\n".join(L))
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
