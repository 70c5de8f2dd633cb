#!/usr/bin/env python3
"""Checks that two vgpu-rt binaries give a user the same bits: images, AOVs, statistics,
--trace-pixel output and every kernel's GLSL.

Usage: check_identical.py OLD NEW [--quick] [--only TEXT]
  --quick      the first three render cases, one trace and the kernel listing only
  --only TEXT  the render and trace cases whose command line contains TEXT

What it compares:
- Renders. Each case renders with OLD at 1 thread, then with NEW at 1 and 2 threads, with
  --walk passes (NEW's default walks in batches at 8 lanes) and at every lane width the case
  allows. Image and AOV pixels must be equal (equal EXR files, else vgpu-rt compare at
  threshold 0 with max 0); the --stats-json must be equal once every wall-clock field (*_ms),
  the threads/lanes/walk fields, the scene path (each binary resolves a bundled scene in its own
  tree) and the version are removed. The
  cases cover the paper's grid and its options (shading, masks, MRT, looping kernels, reduced
  precision), the other three structures (--accel grid2, bvh, kdtree, each multipass, looping
  and fused) and auto, the sampling modes (--spp, --aa adaptive, --aa undersample), textures
  and their filters, glass and ray streams, beams over tiles (every structure, looping, auto),
  the dense streams on and off, adaptive's three criteria, the CPU engine, and animation
  (--frames, every frame's image and the per-frame JSON; a refitted BVH; --time).
- --trace-pixel: the printed history of one pixel, text equal, for each structure.
- Kernels: `vgpu-rt kernels` (the table) and `vgpu-rt kernels NAME --glsl` for every kernel
  OLD lists, text equal.
Prints one line per check and exits 1 if anything differs. Sizes are small (at most 256x256, most
64x64): a full run takes a few minutes on 2 cores (--quick seconds). Used for refactoring and for
emulator speed work (docs/studies/speed.md), where the host may do less but must compute the same.
"""
import filecmp
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

S64, S48 = ["--size", "64x64"], ["--size", "48x48"]
GF6600 = ["--profile", "gf6600"]
LOOPING = GF6600 + ["--kernels", "looping"]
MRT = GF6600 + ["--mrt", "on"]

