#!/usr/bin/env python3
"""Writes docs/studies/structures.md and docs/studies/structures.png: the uniform grid (the paper's), the
two-level grid, the BVH, the kd-tree and --accel auto on the bundled scenes and on uneven scenes
(scripts/scenes/uneven_scenes.py), side by side in one run.

Usage: /usr/bin/python3 scripts/docs/structures.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
                                              [--runs 3] [--h200 FILE ...]
                                              [--h200-looping FILE ...] [--h200-looping-again FILE ...]
                                              [--h200-layout SQUARE MULTI_WIDE MULTI_SQUARE WIDE]
                                              [--h200-programs DIR] [--h200-precise ON OFF]
                                              [--h200-ablation FULL STEP TEST]
                                              [--h200-sizes FILE ...] [--h200-sizes-grid FILE]
                                              [--h200-latency FILE] [--h200-looping-third FILE]
                                              [--reuse [--only ACCEL ...]]

Per scene and structure, primary rays only (--bounces 0 --shadows off, as the issue's table) and
the full frame (2 bounces, shadows): build ms, passes, query read-backs, fragments, voxel steps
or nodes visited, triangle tests, the cost model's ms on gf5700 / gf6600 / h200 (one run: the
statistics do not change between runs), emulator ms and CPU tracer ms (medians of --runs runs,
2 host threads). --accel auto chooses per profile: it is run with --profile gf6600 and with
--profile h200. --h200 FILE... adds frames measured on an H200 through the GL device: bench_gl JSON files
(bench/bench_gl.cpp with --accel, warm frames after one warm-up, polled read-backs; made by
scripts/h200/structures.sh), each GL frame set beside the cost model's prediction from the
same frame's emulator statistics in the same file. --reuse --only grid2 "auto gf6600" "auto h200"
renders only those rows again and keeps the others from results/structures/structures.json (rows of one size).
--h200-sizes FILE... (scripts/h200/structures.sh with SIZES=1: the same walks from 8x8 to
512x512) tests whether what the model lacks in the H200's looping frames is a cost per frame or
one that grows with the image, and writes what it finds under "Left out".
"""
import argparse
import json
import os
import re
import statistics
import sys
import tempfile
import textwrap

import matplotlib
import numpy as np
import accel_auto
import structures_trials as st

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUNDLED = ["sphere", "bunny", "bunny-refl", "classic", "teapot"]
UNEVEN = ["stadium", "scales"]
MODES = {"primary": ["--bounces", "0", "--shadows", "off"], "full": []}
COLOURS = {"grid": "C0", "grid2": "C1", "bvh": "C2", "kdtree": "C3"}  # the same in every panel


