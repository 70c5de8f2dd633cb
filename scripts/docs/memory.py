#!/usr/bin/python3
"""Writes the memory model's tables in docs/studies/scale.md (issue 50): for each run of
scripts/h200/scale.sh, the statistics' memory terms (host/report/memory_json.h), their sum and the
process's measured peak; then the bytes per pixel and per triangle of each structure, fitted on
the runs (least squares of each term against the pixels, or the triangles, of its sweep).

Usage: /usr/bin/python3 scripts/docs/memory.py [--runs results/scale/memory_*.csv] [--doc docs/studies/scale.md]
  --runs  CSV files packed by scripts/docs/scale.py --pack, or scale.sh's OUT folder (its json/)
  --doc   the Markdown file whose block between '<!-- memory.py: begin -->' and
          '<!-- memory.py: end -->' is replaced by the tables ('-' prints them instead)
"""
import argparse
import glob
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scale  # noqa: E402  (the runs' readers and the run names)

ROOT = scale.ROOT
TERMS = ["texture_storage", "scene", "structure", "frame", "walk_tallies", "image_library",
         "process"]
MIB = 1 << 20


def runs(rows):
    """The rows with memory terms, as (sweep, accel, walk, threads, size value, row)."""
    out = []
    for r in rows:
        m = scale.NAME.match(r["name"])
        if not m or m.group(1) or int(r.get("memory_peak_resident") or 0) <= 0:
            continue  # GL runs hold the driver's memory too: not modeled
        kind, accel, walk, threads = m.group(2), m.group(4), m.group(5), m.group(6)
        value = int(r["triangles"]) if kind == "tris" else int(r["width"]) * int(r["height"])
        out.append((kind, accel, walk, int(threads or 1), value, r))
    return out


def fit(points):
    """Least-squares slope and intercept of y against x."""
    n = len(points)
    if n < 2:
        return 0.0, 0.0
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    sxx = sum((x - mx) ** 2 for x, _ in points)
    if sxx == 0:
        return 0.0, my
    b = sum((x - mx) * (y - my) for x, y in points) / sxx
    return b, my - b * mx


def tables(rs):
    lines = ["| run | threads | texture storage | scene | structure | frame | walk tallies | "
             "image library | process | predicted | peak | predicted / peak |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    worst, within = 0.0, 0
    order = sorted(rs, key=lambda t: (t[0], t[1], t[2], t[3], t[4]))
    for kind, accel, walk, threads, value, r in order:
        pred, peak = int(r["memory_predicted_peak"]), int(r["memory_peak_resident"])
        ratio = pred / peak
        worst = max(worst, abs(ratio - 1))
        within += abs(ratio - 1) <= 0.10
        cells = [f"{int(r['memory_' + t]) / MIB:,.1f}" for t in TERMS]
        lines.append(f"| {r['name']} | {threads} | " + " | ".join(cells) +
                     f" | {pred / MIB:,.1f} | {peak / MIB:,.1f} | {ratio:.3f} |")
    head = [f"{within} of {len(rs)} runs within 10% of the measured peak; the largest miss "
            f"{100 * worst:.1f}%. MiB.", ""]
    # Bytes per pixel and per triangle, per structure and walk: each term's slope.
    per = ["| structure | walk | texture storage per pixel | frame per pixel | textures per "
           "triangle | scene per triangle | structure per triangle |",
           "|---|---|---:|---:|---:|---:|---:|"]
    for accel in scale.ACCELS:
        for walk in scale.WALKS:
            px = [t for t in rs if t[0] == "pixels" and t[1] == accel and t[2] == walk]
            tr = [t for t in rs if t[0] == "tris" and t[1] == accel and t[2] == walk]
            if len(px) < 2 or len(tr) < 2:
                continue

            def slope(ts, term):
                return fit([(t[4], int(t[5]["memory_" + term])) for t in ts])[0]

            per.append(f"| {accel} | {walk} | {slope(px, 'texture_storage'):.1f} | "
                       f"{slope(px, 'frame'):.1f} | {slope(tr, 'texture_storage'):.1f} | "
                       f"{slope(tr, 'scene'):.1f} | {slope(tr, 'structure'):.1f} |")
    return "\n".join(head + lines + ["", "Bytes per pixel (the bunny's sweep) and per triangle "
                                     "(the heightfields' sweep at 256x256), fitted:", ""] + per)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", nargs="+",
                    default=sorted(glob.glob(os.path.join(ROOT, "results", "scale",
                                                          "memory_*.csv"))))
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "studies", "scale.md"))
    a = ap.parse_args()
    rs = runs(scale.read_runs(a.runs))
    if not rs:
        scale.fail("no runs with the memory model's terms (scale.sh's runs since issue 50)")
    scale.write_block(a.doc, "memory.py", tables(rs))


if __name__ == "__main__":
    main()
