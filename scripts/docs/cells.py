#!/usr/bin/env python3
"""Measured GL frames against the cost model's prediction on the profile of the card they ran on.

Reads bench_gl JSON files measured on a GPU (bench/bench_gl.cpp; scripts/h200/*.sh). Each file
names its card (GL_RENDERER; "card_profile" where bench_gl knew the profile measured on it). For
every GL frame (the polled read-back where both waits ran) the prediction is the emulator's frame
of the same options priced on that profile by the model as it stands: bench_gl run here with
--readback-wait none (the counts are the same on every machine; predictions stored beside the
measurements are the model of their day and are not read). A cell is within its target where
|predicted / wall - 1| is at most 10% for the multipass pipeline and 15% for the looping and
MRT pipelines (issue 51's targets).

Usage: /usr/bin/python3 scripts/docs/cells.py FILE.json[@GRID][+PIPELINE] ...
           [--bench build/bench/bench_gl] [--scene-dir DIR ...] [--block DOC.md NAME] [--host-fit]
FILE@GRID: the frames ran with bench_gl --grid GRID, for files written before bench_gl recorded
it (default auto; a file that records its grid is refused another). FILE+PIPELINE: only the
file's frames of that pipeline (multipass, mrt or looping), where a later call measured the
others again after the program changed. --block writes the table
between '<!-- NAME: begin -->' and '<!-- NAME: end -->' of DOC.md. --host-fit prints, instead,
what the frames' wall time holds per pixel beyond the GPU and the modeled fixed costs."""
import argparse
import json
import os
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
import bench_frames  # noqa: E402
from bench_frames import key  # noqa: E402
from scale import write_block  # noqa: E402

TARGETS = {"multipass": 0.10, "mrt": 0.15, "looping": 0.15}
# Cards named by their driver, for files written before bench_gl recorded card_profile.
RENDERERS = {"NVIDIA H200/": "h200", "NVIDIA H100 80GB HBM3/": "h100"}


def fail(msg):
    sys.exit(f"cells: {msg}")


def card_of(path, doc):
    card = doc.get("card_profile")
    if card:
        return card
    for word, name in RENDERERS.items():
        if word in doc.get("renderer", ""):
            return name
    fail(f"{path}: no profile was measured on '{doc.get('renderer', '?')}'")


def emulate(bench, k, dirs, grid, cache):
    """The emulator's frame of options k, cached by k and the grid."""
    if (k, grid) not in cache:
        cache[(k, grid)] = bench_frames.emulate(bench, k, dirs, grid, "cells")
    return cache[(k, grid)]


def cells(paths, bench, dirs):
    cache, rows = {}, []
    for spec in paths:
        head, plus, only = spec.rpartition("+")
        if plus and only in TARGETS:  # a path may hold '+' itself: only a pipeline's name ends it
            spec = head
        else:
            only = ""
        path, at, grid = spec.rpartition("@")
        if not at:
            path, grid = spec, ""
        try:
            with open(path) as fh:
                doc = json.load(fh)
        except (OSError, ValueError) as e:
            fail(f"{path}: {e}")
        card = card_of(path, doc)
        if grid and doc.get("grid") and grid != doc["grid"]:
            fail(f"{spec}: the file records --grid {doc['grid']}")
        grid = grid or doc.get("grid", "auto")
        frames = doc.get("frames", [])
        gl = {}
        for f in frames:  # the polled read-back where both waits ran
            if f["engine"].startswith("gl") and (key(f) not in gl or f["engine"] == "gl-poll"):
                gl[key(f)] = f
        for k, f in gl.items():
            if only and k[2] != only:
                continue
            e = emulate(bench, k, dirs, grid, cache)
            pred = e["predicted_ms"].get(card)
            if pred is None:
                fail(f"{path}: {k}: no prediction on {card} (is the profile built in?)")
            runs = f.get("wall_runs_ms")
            wall = statistics.median(runs) if runs else f["wall_ms"]
            gpu = statistics.median(f["gpu_runs_ms"]) if f.get("gpu_runs_ms") else f.get("gpu_ms")
            # The GL driver's arithmetic can end a walk a pass or two from the emulator's
            # (scales' two-level grid: 3,133 passes against 3,130): priced as emulated, shown.
            b = e.get(f"predicted_{card}", {})
            fixed = sum(b.get(t, 0.0) for t in ("per_pass_ms", "program_load_ms", "readback_ms",
                                                 "download_ms"))
            rows.append({"file": os.path.basename(path), "card": card, "key": k, "fixed": fixed,
                         "wall": wall, "gpu": gpu, "pred": pred, "passes": f["passes"],
                         "emulated_passes": e["passes"],
                         "err": pred / wall - 1, "target": TARGETS[k[2]]})
    return rows


