#!/usr/bin/env python3
"""Measures the texture filters on the bundled `textured` scene and prints docs/studies/materials.md's
table (markdown) on stdout; with --glass, measures the bundled `glass` scene instead and writes
its tables into docs/studies/materials.md between the glass-measured markers.

Usage: /usr/bin/python3 scripts/docs/materials.py [--vgpu-rt build/host/vgpu-rt] [--size 256] [--glass]
       /usr/bin/python3 scripts/docs/materials.py --h200 FILE... [--h200-clocks CSV]
       /usr/bin/python3 scripts/docs/materials.py --opaque-copy PATH
--h200 measures nothing: it reads bench_gl's JSON from an H200 (scripts/h200/streams_sampling.sh)
and writes docs/studies/materials.md's H200 section between the h200-measured markers.
Each filter renders once on the stream engine (the emulator, gf5700: every fragment runs every
pass, as on the paper's card) with --predict: the shader's texture fetches, the frame's, and
the cost model's predicted ms for gf5700, gf6600 and h200 from those statistics. The baseline
is the same scene with every baseColorTexture removed (a copy of the file written to a
temporary directory). RMS error is against the CPU tracer at --spp 64 with bilinear filtering,
a supersampled reference of the textures' footprint in each pixel.
"""
import argparse
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import h200_frames as hf  # noqa: E402
import vgpurt  # noqa: E402

import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROFILES = ["gf5700", "gf6600", "h200"]


def render(exe, scene, size, opts, png, js=None, predict=True):
    opts = ["--size", f"{size}x{size}", *opts] + (["--predict"] if js and predict else [])
    vgpurt.run(vgpurt.render_command(exe, scene, opts, stats_json=js, out=png))
    img = mpimg.imread(png)[..., :3].astype(np.float64)
    return img, (vgpurt.read_stats(js) if js else None)


def shader(stats):
    return next(k for k in stats["kernels"] if k["name"] == "shader")


BEGIN, END = "<!-- glass-measured:begin -->", "<!-- glass-measured:end -->"


def opaque_copy(path):
    """Writes the glass scene with every transmissionFactor 0 (the paper's opaque materials; the
    buffers are embedded, so the copy can lie anywhere) to path."""
    doc = json.load(open(os.path.join(ROOT, "scenes", "glass.gltf")))
    for m in doc["materials"]:
        ext = m.get("extensions", {}).get("KHR_materials_transmission")
        if ext is not None:
            ext["transmissionFactor"] = 0.0
    json.dump(doc, open(path, "w"))


