#!/usr/bin/env python3
"""The paper's passes on real OpenGL drivers, beside the emulator and the cost model.

Writes docs/studies/real_gpu.md and its chart docs/studies/real_gpu.png (matplotlib) from JSON that
bench/bench_gl wrote:
  results/real_gpu/real_gpu_llvmpipe.json     this machine's EGL device (Mesa llvmpipe); measured again
                                  unless --reuse
  results/real_gpu/real_gpu_predictions.json  the emulator's counts and the cost model's predictions
                                  (bench_gl --readback-wait none); computed again unless --reuse
  --add NAME=FILE.json            figures measured on another machine (the H200:
                                  scripts/h200/real_gpu.sh), with NAME_clocks.csv beside it if
                                  nvidia-smi sampled the clocks there
  --add-run NAME=FILE.json        an earlier run on that machine, shown for its clocks only

Usage: /usr/bin/python3 scripts/docs/real_gpu.py [--bench build/bench/bench_gl] [--runs 3] [--reuse]
         [--add h200=results/real_gpu/real_gpu_h200.json] [--add-run h200-run1=results/real_gpu/real_gpu_h200_run1.json]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOCS = os.path.join(ROOT, "docs", "studies")
RESULTS = os.path.join(ROOT, "results", "real_gpu")  # the measurements (results/real_gpu/README.md)


def run(cmd):
    print("real_gpu:", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, cwd=ROOT)


def fmt(v, digits=1):
    return "—" if v is None else f"{v:,.{digits}f}"


def fps(ms):
    x = 1e3 / ms
    return f"{x:.1f}" if x < 10 else f"{x:,.0f}"


def pct(pred, meas):
    return "—" if not pred or not meas else f"{100 * (pred / meas - 1):+.0f}%"


def load(path):
    with open(path) as f:
        return json.load(f)


def clocks(path):
    """SM clock samples (MHz) taken while the GPU was busy (utilization > 0)."""
    if not os.path.exists(path):
        return None
    busy = []
    with open(path) as f:
        for row in csv.reader(f, skipinitialspace=True):
            if len(row) < 4 or not row[1].endswith("MHz"):
                continue
            mhz, util = float(row[1].split()[0]), float(row[3].split()[0])
            if util > 0:
                busy.append(mhz)
    return busy or None


def frames_by(d, variant="multipass"):
    return {(f["scene"], f["size"], f["engine"]): f for f in d.get("frames", [])
            if f.get("variant", "multipass") == variant}


def fixed_table(d):
    lines = ["| pass | size | wall µs | GPU µs |", "|---|---|---|---|"]
    for r in d["fixed"]:
        lines.append(f"| {r['what']} | {r['size']}² | {fmt(r['wall_us'], 2)} | "
                     f"{fmt(r['gpu_us'], 2)} |")
    return lines


def plot_chart(pred, llvm, remote, earlier):
    """docs/studies/real_gpu.png: per scene and size, bars for each measured and predicted frame time
    (log scale); and the fixed cost of a pass against its size."""
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.4), gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    cells = sorted({(s, z) for (s, z, e) in pred}, key=lambda c: (c[1], c[0]))
    series = [("emulator host ms (2-core dev machine)",
               {(s, z): f["wall_ms"] for (s, z, e), f in pred.items() if e == "stream"}),
              ("llvmpipe wall ms", {(f["scene"], f["size"]): f["wall_ms"]
                                    for f in llvm.get("frames", []) if f["engine"] == "gl"})]
    for name, (d, _) in remote.items():
        fb = frames_by(d)
        for eng, label in (("gl", "wall ms, blocking"), ("gl-poll", "wall ms, polled")):
            series.append((f"{name} {label}", {(s, z): f["wall_ms"]
                                                for (s, z, e), f in fb.items() if e == eng}))
        series.append((f"{name} GPU ms", {(s, z): f["gpu_ms"]
                                          for (s, z, e), f in fb.items() if e == "gl-poll"}))
        series.append((f"predicted {name}", {(s, z): f["predicted_ms"][name]
                                             for (s, z, e), f in pred.items()
                                             if e == "stream" and name in f["predicted_ms"]}))
    for name, (d, _) in earlier.items():
        series.append((f"{name} wall ms (clock dropped)",
                       {(f["scene"], f["size"]): f["wall_ms"] for f in d.get("frames", [])
                        if f["engine"] == "gl"}))
    series = [s for s in series if s[1]]
    width = 0.84 / max(1, len(series))
    for i, (label, values) in enumerate(series):
        xs = [c + i * width for c in range(len(cells)) if cells[c] in values]
        ys = [values[cells[c]] for c in range(len(cells)) if cells[c] in values]
        ax.bar(xs, ys, width, label=label)
    ax.set_xticks([c + 0.42 - width / 2 for c in range(len(cells))])
    ax.set_xticklabels([f"{s}\n{n}²" for s, n in cells])
    ax.set_yscale("log")
    ax.set_ylabel("frame time, ms (log scale)")
    ax.set_title("One frame at Table 1's settings")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    ax.grid(axis="y", which="both", alpha=0.3)
    ax = axes[1]
    kinds = [("pass", "o"), ("pass + blocking query read-back", "s"),
             ("pass + polled query read-back", "^"), ("pass, two RGBA32F targets (MRT)", "D")]
    for name, d in [("llvmpipe", llvm)] + [(n, d) for n, (d, _) in remote.items()]:
        for kind, marker in kinds:
            rows = sorted((r for r in d["fixed"]
                           if r["what"] == kind or (kind == "pass" and r["what"].startswith(
                               "pass, one"))), key=lambda r: r["size"])
            if rows:
                ax.plot([r["size"] for r in rows], [r["wall_us"] for r in rows], marker=marker,
                        label=f"{name}: {kind}")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("pass size, pixels per side")
    ax.set_ylabel("wall time per pass, µs (log scale)")
    ax.set_title("Fixed and per-pixel cost of one pass")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    ax.grid(which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "real_gpu.png"), dpi=110)


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench", default=os.path.join(ROOT, "build/bench/bench_gl"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--reuse", action="store_true",
                    help="keep the llvmpipe and prediction JSON instead of measuring again")
    ap.add_argument("--add", action="append", default=[],
                    help="NAME=FILE.json: bench_gl figures measured on another machine")
    ap.add_argument("--add-variants", action="append", default=[],
                    help="NAME=FILE.json: that machine's frames with --variants (MRT, looping)")
    ap.add_argument("--add-run", action="append", default=[],
                    help="NAME=FILE.json: an earlier run there, for its frame times and clocks")
    return ap.parse_args()


def measure(args):
    """Runs bench_gl on this machine for the JSON that is missing (all of it without --reuse).
    Returns the paths of the llvmpipe figures, the predictions and the variants' predictions."""
    local = os.path.join(RESULTS, "real_gpu_llvmpipe.json")
    preds = os.path.join(RESULTS, "real_gpu_predictions.json")
    if not args.reuse or not os.path.exists(local):
        run([args.bench, "--runs", str(args.runs), "--grid", "15", "--json", local])
    if not args.reuse or not os.path.exists(preds):
        run([args.bench, "--runs", "1", "--sizes", "256", "1024", "--readback-wait", "none",
             "--grid", "15", "--json", preds])
    preds_var = os.path.join(RESULTS, "real_gpu_predictions_variants.json")
    if args.add_variants and (not args.reuse or not os.path.exists(preds_var)):
        run([args.bench, "--runs", "1", "--sizes", "256", "1024", "--readback-wait", "none",
             "--grid", "15", "--variants", "mrt", "looping", "--json", preds_var])
    return local, preds, preds_var