def changed(r):
    """A stored frame the program no longer renders alike (more than 3 passes and more than 1%
    apart: the kernels changed since it was measured), which its prediction cannot judge."""
    return abs(r["passes"] - r["emulated_passes"]) > max(3, 0.01 * r["emulated_passes"])


def table(rows):
    L = ["| card | scene | size | structure | pipeline | rays | beams | sampling | streams | "
         "passes | wall ms | GPU ms | predicted ms | error | within |",
         "|---|---|---|---|---|---|---|---|---|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        scene, accel, variant, bounces, shadows, streams, sampling, beams, size = r["key"]
        rays = "primary" if bounces == 0 and not shadows else \
            f"{bounces} bounces{', shadows' if shadows else ''}"
        ok = abs(r["err"]) <= r["target"]
        if changed(r):
            L.append(f"| {r['card']} | {scene} | {size}² | {accel} | {variant} | {rays} | "
                     f"{beams} | {sampling} | {streams} | {r['passes']:,} (emulator "
                     f"{r['emulated_passes']:,}) | {r['wall']:,.2f} | - | - | - | not judged: "
                     "the frame has changed since |")
            continue
        gpu = f"{r['gpu']:,.2f}" if r["gpu"] is not None else "-"
        passes = f"{r['passes']:,}" + ("" if r["passes"] == r["emulated_passes"] else
                                          f" (emulator {r['emulated_passes']:,})")
        L.append(f"| {r['card']} | {scene} | {size}² | {accel} | {variant} | {rays} | {beams} | "
                 f"{sampling} | {streams} | {passes} | {r['wall']:,.2f} | {gpu} | "
                 f"{r['pred']:,.2f} | {100 * r['err']:+.0f}% | {'yes' if ok else '**no**'} |")
    L.append("")
    for card in sorted({r["card"] for r in rows}):
        for v in ("multipass", "mrt", "looping"):
            sel = [r for r in rows if r["card"] == card and r["key"][2] == v and not changed(r)]
            if not sel:
                continue
            ok = sum(abs(r["err"]) <= r["target"] for r in sel)
            errs = sorted(r["err"] for r in sel)
            L.append(f"- {card}, {v}: **{ok} of {len(sel)}** within "
                     f"{100 * TARGETS[v]:.0f}%; errors from {100 * errs[0]:+.0f}% to "
                     f"{100 * errs[-1]:+.0f}%, median {100 * statistics.median(errs):+.0f}%.")
    return "\n".join(L)


def host_fit(rows):
    """What the wall clock holds beyond the GPU's timer queries and the modeled fixed costs
    (passes, program loads, read-backs, downloads), against the frame's pixels: ns a pixel by
    least squares through zero (Profile::download_host_gbps)."""
    lines = []
    for card in sorted({r["card"] for r in rows}):
        pts = [(r["key"][8] ** 2, r["wall"] - r["gpu"] - r["fixed"]) for r in rows
               if r["card"] == card and r["gpu"] is not None and not changed(r)]
        if not pts:
            fail(f"--host-fit: no {card} frame with GPU times")
        ns = 1e6 * sum(p * m for p, m in pts) / sum(p * p for p, _ in pts)
        lines.append(f"{card}: {len(pts)} frames; the remainder beyond the GPU and the fixed "
                     "costs, by size:")
        for px in sorted({p for p, _ in pts}):
            rem = [m for p, m in pts if p == px]
            lines.append(f"  {int(px ** 0.5)}x{int(px ** 0.5)}: median "
                         f"{statistics.median(rem):.3f} ms over {len(rem)}")
        lines.append(f"  least squares: {ns:.2f} ns a pixel beyond the profile as it stands (its "
                     "download_host_gbps was fitted so, with it at 0)")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", metavar="FILE.json[@GRID][+PIPELINE]",
                    help="bench_gl JSON measured on a GPU")
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "bench", "bench_gl"),
                    help="the bench_gl that emulates the frames here (default: %(default)s)")
    ap.add_argument("--scene-dir", action="extend", nargs="+", default=[],
                    help="where the generated scenes are (scenes/ is always searched; "
                    "default .h200)")
    ap.add_argument("--block", nargs=2, metavar=("DOC", "NAME"),
                    help="write the table into DOC's block NAME instead of printing it")
    ap.add_argument("--host-fit", action="store_true",
                    help="print the frames' remainder per pixel instead (download_host_gbps)")
    a = ap.parse_args()
    dirs = a.scene_dir or [os.path.join(ROOT, ".h200")]
    rows = cells(a.files, a.bench, [os.path.join(ROOT, "scenes")] + dirs)
    if a.host_fit:
        print(host_fit(rows))
        return
    text = table(rows)
    if a.block:
        write_block(a.block[0], a.block[1], text)
    else:
        print(text)


if __name__ == "__main__":
    main()
