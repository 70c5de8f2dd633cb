#!/usr/bin/env python3
"""Writes the uneven scenes of docs/studies/structures.md as glTF files, from the bundled bunny.

  stadium.gltf  the bunny of scenes/bunny.gltf, its camera and light, on a two-triangle floor
                270 times the bunny's width ("teapot in a stadium": a uniform grid spends
                almost every voxel on empty floor)
  scales.gltf   25 bunnies from 5% to 15x the bunny's size (log-spaced) on a floor, the same
                mesh instanced by 25 nodes (92k triangles)

Usage: scripts/scenes/uneven_scenes.py OUTDIR
"""
import base64
import json
import struct
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def floor_buffers(half, y):
    """A quad of half-width `half` at height y: positions, normals, indices (bytes)."""
    pos = [(-half, y, -half), (half, y, -half), (half, y, half), (-half, y, half)]
    nrm = [(0.0, 1.0, 0.0)] * 4
    idx = [0, 2, 1, 0, 3, 2]
    return (b"".join(struct.pack("<3f", *p) for p in pos),
            b"".join(struct.pack("<3f", *n) for n in nrm),
            struct.pack("<6H", *idx))


def with_floor(g, half, y, colour):
    """Appends a floor mesh (one buffer of its own) and its node to glTF dict g."""
    pos, nrm, idx = floor_buffers(half, y)
    data = pos + nrm + idx
    b = len(g["buffers"])
    g["buffers"].append({"byteLength": len(data),
                         "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(data).decode()})
    views = []
    for off, ln in ((0, len(pos)), (len(pos), len(nrm)), (len(pos) + len(nrm), len(idx))):
        views.append(len(g["bufferViews"]))
        g["bufferViews"].append({"buffer": b, "byteOffset": off, "byteLength": ln})
    acc = len(g["accessors"])
    g["accessors"] += [
        {"bufferView": views[0], "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-half, y, -half], "max": [half, y, half]},
        {"bufferView": views[1], "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": views[2], "componentType": 5123, "count": 6, "type": "SCALAR"}]
    mat = len(g["materials"])
    g["materials"].append({"name": "floor", "pbrMetallicRoughness": {
        "baseColorFactor": colour + [1], "metallicFactor": 0, "roughnessFactor": 0.8},
        "extras": {"reflect": 0}})
    mesh = len(g["meshes"])
    g["meshes"].append({"name": "floor", "primitives": [{
        "attributes": {"POSITION": acc, "NORMAL": acc + 1}, "indices": acc + 2,
        "material": mat, "mode": 4}]})
    g["nodes"].append({"name": "floor", "mesh": mesh})
    g["scenes"][g.get("scene", 0)]["nodes"].append(len(g["nodes"]) - 1)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    base = json.loads((ROOT / "scenes" / "bunny.gltf").read_text())
    bunny = next(n for n in base["nodes"] if n.get("name") == "bunny")
    lo = base["accessors"][0]["min"]
    hi = base["accessors"][0]["max"]
    s = bunny["scale"][0]
    width = (hi[0] - lo[0]) * s  # world width of the bunny

    g = json.loads(json.dumps(base))
    g["asset"]["generator"] = "vgpu-rt scripts/scenes/uneven_scenes.py"
    with_floor(g, 270 * width / 2, 0.0, [0.6, 0.6, 0.62])
    (out / "stadium.gltf").write_text(json.dumps(g))

    g = json.loads(json.dumps(base))
    g["asset"]["generator"] = "vgpu-rt scripts/scenes/uneven_scenes.py"
    g["nodes"] = [n for n in g["nodes"] if n.get("name") in ("light",)]
    g["cameras"] = []
    g["scenes"] = [{"nodes": [0]}]
    g["scene"] = 0
    x = 0.0
    for k in range(25):
        f = 0.05 * (15 / 0.05) ** (k / 24)  # 5% .. 15x, log-spaced
        w = width * f
        g["nodes"].append({"name": "bunny %d" % k, "mesh": 0,
                           "translation": [x + w / 2, -lo[1] * s * f, 0.0],
                           "scale": [s * f] * 3})
        g["scenes"][0]["nodes"].append(len(g["nodes"]) - 1)
        x += w * 1.2
    for n in g["nodes"]:
        if n.get("name") == "light":
            n["translation"] = [x / 2, x, x]
    with_floor(g, x, 0.0, [0.6, 0.6, 0.62])
    for n in g["nodes"]:
        if n.get("name") == "floor":
            n["translation"] = [x / 2, 0.0, 0.0]
    (out / "scales.gltf").write_text(json.dumps(g))
    print("wrote", out / "stadium.gltf", "and", out / "scales.gltf")


if __name__ == "__main__":
    main()
