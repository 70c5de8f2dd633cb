#!/usr/bin/env python3
"""Each looping traversal kernel's GPU time (timer queries) against the cost model's price of its
passes, per structure: the pass work and the longest lanes, without and with the fetch wait (a
loop body's arithmetic between two of its fetches, Counters::loop_dependent_instructions).

Reads bench_gl JSON files measured on a GPU, as scripts/docs/cells.py does; every looping frame's
kernels are priced from the emulator's frame of the same options (bench_gl run here), on the
profile of the card that measured them.

Usage: /usr/bin/python3 scripts/docs/loop_kernels.py FILE.json ... [--bench build/bench/bench_gl]
           [--scene-dir DIR ...] [--json OUT.json]
Prints the table; --json writes the kernels' rows instead (results/structures/loop_kernels.json,
which scripts/docs/structures.py turns into the "fetch wait" section of
docs/studies/structures.md)."""
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
from cells import card_of, fail  # noqa: E402

STRUCTURES = ("grid", "grid2", "bvh", "kdtree")


def kernels(paths, bench, dirs):
    """(card, structure, size, GPU ms, price without the wait, price with it, dependent share)
    of every looping traversal kernel the files timed."""
    cache, out = {}, []
    for path in paths:
        try:
            with open(path) as fh:
                doc = json.load(fh)
        except (OSError, ValueError) as e:
            fail(f"{path}: {e}")
        card, grid = card_of(path, doc), doc.get("grid", "auto")
        for f in doc.get("frames", []):
            if f["variant"] != "looping" or not f["engine"].startswith("gl"):
                continue
            k = key(f)
            if (k, grid) not in cache:
                cache[(k, grid)] = bench_frames.emulate(bench, k, dirs, grid, "loop_kernels")
            emulated = {e["name"]: e for e in cache[(k, grid)]["kernels"]}
            for g in f["kernels"]:
                e = emulated.get(g["name"])
                if "looping traversal" not in g["name"] or g.get("gpu_ms") is None or not e:
                    continue
                p = f"predicted_{card}_"
                with_wait = e[p + "work_ms"] + e[p + "latency_ms"]
                c = e["counters"]
                ops = c["instructions"] - c["texture_fetches"]
                out.append({"card": card, "accel": k[1], "size": k[8], "gpu": g["gpu_ms"],
                            "without": with_wait - e[p + "fetch_wait_ms"], "with": with_wait,
                            "share": c["loop_dependent_instructions"] / ops if ops else 0.0})
    return out


def table(rows):
    L = ["| card | structure | kernels | operations between fetches | GPU / price without the "
         "wait | GPU / price with it |", "|---|---|---:|---:|---|---|"]

    def spread(v):
        return f"{min(v):.2f}-{max(v):.2f} (median {statistics.median(v):.2f})"
    for card in sorted({r["card"] for r in rows}):
        for a in STRUCTURES:
            sel = [r for r in rows if r["card"] == card and r["accel"] == a]
            if not sel:
                continue
            share = statistics.median(r["share"] for r in sel)
            L.append(f"| {card} | {a} | {len(sel)} | {100 * share:.0f}% | "
                     f"{spread([r['gpu'] / r['without'] for r in sel])} | "
                     f"{spread([r['gpu'] / r['with'] for r in sel])} |")
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", help="bench_gl JSON files measured on a GPU")
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "bench", "bench_gl"))
    ap.add_argument("--scene-dir", action="append", default=[],
                    help="where scenes not in scenes/ are (repeatable)")
    ap.add_argument("--json", metavar="OUT", help="write the kernels' rows here")
    args = ap.parse_args()
    if not os.path.exists(args.bench):
        fail(f"{args.bench}: not built (cmake --build build --target bench_gl)")
    dirs = [os.path.join(ROOT, "scenes")] + args.scene_dir
    rows = kernels(args.files, args.bench, dirs)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"files": [os.path.relpath(f, ROOT) for f in args.files], "kernels": rows},
                      fh, indent=1)
        print(f"wrote {args.json}")
    else:
        print(table(rows))


if __name__ == "__main__":
    main()
