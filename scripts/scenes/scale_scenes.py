#!/usr/bin/python3
"""Writes the large scenes of issue 50 (scale) as glTF files with an external .bin, not bundled:

  heightfield-N.gltf  a rolling heightfield of about N triangles (two per grid cell) over
                      [-1, 1]^2, lit from above, seen at an angle (bench/bench_speed's terrain,
                      larger): N = 10k, 100k, 320k, 1M, 4M by default
  objects-N.gltf      N triangles as many small objects: geodesic spheres of 1,280 triangles,
                      one mesh instanced by nodes scattered (a fixed seed) over a 40-unit square
                      at varied sizes, so their boxes overlap unevenly

Usage: scripts/scenes/scale_scenes.py OUTDIR [--heightfields 10k,1M] [--objects 1M]
       (sizes take k and M; writes OUTDIR/heightfield-1M.gltf and .bin, ...)
The 4M heightfield's .bin is about 100 MB. Needs NumPy (Debian's /usr/bin/python3 has it).
"""
import argparse
import json
import math
import sys
from pathlib import Path

try:
    import numpy as np
except ImportError:
    sys.exit(f"scale_scenes.py: NumPy is missing for {sys.executable} (use /usr/bin/python3)")


def count(text):
    """'10k' -> 10000, '4M' -> 4000000, '320000' -> 320000."""
    t = text.strip()
    scale = {"k": 1000, "K": 1000, "M": 1000000}.get(t[-1:], 1)
    try:
        n = int(float(t[:-1] if scale > 1 else t) * scale)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a triangle count (e.g. 320k, 1M)")
    if n < 2:
        raise argparse.ArgumentTypeError(f"'{text}': at least 2 triangles")
    return n


def label(n):
    return f"{n // 1000000}M" if n % 1000000 == 0 else f"{n // 1000}k" if n % 1000 == 0 else str(n)


def write(out, name, positions, normals, indices, nodes, camera, light):
    """One mesh (float32 positions and normals, uint32 indices) under `nodes` (translation,
    scale), a camera node and a point light, as OUTDIR/name.gltf and name.bin."""
    pos = positions.astype("<f4").tobytes()
    nrm = normals.astype("<f4").tobytes()
    idx = indices.astype("<u4").tobytes()
    (out / f"{name}.bin").write_bytes(pos + nrm + idx)
    p32 = positions.astype("<f4")
    lo, hi = p32.min(axis=0).tolist(), p32.max(axis=0).tolist()
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
             {"buffer": 0, "byteOffset": len(pos), "byteLength": len(nrm), "target": 34962},
             {"buffer": 0, "byteOffset": len(pos) + len(nrm), "byteLength": len(idx),
              "target": 34963}]
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
         "min": lo, "max": hi},
        {"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
        {"bufferView": 2, "componentType": 5125, "count": int(indices.size), "type": "SCALAR"}]
    # The camera looks down its -Z with +Y up: a look-at basis (world up +Y), as a quaternion.
    eye, target = np.array(camera[0], float), np.array(camera[1], float)
    back = (eye - target) / np.linalg.norm(eye - target)
    right = np.cross([0.0, 1.0, 0.0], back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    m = np.stack([right, up, back], axis=1)  # columns: the camera's x, y, z in the world
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    rot = [float((m[2, 1] - m[1, 2]) / (4 * w)), float((m[0, 2] - m[2, 0]) / (4 * w)),
           float((m[1, 0] - m[0, 1]) / (4 * w)), float(w)]
    gltf_nodes = [{"mesh": 0, "translation": list(map(float, t)), "scale": [float(k)] * 3}
                  for t, k in nodes]
    gltf_nodes.append({"camera": 0, "translation": camera[0], "rotation": rot})
    gltf_nodes.append({"extensions": {"KHR_lights_punctual": {"light": 0}},
                       "translation": light})
    g = {"asset": {"version": "2.0", "generator": "vgpu-rt scripts/scenes/scale_scenes.py"},
         "extensionsUsed": ["KHR_lights_punctual"],
         "extensions": {"KHR_lights_punctual": {"lights": [
             {"type": "point", "intensity": 1.0, "color": [1, 1, 1]}]}},
         "scene": 0, "scenes": [{"nodes": list(range(len(gltf_nodes)))}],
         "nodes": gltf_nodes,
         "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
         "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.4, 0.6, 0.3, 1.0],
                                                  "metallicFactor": 0.0}}],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                     "material": 0}]}],
         "buffers": [{"byteLength": len(pos) + len(nrm) + len(idx), "uri": f"{name}.bin"}],
         "bufferViews": views, "accessors": accessors}
    (out / f"{name}.gltf").write_text(json.dumps(g))
    print(f"{out / name}.gltf: {indices.size // 3 * len(nodes):,} triangles "
          f"({len(nodes)} node(s) of a mesh of {indices.size // 3:,})")


