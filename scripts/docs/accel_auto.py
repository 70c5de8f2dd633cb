#!/usr/bin/env python3
"""--accel auto against the cheapest structure, on every bundled and uneven scene.

For each scene (scenes/*.gltf and the uneven scenes of scripts/scenes/uneven_scenes.py), primary
rays (--bounces 0 --shadows off) and the full frame (the defaults), both walks (--kernels
multipass and looping) and the profiles gf6600, h200 and h100: renders the full frame with each
of the four structures (the cost model's ms of each, the truth `auto` is judged against) and once
with --accel auto (what it chose, what its probes cost). Writes results/structures/accel_auto.json;
scripts/docs/structures.py turns it into the "--accel auto" section of
docs/studies/structures.md.

Usage: /usr/bin/python3 scripts/docs/accel_auto.py [--vgpu-rt build/host/vgpu-rt] [--size 256]
                                                   [--threads 1] [--scene-dir .h200]
                                                   [--json results/structures/accel_auto.json]
Host times are taken on --threads threads (default 1, so that two runs of the sweep compare).
About 8 minutes on 2 cores. The default --json is the committed file, written over."""
import argparse
import glob
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
STRUCTURES = ["grid", "grid2", "bvh", "kdtree"]
PROFILES = ["gf6600", "h200", "h100"]
MODES = {"primary": ["--bounces", "0", "--shadows", "off"], "full": []}
WALKS = ["multipass", "looping"]
DEFAULT_JSON = os.path.join(ROOT, "results", "structures", "accel_auto.json")


def render(exe, scene, args):
    """One render's statistics (--stats json); exits with the tool's own line on failure."""
    cmd = [exe, "render", scene, "--stats", "json", "--quiet"] + args
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"accel_auto: {' '.join(cmd)}: {r.stderr.strip() or r.returncode}")
    return json.loads(r.stdout)


def sweep(exe, scenes, size, threads):
    rows = []
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for mode, extra in MODES.items():
            for walk in WALKS:
                for prof in PROFILES:
                    common = ["--size", f"{size}x{size}", "--kernels", walk, "--profile", prof,
                              "--threads", str(threads)] + extra
                    row = {"scene": name, "rays": mode, "walk": walk, "profile": prof,
                           "size": size, "threads": threads, "structures": {}}
                    for acc in STRUCTURES:
                        d = render(exe, scene, common + ["--accel", acc])
                        row["structures"][acc] = {"predicted_ms": d["predicted_ms"][prof],
                                                  "render_ms": d["render_ms"],
                                                  "init_ms": d["init_ms"],
                                                  "build_ms": d["accel"]["build_ms"]}
                    d = render(exe, scene, common + ["--accel", "auto"])
                    au = d["accel"]["auto"]
                    row["auto"] = {"chosen": d["accel"]["structure"], "probe_ms": au["probe_ms"],
                                   "init_ms": d["init_ms"], "render_ms": d["render_ms"],
                                   "refined": au["refined"], "stopped": au["stopped"],
                                   "coarse_ms": au["coarse_ms"],
                                   "predicted_ms": au["predicted_ms"]}
                    rows.append(row)
                    print(f"{name:12} {mode:7} {walk:9} {prof:6} auto -> {row['auto']['chosen']:6}"
                          f" {judge(row)['ratio']:.3f}x the cheapest", flush=True)
    return rows


def judge(row):
    """What the choice is worth: its structure's full frame over the cheapest's, and what the
    choice cost the host (the other structures' builds and the probes) over the frame's own
    host time (the chosen structure's build and its render)."""
    s = row["structures"]
    cheapest = min(s, key=lambda a: s[a]["predicted_ms"])
    chosen = row["auto"]["chosen"]
    others = sum(v["build_ms"] for a, v in s.items() if a != chosen)
    frame = s[chosen]["init_ms"] + s[chosen]["render_ms"]
    return {"cheapest": cheapest,
            "ratio": s[chosen]["predicted_ms"] / s[cheapest]["predicted_ms"],
            "choice_ms": row["auto"]["probe_ms"] + others,
            "frame_ms": frame,
            "cost": (row["auto"]["probe_ms"] + others) / frame,
            "builds": others / frame}