def run(exe, scene, opts, js):
    return vgpurt.render(exe, scene, opts, stats_json=js)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--h200", nargs="*", default=[],
                    help="bench_gl JSON files measured on an H200 (results/structures/structures_h200_*.json)")
    ap.add_argument("--h200-looping", nargs="*", default=[],
                    help="bench_gl JSON of the looping frames measured again with a warm-up "
                    "(results/structures/structures_h200_looping_warm.json): they replace the looping cells")
    ap.add_argument("--h200-looping-again", nargs="*", default=[],
                    help="bench_gl JSON of a second warmed run of the looping frames, with every "
                    "frame's time (results/structures/structures_h200_looping_warm2.json, RUNS=15): shown beside "
                    "the first, with the traversal kernels' GPU time against their modeled work")
    ap.add_argument("--h200-layout", nargs=4, default=[], metavar="FILE",
                    help="the texture-layout trial: looping frames with the structures' textures "
                    "laid out square (results/structures/structures_h200_looping_square.json), then multipass "
                    "frames with the old (wide) and the square layout in one run "
                    "(results/structures/structures_h200_layout_multipass_{wide,square}.json), then the same "
                    "looping frames wide (results/structures/structures_h200_looping_warm2.json)")
    ap.add_argument("--h200-precise", nargs=2, default=[], metavar="FILE",
                    help="the same looping frames with the GLSL's `precise` qualifiers, then "
                    "with them removed (an experiment binary; results/structures/structures_h200_precise_"
                    "{on,off}.json)")
    ap.add_argument("--h200-ablation", nargs=3, default=[], metavar="FILE",
                    help="grid2's looping frames whole, with the step alone and with the "
                    "triangle test alone (experiment binaries; "
                    "results/structures/structures_h200_grid2_ablation_{full,step,test}.json)")
    ap.add_argument("--h200-programs", metavar="DIR",
                    help="NVIDIA's compiled assembly of the looping traversal kernels, from "
                    "bench_gl --dump-programs on the H200 (results/structures/h200_programs/*.nvfp): their "
                    "loop bodies beside the vgpu's counts")
    ap.add_argument("--h200-latency", metavar="FILE",
                    help="bench_gl --latency JSON from the H200 (results/structures/structures_h200_latency.json):"
                    " the latency term's section")
    ap.add_argument("--h200-looping-third", nargs="*", default=[],
                    help="bench_gl JSON of the looping frames measured with the latency term "
                    "(results/structures/structures_h200_looping_warm3.json)")
    ap.add_argument("--h200-sizes-grid", nargs="*", default=[],
                    help="the grid's looping frames at 8x8, 64x64 and 512x512 "
                    "(results/structures/structures_h200_sizes_looping_grid.json), for the latency term")
    ap.add_argument("--h200-sizes", nargs="*", default=[],
                    help="bench_gl JSON files of the same frames at several sizes "
                    "(results/structures/structures_h200_sizes_*.json)")
    ap.add_argument("--loop-kernels", metavar="FILE",
                    help="scripts/docs/loop_kernels.py's JSON (results/structures/"
                    "loop_kernels.json): the fetch wait's section")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "studies"),
                    help="where structures.md and structures.png go")
    ap.add_argument("--results", default=os.path.join(ROOT, "results", "structures"),
                    help="where structures.json, the raw figures, goes")
    ap.add_argument("--reuse", action="store_true",
                    help="take the emulator and CPU rows from RESULTS/structures.json instead of "
                    "rendering them again (the H200 files are read again)")
    ap.add_argument("--only", nargs="*", default=[],
                    help="with --reuse: render these rows (grid, grid2, bvh, kdtree, 'auto "
                    "gf6600', 'auto h200', or SCENE:STRUCTURE for one scene's) again, "
                    "replacing the stored ones")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="structures_")
    uneven = vgpurt.uneven_scenes(tmp)
    scenes = [(s, s) for s in BUNDLED] + [(s, uneven[s]) for s in UNEVEN]
    size = ["--size", f"{a.size}x{a.size}", "--threads", "2"]
    rows = []
    js = os.path.join(tmp, "r.json")
    if a.reuse:
        rows = [r for r in json.load(open(os.path.join(a.results, "structures.json")))["rows"]
                if not wanted(a.only, r["scene"], r["accel"])]
    for name, path in ([] if a.reuse and not a.only else scenes):
        for mode, mopts in MODES.items():
            for acc, extra in (("grid", ["--accel", "grid"]), ("grid2", ["--accel", "grid2"]),
                               ("bvh", ["--accel", "bvh"]), ("kdtree", ["--accel", "kdtree"]),
                               ("auto gf6600", ["--accel", "auto", "--profile", "gf6600"]),
                               ("auto h200", ["--accel", "auto", "--profile", "h200"])):
                if a.reuse and not wanted(a.only, name, acc):
                    continue
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
                rows.append(row)
                order = ["grid", "grid2", "bvh", "kdtree", "auto gf6600", "auto h200"]
                rows.sort(key=lambda r: ([s for s, _ in scenes].index(r["scene"]),
                                         list(MODES).index(r["mode"]), order.index(r["accel"])))
                print(f"{name:10s} {mode:7s} {acc:11s} -> {row['chosen']:4s} passes "
                      f"{row['passes']:7d} gf6600 {row['gf6600']:10.1f} ms h200 {row['h200']:8.1f}"
                      f" ms emulator {row['emu_ms']:8.1f} ms", file=sys.stderr)
    h200 = gl_cells(a.h200)
    # The looping cells measured again with a warm-up (LOOPING=1 scripts/h200/structures.sh)
    # replace the first runs' and are shown beside them.
    a.looping_first = []
    for w in gl_cells(a.h200_looping):
        for i, r in enumerate(h200):
            if (r["scene"], r["accel"], r["mode"]) == (w["scene"], w["accel"], w["mode"]):
                a.looping_first.append((r, w))
                h200[i] = w
    a.looping_again = []
    for w in gl_cells(a.h200_looping_again):
        first = next((r for r in h200 if (r["scene"], r["accel"], r["mode"]) ==
                      (w["scene"], w["accel"], w["mode"])), None)
        if first:
            a.looping_again.append((first, w))
    a.kernel_ratios = st.traversal_ratios(a.h200_looping_again)
    a.looping_third = gl_cells(a.h200_looping_third)
    a.run = run
    json.dump({"rows": rows, "h200": h200}, open(os.path.join(a.results, "structures.json"), "w"),
              indent=1)
    write_doc(a, rows, h200)
    chart(a, rows, h200)


def wanted(only, scene, acc):
    """Whether --only names this row: by structure ("grid2") or scene and structure
    ("bunny:grid")."""
    return acc in only or f"{scene}:{acc}" in only


def get(rows, scene, mode, acc):
    return next(r for r in rows if r["scene"] == scene and r["mode"] == mode and r["accel"] == acc)


def fmt_ms(v):
    return f"{v:,.1f}" if v < 100 else f"{v:,.0f}"


