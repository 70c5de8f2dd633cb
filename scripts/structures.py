#!/usr/bin/env python3
"""Writes docs/structures.md and docs/structures.png: the uniform grid (the paper's), the BVH
and --accel auto on the bundled scenes and on uneven scenes (scripts/uneven_scenes.py), side by
side in one run.

Usage: /usr/bin/python3 scripts/structures.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
                                              [--runs 3] [--h200 DIR]

Per scene and structure, primary rays only (--bounces 0 --shadows off, as the issue's table) and
the full frame (2 bounces, shadows): build ms, passes, query read-backs, fragments, voxel steps
or nodes visited, triangle tests, the cost model's ms on gf5700 / gf6600 / h200 (one run: the
statistics do not change between runs), emulator ms and CPU tracer ms (medians of --runs runs,
2 host threads). --accel auto chooses per profile: it is run with --profile gf6600 and with
--profile h200. --h200 DIR adds the GL device's wall ms on the H200 from DIR/*.json (files
written by `vgpu-rt render ... --device gl --stats-json`, named SCENE_STRUCTURE_MODE.json).
"""
import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUNDLED = ["sphere", "bunny", "bunny-refl", "classic", "teapot"]
UNEVEN = ["stadium", "scales"]
MODES = {"primary": ["--bounces", "0", "--shadows", "off"], "full": []}


def run(exe, scene, opts, js):
    cmd = [exe, "render", scene, "--stats", "none", "-q", "--stats-json", js, *opts]
    subprocess.run(cmd, check=True)
    return json.load(open(js))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--h200", help="folder of H200 --device gl JSON files")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs"))
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="structures_")
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "uneven_scenes.py"), tmp],
                   check=True, stdout=subprocess.DEVNULL)
    scenes = [(s, s) for s in BUNDLED] + [(s, os.path.join(tmp, s + ".gltf")) for s in UNEVEN]
    size = ["--size", f"{a.size}x{a.size}", "--threads", "2"]
    rows = []
    js = os.path.join(tmp, "r.json")
    for name, path in scenes:
        for mode, mopts in MODES.items():
            for acc, extra in (("grid", ["--accel", "grid"]), ("bvh", ["--accel", "bvh"]),
                               ("kdtree", ["--accel", "kdtree"]),
                               ("auto gf6600", ["--accel", "auto", "--profile", "gf6600"]),
                               ("auto h200", ["--accel", "auto", "--profile", "h200"])):
                runs = [run(a.vgpu_rt, path, size + mopts + extra, js)
                        for _ in range(a.runs if not acc.startswith("auto") else 1)]
                j = runs[0]
                row = {"scene": name, "mode": mode, "accel": acc,
                       "chosen": j["accel"]["structure"],
                       "why": j["accel"].get("auto", {}).get("why", ""),
                       "probe_ms": j["accel"].get("auto", {}).get("probe_ms", 0.0),
                       "triangles": j["triangles"],
                       "build_ms": j["accel"]["build_ms"],
                       "passes": j["totals"]["passes"],
                       "readbacks": j["totals"]["query_readbacks"],
                       "fragments": j["totals"]["fragments_shaded"],
                       "steps": j["accel"]["work"]["voxel_steps"] +
                                j["accel"]["work"]["nodes_visited"],
                       "tests": j["accel"]["work"]["triangle_tests"],
                       "gf5700": j["predicted_ms"]["gf5700"],
                       "gf6600": j["predicted_ms"]["gf6600"],
                       "h200": j["predicted_ms"]["h200"],
                       "emu_ms": statistics.median(r["render_ms"] for r in runs)}
                if not acc.startswith("auto") and mode == "primary":
                    cpu = [run(a.vgpu_rt, path, size + mopts + extra + ["--engine", "cpu"], js)
                           for _ in range(a.runs)]
                    row["cpu_ms"] = statistics.median(r["render_ms"] for r in cpu)
                if a.h200 and not acc.startswith("auto"):
                    f = os.path.join(a.h200, f"{name}_{acc}_{mode}.json")
                    if os.path.exists(f):
                        row["h200_gl_ms"] = json.load(open(f))["render_ms"]
                rows.append(row)
                print(f"{name:10s} {mode:7s} {acc:11s} -> {row['chosen']:4s} passes "
                      f"{row['passes']:7d} gf6600 {row['gf6600']:10.1f} ms h200 {row['h200']:8.1f}"
                      f" ms emulator {row['emu_ms']:8.1f} ms", file=sys.stderr)
    json.dump(rows, open(os.path.join(a.out, "structures.json"), "w"), indent=1)
    write_doc(a, rows)
    chart(a, rows)


