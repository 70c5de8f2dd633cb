#!/usr/bin/env python3
"""The paper's passes on real OpenGL drivers, beside the emulator and the cost model.

Runs bench/bench_gl on this machine's EGL device (Mesa llvmpipe here), or reads JSON it wrote
elsewhere (a GPU host: --add NAME=FILE.json), and writes docs/real_gpu.md with its chart
docs/real_gpu.png (matplotlib): per scene and size, the frame's wall and GPU ms on each driver,
the emulator's host ms, the cost model's prediction for each profile, passes and read-backs;
per kernel, GPU ms; and the fixed costs of a pass, a query read-back and a program switch.

Usage: /usr/bin/python3 scripts/real_gpu.py [--bench build/bench/bench_gl] [--runs 3]
         [--reuse] [--add h200=docs/real_gpu_h200.json]
"""
import argparse
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs")


def run_bench(exe, runs, out):
    cmd = [exe, "--runs", str(runs), "--json", out]
    print("real_gpu:", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, cwd=ROOT)


def fmt(v, digits=1):
    return "—" if v is None else f"{v:,.{digits}f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench", default=os.path.join(ROOT, "build/bench/bench_gl"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--reuse", action="store_true",
                    help="keep docs/real_gpu_llvmpipe.json instead of measuring again")
    ap.add_argument("--add", action="append", default=[],
                    help="NAME=FILE.json: bench_gl figures measured on another machine")
    args = ap.parse_args()

    local = os.path.join(DOCS, "real_gpu_llvmpipe.json")
    if not args.reuse or not os.path.exists(local):
        run_bench(args.bench, args.runs, local)
    sources = [("llvmpipe", local)]
    for a in args.add:
        name, _, path = a.partition("=")
        if not path or not os.path.exists(path):
            sys.exit(f"real_gpu: --add {a}: expected NAME=FILE.json with an existing file")
        sources.append((name, path))
    data = {}
    for name, path in sources:
        with open(path) as f:
            data[name] = json.load(f)

    lines = ["# The paper's passes on real OpenGL drivers",
             "",
             "Written by `scripts/real_gpu.py` from `bench/bench_gl` (do not edit by hand). The GL",
             "device (`gl/`) runs the stream tracer's host loop unchanged, with fragment shaders",
             "generated from the same C++ kernels the emulator runs. Frames use `docs/table1.md`'s",
             "settings (3 iterations, phong, no shadow rays, a 15³ grid); every figure is the median",
             f"of the runs after one warm-up (which compiles the programs).",
             ""]
    for name, d in data.items():
        lines += [f"## {name}: {d['device']}", ""]
        lines += ["Fixed costs (1x1 passes, wall clock per pass; each pass also carries the GL",
                  "device's own non-blocking sample and timer queries):", "",
                  f"- one pass: **{fmt(d['pass_us'], 2)} µs**",
                  f"- one blocking occlusion-query read-back: **{fmt(d['readback_us'], 2)} µs** "
                  "beyond the pass",
                  f"- one program switch: **{fmt(d['program_switch_us'], 2)} µs** beyond the pass",
                  "", "| pass | size | wall µs | GPU µs |", "|---|---|---|---|"]
        for r in d["fixed"]:
            lines.append(f"| {r['what']} | {r['size']}² | {fmt(r['wall_us'], 2)} | "
                         f"{fmt(r['gpu_us'], 2)} |")
        lines += ["", "| scene | size | engine | wall ms | GPU ms | passes | read-backs | "
                  "predicted ms (gf5700 / gf6600 / h200) |", "|---|---|---|---|---|---|---|---|"]
        for f in d.get("frames", []):
            pred = f.get("predicted_ms")
            p = " / ".join(fmt(pred.get(k)) for k in ("gf5700", "gf6600", "h200")) if pred else ""
            eng = "emulator (host)" if f["engine"] == "stream" else "GL device"
            lines.append(f"| {f['scene']} | {f['size']}² | {eng} | {fmt(f['wall_ms'])} | "
                         f"{fmt(f['gpu_ms'])} | {f['passes']:,} | {f['query_readbacks']:,} | {p} |")
        lines += ["", "Per kernel (GL device GPU ms, emulator host ms), first size:", ""]
        gl_frames = [f for f in d.get("frames", []) if f["engine"] == "gl"]
        if gl_frames:
            size0 = gl_frames[0]["size"]
            names = [k["name"] for k in gl_frames[0]["kernels"]]
            lines += ["| scene | " + " | ".join(names) + " |",
                      "|---|" + "---|" * len(names)]
            for f in d["frames"]:
                if f["size"] != size0:
                    continue
                ks = {k["name"]: k for k in f["kernels"]}
                key = "gpu_ms" if f["engine"] == "gl" else "host_ms"
                label = f"{f['scene']} ({'GL GPU' if f['engine'] == 'gl' else 'emulator host'})"
                lines.append(f"| {label} | " + " | ".join(
                    fmt(ks[n][key], 2) if n in ks else "—" for n in names) + " |")
        lines.append("")

    # Chart: per scene x size, a group of bars (emulator host, each driver's wall and GPU ms,
    # each profile's prediction), log scale; and the fixed costs.
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.2), gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    cells = []
    for name, d in data.items():
        for f in d.get("frames", []):
            key = (f["scene"], f["size"])
            if key not in cells:
                cells.append(key)
    series = []
    first = next(iter(data.values()))
    series.append(("emulator host ms (this machine)",
                   {(f["scene"], f["size"]): f["wall_ms"] for f in first.get("frames", [])
                    if f["engine"] == "stream"}))
    for name, d in data.items():
        series.append((f"{name} wall ms", {(f["scene"], f["size"]): f["wall_ms"]
                                             for f in d.get("frames", []) if f["engine"] == "gl"}))
        series.append((f"{name} GPU ms", {(f["scene"], f["size"]): f["gpu_ms"]
                                            for f in d.get("frames", []) if f["engine"] == "gl"}))
    for prof in ("gf5700", "gf6600", "h200"):
        series.append((f"predicted {prof}", {(f["scene"], f["size"]): f["predicted_ms"].get(prof)
                                             for f in first.get("frames", [])
                                             if f["engine"] == "stream"
                                             and f["predicted_ms"].get(prof)}))
    series = [s for s in series if s[1]]
    width = 0.8 / max(1, len(series))
    for i, (label, values) in enumerate(series):
        xs = [c + i * width for c in range(len(cells)) if cells[c] in values]
        ys = [values[cells[c]] for c in range(len(cells)) if cells[c] in values]
        ax.bar(xs, ys, width, label=label)
    ax.set_xticks([c + 0.4 - width / 2 for c in range(len(cells))])
    ax.set_xticklabels([f"{s}\n{n}²" for s, n in cells])
    ax.set_yscale("log")
    ax.set_ylabel("frame time, ms (log scale)")
    ax.set_title("One frame at Table 1's settings")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    ax.grid(axis="y", which="both", alpha=0.3)
    ax = axes[1]
    kinds = ["pass", "pass + blocking query read-back", "pass, program switched every pass"]
    for name, d in data.items():
        for kind, marker in zip(kinds, "os^"):
            rows = [r for r in d["fixed"] if r["what"] == kind]
            ax.plot([r["size"] for r in rows], [r["wall_us"] for r in rows], marker=marker,
                    label=f"{name}: {kind}")
        for prefix, marker, label in (("pass, one", "v", "one RGBA32F target"),
                                      ("pass, two", "D", "two RGBA32F targets (MRT)")):
            rows = [r for r in d["fixed"] if r["what"].startswith(prefix)]
            ax.plot([r["size"] for r in rows], [r["wall_us"] for r in rows], marker=marker,
                    label=f"{name}: {label}")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("pass size, pixels per side")
    ax.set_ylabel("wall time per pass, µs (log scale)")
    ax.set_title("Fixed and per-pixel cost of one pass")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    ax.grid(which="both", alpha=0.3)
    fig.tight_layout()
    png = os.path.join(DOCS, "real_gpu.png")
    fig.savefig(png, dpi=110)
    lines += ["![frame times and pass costs](real_gpu.png)", ""]
    extra = os.path.join(DOCS, "real_gpu_notes.md")
    if os.path.exists(extra):
        with open(extra) as f:
            lines += [f.read().rstrip(), ""]
    with open(os.path.join(DOCS, "real_gpu.md"), "w") as f:
        f.write("\n".join(lines))
    print(f"real_gpu: wrote docs/real_gpu.md and {os.path.relpath(png, ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
