#!/usr/bin/python3
"""The pipeline's structural variants side by side: multipass (the paper's), early-z masks, MRT
fused passes, looping (branching) kernels with a few step budgets, and their combinations, on
every bundled scene at 256x256, on the GeForce 6600 (fp40) and a modern profile (RTX 4090).

Renders each cell with vgpu-rt (--stats-json, --aov hit=...), compares every variant's hit ids
with the multipass run of the same scene and profile (vgpu-rt compare, OpenImageIO, threshold 0),
and writes docs/studies/variants.md, results/variants/variants.csv and docs/studies/variants.png (matplotlib).

Usage: /usr/bin/python3 scripts/docs/variants.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
         [--threads 1] [--reuse] [--scenes NAME ...]
  --reuse  keep the JSON and EXR of earlier renders (build/variants/) instead of rendering again
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOCS = os.path.join(ROOT, "docs", "studies")
PROFILES = [("gf6600", "GeForce 6600 (fp40)"), ("rtx4090", "RTX 4090")]
# name, extra vgpu-rt arguments
VARIANTS = [
    ("multipass", []),
    ("masks", ["--masks", "on"]),
    ("mrt", ["--mrt", "on"]),
    ("mrt + masks", ["--mrt", "on", "--masks", "on"]),
    ("looping 8", ["--kernels", "looping", "--steps-per-pass", "8"]),
    ("looping 32", ["--kernels", "looping", "--steps-per-pass", "32"]),
    ("looping 128", ["--kernels", "looping", "--steps-per-pass", "128"]),
    ("looping 32 + masks", ["--kernels", "looping", "--steps-per-pass", "32", "--masks", "on"]),
    ("looping 32 + mrt", ["--kernels", "looping", "--steps-per-pass", "32", "--mrt", "on"]),
]


def slug(s):
    return re.sub(r"[^a-z0-9]+", "-", s.lower()).strip("-")


def bundled_scenes(exe):
    out = subprocess.run([exe, "scenes"], check=True, capture_output=True, text=True).stdout
    return [line.split()[0] for line in out.splitlines() if line.strip()]


def render(exe, work, scene, profile, variant, args, opts):
    base = os.path.join(work, f"{scene}_{profile}_{slug(variant)}")
    js, hit = base + ".json", base + "_hit.exr"
    if not (opts.reuse and os.path.exists(js) and os.path.exists(hit)):
        try:
            vgpurt.render(exe, scene, ["--size", f"{opts.size}x{opts.size}", "--profile", profile,
                                       "--threads", str(opts.threads)] + args,
                          stats_json=js, aovs={"hit": hit})
        except vgpurt.Failed as e:
            return {"refused": e.message}
    d = vgpurt.read_stats(js)
    d["hit_path"] = hit
    return d


def differing(exe, a, b):
    try:
        return 100.0 * vgpurt.compare(exe, a, b, threshold=0)[0]
    except vgpurt.Failed as e:
        sys.exit(f"variants: {e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build/host/vgpu-rt"))
    ap.add_argument("--work", default=os.path.join(ROOT, "build/variants"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--scenes", nargs="*")
    opts = ap.parse_args()
    exe = opts.vgpu_rt
    if not os.path.exists(exe):
        sys.exit(f"variants: {exe}: no such file (build first: cmake --build build)")
    os.makedirs(opts.work, exist_ok=True)
    scenes = opts.scenes or bundled_scenes(exe)

    rows = []
    total = len(scenes) * len(PROFILES) * len(VARIANTS)
    t0 = time.time()
    n = 0
    for profile, _ in PROFILES:
        for scene in scenes:
            ref = None
            for variant, args in VARIANTS:
                n += 1
                print(f"variants: [{n}/{total}] {scene} {profile} {variant} "
                      f"({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)
                d = render(exe, opts.work, scene, profile, variant, args, opts)
                row = {"scene": scene, "profile": profile, "variant": variant}
                if "refused" in d:
                    row["refused"] = d["refused"]
                    rows.append(row)
                    continue
                t = d["totals"]
                shaded = t["fragments_shaded"]
                slots = t.get("loop_lane_slots", 0) or 0
                idle = (t.get("lanes_idle") or 0) + (t.get("loop_lanes_idle", 0) or 0)
                row.update({
                    "passes": t["passes"],
                    "program_loads": t["program_loads"],
                    "query_readbacks": t["query_readbacks"],
                    "fragments_shaded": shaded,
                    "fragments_masked": t["fragments_masked"],
                    "loop_lane_slots": slots,
                    "idle_share": idle / (shaded + slots) if shaded + slots else 0.0,
                    "bytes": t["bytes_read"] + t["bytes_written"],
                    "predicted_ms": d["predicted_ms"][profile],
                    "host_ms": d["render_ms"],
                })
                if ref is None:
                    ref = d["hit_path"]
                    row["hit_differ_pct"] = 0.0
                else:
                    row["hit_differ_pct"] = differing(exe, ref, d["hit_path"])
                rows.append(row)

    keys = ["scene", "profile", "variant", "passes", "program_loads", "query_readbacks",
            "fragments_shaded", "fragments_masked", "loop_lane_slots", "idle_share", "bytes",
            "predicted_ms", "host_ms", "hit_differ_pct", "refused"]
    with open(os.path.join(ROOT, "results", "variants", "variants.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})

    ok = [r for r in rows if "refused" not in r]
    names = [v for v, _ in VARIANTS]

    def cell(scene, profile, variant):
        for r in ok:
            if (r["scene"], r["profile"], r["variant"]) == (scene, profile, variant):
                return r
        return None

    lines = ["# Pipeline variants: multipass, masks, MRT, looping",
             "",
             "Written by `scripts/docs/variants.py` (do not edit by hand): every bundled scene at "
             f"{opts.size}x{opts.size} with the default settings (3 ray-tracing iterations, phong, "
             "shadow rays), rendered by the emulator with each variant of the pipeline's structure "
             f"on two profiles, {opts.threads} host thread(s). *Predicted* is the cost model's "
             "time for that profile from the run's own counters; *host* is the emulator's wall "
             "time on the development machine (2 cores shared with other work: read ratios). "
             "*Hit ids differ* compares every pixel's hit id with the multipass run "
             "(`vgpu-rt compare`, threshold 0).",
             "",
             "Variants: `--masks on` (early-z: finished rays cost nothing); `--mrt on` (fused "
             "two-output passes, `kernels/fused.h`); `--kernels looping --steps-per-pass N` (one "
             "program walks voxels and tests triangles in a data-dependent loop, N steps a pass); "
             "and combinations.", ""]
    refused = [r for r in rows if "refused" in r]
    if refused:
        lines += ["Refused combinations (the CLI's own words):", ""]
        seen = set()
        for r in refused:
            key = (r["profile"], r["variant"], r["refused"])
            if key not in seen:
                seen.add(key)
                lines.append(f"- {r['profile']}, {r['variant']}: `{r['refused']}`")
        lines.append("")

    for profile, display in PROFILES:
        lines += [f"## {display} (`{profile}`)", "",
                  "Totals over the bundled scenes, and the share of scenes each variant is the "
                  "fastest on (predicted):", "",
                  "| variant | passes | program loads | read-backs | fragments shaded | loop lane "
                  "slots | idle share | GB moved | predicted ms | host ms | wins | hit ids "
                  "differ (worst scene) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        best = {}
        for scene in scenes:
            cands = [cell(scene, profile, v) for v in names]
            cands = [c for c in cands if c]
            if cands:
                best[scene] = min(cands, key=lambda c: c["predicted_ms"])["variant"]
        for v in names:
            cs = [cell(s, profile, v) for s in scenes]
            cs = [c for c in cs if c]
            if not cs:
                continue
            sh = sum(c["fragments_shaded"] for c in cs)
            sl = sum(c["loop_lane_slots"] for c in cs)
            idle = sum(c["idle_share"] * (c["fragments_shaded"] + c["loop_lane_slots"]) for c in cs)
            wins = sum(1 for s in scenes if best.get(s) == v)
            lines.append(
                f"| {v} | {sum(c['passes'] for c in cs):,} | "
                f"{sum(c['program_loads'] for c in cs):,} | "
                f"{sum(c['query_readbacks'] for c in cs):,} | {sh / 1e6:,.1f} M | "
                f"{sl / 1e6:,.1f} M | {100 * idle / (sh + sl):.1f}% | "
                f"{sum(c['bytes'] for c in cs) / 1e9:,.2f} | "
                f"{sum(c['predicted_ms'] for c in cs):,.1f} | "
                f"{sum(c['host_ms'] for c in cs):,.0f} | {wins}/{len(scenes)} | "
                f"{max(c['hit_differ_pct'] for c in cs):.4f}% |")
        lines += ["", "Predicted ms per scene (the fastest in bold):", "",
                  "| scene | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
        for scene in scenes:
            cs = {v: cell(scene, profile, v) for v in names}
            out = []
            for v in names:
                c = cs[v]
                if not c:
                    out.append("refused")
                    continue
                txt = f"{c['predicted_ms']:,.1f}"
                out.append(f"**{txt}**" if best.get(scene) == v else txt)
            lines.append(f"| {scene} | " + " | ".join(out) + " |")
        lines.append("")

    # Chart: predicted ms per scene and variant for each profile; passes; idle share.
    fig, axes = plt.subplots(2, 2, figsize=(15, 10))
    names = [v for v in names if any(cell(s, p, v) for s in scenes for p, _ in PROFILES)]
    width = 0.84 / len(names)
    colors = plt.cm.tab10.colors
    for ax, (profile, display) in zip(axes[0], PROFILES):
        for i, v in enumerate(names):
            xs, ys = [], []
            for j, s in enumerate(scenes):
                c = cell(s, profile, v)
                if c:
                    xs.append(j + i * width)
                    ys.append(c["predicted_ms"])
            ax.bar(xs, ys, width, label=v, color=colors[i % 10])
        ax.set_yscale("log")
        ax.set_title(f"Predicted frame time, {display}")
        ax.set_ylabel("ms (log scale)")
        ax.set_xticks([j + 0.42 - width / 2 for j in range(len(scenes))])
        ax.set_xticklabels(scenes, rotation=30, ha="right")
        ax.grid(axis="y", which="both", alpha=0.3)
    for ax, key, title, ylabel, log in (
            (axes[1][0], "passes", "Passes per frame (gf6600)", "passes (log scale)", True),
            (axes[1][1], "idle_share", "Share of shaded work on idle lanes (gf6600)",
             "idle lanes / (fragments shaded + loop lane slots)", False)):
        for i, v in enumerate(names):
            xs, ys = [], []
            for j, s in enumerate(scenes):
                c = cell(s, "gf6600", v)
                if c:
                    xs.append(j + i * width)
                    ys.append(c[key])
            ax.bar(xs, ys, width, label=v, color=colors[i % 10])
        if log:
            ax.set_yscale("log")
        ax.set_title(title)
        ax.set_ylabel(ylabel)
        ax.set_xticks([j + 0.42 - width / 2 for j in range(len(scenes))])
        ax.set_xticklabels(scenes, rotation=30, ha="right")
        ax.grid(axis="y", which="both", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(names), fontsize=8)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(os.path.join(DOCS, "variants.png"), dpi=100)
    lines += ["![predicted time, passes and idle lanes per variant](variants.png)", ""]
    notes = os.path.join(DOCS, "variants_notes.md")
    if os.path.exists(notes):
        with open(notes) as f:
            lines += [f.read().rstrip(), ""]
    with open(os.path.join(DOCS, "variants.md"), "w") as f:
        f.write("\n".join(lines))
    print(f"variants: wrote docs/studies/variants.md, results/variants/variants.csv, docs/studies/variants.png "
          f"({time.time() - t0:.0f} s)", file=sys.stderr)


if __name__ == "__main__":
    main()
