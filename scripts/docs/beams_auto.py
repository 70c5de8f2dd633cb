#!/usr/bin/env python3
"""Measures --beams auto against --beams off (docs/studies/groups.md's table): every bundled scene
(scenes/*.gltf) and the uneven scenes of scripts/scenes/uneven_scenes.py, primary rays only
(--bounces 0 --shadows off, --accel grid unless told), on gf6600 and h200. Per scene and card: the cost
model's frame time with beams off, on and with --beams auto (auto decides for the card it renders
on), what auto chose, the probes' own modeled time (charged: the frame plus the probes) and their
host time. Prints a Markdown table and writes the rows as JSON.

Usage: python3 scripts/docs/beams_auto.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
                                          [--accel grid|grid2|bvh|kdtree]
                                          [--json results/beams/beams_auto.json]
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def render(vgpu, scene, size, profile, beams, accel):
    out = subprocess.run(
        [vgpu, "render", scene, "--size", f"{size}x{size}", "--bounces", "0", "--shadows", "off",
         "--accel", accel, "--profile", profile, "--beams", beams, "--threads", "2", "--quiet",
         "--stats", "json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build/host/vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--accel", default="grid", choices=("grid", "grid2", "bvh", "kdtree"))
    ap.add_argument("--json", help="rows out (default results/beams/beams_auto.json, "
                    "beams_auto_ACCEL.json for another structure)")
    ap.add_argument("--scenes", nargs="*", help="scene files (default: bundled and uneven)")
    args = ap.parse_args()
    if not args.json:
        suffix = "" if args.accel == "grid" else "_" + args.accel
        args.json = os.path.join(ROOT, f"results/beams/beams_auto{suffix}.json")
    scenes = args.scenes
    if not scenes:
        uneven = vgpurt.uneven_scenes(tempfile.mkdtemp(prefix="beams_auto_"))
        scenes = sorted(glob.glob(os.path.join(ROOT, "scenes/*.gltf"))) + [
            uneven["stadium"], uneven["scales"]]
    rows = []
    print("| scene | card | off | on / off | auto | chose | auto / off | probes (modeled) | "
          "(auto + probes) / off | probes (host) |")
    print("|---|---|---:|---:|---:|---|---:|---:|---:|---:|")
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for profile in ("gf6600", "h200"):
            off = render(args.vgpu_rt, scene, args.size, profile, "off", args.accel)
            auto = render(args.vgpu_rt, scene, args.size, profile, "auto", args.accel)
            on = render(args.vgpu_rt, scene, args.size, profile, "on", args.accel)
            choice = auto["beams"]["auto"]
            off_ms, auto_ms = off["predicted_ms"][profile], auto["predicted_ms"][profile]
            on_ms = on["predicted_ms"][profile]
            probes = choice.get("probe_model_ms", 0.0)
            row = {"scene": name, "profile": profile, "off_ms": off_ms, "on_ms": on_ms,
                   "auto_ms": auto_ms,
                   "on": auto["beams"]["on"], "probe_model_ms": probes,
                   "probe_host_ms": choice.get("probe_ms", 0.0), "why": choice["why"],
                   "passes_off": off["totals"]["passes"], "passes_on": on["totals"]["passes"],
                   "beam_passes": on["beams"]["passes"], "tiles": on["beams"]["tiles"],
                   "tiles_missed": on["beams"]["tiles_missed"]}
            rows.append(row)
            print(f"| {name} | {profile} | {off_ms:,.1f} ms | {on_ms / off_ms:.2f} | "
                  f"{auto_ms:,.1f} ms | "
                  f"{'on' if row['on'] else 'off'} | {auto_ms / off_ms:.2f} | {probes:,.1f} ms | "
                  f"{(auto_ms + probes) / off_ms:.2f} | {row['probe_host_ms']:,.0f} ms |",
                  flush=True)
    os.makedirs(os.path.dirname(args.json), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump({"size": args.size, "rows": rows}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
