#!/usr/bin/python3
"""Writes docs/studies/scale.png and the slopes table of docs/studies/scale.md (issue 50): how a
frame's cost grows with the scene's triangles and with the frame's pixels, per structure and
walk, from the runs scripts/h200/scale.sh made (one --stats-json per frame), packed as CSV in
results/scale/.

Each line of the charts is one structure, walk and source: the emulator's render time on 16 and
on 1 host thread (measured; N is the host's cores), the cost model's gf6600 and h200 frames of the same counters
(modeled, from the many-thread run's predicted_ms), and the GL device's render time (measured,
on the card the run names). The table gives each line's points and its least-squares slope in
log-log (time ~ size^slope), over all its points and over its last three.

Usage: /usr/bin/python3 scripts/docs/scale.py [--runs results/scale/*.csv] [--png docs/studies/scale.png]
         [--doc docs/studies/scale.md]
       /usr/bin/python3 scripts/docs/scale.py --runs OUT --pack results/scale/NAME.csv
  --runs    CSV files of packed runs, or scale.sh's OUT folder (its json/)
  --pack    keep a folder's runs as one CSV (the fields the page needs) and stop
  --png ''  no chart (then matplotlib is not needed)
  --doc     the Markdown file whose block between '<!-- scale.py: begin -->' and
            '<!-- scale.py: end -->' is replaced by the tables ('-' prints them instead)
"""
import argparse
import csv
import glob
import json
import math
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ACCELS = ["grid", "grid2", "bvh", "kdtree"]
WALKS = ["multipass", "looping"]
# (source key, label, colour)
SOURCES = [("tN", "emulator, N threads", "tab:blue"), ("t1", "emulator, 1 thread", "tab:cyan"),
           ("gf6600", "gf6600 modeled", "tab:orange"), ("h200", "h200 modeled", "tab:red"),
           ("gl", "GL device", "tab:green")]
NAME = re.compile(r"^(gl-)?(tris|pixels)-([^-]+)-(grid2|grid|bvh|kdtree)-(multipass|looping)"
                  r"(?:-t(\d+))?$")


def fail(msg):
    sys.exit(f"scale.py: {msg}")


def count(label):
    """'10k' -> 10000, '4M' -> 4000000."""
    scale = {"k": 1000, "M": 1000000}.get(label[-1:], 1)
    return float(label[:-1] if scale > 1 else label) * scale


# The memory model's terms (the statistics' "memory" object, host/report/memory_json.h).
MEMORY = ["texture_storage", "scene", "structure", "frame", "walk_tallies", "image_library",
          "process", "predicted_peak", "peak_resident"]
FIELDS = ["name", "device", "triangles", "width", "height", "render_ms", "gf6600_ms", "h200_ms",
          "passes", "rays_traced", "voxel_steps", "nodes_visited", "triangle_tests", "addressing",
          "texture_bytes", "peak_rss_bytes", "threads"] + ["memory_" + k for k in MEMORY]


def read_json_runs(folder):
    """The rows of scale.sh's runs (FOLDER/json/NAME.json), as FIELDS."""
    folder = os.path.join(folder, "json")
    if not os.path.isdir(folder):
        fail(f"{folder}: no such folder (run scripts/h200/scale.sh first)")
    rows = []
    for f in sorted(os.listdir(folder)):
        if not f.endswith(".json") or not NAME.match(f[:-5]):
            continue
        path = os.path.join(folder, f)
        try:
            with open(path) as fh:
                j = json.load(fh)
        except (OSError, ValueError) as e:
            fail(f"{path}: {e}")
        pred = j.get("predicted_ms") or {}
        work = j["accel"].get("work", {})
        rows.append({"name": f[:-5], "device": j.get("device", ""),
                     "triangles": j["triangles"], "width": j["size"][0], "height": j["size"][1],
                     "render_ms": j["render_ms"], "gf6600_ms": pred.get("gf6600") or "",
                     "h200_ms": pred.get("h200") or "", "passes": j["totals"]["passes"],
                     "rays_traced": j["rays_traced"], "voxel_steps": work.get("voxel_steps", ""),
                     "nodes_visited": work.get("nodes_visited", ""),
                     "triangle_tests": work.get("triangle_tests", ""),
                     "addressing": j["accel"].get("addressing", ""),
                     "texture_bytes": j.get("texture_bytes", ""),
                     "peak_rss_bytes": j.get("peak_rss_bytes", ""), "threads": j.get("threads", ""),
                     **{"memory_" + k: j.get("memory", {}).get(k, "") for k in MEMORY}})
    return rows


def read_csv_runs(paths):
    rows = []
    for path in paths:
        try:
            with open(path, newline="") as fh:
                rows += list(csv.DictReader(fh))
        except OSError as e:
            fail(f"{path}: {e.strerror}")
    return rows