def named(specs):
    """NAME=FILE.json arguments as {NAME: (the JSON, its busy SM clocks or None)}."""
    out = {}
    for a in specs:
        name, _, path = a.partition("=")
        if not path or not os.path.exists(path):
            sys.exit(f"real_gpu: {a}: expected NAME=FILE.json with an existing file")
        out[name] = (load(path), clocks(path.replace(".json", "_clocks.csv")))
    return out


INTRO = ["# The paper's passes on real OpenGL drivers",
         "",
         "Written by `scripts/docs/real_gpu.py` from `bench/bench_gl` (do not edit by hand). The GL",
         "device (`gl/`) runs the stream tracer's host loop unchanged, with fragment shaders",
         "generated from the same C++ kernels the emulator runs. Frames use `docs/studies/table1.md`'s",
         "settings (3 iterations, phong, no shadow rays, a 15³ grid); every figure is the median",
         "of the runs after one warm-up (which compiles the programs). Predictions are the cost",
         "model's (`host/model/cost_model.cpp`) from the emulator's counts of the same frame, which",
         "equal the GL device's (`tests/gl`).",
         ""]


def remote_kernels(name, fb, pred):
    """Per kernel at the largest size: the polled run's GPU ms beside the predicted work."""
    lines = ["", "Per kernel at the largest size, GPU ms (timer queries, polled run) beside "
             "the predicted fragment work (the fixed costs apart):", ""]
    big = max((k[1] for k in fb), default=None)
    rows = [f for (s, z, e), f in fb.items() if z == big and e == "gl-poll"]
    if rows:
        lines += ["| scene | kernel | passes | GPU ms | predicted work ms | measured / "
                  "predicted |", "|---|---|---|---|---|---|"]
        for f in rows:
            pr = pred.get((f["scene"], big, "stream"))
            pk = {k["name"]: k for k in pr["kernels"]} if pr else {}
            for k in f["kernels"]:
                w = pk.get(k["name"], {}).get(f"predicted_{name}_work_ms")
                if k["gpu_ms"] < 1:
                    continue
                ratio = f"{k['gpu_ms'] / w:.2f}" if w else "—"
                lines.append(f"| {f['scene']} | {k['name']} | {k['passes']:,} | "
                             f"{fmt(k['gpu_ms'], 2)} | {fmt(w, 2)} | {ratio} |")
        lines.append("")
    return lines