def heightfield(out, n):
    side = max(1, round(math.sqrt(n / 2)))
    u = np.linspace(-1.0, 1.0, side + 1)
    x, z = np.meshgrid(u, u, indexing="ij")
    h = 0.08 * np.sin(7 * x) * np.cos(5 * z) + 0.03 * np.sin(23 * x + 11 * z)
    # Normals from the height's derivatives.
    hx = 0.56 * np.cos(7 * x) * np.cos(5 * z) + 0.69 * np.cos(23 * x + 11 * z)
    hz = -0.40 * np.sin(7 * x) * np.sin(5 * z) + 0.33 * np.cos(23 * x + 11 * z)
    nrm = np.stack([-hx, np.ones_like(hx), -hz], axis=-1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    pos = np.stack([x, h, z], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    v00 = (i * (side + 1) + j).ravel()
    v01, v10, v11 = v00 + 1, v00 + side + 1, v00 + side + 2
    tris = np.stack([np.stack([v00, v01, v11], 1), np.stack([v00, v11, v10], 1)], 1)
    write(out, f"heightfield-{label(n)}", pos, nrm.reshape(-1, 3), tris.reshape(-1),
          [((0, 0, 0), 1.0)], ([0.0, 1.4, 2.2], [0.0, 0.85, 1.2]), [1.0, 3.0, 2.0])


def geodesic_sphere(levels):
    """An icosahedron subdivided `levels` times (20 * 4^levels triangles), radius 1."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(levels):
        mid, nf = {}, []
        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = verts[a] + verts[b]
                verts.append(p / np.linalg.norm(p))
                mid[k] = len(verts) - 1
            return mid[k]
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    p = np.array(verts)
    return p, p.copy(), np.array(f, dtype=np.uint32).reshape(-1)


def objects(out, n):
    pos, nrm, idx = geodesic_sphere(3)  # 1,280 triangles
    k = max(1, round(n / (idx.size // 3)))
    rng = np.random.default_rng(50)
    xz = rng.uniform(-20, 20, size=(k, 2))
    size = np.exp(rng.uniform(math.log(0.1), math.log(1.5), size=k))
    nodes = [((float(a), float(s), float(b)), float(s)) for (a, b), s in zip(xz, size)]
    name = f"objects-{label(n)}"
    write(out, name, pos, nrm, idx, nodes, ([0.0, 18.0, 34.0], [0.0, 0.0, 0.0]),
          [5.0, 30.0, 10.0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir", type=Path)
    ap.add_argument("--heightfields", default="10k,100k,320k,1M,4M",
                    type=lambda s: [count(x) for x in s.split(",") if x])
    ap.add_argument("--objects", default="1M", type=lambda s: [count(x) for x in s.split(",") if x])
    a = ap.parse_args()
    try:
        a.outdir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        sys.exit(f"scale_scenes.py: {a.outdir}: {e.strerror}")
    for n in a.heightfields:
        heightfield(a.outdir, n)
    for n in a.objects:
        objects(a.outdir, n)


if __name__ == "__main__":
    main()