def load(rows):
    """points[(axis, accel, walk, source)] = sorted [(x, ms)]; the GL runs' devices; the
    many-thread runs' thread count."""
    points, devices, manys = {}, set(), set()
    for row in rows:
        m = NAME.match(row["name"])
        if not m:
            fail(f"run '{row['name']}': not a name scale.sh writes")
        gl, axis, _, accel, walk, threads = m.groups()
        xv = float(row["triangles"]) if axis == "tris" else float(row["width"]) * float(
            row["height"])

        def add(source, ms):
            if ms not in (None, "") and float(ms) > 0:
                points.setdefault((axis, accel, walk, source), []).append((xv, float(ms)))
        if gl:
            add("gl", row["render_ms"])
            devices.add(row["device"] or "?")
        else:
            many = int(threads) > 1
            if many:
                manys.add(int(threads))
            add("tN" if many else "t1", row["render_ms"])
            if many:
                for p in ("gf6600", "h200"):
                    add(p, row[f"{p}_ms"])
    for k in points:
        points[k].sort()
    if len(manys) > 1:
        fail(f"runs on {sorted(manys)} threads: one count per study")
    return points, devices, (manys.pop() if manys else 0)


def slope(pts):
    xs = [math.log(x) for x, _ in pts]
    ys = [math.log(y) for _, y in pts]
    n = len(pts)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def label_of(label, many):
    return label.replace("N threads", f"{many} threads")


def table(points, many):
    lines = ["| axis | structure | walk | source | points | from | to | slope | slope, last 3 |",
             "|---|---|---|---|---:|---:|---:|---:|---:|"]
    for axis, name in (("tris", "triangles"), ("pixels", "pixels")):
        for accel in ACCELS:
            for walk in WALKS:
                for src, label, _ in SOURCES:
                    pts = points.get((axis, accel, walk, src))
                    if not pts:
                        continue
                    s = slope(pts) if len(pts) >= 2 else float("nan")
                    tail = slope(pts[-3:]) if len(pts) >= 3 else float("nan")
                    lines.append(f"| {name} | {accel} | {walk} | {label_of(label, many)} | "
                                 f"{len(pts)} | "
                                 f"{pts[0][1]:,.1f} ms | {pts[-1][1]:,.1f} ms | {s:.2f} | {tail:.2f} |")
    return "\n".join(lines)


def chart(points, devices, many, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(17, 8.5), sharey="row")
    for row, (axis, xlabel) in enumerate((("tris", "triangles (heightfields, 256x256)"),
                                          ("pixels", "pixels (the bunny, 3,674 triangles)"))):
        for col, accel in enumerate(ACCELS):
            ax = axes[row][col]
            for src, label, colour in SOURCES:
                for walk, style in (("multipass", "-"), ("looping", "--")):
                    pts = points.get((axis, accel, walk, src))
                    if not pts:
                        continue
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], style, color=colour,
                            marker="o", markersize=3,
                            label=f"{label_of(label, many)}, {walk}")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_title(accel)
            ax.set_xlabel(xlabel)
            if col == 0:
                ax.set_ylabel("frame ms")
    handles, labels = axes[0][0].get_legend_handles_labels()
    for a in axes.flat:  # every line that appears in any panel, once
        for h, l in zip(*a.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8)
    dev = "; ".join(sorted(devices)) if devices else "no GL device runs"
    fig.suptitle(f"Frame time against triangles and pixels, primary rays (GL: {dev})",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0.08, 1, 0.96))
    fig.savefig(png, dpi=100)
    print(f"wrote {png}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", nargs="+",
                    default=sorted(glob.glob(os.path.join(ROOT, "results", "scale", "h100_*.csv"))),
                    help="CSV files packed from runs (default: results/scale/h100_*.csv, the GPU host's), or a "
                         "folder of scale.sh's runs (OUT, holding json/)")
    ap.add_argument("--pack", help="write the runs' rows to this CSV and stop")
    ap.add_argument("--png", default=os.path.join(ROOT, "docs", "studies", "scale.png"))
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "studies", "scale.md"))
    a = ap.parse_args()
    rows = read_runs(a.runs)
    if a.pack:
        with open(a.pack, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=FIELDS)
            w.writeheader()
            w.writerows(rows)
        print(f"wrote {a.pack}: {len(rows)} runs")
        return
    points, devices, many = load(rows)
    if not points:
        fail("no runs of scale.sh")
    text = table(points, many)
    if a.png:
        chart(points, devices, many, a.png)
    write_block(a.doc, "scale.py", text)


def read_runs(paths):
    """The runs of --runs: scale.sh's OUT folder (its json/), or CSV files packed from runs."""
    if len(paths) == 1 and os.path.isdir(paths[0]):
        return read_json_runs(paths[0])
    return read_csv_runs(paths)


def write_block(doc_path, name, text):
    """Replaces the block between '<!-- NAME: begin -->' and '<!-- NAME: end -->' of the
    Markdown file with text ('-': prints text instead)."""
    if doc_path == "-":
        print(text)
        return
    try:
        with open(doc_path) as fh:
            doc = fh.read()
    except OSError as e:
        fail(f"{doc_path}: {e.strerror}")
    begin, end = f"<!-- {name}: begin -->", f"<!-- {name}: end -->"
    if begin not in doc or end not in doc:
        fail(f"{doc_path}: no block between '{begin}' and '{end}'")
    head, rest = doc.split(begin, 1)
    _, tail = rest.split(end, 1)
    with open(doc_path, "w") as fh:
        fh.write(f"{head}{begin}\n{text}\n{end}{tail}")
    print(f"wrote {doc_path}")


if __name__ == "__main__":
    main()