def glass(exe, size):
    """The glass scene and its opaque copy (every transmissionFactor 0) on both engines, gf5700
    defaults; returns the markdown that goes between the markers."""
    scene = os.path.join(ROOT, "scenes", "glass.gltf")
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        opaque = os.path.join(tmp, "glass-opaque.gltf")
        opaque_copy(opaque)
        runs = {}
        for label, path in [("glass", scene), ("opaque", opaque)]:
            for engine in ["stream", "cpu"]:
                _, js = render(exe, path, size, ["--engine", engine],
                               os.path.join(tmp, f"{label}-{engine}.png"),
                               os.path.join(tmp, f"{label}-{engine}.json"), engine == "stream")
                runs[label, engine] = js
    g, c = runs["glass", "stream"], runs["glass", "cpu"]
    out.append(f"`glass` at {size}x{size}, gf5700 defaults (phong, shadows, 2 bounces), one run "
               f"per engine (`/usr/bin/python3 scripts/docs/materials.py --glass`).\n")
    out.append("Rays per level by kind (spawned by the level for the next), stream engine / CPU "
               "tracer:\n")
    out.append("| level | stream length | chunks | reflected | refracted | of the reflected, "
               "total internal |")
    out.append("|---:|---:|---:|---:|---:|---:|")
    for i, lv in enumerate(g["streams"]["levels"]):
        out.append(f"| {i} | {lv['rays']:,} | {lv['chunks']} | {lv['reflected']:,} / "
                   f"{c['cpu']['reflected'][i]:,} | {lv['refracted']:,} / "
                   f"{c['cpu']['refracted'][i]:,} | {lv['total_internal']:,} / "
                   f"{c['cpu']['total_internal'][i]:,} |")
    st = g["streams"]
    out.append("\nThe streams' own passes and bytes (read + written):\n")
    out.append("| job | passes | bytes |")
    out.append("|---|---:|---:|")
    for key, name in [("split", "split (dividirRayos)"),
                      ("compaction", "compaction (scan, count, compact)"),
                      ("copies", "row copies (copiarFilas)"), ("gather", "gather (reunirHijos)"),
                      ("shadow_glass", "shadows through glass (sombraVidrio)")]:
        out.append(f"| {name} | {st[key]['passes']:,} | {st[key]['bytes']:,} |")
    out.append(f"\nShadow rays continued past a glass surface: {st['shadow_rays_continued']:,} "
               f"(CPU tracer's glass crossings: {c['cpu']['glass_shadow_crossings']:,}).\n")
    out.append("| scene | rays traced (stream) | rays (CPU) | modeled gf5700 ms | modeled gf6600 "
               "ms | modeled h200 ms | emulator ms | CPU tracer ms |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for label in ["glass", "opaque"]:
        s_, c_ = runs[label, "stream"], runs[label, "cpu"]
        out.append(f"| {label} | {s_['rays_traced']:,} | {c_['cpu']['rays']:,} | "
                   + " | ".join(f"{s_['predicted_ms'][p]:,.1f}" for p in PROFILES)
                   + f" | {s_['render_ms']:,.1f} | {c_['render_ms']:,.1f} |")
    return "\n".join(out)


H200_BEGIN, H200_END = "<!-- h200-measured:begin -->", "<!-- h200-measured:end -->"

# What the measured tables say (results/materials/materials_h200_*.json, one device run; kept with the script
# so that a rewrite of the section keeps it).
H200_PROSE = """**What the differences say about the model's pricing of stream passes.**

- *Frames.* The multipass frames, with ray streams or without, are within -8% to +1% of the
  wall time, the band of the acceleration structures' 2-bounce frames in
  [structures.md](structures.md) (-10% to +6%): the streams' passes are priced like the paper's.
  What glass adds to its opaque copy is mostly more walks for the refracted rays (20,716 more
  passes, 110 of them the streams' own): +978 ms measured, +899 ms predicted (-8%). The looping
  frames are 7-17% under the wall time with streams or without (22-29% before the model priced
  the looping passes' longest lanes, structures.md's latency term): that is the looping walk's
  price, not the streams'.
- *The streams' own kernels* (split, scan, count, compaction, gather, shadows through glass)
  are cheap on this GPU: 110 passes, 2.1 GPU ms of glass's 920 (0.2%), and 7% of the looping
  frame's GPU time, where the walk is only tens of passes. The model gives them 3.6 ms, 72%
  above their GPU time, but it is calibrated to the wall time (a pass's submission, and the
  read-back wait that the timer queries do not see: the frame's wall time is 1.66x its GPU time),
  so per kernel it should be above the GPU time by about the per-pass overhead. It is, except
  where a kernel's work dominates: compaction (-4% to -7%: its gathers are priced at what they
  take) and split (+9% to +15%). The scan's 31-32 small passes (8-9 us each on the GPU) are priced
  at 14-15 us each, 10.4 us of it the h200 profile's fixed cost of a pass (measured as wall
  time). The count is the outlier, +235% to +299%: each of its passes ends in an occlusion
  query read back at once, and the model's read-back charge (12 us of its 30-31 us per pass) is
  time the GPU waits idle, in the wall time, not in the timer query; the frame-level agreement
  says that charge is about right.
- *Ray streams for the paper's reflections* (bunny-refl, `--ray-streams on`): 44 more passes.
  Looping: +5.0 ms wall, +3.0 GPU ms, +3.2 ms predicted. Multipass: +1.4 GPU ms and +1.1 ms
  predicted, but +38 ms of wall time (4% of a 1 s frame), which 44 passes of a few tens of us do
  not account for; only medians were stored, so whether this is the wall time's spread between
  frames was not measured."""


def h200(paths, clocks):
    """The glass scene, its opaque copy and bunny-refl with and without ray streams on the H200,
    beside the model; returns the markdown of the section."""
    rows = hf.frames(paths)
    r0 = rows[0]
    clk = hf.sm_clock(clocks)
    out = ["## Measured on an H200 through the GL device", ""]
    out.append(
        f"The glass frames on an NVIDIA H200 through the GL device (`bench/bench_gl.cpp`; the "
        f"files and how they were run: `results/materials/README.md`; {r0['renderer']}, OpenGL {r0['gl_version']}), "
        f"{r0['size']}x{r0['size']}, "
        f"the CLI's defaults ({r0['bounces']} bounces, Phong, shadows, the paper's grid at "
        f"`--grid auto`), polled read-backs: the median of {r0['runs']} warm frames after one "
        "warm-up frame (which also pays the driver's compilation), beside the cost model's "
        "prediction (`h200` profile) from the emulator's statistics of the same frame. "
        "\"multipass\" frames run the paper's kernels as the gf5700 profile has them, "
        "\"looping\" the looping grid walk on the h200 profile. `glass` always runs as ray "
        "streams; `glass-opaque` is the same file with every transmissionFactor 0 "
        "(`materials.py --opaque-copy`); bunny-refl runs its mirror reflections either way"
        + (f". SM clock {clk[0]:.0f} MHz (median of {clk[3]} samples while the GPU was busy, "
           f"{clk[1]}-{clk[2]} MHz)." if clk else "."))
    out.append("")
    label = [("scene", lambda r: r["scene"]),
             ("ray streams", lambda r: "on" if r["streams_ran"] else "off"),
             ("kernels", lambda r: r["variant"])]
    out += hf.frame_table(rows, label)
    out += ["", "What the streams add, measured and predicted (the frame with streams less the "
            "one without; glass less its opaque copy also traces the refracted rays):", "",
            "| frames | kernels | wall ms added | GPU ms added | predicted ms added | "
            "passes added |", "|---|---|---:|---:|---:|---:|"]

    def get(scene, variant, streams):
        return next((r for r in rows if r["scene"] == scene and r["variant"] == variant
                     and r["streams_ran"] == streams), None)

    for a, b, name in [(("glass", True), ("glass-opaque", False), "glass - opaque"),
                       (("bunny-refl", True), ("bunny-refl", False), "bunny-refl on - off")]:
        for variant in ["multipass", "looping"]:
            x, y = get(*a[:1], variant, a[1]), get(*b[:1], variant, b[1])
            if x and y:
                out.append(f"| {name} | {variant} | {x['wall_ms'] - y['wall_ms']:+,.1f} | "
                           f"{x['gpu_ms'] - y['gpu_ms']:+,.1f} | "
                           f"{x['predicted_ms'] - y['predicted_ms']:+,.1f} | "
                           f"{x['passes'] - y['passes']:+,} |")
    streamed = [r for r in rows if r["streams_ran"]]
    for r in streamed:
        r["_label"] = f"{r['scene']} {r['variant']}"
    out += ["", "The streams' own kernels (split, scan, count, compaction, row copies, gather, "
            "shadows through glass), GPU time per kernel from timer queries beside the model's "
            "ms for the same passes (its fixed costs per pass included):", ""]
    out += hf.kernel_table(streamed, "frame", hf.STREAM_KERNELS)
    out += ["", "Summed over those kernels:", ""]
    out += hf.kernel_sum_table(streamed, hf.STREAM_KERNELS)
    if H200_PROSE:
        out += ["", H200_PROSE]
    return "\n".join(out)


def write_h200(paths, clocks):
    text = h200(paths, clocks)
    hf.replace_section(os.path.join(ROOT, "docs", "studies", "materials.md"), H200_BEGIN, H200_END, text)


def write_glass(exe, size):
    path = os.path.join(ROOT, "docs", "studies", "materials.md")
    text = open(path).read()
    a, b = text.index(BEGIN) + len(BEGIN), text.index(END)
    tables = glass(exe, size)  # measured before the file is opened for writing
    with open(path, "w") as f:
        f.write(text[:a] + "\n" + tables + "\n" + text[b:])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--glass", action="store_true",
                    help="measure the glass scene and write docs/studies/materials.md's glass tables")
    ap.add_argument("--opaque-copy", metavar="PATH",
                    help="only write the glass scene's opaque copy to PATH (for bench_gl)")
    ap.add_argument("--h200", nargs="+", metavar="FILE",
                    help="bench_gl JSON measured on an H200 (results/materials/materials_h200_*.json): only "
                    "write docs/studies/materials.md's H200 section")
    ap.add_argument("--h200-clocks", metavar="CSV",
                    default=os.path.join(ROOT, "results", "sampling", "streams_sampling_h200_clocks.csv"),
                    help="nvidia-smi's clock log of the same run")
    args = ap.parse_args()
    exe, size = args.vgpu_rt, args.size
    if args.h200:
        write_h200(args.h200, args.h200_clocks)
        return
    if args.opaque_copy:
        opaque_copy(args.opaque_copy)
        return
    if args.glass:
        write_glass(exe, size)
        return
    scene = os.path.join(ROOT, "scenes", "textured.gltf")
    with tempfile.TemporaryDirectory() as tmp:
        doc = json.load(open(scene))
        for m in doc["materials"]:
            m["pbrMetallicRoughness"].pop("baseColorTexture", None)
        plain = os.path.join(tmp, "untextured.gltf")
        json.dump(doc, open(plain, "w"))
        ref, _ = render(exe, scene, size, ["--engine", "cpu", "--spp", "64",
                                            "--texture-filter", "bilinear"],
                        os.path.join(tmp, "ref.png"))
        rows = []
        for label, path, opts in [("untextured", plain, []),
                                  ("nearest", scene, ["--texture-filter", "nearest"]),
                                  ("bilinear", scene, ["--texture-filter", "bilinear"]),
                                  ("trilinear", scene, ["--texture-filter", "trilinear"])]:
            img, js = render(exe, path, size, opts, os.path.join(tmp, label + ".png"),
                             os.path.join(tmp, label + ".json"))
            sh = shader(js)
            rms = float(np.sqrt(np.mean((img - ref) ** 2))) if label != "untextured" else None
            rows.append((label, sh["fragments_shaded"], sh["texture_fetches"],
                         sh["bytes_read"], js["totals"]["texture_fetches"],
                         [js["predicted_ms"][p] for p in PROFILES], rms))
    print(f"`textured` at {size}x{size}, gf5700 defaults (phong, shadows, 2 bounces), stream "
          f"engine; `scripts/docs/materials.py`.\n")
    print("| filter | shader fetches / fragment | shader fetches | shader bytes read | frame "
          "fetches | predicted gf5700 ms | predicted gf6600 ms | predicted h200 ms | RMS vs "
          "reference |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for label, frags, fetches, bytes_read, total, pred, rms in rows:
        print(f"| {label} | {fetches / frags:.0f} | {fetches:,} | {bytes_read:,} | {total:,} | "
              + " | ".join(f"{p:,.1f}" for p in pred)
              + f" | {'-' if rms is None else f'{rms:.4f}'} |")


if __name__ == "__main__":
    main()
