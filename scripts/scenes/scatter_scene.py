#!/usr/bin/env python3
"""Writes scatter.gltf, the larger animation of docs/studies/animation.md (issue 23): ten full bunnies
of scenes/bunny.gltf (3,674 triangles each, 36,740 in all; 37,228 with the board and sphere)
start inside one another on hop's checkerboard and hop apart onto a ring while the mirror sphere
turns, 2 s. A BVH built at 0 s groups triangles of different bunnies that then move apart: a
refit keeps that grouping, and its boxes grow frame after frame (what the issue wants shown).

  start   bunny k at 0.35 units from (0, 0, 1.5), facing 36k degrees (all ten overlap)
  end     bunny k on a ring of radius 5.5 about (0, 0, 0.5), on the board (+-8 units)
  motion  3 hops of 1 unit (LINEAR keys every 1/16 s), each bunny spinning 90 degrees per second
          about +Y, alternately left and right (LINEAR keys every 1/4 s); the mirror sphere
          turns once as in hop

The file reuses scenes/hop.gltf (board, sphere, camera, light, the sphere's turn) and the bunny
mesh of scenes/bunny.gltf, once, instanced by ten nodes at hop's scale (0.22): about 170 KB.

Usage: scripts/scenes/scatter_scene.py OUTDIR      (writes OUTDIR/scatter.gltf)
"""
import base64
import json
import math
import struct
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUNNIES = 10
SCALE = 0.22  # hop's bunny scale: 2.2 units wide, 2.1 high
DURATION = 2.0  # s
HOPS, HOP_HEIGHT = 3, 1.0
START, START_SPREAD = (0.0, 1.5), 0.35  # (x, z) of the cluster, units
END, END_RADIUS = (0.0, 0.5), 5.5
SPIN = math.pi / 2  # rad/s


def yaw(a):
    """Unit quaternion (x, y, z, w) of a turn by a radians about +Y."""
    return (0.0, math.sin(a / 2), 0.0, math.cos(a / 2))


def add_buffer(g, data):
    """Appends `data` as a base64 buffer; returns its index."""
    g["buffers"].append({"byteLength": len(data),
                         "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(data).decode()})
    return len(g["buffers"]) - 1


def add_accessor(g, buf, offset, data, count, kind, **extra):
    """A float accessor over bytes [offset, offset + len(data)) of buffer `buf`."""
    g["bufferViews"].append({"buffer": buf, "byteOffset": offset, "byteLength": len(data)})
    g["accessors"].append(dict({"bufferView": len(g["bufferViews"]) - 1, "componentType": 5126,
                                "count": count, "type": kind}, **extra))
    return len(g["accessors"]) - 1


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    g = json.loads((ROOT / "scenes" / "hop.gltf").read_text())
    src = json.loads((ROOT / "scenes" / "bunny.gltf").read_text())
    g["asset"]["generator"] = "vgpu-rt scripts/scenes/scatter_scene.py"

    # The full bunny mesh: bunny.gltf's buffer, views and accessors appended; hop's bunny mesh
    # (the simplified one) is pointed at them, so every node naming it draws the full bunny.
    buf = add_buffer(g, base64.b64decode(src["buffers"][0]["uri"].split(",", 1)[1]))
    view0, acc0 = len(g["bufferViews"]), len(g["accessors"])
    for v in src["bufferViews"]:
        g["bufferViews"].append(dict(v, buffer=buf))
    for a in src["accessors"]:
        g["accessors"].append(dict(a, bufferView=a["bufferView"] + view0))
    prim = src["meshes"][0]["primitives"][0]
    mesh = next(i for i, m in enumerate(g["meshes"]) if m["name"] == "bunny")
    g["meshes"][mesh]["primitives"][0].update(
        attributes={k: v + acc0 for k, v in prim["attributes"].items()},
        indices=prim["indices"] + acc0)
    lift = -src["accessors"][prim["attributes"]["POSITION"]]["min"][1] * SCALE  # feet on y = 0

    # Ten nodes: hop's bunny node becomes bunny 0, nine more are appended.
    first = next(i for i, n in enumerate(g["nodes"]) if n.get("name") == "bunny")
    nodes = [first]
    for k in range(1, BUNNIES):
        g["nodes"].append({"mesh": mesh})
        nodes.append(len(g["nodes"]) - 1)
        g["scenes"][g.get("scene", 0)]["nodes"].append(nodes[-1])

    # Keys: hop's bunny channels dropped (the sphere's turn kept), ten bunnies' added.
    anim = g["animations"][0]
    anim["channels"] = [c for c in anim["channels"] if c["target"]["node"] != first]
    anim["name"] = "scatter"
    t_hop = [i / 16 for i in range(int(16 * DURATION) + 1)]  # s
    t_turn = [i / 4 for i in range(int(4 * DURATION) + 1)]
    for k, n in enumerate(nodes):
        phi = 2 * math.pi * k / BUNNIES + 0.3
        face = 2 * math.pi * k / BUNNIES
        spin = SPIN if k % 2 == 0 else -SPIN
        c, s = math.cos(phi), math.sin(phi)
        x0, z0 = START[0] + START_SPREAD * c, START[1] + START_SPREAD * s
        x1, z1 = END[0] + END_RADIUS * c, END[1] + END_RADIUS * s
        trans = []
        for t in t_hop:
            u = t / DURATION
            y = lift + HOP_HEIGHT * abs(math.sin(math.pi * HOPS * u))
            trans.append((x0 + (x1 - x0) * u, y, z0 + (z1 - z0) * u))
        rot = [yaw(face + spin * t) for t in t_turn]
        g["nodes"][n] = {"name": "bunny %d" % k, "mesh": mesh, "translation": list(trans[0]),
                         "rotation": list(rot[0]), "scale": [SCALE] * 3}
        data = (struct.pack("<%df" % len(t_hop), *t_hop) +
                b"".join(struct.pack("<3f", *p) for p in trans) +
                struct.pack("<%df" % len(t_turn), *t_turn) +
                b"".join(struct.pack("<4f", *q) for q in rot))
        b = add_buffer(g, data)
        off = 0
        acc = []
        for count, kind, width in ((len(t_hop), "SCALAR", 4), (len(t_hop), "VEC3", 12),
                                   (len(t_turn), "SCALAR", 4), (len(t_turn), "VEC4", 16)):
            extra = {"min": [0.0], "max": [DURATION]} if kind == "SCALAR" else {}
            acc.append(add_accessor(g, b, off, data[off:off + count * width], count, kind,
                                    name="scatter bunny %d %s" % (k, kind), **extra))
            off += count * width
        for path, (times, values) in (("translation", acc[0:2]), ("rotation", acc[2:4])):
            anim["samplers"].append({"input": times, "interpolation": "LINEAR", "output": values})
            anim["channels"].append({"sampler": len(anim["samplers"]) - 1,
                                     "target": {"node": n, "path": path}})
    (out / "scatter.gltf").write_text(json.dumps(g))
    print("wrote", out / "scatter.gltf")


if __name__ == "__main__":
    main()
