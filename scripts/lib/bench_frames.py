"""A bench_gl frame's options as a key, and the emulator's frame of those options: shared by the
scripts that price stored GPU measurements with the model as it stands (scripts/docs/cells.py,
scripts/h200/repredict.py)."""
import json
import os
import subprocess
import sys
import tempfile

# The options that make a frame (bench_gl JSON fields), and what bench_gl did before a frame
# recorded one (its defaults then).
KEY = ("scene", "accel", "variant", "bounces", "shadows", "ray_streams", "sampling", "beams",
       "size")
DEFAULTS = {"accel": "grid", "bounces": 2, "shadows": False, "ray_streams": "off",
            "sampling": "spp:1", "beams": "off"}


def key(frame):
    return tuple(DEFAULTS.get(k) if frame.get(k) is None else frame[k] for k in KEY)


def scene_path(name, dirs, tool):
    for d in dirs:
        p = os.path.join(d, name + ".gltf")
        if os.path.exists(p):
            return p
    sys.exit(f"{tool}: scene '{name}' is in none of {', '.join(dirs)}")


def emulate(bench, k, dirs, grid, tool):
    """The emulator's frame of options k (bench_gl --readback-wait none, counts and predictions);
    exits naming `tool` where bench_gl fails or gives other than one frame."""
    scene, accel, variant, bounces, shadows, streams, sampling, beams, size = k
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "f.json")
        cmd = [bench, "--readback-wait", "none", "--no-fixed", "--runs", "1", "--grid", grid,
               "--sizes", str(size), "--scenes", scene_path(scene, dirs, tool), "--accel", accel,
               "--variants", variant, "--bounces", str(bounces), "--ray-streams", streams,
               "--sampling", sampling, "--beams", beams, "--json", out]
        cmd += ["--shadows"] if shadows else []
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{tool}: {' '.join(cmd)} failed: {r.stderr.strip()}")
        frames = [f for f in json.load(open(out))["frames"] if key(f) == k]
    if len(frames) != 1:
        sys.exit(f"{tool}: bench_gl gave {len(frames)} frames for {k}")
    return frames[0]