def main_table(rows):
    L = ["| scene | rays | structure | build ms | passes | read-backs | fragments | steps | "
         "tests | gf5700 ms | gf6600 ms | h200 ms | emulator ms | CPU ms |",
         "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        if r["accel"].startswith("auto"):
            continue
        L.append(f"| {r['scene']} | {r['mode']} | {r['accel']} | {r['build_ms']:.1f} | "
                 f"{r['passes']:,} | {r['readbacks']:,} | {r['fragments']:,} | {r['steps']:,} | "
                 f"{r['tests']:,} | {fmt_ms(r['gf5700'])} | {fmt_ms(r['gf6600'])} | "
                 f"{fmt_ms(r['h200'])} | {fmt_ms(r['emu_ms'])} | "
                 + (f"{fmt_ms(r['cpu_ms'])} |" if "cpu_ms" in r else "- |"))
    return "\n".join(L)


def auto_table(rows):
    L = ["| scene | rays | auto on gf6600 picks | grid gf6600 ms | auto gf6600 ms | auto / grid | "
         "auto on h200 picks | probes ms |", "|---|---|---|---:|---:|---:|---|---:|"]
    for sc in BUNDLED + UNEVEN:
        for mode in MODES:
            g = get(rows, sc, mode, "grid")
            a6 = get(rows, sc, mode, "auto gf6600")
            ah = get(rows, sc, mode, "auto h200")
            L.append(f"| {sc} | {mode} | {a6['chosen']} | {fmt_ms(g['gf6600'])} | "
                     f"{fmt_ms(a6['gf6600'])} | {a6['gf6600'] / g['gf6600']:.2f}x | {ah['chosen']} | "
                     f"{a6['probe_ms']:,.0f} |")
    return "\n".join(L)


def target_table(rows):
    L = ["| scene against the bunny alone (grid) | rays | target | auto: emulator ms | ratio | "
         "auto: modeled h200 ms | ratio |", "|---|---|---:|---:|---:|---:|---:|"]
    for mode in MODES:
        b = get(rows, "bunny", mode, "grid")
        for sc, limit in (("stadium", 3.0), ("scales", 5.0)):
            au = get(rows, sc, mode, "auto h200")
            L.append(f"| {sc} ({au['chosen']}) | {mode} | {limit:.0f}x | {fmt_ms(au['emu_ms'])} "
                     f"(bunny {fmt_ms(b['emu_ms'])}) | {au['emu_ms'] / b['emu_ms']:.2f}x | "
                     f"{fmt_ms(au['h200'])} (bunny {fmt_ms(b['h200'])}) | "
                     f"{au['h200'] / b['h200']:.2f}x |")
    return "\n".join(L)


def target_verdict(rows):
    out = []
    for mode in MODES:
        b = get(rows, "bunny", mode, "grid")
        for sc, limit in (("stadium", 3.0), ("scales", 5.0)):
            au = get(rows, sc, mode, "auto h200")
            e, h = au["emu_ms"] / b["emu_ms"], au["h200"] / b["h200"]
            out.append(f"{sc} ({mode}): emulator {e:.2f}x {'met' if e <= limit else 'missed'}, "
                       f"modeled H200 {h:.2f}x {'met' if h <= limit else 'missed'}")
    return "Against the targets (3x for the stadium, 5x for many scales): " + "; ".join(out) + "."


def gl_cells(files):
    """The GL frames of bench_gl JSON files, each beside the h200 prediction from the emulator's
    statistics of the same frame in the same file."""
    cells = []
    for f in files:
        frames = json.load(open(f))["frames"]
        for g in frames:
            if g["engine"] != "gl-poll":
                continue
            em = next(e for e in frames if e["engine"] == "stream" and
                      all(e[k] == g[k] for k in ("scene", "accel", "variant", "bounces", "size")))
            mode = ("looping" if g["variant"] == "looping" else
                    "primary" if g["bounces"] == 0 else f"{g['bounces']} bounces")
            cells.append({"scene": g["scene"], "accel": g["accel"], "mode": mode,
                          "wall_ms": g["wall_ms"], "gpu_ms": g["gpu_ms"], "passes": g["passes"],
                          "readbacks": g["query_readbacks"],
                          "warmup_ms": g.get("warmup_ms", 0),
                          "wall_runs_ms": g.get("wall_runs_ms", []),
                          "predicted_ms": em["predicted_ms"]["h200"],
                          "latency_ms": em["predicted_h200"].get("latency_ms", 0.0)})
    return cells


def grid2_loop(h200, pairs):
    """The two-level grid's looping cells against the model, for Left out."""
    g = [r for r in h200 if r["accel"] == "grid2" and r["mode"] == "looping"]
    if not g:
        return "not measured on the H200."
    e = sorted(100 * (r["predicted_ms"] / r["wall_ms"] - 1) for r in g)
    out = [r for r in g if abs(r["predicted_ms"] / r["wall_ms"] - 1) > 0.35]
    return (f"its H200 frames (warmed up) are predicted {-e[-1]:.0f}-{-e[0]:.0f}% below their "
            f"wall time, the most of any structure's looping frames; {len(out)} of {len(g)} outside 35% ("
            + (", ".join(f"{r['scene']}, {fmt_ms(r['wall_ms'])} ms" for r in out) or "none") +
            "). " + st.slower_sentence(pairs) + "These figures carry the latency term.")


def looping_again(pairs):
    """The looping cells of the first runs beside the same frames warmed up before timing."""
    if not pairs:
        return ""
    within = sum(abs(w["predicted_ms"] / w["wall_ms"] - 1) <= 0.35 for _, w in pairs)
    warm_s = sorted(w["warmup_ms"] for _, w in pairs)[len(pairs) // 2] / 1000
    L = ["", "", f"The looping rows above come from a later run (`LOOPING=1 "
         "scripts/h200/structures.sh`, `results/structures/structures_h200_looping_warm.json`): the same frames, "
         f"each configuration's GL frames run for about {warm_s:.1f} s (`bench_gl --warmup-ms`) "
         "before the timed ones, since a GPU left idle while the emulator computes the frame's "
         "prediction lowers its clock (docs/studies/sampling.md's H200 section measured it: 345 MHz, and "
         f"frames 3-5x slower). {within} of its {len(pairs)} looping cells are within 35%. "
         "Beside the first runs' (one warm-up frame):", "",
         "| scene | structure | first run wall ms | vs | warmed wall ms | GPU ms | predicted ms "
         "| vs |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r, w in pairs:
        L.append(f"| {w['scene']} | {w['accel']} | {fmt_ms(r['wall_ms'])} | "
                 f"{100 * (r['predicted_ms'] / r['wall_ms'] - 1):+.0f}% | "
                 f"{fmt_ms(w['wall_ms'])} | {fmt_ms(w['gpu_ms'])} | {fmt_ms(w['predicted_ms'])} | "
                 f"{100 * (w['predicted_ms'] / w['wall_ms'] - 1):+.0f}% |")
    return "\n".join(L)


def h200_table(h200):
    L = ["| scene | structure | rays / kernels | passes | read-backs | H200 wall ms | GPU ms | "
         "predicted ms | predicted vs wall |", "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in h200:
        L.append(f"| {r['scene']} | {r['accel']} | {r['mode']} | {r['passes']:,} | "
                 f"{r['readbacks']:,} | {fmt_ms(r['wall_ms'])} | {fmt_ms(r['gpu_ms'])} | "
                 f"{fmt_ms(r['predicted_ms'])} | "
                 f"{100 * (r['predicted_ms'] / r['wall_ms'] - 1):+.0f}% |")
    return "\n".join(L)


def grid2_sentence(rows):
    """The two-level grid against the grid and the BVH, primary rays, modeled gf6600."""
    parts = []
    for sc in ("bunny", "teapot", "stadium", "scales"):
        g, g2, b = (get(rows, sc, "primary", acc) for acc in ("grid", "grid2", "bvh"))
        parts.append(f"{sc} {g2['gf6600'] / g['gf6600']:.2f}x the grid's and "
                     f"{g2['gf6600'] / b['gf6600']:.2f}x the BVH's")
    return ("The two-level grid keeps the paper's DDA and its in-voxel rule, and cuts finely only "
            "where triangles crowd; its modeled gf6600 time with primary rays is " +
            "; ".join(parts) + ". On an uneven scene it removes most of the grid's triangle tests, "
            "but a ray still steps every empty coarse cell and every sub-cell of each crowded cell "
            "it crosses, one pass each, where a tree skips empty space in a few nodes.")


def measured_cells(path):
    """A bench_gl file's GL frames, each with the cost model's prediction (and its parts) from
    the emulator's statistics of the same frame in the same file."""
    frames = json.load(open(path))["frames"]
    cells = []
    for g in frames:
        if g["engine"] != "gl-poll":
            continue
        em = next(e for e in frames if e["engine"] == "stream" and
                  all(e[k] == g[k] for k in ("scene", "accel", "variant", "bounces", "size")))
        p = em["predicted_h200"]
        cells.append({"scene": g["scene"], "accel": g["accel"], "variant": g["variant"],
                      "size": g["size"], "wall": g["wall_ms"], "gpu": g["gpu_ms"],
                      "passes": g["passes"], "readbacks": g["query_readbacks"],
                      "pred": p["total_ms"],
                      "work": p["arithmetic_ms"] + p["texture_ms"] + p["memory_ms"] +
                              p.get("latency_ms", 0.0),
                      "fixed": p["per_pass_ms"] + p["readback_ms"] + p["program_load_ms"],
                      "download": p["download_ms"]})
    return cells


def frame_cost(h200_files, sizes_files):
    """Left out: whether a cost per frame explains the looping frames' shortfall. On the stored
    256x256 cells a constant added to every prediction is fitted (the one of least relative RMS
    error); the frames at other sizes then show whether the shortfall stays per frame or grows
    with the pixels. The remainder on the host is wall minus GPU (timer queries) minus the
    model's passes, read-backs, program loads and downloads."""
    cells = [c for f in h200_files for c in measured_cells(f)]
    sized = [c for f in sizes_files for c in measured_cells(f)]
    if not cells or not sized:
        return ""
    med = statistics.median

    def err(c, k=0.0):
        return (c["pred"] + k) / c["wall"] - 1

    def rms(k):
        return (sum(err(c, k) ** 2 for c in cells) / len(cells)) ** 0.5

    loop = [c for c in cells if c["variant"] == "looping"]
    multi = [c for c in cells if c["variant"] != "looping"]
    ks = [i / 100 for i in range(201)]
    best = min(ks, key=rms)
    fits = [k for k in ks if all(abs(err(c, k)) <= 0.35 for c in cells)]

    def mean_err(cs, k=0.0):
        return 100 * sum(err(c, k) for c in cs) / len(cs)

    worst = max(cells, key=lambda c: abs(err(c, best)))
    host = lambda c: c["wall"] - c["gpu"] - c["fixed"] - c["download"]  # noqa: E731
    lsized = [c for c in sized if c["variant"] == "looping"]
    sizes = sorted({c["size"] for c in lsized})
    per = {s: [c for c in lsized if c["size"] == s] for s in sizes}
    # The host remainder against the pixel count, least squares over every looping frame.
    xs = [c["size"] ** 2 for c in lsized]
    ys = [host(c) for c in lsized]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = (sum((x - mx) * (y - my) for x, y in zip(xs, ys)) /
             sum((x - mx) ** 2 for x in xs))
    small = per[sizes[0]]
    msized = [c for c in sized if c["variant"] != "looping" and c["size"] == sizes[0]]
    over = {acc: med([c["gpu"] - c["work"] for c in loop if c["accel"] == acc])
            for acc in ("grid2", "bvh", "kdtree")}
    over_rel = med([(c["gpu"] - c["work"]) / c["work"] for c in loop if c["accel"] == "grid2"])
    size_rows = "; ".join(
        f"{s}x{s}: wall {med([c['wall'] for c in per[s]]):.2f} ms, remainder "
        f"{med([host(c) for c in per[s]]):.2f} ms" for s in sizes)
    clears = []
    for f in sizes_files:
        for r in json.load(open(f)).get("fixed", []):
            if r["what"] == "clear one RGBA32F texture" and r["size"] == 1024:
                clears.append(r["wall_us"])
    clocks = []
    cpath = sizes_files[0].rsplit("_", 1)[0] + "_clocks.csv"
    if os.path.exists(cpath):
        for line in open(cpath).read().splitlines()[1:]:
            clocks.append(int(line.split(",")[1].split()[0]))
    clock_note = ""
    if clocks:
        clock_note = (f" That run's SM clock sat at 1980 MHz in only {clocks.count(1980)} of "
                      f"{len(clocks)} samples (down to {min(clocks)} MHz while the emulator ran "
                      "between GL frames), so its GPU times at the larger sizes are slower than "
                      "the table's and are not used; the remainder beyond them is, though the "
                      "clears and copies in it may have run slower too.")
    loop_host = med([c["wall"] - c["gpu"] - c["fixed"] - c["download"] for c in loop])

    def regress(cs):
        """Wall minus GPU ms against passes, read-backs and 1, least squares weighted by
        1 / wall (relative errors): (us a pass, us a read-back, ms a frame)."""
        A = np.array([[c["passes"], c["readbacks"], 1.0] for c in cs]) / \
            np.array([c["wall"] for c in cs])[:, None]
        b = np.array([(c["wall"] - c["gpu"]) / c["wall"] for c in cs])
        x = np.linalg.lstsq(A, b, rcond=None)[0]
        return 1e3 * x[0], 1e3 * x[1], x[2]

    ra, rm = regress(cells), regress(multi)
    text = (
        "**A cost per frame, tried and refuted.** Every looping cell of the first runs (one "
        "warm-up frame) is under-predicted "
        f"(from {100 * max(err(c) for c in loop):+.0f}% to {100 * min(err(c) for c in loop):+.0f}%; "
        f"the multipass cells {100 * min(err(c) for c in multi):+.0f}% to "
        f"{100 * max(err(c) for c in multi):+.0f}%), and looping frames have few passes and "
        "read-backs, so a fixed cost per frame that the model lacks was the first suspect. "
        "Wall minus GPU time (timer queries) against passes, read-backs and a constant, least "
        f"squares weighted by 1 / wall, leaves {ra[2]:.2f} ms a frame over all {len(cells)} "
        f"cells but {rm[2]:.2f} ms on the {len(multi)} multipass cells alone (passes and "
        "read-backs, nearly proportional in every frame, trade their shares between them: the "
        "fitted us a pass and a read-back mean little). "
        f"Fitted on the {len(cells)} cells, a constant added to every prediction does best at "
        f"{best:.2f} ms (least relative RMS error), and any constant from {min(fits):.2f} to "
        f"{max(fits):.2f} ms puts all {len(cells)} cells within 35% (at {best:.2f} ms the farthest "
        f"is {worst['scene']} / {worst['accel']} / {worst['variant']} at "
        f"{100 * err(worst, best):+.0f}%; the looping cells' mean error goes from "
        f"{mean_err(loop):+.0f}% to {mean_err(loop, best):+.0f}%, the multipass cells' from "
        f"{mean_err(multi):+.1f}% to {mean_err(multi, best):+.1f}%). But every cell is 256x256, "
        "where a cost per frame and a cost per pixel look the same. One more run "
        "(`SIZES=1 scripts/h200/structures.sh`, `results/structures/structures_h200_sizes_*.json`: the looping "
        "walks of grid2, bvh and kdtree on the seven scenes at "
        f"{', '.join(f'{s}x{s}' for s in sizes)}, medians of 5 frames) tells them apart: an "
        f"{sizes[0]}x{sizes[0]} frame takes {med([c['wall'] for c in small]):.2f} ms in all "
        f"(median of {len(small)}), less than the constant, which would put those predictions at "
        f"{100 * med([err(c, best) for c in small]):+.0f}%. What the wall time holds beyond the "
        "GPU's own time (timer queries) and the model's passes, read-backs, program loads and "
        f"downloads grows with the image instead: {size_rows} (medians; "
        f"{loop_host:.2f} ms in the table's looping cells), about {1e6 * slope:.1f} ns a pixel "
        f"by least squares over that run's {len(lsized)} frames. Per frame the host reads two RGBA32F "
        "textures back (the hits and the image, priced at the 3.1 GB/s of a lone "
        "`glGetTexImage`: 0.68 ms at 256x256), clears four (priced at the memory's 4.8 TB/s, "
        "where bench_gl's clear of a 1024x1024 one takes "
        f"{' and '.join(f'{c:.0f}' for c in clears)} us, near the ROPs' 28 bytes a clock) and "
        "loops over the image on the CPU: one of these, or their sum, is what grows, and these "
        f"runs cannot tell which. In multipass {sizes[0]}x{sizes[0]} frames the remainder is "
        f"{min(host(c) for c in msized):.2f}-{max(host(c) for c in msized):.2f} ms for "
        f"{min(c['passes'] for c in msized)}-{max(c['passes'] for c in msized)} passes, a few us "
        "a pass, well inside the multipass cells' errors." + clock_note + " The rest of the "
        "two-level grid's shortfall is on the GPU: its looping kernel's timer-query time is "
        f"{over['grid2']:.2f} ms (median; {100 * over_rel:.0f}%) above its modeled pass work and "
        "longest lanes at "
        f"256x256, the kd-tree's {over['kdtree']:.2f} ms (on longer frames), the BVH's "
        f"{over['bvh']:+.2f} ms. No term per frame or per pixel was added: the small frames leave room for "
        f"about {med([host(c) for c in small]):.2f} ms per frame, not {best:.2f}, and a "
        "cost per pixel fitted on these cells would be validated on the data it came from. The "
        "next step is to time each candidate alone on the H200: a download and a clear inside a "
        "frame, and the host's loops.")
    # Numbers stay on one line with their units.
    text = re.sub(r" (ms|us|ns|MHz|GB/s|TB/s)\b", "\x00\\1", text)
    return textwrap.fill(text, width=98, initial_indent="- ", subsequent_indent="  ",
                         break_on_hyphens=False, break_long_words=False).replace("\x00", " ") + "\n"


# The "--accel auto" section's paragraphs on stopped probes (write_doc).
STOPPED_PROBES = """**Stopped probes.** A price only grows as a probe runs: each pass adds its fixed costs (the
pass, its program load and read-back), its longest lanes and its work, none of them negative.
So a probe whose price so far passes the band of the cheapest first price so far cannot be in
the band, and a second probe whose price so far passes the cheapest second price so far cannot
be the pick; the emulator stops them there (the column "stopped"; their price in the JSON is
that lower bound). The price so far is `RunningPrice` (`host/model/cost_model.h`): each pass
priced as `predict` prices it, as the pass is counted, scaled as the probe's full frame is. The
pick, the band and every other price are those of probes run to their ends
(`tests/trace/test_structure_walks.cpp`, three scenes on three profiles; and the running price
never passes the whole frame's, on every structure's frames of two scenes on four profiles).

Before the running price, a probe stopped on its fixed costs alone, which only a multipass
kd-tree probe (whose restarts cost passes) ever passed: measured then against no stops, both
rounds of probes took a median 0.71x the host time in the 78 choices that stopped one. With the
pass work counted too, looping probes and other structures stop as well. Measured in one run
against the fixed-cost rule (bunny, teapot, classic, sphere, bunny-refl, glass and stadium at
256x256, both walks, gf6600 and h200, primary rays and full frames: 56 choices, the median of 3
alternated runs each): the probes' host time is a median 0.95x (0.75x to 1.09x), the full frames'
the most (classic and bunny-refl multipass on h200 0.75x, glass looping on h200 0.83x); the
same 56 picks."""


def write_doc(a, rows, h200):
    size = f"{a.size}x{a.size}"
    within = [r for r in h200 if abs(r["predicted_ms"] / r["wall_ms"] - 1) <= 0.35]
    worst = max(h200, key=lambda r: abs(r["predicted_ms"] / r["wall_ms"] - 1)) if h200 else None
    bunny_kd_loop = next((r for r in h200 if r["scene"] == "bunny" and r["accel"] == "kdtree"
                          and r["mode"] == "looping"), None)
    worse = [(sc, mode) for sc in BUNDLED for mode in MODES
             if get(rows, sc, mode, "auto gf6600")["gf6600"] >
             1.10 * get(rows, sc, mode, "grid")["gf6600"]]
    auto_rows = []  # scripts/docs/accel_auto.py's judgement of --accel auto, where it ran
    if os.path.exists(accel_auto.DEFAULT_JSON):
        with open(accel_auto.DEFAULT_JSON) as fh:
            auto_rows = json.load(fh)
    doc = f"""# Acceleration structures: the grid, a two-level grid, a BVH, a kd-tree, and `--accel auto`

Written by `scripts/docs/structures.py` (run it again to refresh every figure here); the chart is
`docs/studies/structures.png`, the raw figures `results/structures/structures.json`.

The paper walks one uniform grid. A grid fits an object that fills its box; it fails where the
scene is uneven: a small detailed object on a large floor puts the object in a few voxels of a
grid sized by the triangle count (the automatic 121x1x121 grid of the "stadium" scene below
holds the whole bunny in one column of voxels), and objects at very different scales leave most
voxels empty or crowded. The paper names other structures ("bounding volumes, adaptive
subdivision") as future work. vgpu-rt has three beside the grid, each built on the host, stored in
textures (`kernels/layout.h`) and walked by fragment programs under the paper's constraints: no
recursion, no stack, one output per pass on the GeForce FX (two with `--mrt on` elsewhere), and
the host steering passes by occlusion queries.

| `--accel` | built on the host | walked by | state per ray |
|---|---|---|---|
| `grid` (default) | the paper's uniform grid | 3D-DDA, one voxel per pass (Amanatides & Woo) | voxel, entry t |
| `grid2` | a coarse uniform grid (the automatic rule at 0.25 cells per triangle) whose crowded cells (more than 8 triangles) hold a grid of their own, at the automatic resolution of the part their triangles occupy carried over the cell, at most 64 sub-cells per triangle (Jevans & Wyvill 1989; Kalojanov et al. 2011) | 3D-DDA on two levels without a stack: one sub-cell per pass; leaving a sub-grid steps the coarse grid and descends into the next cell's sub-grid on the face crossed | sub-cell, its list, segment [t in, t out] |
| `bvh` | binned SAH (16 bins), leaves of up to 4 triangles | stackless: nodes in depth-first order, each with the index to jump to when the ray misses it (Thrane & Simonsen 2005); one node per pass | next node, leaf to load |
| `kdtree` | SAH over the triangles' clipped box faces, depth 8 + 1.3 log2 n | kd-restart (Foley & Sugerman 2005): descend to the first leaf the ray's segment reaches, test it (a hit counts only inside the leaf's segment), restart from the root past it; one node per pass | node, leaf to load, segment [tmin, tmax] |
| `auto` | all four | the one the cost model predicts cheapest on `--profile`: a probe frame at a quarter of the size in x and y (at least 16x16) with each, then those priced within 20% of the cheapest again at half the size (the fixed per-pass, program-load and read-back costs and the looping passes' longest lanes as measured, the fragment work scaled by the pixel ratio: every term of the model's total) | |

Each walk is the grid's pass sequence with its own kernels in the places of the paper's: a step
pass (`recorridoGrilla2` / `recorridoBVH` / `recorridoKd` where the grid has `traversal`), a
load (`cargarCelda` / `cargarHoja` / `cargarHojaKd` where it has `actualizarVoxel`), one
triangle per pass (`interseccionesGrilla2` / `interseccionesBVH` / `interseccionesKd`, then
`proximoTriangulo`), and the same two queries
(`rayosIntersectando`, `rayosEnGrilla`). Each has fused two-output forms for `--mrt on` and a
looping kernel for profiles with data-dependent loops (`--kernels looping`); the kd-tree's
looping kernel restarts with push-down (Horn et al., I3D 2007: a restart begins at the deepest
node whose subtree holds the whole remaining segment). All of them run on the emulator (pass
by pass and in batches, bit-identical), on the GL device (GLSL generated from the same
functors) and in the CPU tracer (double precision). On every bundled scene the BVH and the
kd-tree give the grid's hit ids, depths and colours, bit for bit, on the emulator and on
llvmpipe; the two-level grid gives the grid's primary hit ids on every bundled scene at 48x48
and on every stability case but for 3 pixels of the triangle fan, exact ties on a shared spoke
checked in double (`tests/trace/test_structure_walks.cpp`), and llvmpipe gives the emulator's.

## The figures

{size}, one run per row on this 2-core machine (2 host threads; emulator and CPU ms are medians
of {a.runs} runs; read them as ratios within a row group: the modeled ms and the counts do not
depend on the load).
"primary" is primary rays only (`--bounces 0 --shadows off`, as the issue's table); "full" is the
default frame (2 bounces, shadows). Steps: voxels stepped (grid) or nodes visited (BVH, kd-tree)
by the step passes' working fragments; tests: triangle tests. The modeled ms come from the same
statistics (cost model, `docs/studies/table1.md`); the scenes "stadium" (the bunny on a floor 270 times
its width) and "scales" (25 bunnies from 5% to 15 times its size, 92k triangles) are written by
`scripts/scenes/uneven_scenes.py`.

{main_table(rows)}

![grid, BVH and kd-tree per scene](structures.png)

### `--accel auto`

{auto_table(rows)}

`auto` is never more than 10% worse than `grid` in modeled gf6600 time on a bundled scene: {"met" if not worse else "missed on " + ", ".join(f"{s} ({m})" for s, m in worse)}.
The probes cost host time at initialization (the column "probes ms", both rounds; the builds of
all four structures come before them); the frame's own render time is the same as with the
chosen structure.

**Two rounds of probes.** A 64x64 probe misjudges how two structures compare at 256x256 where a
walk's longest rays grow with the image: the bunny's primary rays on gf6600 priced the two-level
grid 6% under the grid from 64x64 probes, and it is 12% over at 256x256. Until issue 51 the grid
was kept unless another structure was predicted at least 10% cheaper, which covered that case
but cost others: it kept the grid at 1.26x the BVH's frame (classic, full frame, looping,
gf6600). Now every candidate priced within 20% of the cheapest (`kAutoProbeBand`: the largest
misjudgment measured between two candidates was 17%) is probed again at half the size, and the
cheapest of those is taken; no structure is preferred.

{accel_auto.section(auto_rows)}

The choice is not cheap. The probes render at least four frames of a quarter of the pixels and
up to three of half, and a probe costs more than its share of the pixels: a multipass walk runs
as many passes at 64x64 as at 256x256, each with its fixed host work. Where one structure is
slow (the grid on stadium and scales) its probe alone outlasts the chosen frame, and where a
build is slow (scales: the kd-tree's 0.4 s) so does that. A choice within a quarter of the frame's
host time needs a predictor that renders nothing, and where the builds alone pass the quarter (the
count above), one that builds nothing either: not built here. (The kd-tree's build now sorts its
events once: 2.1x to 2.8x faster, the same tree, `bench_builds`. The sweep of issue 51's
earlier stop ran slower throughout, its two-level grid's build on scales 204 ms against 91 to
107 ms here, which nothing changed, so the medians' change since is not the kd-tree's or the
stops' alone: each is measured in one run, `bench_builds` and "Stopped probes" below.)

{STOPPED_PROBES}

**The longest-lane term (issue 34).** Until issue 34 the price of a candidate left out the
cost model's `latency_ms` (a looping pass waits for its longest lane: `docs/studies/table1.md`),
which only the looping kernels on the `h200` profile have. With `--kernels looping --profile
h200` the price now includes it (unscaled: one lane's walk does not grow with the pixel count),
and at a size where the probe is the whole frame (16x16 or less) each candidate's price is the
model's `total_ms` of that structure's frame (`tests/trace/test_structure_walks.cpp`).

### Uneven scenes against the object alone

{target_table(rows)}

{target_verdict(rows)} The stadium's floor fills the image, so every pixel's ray walks the
structure, where the bunny alone lets most rays miss its box at once: the stadium does several
times the bunny's fragment work however good the structure, which the emulator's host time
follows more closely than a modeled GPU's pass-bound time does.

## Measured on an H200 through the GL device

The same frames on an NVIDIA H200 through the GL device (`bench/bench_gl.cpp --accel grid bvh
kdtree grid2`, 256x256, polled read-backs, SM clock 1980 MHz while busy; how they were run: `results/structures/README.md`): the
median of 3 frames after one warm-up frame, beside the cost model's prediction (`h200`
profile) from the emulator's statistics of the same frame. "primary" is `--bounces 0`, "2
bounces" Table 1's setting (no shadows); multipass frames use the paper's kernels, "looping"
the looping walks. {len(within)} of {len(h200)} cells are within 35%{"" if not worst else f"; the farthest is {worst['scene']} / {worst['accel']} / {worst['mode']} at {100 * (worst['predicted_ms'] / worst['wall_ms'] - 1):+.0f}%"}.
A first frame in a fresh process also pays the driver's compilation of every program: single
`vgpu-rt render --engine gl` runs, one frame each, measured 29.6 ms for the bunny's looping grid
walk (99.5 ms multipass) where the warm frames below take a few ms (61 ms), so only warm frames
are compared with the model, which has no compilation term.

{h200_table(h200)}{looping_again(a.looping_first)}{st.looping_second(a)}{st.layout_trial(a.h200_layout)}{st.compiled_bodies(a)}{st.precise_trial(a.h200_precise)}{st.ablation_trial(a.h200_ablation)}{st.latency_term(a)}{st.fetch_wait(a)}

## Which structure wins where, and why

- **Passes against read-backs.** On the 2004 cards a frame costs its passes (651 us each on the
  FX 5700, 160 us on the 6600, fitted on the paper's Table 1 in `docs/studies/table1.md`) and its query
  read-backs (1.3 ms and 320 us) far more than its fragment work. The grid's pass count is the longest ray's voxel steps plus its triangle loop
  per voxel; an uneven scene makes one ray cross a hundred empty voxels (stadium) or sit in a
  voxel listing hundreds of triangles (scales). The BVH's and kd-tree's pass counts follow the
  tree depth and leaf size instead, so they barely move with the scene's spread.
- **Two levels against a tree.** {grid2_sentence(rows)}
- **Restarts against a stack.** The FX has no loops and no indexable registers: a stack is out
  of reach, so the BVH walks its escape indices and the kd-tree restarts from the root. Every
  restart costs a descent (about the tree's depth in passes): on the bundled scenes kd-restart
  takes several times the BVH's passes. The stackless BVH's order is fixed, not front to back,
  so it cannot stop at the first hit, but a box beyond the nearest hit so far is skipped.
- **Loops.** Profiles with data-dependent loops (gf6600 and later) run a whole walk in a few
  looping passes; then the per-pass cost vanishes and the work per ray decides. Push-down cuts
  the kd-tree's restarts.
- **Published figures.** Foley & Sugerman report kd-restart and kd-backtrack up to 8 times faster
  than a uniform grid on scenes with objects at many scales, on an ATI X800 in the same multipass
  style; Horn et al. report 15-18 million primary rays per second for kd-restart with push-down
  and a short stack in one looping pass on an ATI X1900. Here the H200 ran the kd-tree's looping
  kernel on the bunny's {size} primary rays in {fmt_ms(bunny_kd_loop["wall_ms"]) if bunny_kd_loop else "-"} ms
  ({(a.size * a.size / bunny_kd_loop["wall_ms"] / 1000) if bunny_kd_loop else 0:.1f} million rays per second, wall time
  including read-backs). Thrane & Simonsen (2005) are cited for finding the stackless BVH the
  fastest of the three; that thesis was not at hand here to check.

## Precision: where each breaks

Node indices and list positions are texel addresses: fp16 addresses texels exactly only to 1023
(`host/model/formats.h`), fp24 to 65535. The bundled bunny's BVH has 4,225 nodes and its
kd-tree 8,287, so neither can keep node indices in fp16; `--precision auto` keeps the traversal
group (which holds them) at the part's finest format, and checks the voxel group's list
positions against the structure's own lists. Asked for a format that cannot count to the node
count or the list length (`--precision fp16`, or fp24 past 65535), `--accel bvh` and `kdtree`
are refused with one line naming the group, the count and the limit: a node index that stops
counting up would stall the walk (the grid instead stops at its pass cap and reports the rays
left unfinished). `--accel grid2` is refused alike where its sub-cell indices, coarse cell
indices or list positions pass what the traversal or voxel group's format addresses (the bunny's
two-level grid has 96,334 sub-cells: fp16 and fp24 traversal groups both refuse it, and
`--precision auto` keeps that group at fp32).

## Left out

- The cost model for the two-level grid's looping kernel: {grid2_loop(h200, a.looping_first)}{st.grid2_again(a)}
{frame_cost(a.h200, a.h200_sizes)}- kd-backtrack and the short stack of Horn et al.: kd-restart (with push-down in the looping
  kernel) is the only kd walk.
- Front-to-back BVH order: it needs a stack or parent links with a direction flag.
"""
    open(os.path.join(a.out, "structures.md"), "w").write(doc)
    print(f"wrote {a.out}/structures.md", file=sys.stderr)


def chart(a, rows, h200):
    scenes = BUNDLED + UNEVEN
    fig, axes = plt.subplots(1, 4 if h200 else 3, figsize=(20 if h200 else 15, 4.8))
    for ax, key, title in ((axes[0], "gf6600", "modeled GeForce 6600 (multipass)"),
                           (axes[1], "h200", "modeled H200 (multipass)"),
                           (axes[2], "emu_ms", "emulator host ms (2 threads)")):
        w = 0.21
        for k, acc in enumerate(("grid", "grid2", "bvh", "kdtree")):
            vals = [get(rows, s, "primary", acc)[key] for s in scenes]
            ax.bar([i + (k - 1.5) * w for i in range(len(scenes))], vals, w, label=acc,
                   color=COLOURS[acc])
        ch = [get(rows, s, "primary", "auto gf6600" if key != "h200" else "auto h200")["chosen"]
              for s in scenes]
        ax.set_xticks(range(len(scenes)))
        ax.set_xticklabels([f"{s}\nauto: {c}" for s, c in zip(scenes, ch)], fontsize=7)
        ax.set_yscale("log")
        ax.set_ylabel("ms per frame (log)")
        ax.set_title(title + ", primary rays", fontsize=10)
        ax.legend(fontsize=8)
    if h200:
        ax = axes[3]
        for acc, m in (("grid", "o"), ("grid2", "D"), ("bvh", "s"), ("kdtree", "^")):
            pts = [r for r in h200 if r["accel"] == acc]
            ax.scatter([r["wall_ms"] for r in pts], [r["predicted_ms"] for r in pts], marker=m,
                       label=acc, alpha=0.8, color=COLOURS[acc])
        lo = min(min(r["wall_ms"], r["predicted_ms"]) for r in h200) * 0.7
        hi = max(max(r["wall_ms"], r["predicted_ms"]) for r in h200) * 1.4
        xs = [lo, hi]
        ax.plot(xs, xs, "k-", lw=0.8, label="predicted = measured")
        ax.plot(xs, [x * 1.35 for x in xs], "k:", lw=0.8, label="+/- 35%")
        ax.plot(xs, [x / 1.35 for x in xs], "k:", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("H200 wall ms (GL device)")
        ax.set_ylabel("predicted ms")
        ax.set_title("H200: measured against predicted, every frame", fontsize=10)
        ax.legend(fontsize=7)
    fig.suptitle(f"Grid, two-level grid, BVH and kd-tree, {a.size}x{a.size}: where each "
                 "structure wins")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "structures.png"), dpi=100)
    print(f"wrote {a.out}/structures.png", file=sys.stderr)


if __name__ == "__main__":
    main()
