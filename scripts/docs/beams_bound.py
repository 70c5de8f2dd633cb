#!/usr/bin/env python3
"""How far beams over tiles can go (docs/studies/groups.md, "How far beams can go"): the cost model's
frame time with --beams on at every tile size from 1x1 (each pixel its own beam: the finest
entry-point search there is) to 32x32, against --beams off, on the scenes the issue's 0.7x target
names (classic, hop, and stadium and scales from scripts/scenes/uneven_scenes.py) and bunny (where
beams pay most), through each of the four structures (so whatever --accel auto picks), with the
multipass and the looping kernels, 256x256, primary rays only (--bounces 0 --shadows off), on
gf6600 and h200. A multipass frame prices the same passes on both cards, so it is rendered once;
a looping frame is rendered for each card (its batches follow the card's branch granularity).
Prints a Markdown table of the best tile per case and writes every frame's figures as JSON.

Usage: python3 scripts/docs/beams_bound.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
                                           [--json results/beams/beams_bound.json]
                                           [--scenes FILE.gltf ...] [--tiles 1 2 4 8 16 32]
"""
import argparse
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CARDS = ("gf6600", "h200")
ACCELS = ("grid", "grid2", "bvh", "kdtree")


def render(vgpu, scene, size, profile, accel, kernels, tile, work):
    beams = ["--beams", "off"] if tile == 0 else ["--beams", "on", "--beam-tile", str(tile)]
    d = vgpurt.render(vgpu, scene, ["--size", f"{size}x{size}", "--bounces", "0", "--shadows",
                                    "off", "--accel", accel, "--kernels", kernels, "--profile",
                                    profile, "--threads", "2"] + beams,
                      stats_json=os.path.join(work, "frame.json"))
    return {"passes": d["totals"]["passes"], "beam_passes": d.get("beams", {}).get("passes", 0),
            "predicted_ms": {c: d["predicted_ms"][c] for c in CARDS}}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build/host/vgpu-rt"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--json", default=os.path.join(ROOT, "results/beams/beams_bound.json"))
    ap.add_argument("--scenes", nargs="*", help="scene files (default: the target's four, bunny)")
    ap.add_argument("--tiles", nargs="*", type=int, default=[1, 2, 4, 8, 16, 32])
    ap.add_argument("--summary", metavar="JSON",
                    help="print only the summary of rows written before (no renders)")
    args = ap.parse_args()
    if args.summary:
        with open(args.summary) as f:
            summary(json.load(f)["rows"])
        return
    work = tempfile.mkdtemp(prefix="beams_bound_")
    scenes = args.scenes
    if not scenes:
        uneven = vgpurt.uneven_scenes(work)
        scenes = [os.path.join(ROOT, "scenes", s + ".gltf") for s in ("classic", "hop", "bunny")]
        scenes += [uneven["stadium"], uneven["scales"]]
    rows = []
    print("| scene | structure | kernels | card | off | best tile | best on / off | 8x8 on / off "
          "| 1x1 on / off |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|")
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for accel in ACCELS:
            for kernels in ("multipass", "looping"):
                # A multipass frame's passes do not depend on the card; a looping one's batches do.
                runs = {}
                for card in (CARDS if kernels == "looping" else ("gf6600",)):
                    for tile in [0] + args.tiles:
                        print(f"{name} {accel} {kernels} {card} tile {tile}", file=sys.stderr,
                              flush=True)
                        runs[(card, tile)] = render(args.vgpu_rt, scene, args.size, card, accel,
                                                    kernels, tile, work)
                for card in CARDS:
                    src = card if kernels == "looping" else "gf6600"
                    frames = {t: runs[(src, t)] for t in [0] + args.tiles}
                    off = frames[0]["predicted_ms"][card]
                    ratio = {t: frames[t]["predicted_ms"][card] / off for t in args.tiles}
                    best = min(args.tiles, key=lambda t: ratio[t])
                    rows.append({"scene": name, "accel": accel, "kernels": kernels,
                                 "profile": card, "off_ms": off, "ratio": ratio,
                                 "best_tile": best,
                                 "passes": {t: f["passes"] for t, f in frames.items()},
                                 "beam_passes": {t: f["beam_passes"] for t, f in frames.items()}})
                    r8 = f"{ratio[8]:.3f}" if 8 in ratio else ""
                    r1 = f"{ratio[1]:.3f}" if 1 in ratio else ""
                    print(f"| {name} | {accel} | {kernels} | {card} | {off:,.1f} ms | "
                          f"{best}x{best} | {ratio[best]:.3f} | {r8} | {r1} |", flush=True)
    os.makedirs(os.path.dirname(args.json), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump({"size": args.size, "tiles": args.tiles, "rows": rows}, f, indent=1)
    print(f"wrote {args.json}", file=sys.stderr)
    print()
    summary(rows)


def summary(rows):
    """Per scene, kernels and card: the best beams frame over every structure and tile, and the
    uniform grid's (the default structure) best."""
    print("| scene | kernels | card | best on / off | its structure, tile | uniform grid's best "
          "on / off (tile) |")
    print("|---|---|---|---:|---|---:|")
    keys = []
    for r in rows:
        k = (r["scene"], r["kernels"], r["profile"])
        if k not in keys:
            keys.append(k)
    for k in keys:
        cases = [r for r in rows if (r["scene"], r["kernels"], r["profile"]) == k]
        best = min(cases, key=lambda r: min(r["ratio"].values()))
        grid = next(r for r in cases if r["accel"] == "grid")
        bt, gt = best["best_tile"], grid["best_tile"]
        print(f"| {k[0]} | {k[1]} | {k[2]} | {min(best['ratio'].values()):.3f} | "
              f"{best['accel']}, {bt}x{bt} | {min(grid['ratio'].values()):.3f} ({gt}x{gt}) |")


if __name__ == "__main__":
    main()
