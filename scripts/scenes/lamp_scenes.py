#!/usr/bin/env python3
"""Writes bundled scenes with their point light moved among the objects, as glTF files.

The bundled scenes keep their light outside the grid's box (above and behind the camera), so a
shadow ray that reaches its light unblocked has no voxel left behind the light: no walk goes on
past it. A lamp among the objects is the case where it could; docs/studies/groups.md ("Shadow rays end
at the light") measures it with these:

  classic-lamp.gltf  scenes/classic.gltf, light at (-2, 1.2, 2.5): between the spheres and the
                     camera, 1.2 above the floor
  hop-lamp.gltf      scenes/hop.gltf, light at (-2, 2, 2.5)

Usage: scripts/scenes/lamp_scenes.py OUTDIR
"""
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAMPS = {"classic": [-2.0, 1.2, 2.5], "hop": [-2.0, 2.0, 2.5]}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[-1])
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for name, position in LAMPS.items():
        src = ROOT / "scenes" / f"{name}.gltf"
        g = json.loads(src.read_text())
        lights = [n for n in g["nodes"]
                  if "KHR_lights_punctual" in n.get("extensions", {})]
        if len(lights) != 1:
            sys.exit(f"{src}: expected one light node, found {len(lights)}")
        lights[0]["translation"] = position
        dst = out / f"{name}-lamp.gltf"
        dst.write_text(json.dumps(g))
        print(dst)


if __name__ == "__main__":
    main()