# (scene, extra options, which NEW variants: "all", "reduced" (1 lane only: reduced precision),
# "threads" (thread counts only: the CPU engine), frames (0, or how many --frames writes)).
CASES = [
    # The paper's grid and its switches (the original cases).
    ("bunny", ["--shadows", "off", "--bounces", "0"], "all", 0),
    ("bunny", ["--bounces", "3"], "all", 0),
    ("bunny-refl", ["--bounces", "3"], "all", 0),
    ("bunny-mirror", [], "all", 0),
    ("classic", ["--size", "128x96"], "all", 0),
    ("sphere", ["--masks", "on"], "all", 0),
    ("teapot", ["--size", "96x128", "--precision", "fp16"], "reduced", 0),
    ("bunny-low", ["--precision", "fp24", "--grid", "7x9x5"], "reduced", 0),
    ("sphere-alone", ["--shading", "phong-atten", "--grid", "15"], "all", 0),
    ("bunny-refl", MRT, "all", 0),
    ("classic", LOOPING + ["--size", "96x96"], "all", 0),
    ("textured", ["--size", "96x96", "--texture-filter", "trilinear"], "all", 0),
    # The other structures: multipass, the looping kernels and the fused (MRT) passes each.
    *[(scene, S64 + ["--accel", acc] + extra, "all", 0)
      for acc in ("grid2", "bvh", "kdtree")
      for scene, extra in (("bunny", []), ("bunny-refl", LOOPING), ("classic", MRT))],
    ("bunny", S64 + ["--accel", "bvh", "--masks", "on", "--shadows", "off"], "all", 0),
    ("bunny", S64 + ["--accel", "auto"], "all", 0),
    ("bunny", S64 + ["--precision", "auto"], "reduced", 0),
    # The sampling modes.
    ("bunny", S64 + ["--spp", "4"], "all", 0),
    ("bunny-refl", S64 + ["--aa", "adaptive", "--spp", "16"], "all", 0),
    ("classic", S64 + ["--aa", "undersample:2"], "all", 0),
    ("bunny", S48 + ["--accel", "kdtree", "--aa", "undersample:3", "--aa-threshold", "0.05"], "all", 0),
    ("sphere", S48 + ["--accel", "grid2", "--spp", "9"] + LOOPING, "all", 0),
    # Textures and their filters.
    ("textured", S64 + ["--texture-filter", "nearest", "--accel", "bvh"], "all", 0),
    ("textured", S64 + ["--texture-filter", "bilinear", "--spp", "4"], "all", 0),
    # Glass (ray streams) and an opaque scene through the ray streams.
    ("glass", S64, "all", 0),
    ("glass", S48 + ["--accel", "kdtree", "--spp", "4"], "all", 0),
    ("glass", S48 + ["--accel", "bvh"] + LOOPING, "all", 0),
    ("bunny-refl", S64 + ["--ray-streams", "on"], "all", 0),
    # Beams over tiles through every structure, multipass and looping, and auto.
    ("bunny", S64 + ["--beams", "on"], "all", 0),
    ("bunny-refl", S64 + ["--beams", "on", "--accel", "grid2", "--beam-tile", "4"], "all", 0),
    ("classic", S64 + ["--beams", "on", "--accel", "bvh"], "all", 0),
    ("bunny", S64 + ["--beams", "on", "--accel", "kdtree"] + LOOPING, "all", 0),
    ("classic", S64 + ["--beams", "on"] + LOOPING, "all", 0),
    ("classic", S64 + ["--beams", "auto"], "all", 0),
    # The dense streams (sampling that saves time) off as well as on, and adaptive's criteria.
    ("bunny-refl", S48 + ["--aa", "adaptive", "--spp", "16", "--compact", "off"], "all", 0),
    ("classic", S48 + ["--aa", "undersample:2", "--compact", "off"], "all", 0),
    ("classic", S48 + ["--aa", "adaptive", "--spp", "16", "--aa-criterion", "image"], "all", 0),
    ("bunny-refl", S48 + ["--aa", "adaptive", "--spp", "16", "--aa-criterion", "object",
                          "--accel", "bvh"], "all", 0),
    ("bunny", S48 + ["--aa", "adaptive", "--spp", "16", "--aa-budget", "20"], "all", 0),
    # The CPU reference tracer.
    ("bunny-refl", S64 + ["--engine", "cpu"], "threads", 0),
    ("glass", S48 + ["--engine", "cpu", "--accel", "bvh"], "threads", 0),
    # Animation: every frame of a sequence, a refitted BVH, one time.
    ("hop", S48 + ["--frames", "0:2:4"], "all", 4),
    ("hop", S48 + ["--frames", "0:2:3", "--accel", "bvh", "--update", "refit"], "all", 3),
    ("hop", S48 + ["--frames", "0:2:3", "--accel", "bvh", "--update", "auto"] + LOOPING, "all", 3),
    ("hop", S64 + ["--time", "0.7", "--accel", "kdtree"], "all", 0),
]
# --trace-pixel: one pixel's passes (the stream engine), for each structure.
TRACES = [
    ("bunny", S64 + ["--trace-pixel", "32,30"]),
    ("bunny", S64 + ["--trace-pixel", "32,30", "--accel", "grid2"]),
    ("bunny-refl", S64 + ["--trace-pixel", "30,34", "--accel", "bvh", "--bounces", "3"]),
    ("bunny-refl", S64 + ["--trace-pixel", "30,34", "--accel", "kdtree"] + LOOPING),
    ("classic", S64 + ["--trace-pixel", "20,40", "--spp", "4"] + MRT),
]
DROPPED = ("threads", "lanes", "walk", "walk_passes_because", "scene_path", "version",
           "peak_rss_bytes", "memory")


def strip(j):
    """The JSON without what may differ between two runs of the same frame."""
    if isinstance(j, dict):
        return {k: strip(v) for k, v in j.items() if not k.endswith("_ms") and k not in DROPPED}
    if isinstance(j, list):
        return [strip(v) for v in j]
    return j


def variants(kind):
    """NEW's runs of a case: thread counts, walks and lane widths."""
    if kind == "threads":
        return [["--threads", "1"], ["--threads", "2"]]
    v = [["--threads", "1"], ["--threads", "2"], ["--threads", "1", "--walk", "passes"],
         ["--threads", "2", "--walk", "passes"]]
    return v + [["--threads", "2", "--lanes", w] for w in
                (["1"] if kind == "reduced" else ["1", "4", "16"])]