def get(rows, scene, mode, acc):
    return next(r for r in rows if r["scene"] == scene and r["mode"] == mode and r["accel"] == acc)


def write_doc(a, rows):
    L = []
    L.append("| scene | rays | structure | build ms | passes | read-backs | fragments | "
             "steps | tests | gf5700 ms | gf6600 ms | h200 ms | emulator ms | CPU ms |"
             + (" H200 GL ms |" if a.h200 else ""))
    L.append("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
             + ("---:|" if a.h200 else ""))
    for r in rows:
        acc = r["accel"] if not r["accel"].startswith("auto") else f"{r['accel']}: {r['chosen']}"
        L.append(f"| {r['scene']} | {r['mode']} | {acc} | {r['build_ms']:.1f} | {r['passes']:,} | "
                 f"{r['readbacks']:,} | {r['fragments']:,} | {r['steps']:,} | {r['tests']:,} | "
                 f"{r['gf5700']:.0f} | {r['gf6600']:.0f} | {r['h200']:.1f} | {r['emu_ms']:.0f} | "
                 + (f"{r['cpu_ms']:.0f} |" if "cpu_ms" in r else "- |")
                 + ((f" {r['h200_gl_ms']:.1f} |" if "h200_gl_ms" in r else " - |") if a.h200 else ""))
    table = "\n".join(L)
    targets = []
    for mode in MODES:
        b = get(rows, "bunny", mode, "grid")
        for sc, limit in (("stadium", 3.0), ("scales", 5.0)):
            au = get(rows, sc, mode, "auto h200")
            targets.append(f"| {sc} / bunny ({mode}) | {limit:.0f}x | "
                           f"{au['emu_ms'] / b['emu_ms']:.2f}x | {au['h200'] / b['h200']:.2f}x | "
                           f"{au['chosen']} |")
    worse = []
    for sc in BUNDLED:
        for mode in MODES:
            g = get(rows, sc, mode, "grid")
            au = get(rows, sc, mode, "auto gf6600")
            worse.append(f"| {sc} ({mode}) | {au['chosen']} | {g['gf6600']:.0f} | "
                         f"{au['gf6600']:.0f} | {au['gf6600'] / g['gf6600']:.2f}x |")
    open(os.path.join(a.out, "structures_table.md"), "w").write(
        table + "\n\n" + "\n".join(targets) + "\n\n" + "\n".join(worse) + "\n")
    print(f"wrote {a.out}/structures.json and structures_table.md", file=sys.stderr)


def chart(a, rows):
    scenes = BUNDLED + UNEVEN
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    for ax, key, title in ((axes[0], "gf6600", "modeled GeForce 6600 (multipass)"),
                           (axes[1], "h200", "modeled H200 (multipass)"),
                           (axes[2], "emu_ms", "emulator host ms (2 threads)")):
        w = 0.27
        for k, acc in enumerate(("grid", "bvh", "kdtree")):
            vals = [get(rows, s, "primary", acc)[key] for s in scenes]
            ax.bar([i + (k - 1) * w for i in range(len(scenes))], vals, w, label=acc)
        ch = [get(rows, s, "primary", "auto gf6600" if key != "h200" else "auto h200")["chosen"]
              for s in scenes]
        ax.set_xticks(range(len(scenes)))
        ax.set_xticklabels([f"{s}\nauto: {c}" for s, c in zip(scenes, ch)], fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel("ms per frame (log)")
        ax.set_title(title + ", primary rays", fontsize=10)
        ax.legend(fontsize=8)
    fig.suptitle(f"Grid, BVH and kd-tree, {a.size}x{a.size}: where each structure wins")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "structures.png"), dpi=110)
    print(f"wrote {a.out}/structures.png", file=sys.stderr)


if __name__ == "__main__":
    main()
