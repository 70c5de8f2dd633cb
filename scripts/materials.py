#!/usr/bin/env python3
"""Measures the texture filters on the bundled `textured` scene and prints docs/materials.md's
table (markdown) on stdout; with --glass, measures the bundled `glass` scene instead and writes
its tables into docs/materials.md between the glass-measured markers.

Usage: /usr/bin/python3 scripts/materials.py [--vgpu-rt build/host/vgpu-rt] [--size 256] [--glass]
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
import subprocess
import tempfile

import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROFILES = ["gf5700", "gf6600", "h200"]


def render(exe, scene, size, opts, png, js=None, predict=True):
    cmd = [exe, "render", scene, "--size", f"{size}x{size}", "--out", png, "--stats", "none", "-q",
           *opts]
    if js:
        cmd += ["--stats-json", js] + (["--predict"] if predict else [])
    subprocess.run(cmd, check=True)
    img = mpimg.imread(png)[..., :3].astype(np.float64)
    return img, (json.load(open(js)) if js else None)


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
               f"per engine (`/usr/bin/python3 scripts/materials.py --glass`).\n")
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


def write_glass(exe, size):
    path = os.path.join(ROOT, "docs", "materials.md")
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
                    help="measure the glass scene and write docs/materials.md's glass tables")
    ap.add_argument("--opaque-copy", metavar="PATH",
                    help="only write the glass scene's opaque copy to PATH (for bench_gl)")
    args = ap.parse_args()
    exe, size = args.vgpu_rt, args.size
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
          f"engine; `scripts/materials.py`.\n")
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
