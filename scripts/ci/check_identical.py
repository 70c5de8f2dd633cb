#!/usr/bin/env python3
"""Checks that two vgpu-rt binaries render bit-identical images, AOVs and statistics.

Usage: check_identical.py OLD NEW [--quick]
Renders each case with both binaries (OLD at 1 thread, NEW at 1 and 2 threads and every lane
width the case allows), then compares the image and AOV pixels exactly (vgpu-rt compare, threshold
0) and the --stats-json output with every wall-clock field (*_ms), the threads/lanes/walk fields
and the scene path (each binary resolves it in its own tree) removed; NEW also runs with --walk
passes (its default walks in batches at 8 lanes).
Prints one line per case and exits 1 if anything differs. Used for emulator speed work
(docs/speed.md), where the host may do less but must compute the same.
"""
import json
import os
import subprocess
import sys
import tempfile

CASES = [  # (scene, extra options)
    ("bunny", ["--shadows", "off", "--bounces", "0"]),
    ("bunny", ["--bounces", "3"]),
    ("bunny-refl", ["--bounces", "3"]),
    ("bunny-mirror", []),
    ("classic", ["--size", "128x96"]),
    ("sphere", ["--masks", "on"]),
    ("teapot", ["--size", "96x128", "--precision", "fp16"]),
    ("bunny-low", ["--precision", "fp24", "--grid", "7x9x5"]),
    ("sphere-alone", ["--shading", "phong-atten", "--grid", "15"]),
    ("bunny-refl", ["--profile", "gf6600", "--mrt", "on"]),
    ("classic", ["--profile", "gf6600", "--kernels", "looping", "--size", "96x96"]),
    ("textured", ["--size", "96x96", "--texture-filter", "trilinear"]),  # both binaries need textures
]
TIMING = ("_ms",)


def strip(j):
    if isinstance(j, dict):
        return {k: strip(v) for k, v in j.items()
                if not k.endswith(TIMING) and k not in ("threads", "lanes", "walk", "scene_path", "sampling")}
    if isinstance(j, list):
        return [strip(v) for v in j]
    return j


def render(exe, work, tag, scene, extra):
    out = {k: os.path.join(work, tag + s) for k, s in
           [("rgb", ".exr"), ("depth", "_d.exr"), ("hit", "_h.exr"), ("json", ".json")]}
    cmd = [exe, "render", scene, *extra, "--out", out["rgb"], "--aov", "depth=" + out["depth"],
           "hit=" + out["hit"], "--stats-json", out["json"], "--stats", "none", "-q"]
    subprocess.run(cmd, check=True)
    with open(out["json"]) as f:
        out["stats"] = strip(json.load(f))
    return out


def same_pixels(exe, a, b):
    p = subprocess.run([exe, "compare", a, b, "--threshold", "0"], capture_output=True, text=True)
    return p.returncode == 0 and "0.0000% of pixels" in p.stdout and "max 0\n" in p.stdout


def main():
    old, new = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    bad = 0
    with tempfile.TemporaryDirectory() as work:
        for i, (scene, extra) in enumerate(CASES[:3] if quick else CASES):
            ref = render(old, work, f"c{i}_old", scene, extra + ["--threads", "1"])
            reduced = "--precision" in extra
            # NEW's default walks in batches (at 8 lanes); --walk passes runs pass by pass.
            variants = [["--threads", "1"], ["--threads", "2"], ["--threads", "1", "--walk", "passes"],
                        ["--threads", "2", "--walk", "passes"]]
            variants += [["--threads", "2", "--lanes", w] for w in
                         (["1"] if reduced else ["1", "4", "16"])]
            for v in variants:
                got = render(new, work, f"c{i}_new", scene, extra + v)
                diffs = [k for k in ("rgb", "depth", "hit") if not same_pixels(new, ref[k], got[k])]
                if got["stats"] != ref["stats"]:
                    diffs.append("stats")
                bad += bool(diffs)
                print(f"{'DIFF' if diffs else 'same'} {scene} {' '.join(extra + v)}"
                      + (f": {', '.join(diffs)}" if diffs else ""), flush=True)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
