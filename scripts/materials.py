#!/usr/bin/env python3
"""Measures the texture filters on the bundled `textured` scene and prints docs/materials.md's
table (markdown) on stdout.

Usage: /usr/bin/python3 scripts/materials.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
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


def render(exe, scene, size, opts, png, js=None):
    cmd = [exe, "render", scene, "--size", f"{size}x{size}", "--out", png, "--stats", "none", "-q",
           *opts]
    if js:
        cmd += ["--stats-json", js, "--predict"]
    subprocess.run(cmd, check=True)
    img = mpimg.imread(png)[..., :3].astype(np.float64)
    return img, (json.load(open(js)) if js else None)


def shader(stats):
    return next(k for k in stats["kernels"] if k["name"] == "shader")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    args = ap.parse_args()
    exe, size = args.vgpu_rt, args.size
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