def section(rows):
    """The Markdown of structures.md's judgement of --accel auto."""
    if not rows:
        return "(no `results/structures/accel_auto.json`: run `scripts/docs/accel_auto.py`)"
    js = [(r, judge(r)) for r in rows]
    size, threads = rows[0]["size"], rows[0]["threads"]
    within = sum(j["ratio"] <= 1.05 for _, j in js)
    worst = max(js, key=lambda x: x[1]["ratio"])
    L = [f"Every bundled and uneven scene at {size}x{size}, primary rays and the full frame, both "
         f"walks, on {', '.join(PROFILES[:-1])} and {PROFILES[-1]} ({len(rows)} frames; "
         "`scripts/docs/accel_auto.py`, `results/structures/accel_auto.json`): each structure's "
         "full frame priced by the cost "
         "model, and `auto`'s pick. **"
         f"{within} of {len(rows)}** picks are within 5% of the cheapest structure's frame; the "
         f"farthest is {worst[0]['scene']} ({worst[0]['rays']}, {worst[0]['walk']}, "
         f"{worst[0]['profile']}) at {worst[1]['ratio']:.3f}x.", ""]
    L += ["| scene | rays | walk | profile | cheapest | auto picks | x cheapest | probed again | "
          "stopped | choice ms | frame ms | choice / frame |",
          "|---|---|---|---|---|---|---:|---|---|---:|---:|---:|"]
    for r, j in js:
        L.append(f"| {r['scene']} | {r['rays']} | {r['walk']} | {r['profile']} | {j['cheapest']} "
                 f"| {r['auto']['chosen']} | {j['ratio']:.3f} | "
                 f"{', '.join(r['auto']['refined']) or '-'} | "
                 f"{', '.join(r['auto']['stopped']) or '-'} | {j['choice_ms']:,.0f} | "
                 f"{j['frame_ms']:,.0f} | {j['cost']:.2f} |")
    costs = sorted(j["cost"] for _, j in js)
    quarter = sum(c <= 0.25 for c in costs)
    by_walk = {w: statistics.median(j["cost"] for r, j in js if r["walk"] == w) for w in WALKS}
    L += ["", f"The choice's host time (the other structures' builds and both rounds of probes, "
          f"{threads} host thread) over the frame's (the chosen structure's build and its render): "
          f"median {statistics.median(costs):.2f}, from {costs[0]:.2f} to {costs[-1]:.2f}; "
          f"multipass median {by_walk['multipass']:.2f}, looping {by_walk['looping']:.2f}. "
          f"{quarter} of {len(costs)} choices cost at most a quarter of their frame; in "
          f"{sum(j['builds'] > 0.25 for _, j in js)} the other structures' builds alone cost "
          f"more than a quarter of it (median "
          f"{statistics.median(j['builds'] for _, j in js):.2f} of the frame). "
          f"{sum(len(r['auto']['stopped']) for r in rows)} probes stopped once their price so "
          f"far priced them out, in {sum(bool(r['auto']['stopped']) for r in rows)} of the "
          f"{len(rows)} choices."]
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"),
                    help="the renderer (default: %(default)s)")
    ap.add_argument("--size", type=int, default=256, help="square frames, pixels a side")
    ap.add_argument("--threads", type=int, default=1, help="host threads of every render")
    ap.add_argument("--scene-dir", default=os.path.join(ROOT, ".h200"),
                    help="where scripts/scenes/uneven_scenes.py wrote stadium and scales")
    ap.add_argument("--json", default=DEFAULT_JSON,
                    help="where to write the rows (default: the committed %(default)s)")
    a = ap.parse_args()
    uneven = [os.path.join(a.scene_dir, f"{s}.gltf") for s in ("stadium", "scales")]
    for u in uneven:
        if not os.path.exists(u):
            sys.exit(f"accel_auto: {u}: no such file (run scripts/scenes/uneven_scenes.py "
                     f"{a.scene_dir})")
    scenes = sorted(glob.glob(os.path.join(ROOT, "scenes", "*.gltf"))) + uneven
    rows = sweep(a.vgpu_rt, scenes, a.size, a.threads)
    with open(a.json, "w") as fh:
        json.dump(rows, fh, indent=1)
    print(f"wrote {a.json}")
    print(section(rows))


if __name__ == "__main__":
    main()
