#!/usr/bin/python3
"""Per-frame cost of a moving scene (issue 23): renders a bundled animation with vgpu-rt
--frames (the grid rebuilt and the changed static textures uploaded again every frame) and
prints, as Markdown, the medians over the frames after the first and the frames one by one:
the host's update (pose, grid build, texture writes), the bytes uploaded, the emulator's render
time and passes, and the cost model's charge on gf5700, gf6600 and h200 (the upload over each
profile's bus, the frame's passes).

Usage: /usr/bin/python3 scripts/animation.py [--vgpu-rt build/host/vgpu-rt] [--scene hop]
         [--frames 0:2:25] [--size 256] [--threads 0] [--accel grid] [--json FILE]
  --json FILE  read an earlier run's --stats-json instead of rendering
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROFILES = ["gf5700", "gf6600", "h200"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--scene", default="hop")
    ap.add_argument("--frames", default="0:2:25")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--accel", default="grid", help="grid, bvh or kdtree")
    ap.add_argument("--json")
    opts = ap.parse_args()
    path = opts.json
    if not path:
        path = os.path.join(tempfile.mkdtemp(prefix="vgpu_animation_"), "frames.json")
        subprocess.run([opts.vgpu_rt, "render", opts.scene, "--frames", opts.frames, "--size",
                        f"{opts.size}x{opts.size}", "--threads", str(opts.threads), "--accel",
                        opts.accel, "-q", "--stats", "none", "--stats-json", path], check=True)
    with open(path) as f:
        run = json.load(f)
    frames = run["frames"]
    later = frames[1:] or frames  # the first frame's update is the initialization's

    def med(key):
        return statistics.median(key(r) for r in later)

    u = lambda r: r["update"]  # noqa: E731
    host_update = lambda r: u(r)["pose_ms"] + u(r)["build_ms"] + u(r)["write_ms"]  # noqa: E731
    first = frames[0]
    print(f"`{run['scene']}`, animation '{run['animation']['name']}', {len(frames)} frames "
          f"({opts.frames if not opts.json else 'from ' + opts.json}), "
          f"{first['size'][0]}x{first['size'][1]}, {first['triangles']} triangles, "
          f"structure {first['accel']['structure']}, threads {first['threads']}.\n")
    print("Medians over frames 2..N (frame 1's update is the initialization):\n")
    print("| quantity | median |")
    print("|---|---:|")
    rows = [
        ("pose (animation sampled, scene flattened), host ms", med(lambda r: u(r)["pose_ms"])),
        (f"{u(first)['structure']} rebuilt, host ms", med(lambda r: u(r)["build_ms"])),
        ("static textures rewritten and compared, host ms", med(lambda r: u(r)["write_ms"])),
        ("update in all, host ms", med(host_update)),
        ("uploaded bytes", med(lambda r: u(r)["uploaded_bytes"])),
        ("render, emulator host ms", med(lambda r: r["render_ms"])),
        ("update / render (emulator)", med(lambda r: host_update(r) / r["render_ms"])),
        ("passes", med(lambda r: r["totals"]["passes"])),
    ]
    for p in PROFILES:
        rows.append((f"upload over the bus, modeled {p} ms",
                     med(lambda r: u(r)["predicted"][p]["upload_ms"])))
        rows.append((f"frame (passes), modeled {p} ms", med(lambda r: r["predicted_ms"][p])))
    for name, v in rows:
        print(f"| {name} | {v:,.0f} |" if v >= 1000 else f"| {name} | {v:.3g} |")
    print(f"\nFrame 1: {first['update']['uploaded_bytes']} bytes uploaded at initialization "
          f"(init {first['init_ms']:.1f} ms host), build {first['update']['build_ms']:.2f} ms.\n")
    print("| frame | time s | update host ms | uploaded bytes | render ms | passes | "
          + " | ".join(f"{p} ms" for p in PROFILES) + " |")
    print("|---:|---:|---:|---:|---:|---:|" + "---:|" * len(PROFILES))
    for r in frames:
        print(f"| {r['frame']} | {r['time']:.4g} | {host_update(r):.2f} | "
              f"{u(r)['uploaded_bytes']} | {r['render_ms']:.1f} | {r['totals']['passes']} | "
              + " | ".join(f"{r['predicted_ms'][p]:.1f}" for p in PROFILES) + " |")


if __name__ == "__main__":
    main()
