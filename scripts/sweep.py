#!/usr/bin/python3
"""Speed vs accuracy sweep of the stream tracer.

For each scene (sphere, bunny, bunny-refl, classic), grid resolution (auto, 8, 32 by default; 16 is left out to keep
the sweep near 10 minutes on 2 cores, since fp16 runs hit the pass cap and take 30-60 s each at one
thread; add it with --grids auto,8,16,32) and bounce
count (0, 2): one CPU reference render (--engine cpu, double precision) and one stream render per
precision (fp32, fp24, fp16), all at 128x128. Per run it records render_ms (--stats-json), the
share of pixels whose primary hit id differs from the CPU reference at the same grid and bounces
(`vgpu-rt compare` of the hit AOVs, threshold 0.5) and the PSNR of the colour image against the
reference (`vgpu-rt compare` of linear EXRs). A grid the profile refuses (the render fails) is
recorded with its message and left out of the chart; a run over --timeout seconds likewise.

Writes docs/sweep.csv and docs/speed_vs_accuracy.png.
Usage: /usr/bin/python3 scripts/sweep.py [--grids auto,8,32] [--jobs 2] [--timeout 60]
"""
import argparse
import concurrent.futures as cf
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["sphere", "bunny", "bunny-refl", "classic"]
PRECISIONS = ["fp32", "fp24", "fp16"]
BOUNCES = [0, 2]


def render(exe, work, scene, grid, engine, precision, bounces, size, timeout):
    tag = f"{scene}_{grid}_{engine}_{precision}_b{bounces}"
    out = {k: os.path.join(work, tag + s) for k, s in
           [("rgb", ".exr"), ("hit", "_hit.exr"), ("json", ".json")]}
    cmd = [exe, "render", scene, "--engine", engine, "--grid", grid, "--bounces", str(bounces),
           "--size", size, "--out", out["rgb"], "--aov", "hit=" + out["hit"],
           "--stats-json", out["json"], "--quiet", "--stats", "none", "--threads", "1"]
    if engine == "stream":
        cmd += ["--precision", precision]
    t0 = time.time()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return tag, out, None, f"timeout after {timeout} s"
    if p.returncode != 0:
        msg = (p.stderr.strip() or p.stdout.strip()).splitlines()
        return tag, out, None, "refused: " + (msg[-1] if msg else f"exit {p.returncode}")
    with open(out["json"]) as f:
        stats = json.load(f)
    stats["_wall_s"] = time.time() - t0
    return tag, out, stats, ""