def remote_section(name, d, clk, pred):
    """The section of one machine given with --add: its clock, fixed costs, frames and kernels."""
    fb = frames_by(d)
    lines = [f"## {name}: {d['device']}", ""]
    if clk:
        lines += [f"SM clock while the GPU was busy (nvidia-smi every 200 ms): median "
                  f"**{statistics.median(clk):.0f} MHz**, {min(clk):.0f}–{max(clk):.0f} MHz "
                  f"over {len(clk)} samples.", ""]
    lines += ["### Fixed costs", "",
              "Tiny passes (copy the own texel), wall clock per pass; each pass also carries",
              "the GL device's own non-blocking sample and timer queries. *Blocking*: the host",
              "asks for GL_QUERY_RESULT and the driver waits; *polled*: it spins on",
              "GL_QUERY_RESULT_AVAILABLE.", "",
              f"- one pass: **{fmt(d['pass_us'], 2)} µs**; a blocking read-back "
              f"**{fmt(d['readback_us'], 2)} µs** more; a program switch "
              f"{fmt(d['program_switch_us'], 2)} µs (noise)", ""]
    lines += fixed_table(d) + [""]
    lines += ["### Frames, measured and predicted", "",
              "| scene | size | wall ms, blocking | wall ms, polled | GPU ms | passes | "
              "read-backs | predicted ms | predicted vs polled | vs blocking |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for (scene, size, eng), f in fb.items():
        if eng != "gl":
            continue
        p = fb.get((scene, size, "gl-poll"))
        pr = pred.get((scene, size, "stream"))
        pm = pr["predicted_ms"].get(name) if pr else None
        lines.append(
            f"| {scene} | {size}² | {fmt(f['wall_ms'])} | {fmt(p and p['wall_ms'])} | "
            f"{fmt(f['gpu_ms'])} | {f['passes']:,} | {f['query_readbacks']:,} | {fmt(pm)} | "
            f"{pct(pm, p and p['wall_ms'])} | {pct(pm, f['wall_ms'])} |")
    return lines + remote_kernels(name, fb, pred)


def variants_section(name, d, clk, pred, pv, source):
    """The MRT and looping frames given with --add-variants (read from SOURCE) beside the
    multipass ones; PV holds this machine's predictions of the variants."""
    lines = [f"### The paper's future work on the {name}: MRT and looping kernels", "",
             "The same frames with the fused two-output passes (`--mrt on`) and with the "
             "looping kernels (`--kernels looping`, 32 steps a pass), priced on the "
             f"`{name}` profile, polled read-backs, measured beside the multipass pipeline "
             f"(`{os.path.relpath(os.path.abspath(source), ROOT)}`)."]
    if clk:
        lines[-1] += (f" SM clock while busy: median {statistics.median(clk):.0f} MHz, "
                      f"{min(clk):.0f}–{max(clk):.0f} MHz.")
    lines += ["", "| scene | size | pipeline | wall ms | GPU ms | passes | read-backs | "
              "predicted ms | predicted vs wall | frames per second | x multipass |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    base = frames_by(d, "multipass")
    cells = sorted({(f["scene"], f["size"]) for f in d["frames"]}, key=lambda c: (c[1], c[0]))
    for scene, size in cells:
        for v in ("multipass", "mrt", "looping"):
            f = frames_by(d, v).get((scene, size, "gl-poll"))
            if not f:
                continue
            src = pred if v == "multipass" else frames_by(pv, v)
            pr = src.get((scene, size, "stream"))
            # multipass predictions are the gf5700-profile run's counts priced on this card's profile
            pm = pr["predicted_ms"].get(name) if pr else None
            b = base.get((scene, size, "gl-poll"))
            lines.append(
                f"| {scene} | {size}² | {v} | {fmt(f['wall_ms'])} | {fmt(f['gpu_ms'])} | "
                f"{f['passes']:,} | {f['query_readbacks']:,} | {fmt(pm)} | "
                f"{pct(pm, f['wall_ms'])} | {fps(f['wall_ms'])} | "
                f"{b['wall_ms'] / f['wall_ms']:.1f}x |")
    lines.append("")
    return lines


def earlier_section(name, d, clk):
    """An earlier run given with --add-run: its GL frames beside the emulator's."""
    fb = frames_by(d)
    lines = [f"### An earlier run ({name}): the emulator's runs between the GL frames", ""]
    if clk:
        lines += [f"SM clock while busy: median {statistics.median(clk):.0f} MHz, "
                  f"{min(clk):.0f}–{max(clk):.0f} MHz over {len(clk)} samples.", ""]
    lines += ["| scene | size | GL wall ms (blocking) | GL GPU ms | emulator host ms "
              "(16 threads) |", "|---|---|---|---|---|"]
    for (scene, size, eng), f in fb.items():
        if eng != "gl":
            continue
        s = fb.get((scene, size, "stream"))
        lines.append(f"| {scene} | {size}² | {fmt(f['wall_ms'])} | {fmt(f['gpu_ms'])} | "
                     f"{fmt(s and s['wall_ms'])} |")
    lines.append("")
    return lines


def llvmpipe_section(llvm):
    """This machine's EGL device: fixed costs and Table 1's frames, GL beside the emulator."""
    lines = [f"## llvmpipe: {llvm['device']}", "",
             f"- one pass: **{fmt(llvm['pass_us'], 2)} µs**; a blocking read-back "
             f"**{fmt(llvm['readback_us'], 2)} µs** more; a program switch "
             f"**{fmt(llvm['program_switch_us'], 2)} µs** more", ""]
    lines += fixed_table(llvm) + [""]
    lines += ["| scene | size | engine | wall ms | GPU ms | passes | read-backs |",
              "|---|---|---|---|---|---|---|"]
    for f in llvm.get("frames", []):
        eng = "emulator (host, this machine)" if f["engine"] == "stream" else "GL device"
        lines.append(f"| {f['scene']} | {f['size']}² | {eng} | {fmt(f['wall_ms'])} | "
                     f"{fmt(f.get('gpu_ms'))} | {f['passes']:,} | {f['query_readbacks']:,} |")
    lines.append("")
    return lines


def main():
    args = parse_args()
    local, preds, preds_var = measure(args)
    remote = named(args.add)
    earlier = named(args.add_run)
    variants = named(args.add_variants)
    llvm = load(local)
    pred = frames_by(load(preds))

    lines = list(INTRO)
    for name, (d, clk) in remote.items():
        lines += remote_section(name, d, clk, pred)
    for name, (d, clk) in variants.items():
        pv = load(preds_var) if os.path.exists(preds_var) else {"frames": []}
        source = next(a.partition("=")[2] for a in args.add_variants if a.startswith(name + "="))
        lines += variants_section(name, d, clk, pred, pv, source)
    for name, (d, clk) in earlier.items():
        lines += earlier_section(name, d, clk)
    lines += llvmpipe_section(llvm)

    plot_chart(pred, llvm, remote, earlier)
    png = os.path.join(DOCS, "real_gpu.png")
    lines += ["![frame times and pass costs](real_gpu.png)", ""]
    extra = os.path.join(DOCS, "real_gpu_notes.md")
    if os.path.exists(extra):
        with open(extra) as f:
            lines += [f.read().rstrip(), ""]
    with open(os.path.join(DOCS, "real_gpu.md"), "w") as f:
        f.write("\n".join(lines))
    print(f"real_gpu: wrote docs/studies/real_gpu.md and {os.path.relpath(png, ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
