#!/usr/bin/env python3
"""Brings the cost model's predictions in stored H200 measurements up to date.

Each stored file (bench_gl --json, run on the H200) holds the GL frames as measured and, beside
each, the emulator's run of the same frame with the cost model's predictions as the model stood
that day. When the model changes, the measurements stay and the predictions should follow: this
runs bench_gl here, emulator only (--readback-wait none), for every emulator frame of a chosen
variant, and replaces that frame's predicted fields (predicted_ms, predicted_h200 and each
kernel's predicted_h200_*). Wall times, GPU times and the emulator's own timings are kept. The
file records when and why under "predictions_updated".

  /usr/bin/python3 scripts/h200/repredict.py --why "..." results/structures/structures_h200_looping_warm2.json

Scenes are found in scenes/ or in --scene-dir (.h200: the uneven scenes of
scripts/scenes/uneven_scenes.py, glass-opaque of scripts/docs/materials.py --opaque-copy)."""
import argparse
import datetime
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
import bench_frames  # noqa: E402
from bench_frames import key  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+", help="stored bench_gl JSON files, rewritten in place")
    ap.add_argument("--why", required=True, help="what changed in the model (kept in the file)")
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "bench", "bench_gl"))
    ap.add_argument("--scene-dir", default=os.path.join(ROOT, ".h200"))
    ap.add_argument("--variants", nargs="+", default=["looping"],
                    help="the variants whose predictions changed (default: looping)")
    ap.add_argument("--grid", default="auto", help="bench_gl --grid of the stored runs")
    a = ap.parse_args()
    dirs = [os.path.join(ROOT, "scenes"), a.scene_dir]
    for path in a.files:
        doc = json.load(open(path))
        changed = 0
        for f in doc["frames"]:
            if f["engine"] != "stream" or f["variant"] not in a.variants:
                continue
            new = bench_frames.emulate(a.bench, key(f), dirs, a.grid, "h200_repredict")
            if new["passes"] != f["passes"]:
                sys.exit(f"h200_repredict: {path}: {key(f)} now takes {new['passes']} passes, "
                         f"stored {f['passes']}: the frame itself changed, measure it again")
            before = f["predicted_ms"]["h200"]
            f["predicted_ms"] = new["predicted_ms"]
            f["predicted_h200"] = new["predicted_h200"]
            kernels = {k["name"]: k for k in new["kernels"]}
            for k in f["kernels"]:
                for field, v in kernels[k["name"]].items():
                    if field.startswith("predicted_"):
                        k[field] = v
            changed += 1
            print(f"{os.path.basename(path)}: {' '.join(str(x) for x in key(f))}: h200 "
                  f"{before:.2f} -> {f['predicted_ms']['h200']:.2f} ms", flush=True)
        doc.setdefault("predictions_updated", []).append(
            {"date": datetime.date.today().isoformat(), "why": a.why, "frames": changed})
        with open(path + ".tmp", "w") as out:
            json.dump(doc, out, indent=2)
            out.write("\n")
        os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