def compare(exe, a, b, threshold=None):
    cmd = [exe, "compare", a, b] + (["--threshold", str(threshold)] if threshold else [])
    p = subprocess.run(cmd, capture_output=True, text=True)
    text = p.stdout + p.stderr
    share = re.search(r"([0-9.eE+-]+)% of pixels differ", text)
    psnr = re.search(r"PSNR ([0-9.eE+-]+|inf)", text)
    if not share:
        raise RuntimeError(f"cannot parse compare output: {text!r}")
    return float(share.group(1)) / 100.0, (float(psnr.group(1)) if psnr else math.inf)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", default="auto,8,32")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--build", default=os.path.join(ROOT, "build-stab"))
    ap.add_argument("--plot-only", action="store_true", help="redraw the chart from docs/sweep.csv")
    args = ap.parse_args()
    if args.plot_only:
        with open(os.path.join(ROOT, "docs", "sweep.csv")) as f:
            rows = [dict(r, bounces=int(r["bounces"])) for r in csv.DictReader(f)]
        plot(rows, os.path.join(ROOT, "docs", "speed_vs_accuracy.png"), args.size)
        return 0
    exe = os.path.join(args.build, "host", "vgpu-rt")
    grids = args.grids.split(",")
    work = tempfile.mkdtemp(prefix="vgpu-sweep-")
    jobs = []
    for scene in SCENES:
        for grid in grids:
            for b in BOUNCES:
                jobs.append((scene, grid, "cpu", "fp64", b))
                for prec in PRECISIONS:
                    jobs.append((scene, grid, "stream", prec, b))
    # Slow ones first so the pool drains evenly.
    order = {"fp16": 0, "fp24": 1, "fp32": 2, "fp64": 3}
    jobs.sort(key=lambda j: (order[j[3]], j[0] != "bunny-refl"))
    results = {}
    t0 = time.time()
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        futs = {pool.submit(render, exe, work, j[0], j[1], j[2], j[3], j[4], args.size,
                            args.timeout): j for j in jobs}
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
               "grid_res": "", "render_ms": "", "wrong_hit_share": "", "psnr_db": "",
               "rays_unfinished": "", "status": err or "ok"}
        if stats:
            row["grid_res"] = "x".join(map(str, stats.get("grid", [])))
            row["render_ms"] = f"{stats['render_ms']:.3f}"
            row["rays_unfinished"] = stats.get("rays_unfinished", 0)
            ref = results.get((scene, grid, "cpu", "fp64", b))
            if ref and ref[2]:
                if engine == "cpu":
                    row["wrong_hit_share"], row["psnr_db"] = "0", "inf"
                else:
                    share, _ = compare(exe, out["hit"], ref[1]["hit"], 0.5)
                    _, psnr = compare(exe, out["rgb"], ref[1]["rgb"])
                    row["wrong_hit_share"] = f"{share:.6f}"
                    row["psnr_db"] = "inf" if math.isinf(psnr) else f"{psnr:.2f}"
            elif engine != "cpu":
                row["status"] += " (no cpu reference)"
        rows.append(row)

    os.makedirs(os.path.join(ROOT, "docs"), exist_ok=True)
    csv_path = os.path.join(ROOT, "docs", "sweep.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {csv_path} ({len(rows)} runs, {time.time() - t0:.0f} s)")
    plot(rows, os.path.join(ROOT, "docs", "speed_vs_accuracy.png"), args.size)


def plot(rows, path, size):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"fp64": "black", "fp32": "tab:blue", "fp24": "tab:green", "fp16": "tab:red"}
    markers = {0: "o", 2: "^"}
    psnr_cap = 120.0
    fig, axes = plt.subplots(2, len(SCENES), figsize=(4.2 * len(SCENES), 7.5), squeeze=False)
    for c, scene in enumerate(SCENES):
        top, bot = axes[0][c], axes[1][c]
        for r in rows:
            if r["scene"] != scene or r["render_ms"] == "" or r["psnr_db"] == "":
                continue
            x = float(r["render_ms"])
            psnr = min(float(r["psnr_db"]), psnr_cap)
            share = 100 * float(r["wrong_hit_share"])
            kw = dict(color=colours[r["precision"]], marker=markers[r["bounces"]], s=36,
                      alpha=0.85, edgecolors="none")
            top.scatter(x, psnr, **kw)
            bot.scatter(x, share, **kw)
            for ax, y in ((top, psnr), (bot, share)):
                ax.annotate(r["grid"], (x, y), fontsize=6, xytext=(3, 2), textcoords="offset points")
        top.set_title(scene)
        for ax in (top, bot):
            ax.set_xscale("log")
            ax.grid(True, which="both", alpha=0.3)
        top.set_ylabel(f"PSNR vs CPU fp64 [dB] (inf drawn at {psnr_cap:.0f})")
        bot.set_ylabel("wrong primary hit ids [% of pixels]")
        bot.set_xlabel(f"render time [ms], {size}, 1 host thread (log)")
    handles = [plt.Line2D([], [], color=colours[p], marker="s", linestyle="", label=p)
               for p in ["fp64", "fp32", "fp24", "fp16"]]
    handles += [plt.Line2D([], [], color="gray", marker=markers[b], linestyle="",
                           label=f"{b} bounces") for b in BOUNCES]
    fig.suptitle("Stream tracer: render time vs accuracy against the CPU fp64 reference "
                 "(labels = grid; timed-out runs omitted)", y=0.99, fontsize=11)
    fig.legend(handles=handles, loc="upper center", ncol=6, frameon=False,
               bbox_to_anchor=(0.5, 0.955))
    fig.tight_layout(rect=(0, 0, 1, 0.91))
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