def render(exe, work, tag, scene, extra, frames):
    """One run: its image and AOV files (one set per frame) and its stripped JSON."""
    mark = "_####" if frames else ""
    base = os.path.join(work, tag)
    files = {"rgb": base + mark + ".exr", "depth": base + "_d" + mark + ".exr",
             "hit": base + "_h" + mark + ".exr"}
    stats = vgpurt.render(exe, scene, extra, stats_json=base + ".json", out=files["rgb"],
                          aovs={"depth": files["depth"], "hit": files["hit"]})
    names = {k: [p.replace("####", f"{i:04d}") for i in range(1, frames + 1)] if frames else [p]
             for k, p in files.items()}
    return names, strip(stats)


def same_pixels(exe, a, b):
    """Equal pixels: equal files (one writer, so equal pixels give equal bytes: no compare to
    start), else vgpu-rt compare at threshold 0."""
    if filecmp.cmp(a, b, shallow=False):
        return True
    try:
        share, _, most, _ = vgpurt.compare(exe, a, b, threshold=0)
    except vgpurt.Failed:
        return False
    return share == 0 and most == 0


def check_renders(old, new, work, cases, report):
    for i, (scene, extra, kind, frames) in enumerate(cases):
        ref_files, ref = render(old, work, f"c{i}_old", scene, extra + ["--threads", "1"], frames)
        for v in variants(kind):
            files, got = render(new, work, f"c{i}_new", scene, extra + v, frames)
            diffs = [k for k in ("rgb", "depth", "hit")
                     if not all(same_pixels(new, a, b) for a, b in zip(ref_files[k], files[k]))]
            if got != ref:
                diffs.append("stats")
            report(f"{scene} {' '.join(extra + v)}", diffs)


def check_traces(old, new, traces, report):
    for scene, extra in traces:
        def text(exe, v):
            return vgpurt.run(vgpurt.render_command(exe, scene, extra + v))
        ref = text(old, ["--threads", "1"])
        for v in (["--threads", "1"], ["--threads", "2", "--lanes", "16"],
                  ["--threads", "2", "--walk", "passes"]):
            report(f"trace {scene} {' '.join(extra + v)}",
                   [] if text(new, v) == ref else ["--trace-pixel output"])


def check_kernels(old, new, quick, report):
    table = [vgpurt.run([exe, "kernels"]) for exe in (old, new)]
    report("kernels (the table)", [] if table[0] == table[1] else ["listing"])
    if quick:
        return
    for name in vgpurt.kernel_names(old):
        glsl = []
        for exe in (old, new):
            try:
                glsl.append(vgpurt.run([exe, "kernels", name, "--glsl"]))
            except vgpurt.Failed as e:
                glsl.append(f"failed: {e.message}")
        report(f"kernels {name} --glsl", [] if glsl[0] == glsl[1] else ["GLSL"])


def main():
    args = sys.argv[1:]
    if len(args) < 2 or args[0].startswith("-"):
        sys.exit(__doc__.strip())
    old, new = args[0], args[1]
    quick = "--quick" in args
    only = args[args.index("--only") + 1] if "--only" in args else None
    cases, traces = (CASES[:3], TRACES[:1]) if quick else (CASES, TRACES)
    if only:
        cases = [c for c in cases if only in " ".join([c[0], *c[1]])]
        traces = [t for t in traces if only in " ".join([t[0], *t[1]])]
    counts = {"same": 0, "DIFF": 0}

    def report(what, diffs):
        word = "DIFF" if diffs else "same"
        counts[word] += 1
        print(f"{word} {what}" + (f": {', '.join(diffs)}" if diffs else ""), flush=True)

    start = time.time()
    with tempfile.TemporaryDirectory() as work:
        check_renders(old, new, work, cases, report)
    check_traces(old, new, traces, report)
    if not only:
        check_kernels(old, new, quick, report)
    print(f"check_identical: {counts['same']} same, {counts['DIFF']} different "
          f"({len(cases)} render cases, {len(traces)} traces; {time.time() - start:.0f} s)")
    sys.exit(1 if counts["DIFF"] else 0)


if __name__ == "__main__":
    try:
        main()
    except (vgpurt.Failed, subprocess.TimeoutExpired) as e:
        sys.exit(f"check_identical: {e}")
