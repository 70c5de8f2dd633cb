#!/usr/bin/env python3
"""Writes the small glTF files that tests/scene/test_gltf_loader.cpp loads, valid and broken.

Run from anywhere: python3 tests/data/gltf/make_cases.py. The output is committed next to this
script; each case is a few triangles whose expected values the test states exactly.
"""
import base64
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))

FLOAT, BYTE, UBYTE, SHORT, USHORT, UINT = 5126, 5120, 5121, 5122, 5123, 5125
POINTS, LINES, LINE_STRIP, TRIANGLES, STRIP, FAN = 0, 1, 3, 4, 5, 6
INDEX_FORMAT = {UBYTE: "B", USHORT: "H", UINT: "I"}


class Builder:
    """Collects binary data, buffer views and accessors for one buffer."""

    def __init__(self):
        self.bin = bytearray()
        self.views = []
        self.accessors = []

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        self.bin += data
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, view, comp, type_, count, normalized=False, extra=None):
        a = {"bufferView": view, "componentType": comp, "type": type_, "count": count}
        if normalized:
            a["normalized"] = True
        if extra:
            a.update(extra)
        self.accessors.append(a)
        return len(self.accessors) - 1

    def vec3(self, points):
        data = b"".join(struct.pack("<3f", *p) for p in points)
        finite = [p for p in points if all(math.isfinite(c) for c in p)] or [(0, 0, 0)]
        mm = {"min": [min(p[i] for p in finite) for i in range(3)],
              "max": [max(p[i] for p in finite) for i in range(3)]}
        return self.accessor(self.view(data), FLOAT, "VEC3", len(points), extra=mm)

    def vec3_quantized(self, points, comp, normalized):
        fmt, size = {BYTE: ("b", 1), UBYTE: ("B", 1), SHORT: ("h", 2), USHORT: ("H", 2)}[comp]
        stride = (3 * size + 3) // 4 * 4  # glTF: vertex strides are multiples of 4
        data = b"".join(struct.pack("<3" + fmt, *p) + b"\0" * (stride - 3 * size) for p in points)
        return self.accessor(self.view(data, stride=stride), comp, "VEC3", len(points), normalized)

    def indices(self, idx, comp=USHORT):
        data = struct.pack("<%d%s" % (len(idx), INDEX_FORMAT[comp]), *idx)
        return self.accessor(self.view(data), comp, "SCALAR", len(idx))

    def doc(self, **parts):
        d = {"asset": {"version": "2.0", "generator": "tests/data/gltf/make_cases.py"}}
        d.update(parts)
        d["buffers"] = [{"byteLength": len(self.bin)}]
        d["bufferViews"] = self.views
        d["accessors"] = self.accessors
        return d


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()


def write_text(name, text):
    with open(os.path.join(HERE, name), "w") as f:
        f.write(text)


def write_bytes(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def write_gltf(name, doc, data, external=False):
    doc = json.loads(json.dumps(doc))
    if external:
        bin_name = name.replace(".gltf", ".bin")
        doc["buffers"][0]["uri"] = bin_name
        write_bytes(bin_name, data)
    else:
        doc["buffers"][0]["uri"] = data_uri(data)
    write_text(name, json.dumps(doc, indent=1) + "\n")


def glb_bytes(doc, data, version=2):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    data = bytes(data) + b"\0" * (-len(data) % 4)
    out = struct.pack("<I", len(text)) + b"JSON" + text
    if data:
        out += struct.pack("<I", len(data)) + b"BIN\0" + data
    return b"glTF" + struct.pack("<II", version, 12 + len(out)) + out


def simple(points, mode=TRIANGLES, idx=None, normals=None, **doc_parts):
    """One node, one mesh, one primitive."""
    b = Builder()
    prim = {"attributes": {"POSITION": b.vec3(points)}, "mode": mode}
    if normals:
        prim["attributes"]["NORMAL"] = b.vec3(normals)
    if idx is not None:
        prim["indices"] = b.indices(idx)
    parts = {"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
             "meshes": [{"primitives": [prim]}]}
    parts.update(doc_parts)
    return b, b.doc(**parts)


TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
UP = [(0, 0, 1)] * 3


def triangle_cases():
    b, d = simple(TRI, idx=[0, 1, 2], normals=UP)
    write_gltf("triangle.gltf", d, b.bin)
    write_gltf("triangle_external.gltf", d, b.bin, external=True)
    write_bytes("triangle.glb", glb_bytes(d, b.bin))


def hierarchy_case():
    b = Builder()
    tri = {"attributes": {"POSITION": b.vec3(TRI), "NORMAL": b.vec3(UP)}, "indices": b.indices([0, 1, 2])}
    # A triangle in the plane x + y = 1, front (1, 1, 0).
    slanted = [(1, 0, 0), (0, 1, 0), (0, 1, 1)]
    n = 1 / math.sqrt(2)
    tilt = {"attributes": {"POSITION": b.vec3(slanted), "NORMAL": b.vec3([(n, n, 0)] * 3)}}
    nodes = [
        {"name": "trs", "mesh": 0, "children": [1], "translation": [1, 2, 3],
         "rotation": [0, 0, 1, 0], "scale": [2, 2, 2]},  # 180 degrees about +Z
        {"name": "matrix", "mesh": 0,
         "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1]},  # translate (10, 0, 0)
        {"name": "mirror", "mesh": 0, "scale": [-1, 1, 1]},
        {"name": "stretch", "mesh": 1, "scale": [1, 2, 1]},
    ]
    d = b.doc(scene=0, scenes=[{"nodes": [0, 2, 3]}], nodes=nodes,
              meshes=[{"primitives": [tri]}, {"primitives": [tilt]}])
    write_gltf("hierarchy.gltf", d, b.bin)


def roots_case():
    # No "scenes": every root node, in index order; node 2 is node 0's child.
    b, d = simple(TRI, idx=[0, 1, 2])
    del d["scene"], d["scenes"]
    d["nodes"] = [{"mesh": 0, "children": [2]}, {"mesh": 0, "translation": [0, 0, 1]},
                  {"mesh": 0, "translation": [0, 0, 2]}]
    write_gltf("no_scenes.gltf", d, b.bin)


def strip_fan_case():
    b = Builder()
    strip = {"attributes": {"POSITION": b.vec3([(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0), (2, 0, 0)])},
             "indices": b.indices([0, 1, 2, 3, 4]), "mode": STRIP}
    fan = {"attributes": {"POSITION": b.vec3([(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])},
           "indices": b.indices([0, 1, 2, 3]), "mode": FAN}
    plain_strip = {"attributes": {"POSITION": b.vec3([(0, 0, 2), (0, 1, 2), (1, 0, 2), (1, 1, 2)])},
                   "mode": STRIP}
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
              meshes=[{"primitives": [strip, fan, plain_strip]}])
    write_gltf("strip_fan.gltf", d, b.bin)


def index_types_case():
    b = Builder()
    pos = b.vec3([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    prims = [{"attributes": {"POSITION": pos}, "indices": b.indices([0, 1, 2, 0, 2, 3], comp)}
             for comp in (UBYTE, USHORT, UINT)]
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}], meshes=[{"primitives": prims}])
    write_gltf("index_types.gltf", d, b.bin)


def non_indexed_case():
    pts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)]
    b, d = simple(pts)
    write_gltf("non_indexed.gltf", d, b.bin)


def quantized_case():
    b = Builder()
    u16 = {"attributes": {
        "POSITION": b.vec3_quantized([(0, 0, 0), (65535, 0, 0), (0, 32768, 0)], USHORT, True),
        "NORMAL": b.vec3_quantized([(0, 0, 127)] * 3, BYTE, True)}}
    i8 = {"attributes": {"POSITION": b.vec3_quantized([(-128, 0, 0), (127, 0, 0), (0, 64, 0)], BYTE, True)}}
    i16 = {"attributes": {"POSITION": b.vec3_quantized([(0, 0, 0), (300, 0, 0), (0, -200, 0)], SHORT, False)}}
    d = b.doc(extensionsUsed=["KHR_mesh_quantization"], extensionsRequired=["KHR_mesh_quantization"],
              scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
              meshes=[{"primitives": [u16, i8, i16]}])
    write_gltf("quantized.gltf", d, b.bin)


def no_normals_case():
    # Two triangles folded along the edge 1-2, plus a separate non-indexed triangle.
    b = Builder()
    roof = {"attributes": {"POSITION": b.vec3([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 1)])},
            "indices": b.indices([0, 1, 2, 1, 3, 2])}
    flat = {"attributes": {"POSITION": b.vec3([(0, 0, 5), (0, 0, 6), (0, 1, 5)])}}
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}], meshes=[{"primitives": [roof, flat]}])
    write_gltf("no_normals.gltf", d, b.bin)


def degenerate_case():
    pts = [(0, 0, 0), (1, 0, 0), (0, 1, 0),      # id 0
           (0, 0, 0), (1, 1, 1), (2, 2, 2),      # id 1: collinear
           (3, 3, 3), (3, 3, 3), (4, 4, 5),      # id 2: repeated corner
           (0, 0, 1), (1, 0, 1), (0, 1, 1)]      # id 3
    b, d = simple(pts)
    write_gltf("degenerate.gltf", d, b.bin)


def cameras_case():
    s = math.sqrt(0.5)
    b, d = simple(TRI, idx=[0, 1, 2])
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": y, "znear": 0.1}} for y in (0.5, 0.7, 0.9)]
    d["nodes"] = [
        {"name": "root", "mesh": 0, "children": [3, 1]},
        {"name": "shallow camera", "camera": 0, "translation": [5, 5, 5]},
        {"name": "deep camera", "camera": 1, "translation": [1, 2, 3], "rotation": [0, s, 0, s]},
        {"name": "group", "children": [2], "translation": [0, 0, 10]},
        {"name": "scene 0 only", "camera": 2, "mesh": 0},
    ]
    d["scenes"] = [{"nodes": [4]}, {"nodes": [0]}]
    d["scene"] = 1
    write_gltf("cameras.gltf", d, b.bin)


def ortho_case():
    b, d = simple(TRI, idx=[0, 1, 2])
    d["cameras"] = [{"type": "orthographic",
                     "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    d["nodes"][0]["camera"] = 0
    write_gltf("orthographic_camera.gltf", d, b.bin)


def lights_case():
    b, d = simple(TRI, idx=[0, 1, 2])
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.5, 0.25], "intensity": 2},
        {"type": "point", "intensity": 4},
        {"type": "spot", "color": [0, 1, 0], "intensity": 1, "spot": {}},
        {"type": "directional", "intensity": 3},
    ]}}
    d["nodes"] = [{"mesh": 0}] + [
        {"translation": t, "extensions": {"KHR_lights_punctual": {"light": i}}}
        for i, t in enumerate([[1, 2, 3], [0, 5, 0], [0, 0, 5], [0, 0, 0]])]
    d["scenes"] = [{"nodes": [0, 1, 2, 3, 4]}]
    write_gltf("lights.gltf", d, b.bin)


def materials_case():
    b = Builder()
    pos = b.vec3(TRI)
    prims = [{"attributes": {"POSITION": pos}, "material": m} for m in range(4)]
    prims.append({"attributes": {"POSITION": pos}})
    materials = [
        {"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1], "metallicFactor": 0.25}},
        {"pbrMetallicRoughness": {"metallicFactor": 0.1}, "extras": {"reflect": 0.75}},
        {},
        {"pbrMetallicRoughness": {"metallicFactor": 0}, "extras": {"reflect": 1.5}},
    ]
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
              meshes=[{"primitives": prims}], materials=materials)
    write_gltf("materials.gltf", d, b.bin)


def glass_case():
    """Glass materials: valid ones, then one file per refused value (a triangle each)."""
    b = Builder()
    pos = b.vec3(TRI)
    materials = [
        {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.75},
                        "KHR_materials_ior": {"ior": 1.33}}},
        {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}},
        {"extensions": {"KHR_materials_ior": {"ior": 2.42}}},
        # ior 0: the extension's "Fresnel term 1": an opaque mirror, a + t (1 - a) = 0.5 + 0.25.
        {"pbrMetallicRoughness": {"metallicFactor": 0.5},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5},
                        "KHR_materials_ior": {"ior": 0}}},
        {"extensions": {"KHR_materials_transmission": {
            "transmissionFactor": 0.5, "transmissionTexture": {"index": 0}},
            "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": 2,
                                     "attenuationColor": [1, 0.5, 0.5]}}},
        {"extensions": {"KHR_materials_ior": {"ior": 1}}},
    ]
    prims = [{"attributes": {"POSITION": pos}, "material": m} for m in range(len(materials))]
    used = ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"]
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
              meshes=[{"primitives": prims}], materials=materials, extensionsUsed=used)
    write_gltf("glass.gltf", d, b.bin)

    bad = {
        "glass_ior_below_one.gltf": {"KHR_materials_ior": {"ior": 0.5}},
        "glass_ior_negative.gltf": {"KHR_materials_ior": {"ior": -1.5}},
        "glass_ior_string.gltf": {"KHR_materials_ior": {"ior": "1.5"}},
        "glass_transmission_above_one.gltf": {"KHR_materials_transmission": {"transmissionFactor": 1.5}},
        "glass_transmission_negative.gltf": {"KHR_materials_transmission": {"transmissionFactor": -0.25}},
        "glass_transmission_bool.gltf": {"KHR_materials_transmission": {"transmissionFactor": True}},
    }
    for name, ext in bad.items():
        b = Builder()
        pos = b.vec3(TRI)
        # Material 1 is the bad one, so the message must name it (not the first material).
        d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
                  meshes=[{"primitives": [{"attributes": {"POSITION": pos}, "material": 1}]}],
                  materials=[{}, {"extensions": ext}], extensionsUsed=sorted(ext))
        write_gltf(name, d, b.bin)
    # An ior that overflows a double: JSON has no NaN or infinity, this is as close as it gets
    # (the JSON parser refuses it before the material is read).
    b = Builder()
    pos = b.vec3(TRI)
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
              meshes=[{"primitives": [{"attributes": {"POSITION": pos}, "material": 1}]}],
              materials=[{}, {"extensions": {"KHR_materials_ior": {"ior": 7}}}])
    d["buffers"][0]["uri"] = data_uri(b.bin)
    write_text("glass_ior_overflow.gltf",
               json.dumps(d, indent=1).replace('"ior": 7', '"ior": 1e999') + "\n")


def modes_case():
    b = Builder()
    pos = b.vec3(TRI)
    prims = [{"attributes": {"POSITION": pos}, "mode": m} for m in (TRIANGLES, LINES, POINTS, LINE_STRIP)]
    prims[1]["indices"] = b.indices([0, 1])
    d = b.doc(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}], meshes=[{"primitives": prims}])
    write_gltf("modes.gltf", d, b.bin)


def bad_cases():
    write_text("not_gltf.txt", "This is a plain text file, not a glTF scene.\n")

    b, d = simple(TRI, idx=[0, 1, 2], normals=UP)
    glb = glb_bytes(d, b.bin)
    write_bytes("truncated.glb", glb[:len(glb) // 2])
    bad_chunk = bytearray(glb)
    bad_chunk[12:16] = struct.pack("<I", 10000)
    write_bytes("bad_chunk_length.glb", bytes(bad_chunk))
    write_bytes("bad_version.glb", glb_bytes(d, b.bin, version=1))
    # BIN chunk holds 8 bytes fewer than the buffer's byteLength.
    short = json.loads(json.dumps(d))
    short["buffers"][0]["byteLength"] = len(b.bin) + 8
    write_bytes("short_buffer.glb", glb_bytes(short, b.bin))

    write_text("json_syntax.gltf", '{\n  "asset": {"version": "2.0"}\n  "scenes": []\n}\n')

    b, d = simple(TRI, idx=[0, 1, 2])
    d["accessors"][0]["count"] = 4
    write_gltf("accessor_past_view.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    d["bufferViews"][1]["byteLength"] = 100
    write_gltf("view_past_buffer.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    d["buffers"][0]["byteLength"] = len(b.bin) + 8
    write_gltf("short_buffer.gltf", d, b.bin, external=True)
    write_gltf("short_buffer_embedded.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 5])
    write_gltf("index_past_vertices.gltf", d, b.bin)

    b, d = simple([(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)])
    write_gltf("nan_position.gltf", d, b.bin)
    b, d = simple([(0, 0, 0), (1, 0, 0), (0, float("inf"), 0)])
    write_gltf("inf_position.gltf", d, b.bin)

    b, d = simple(TRI, mode=LINES, idx=[0, 1, 1, 2])
    write_gltf("only_lines.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    d["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
    write_gltf("node_cycle.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 7
    write_gltf("accessor_index_out_of_range.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write_gltf("draco_required.gltf", d, b.bin)

    b, d = simple(TRI, idx=[0, 1, 2])
    nested = 0
    for _ in range(100):
        nested = [nested]
    d["nodes"][0]["extras"] = {"deep": nested}
    write_gltf("deep_json.gltf", d, b.bin)


def png_bytes(width, height, rows):
    """An 8-bit RGB PNG; rows: height lists of width (r, g, b) tuples, the top row first."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# The Duck-like case's texture: red, green / blue, white (top row first).
QUAD_TEXELS = [[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (255, 255, 255)]]
REPEAT, CLAMP, MIRROR = 10497, 33071, 33648


def textured_quad(image, uv_type="VEC2", transform=None):
    """A 2 x 2 quad in z = 0 facing +z, (0, 0) of its texture at its top-left corner; a camera
    2.5 in front and a light beside it; `image` is the glTF image object."""
    b = Builder()
    pos = [(-1, 1, 0), (1, 1, 0), (-1, -1, 0), (1, -1, 0)]
    uvs = [(0, 0), (1, 0), (0, 1), (1, 1)]
    if uv_type == "VEC2":
        uv = b.accessor(b.view(b"".join(struct.pack("<2f", *t) for t in uvs)), FLOAT, "VEC2", 4)
    else:  # a VEC3 accessor where TEXCOORD_0 must be VEC2
        uv = b.accessor(b.view(b"".join(struct.pack("<3f", *t, 0) for t in uvs)), FLOAT, "VEC3", 4)
    prim = {"attributes": {"POSITION": b.vec3(pos), "NORMAL": b.vec3([(0, 0, 1)] * 4),
                           "TEXCOORD_0": uv},
            "indices": b.indices([0, 2, 1, 1, 2, 3]), "material": 0}
    info = {"index": 0}
    if transform:
        info["extensions"] = {"KHR_texture_transform": transform}
    d = b.doc(scene=0, scenes=[{"nodes": [0, 1, 2]}],
              nodes=[{"mesh": 0}, {"camera": 0, "translation": [0, 0, 2.5]},
                     {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 0, 2.5]}],
              meshes=[{"primitives": [prim]}],
              cameras=[{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}],
              extensionsUsed=["KHR_lights_punctual"] + (["KHR_texture_transform"] if transform else []),
              extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}},
              materials=[{"pbrMetallicRoughness": {"baseColorTexture": info, "metallicFactor": 0}}],
              textures=[{"source": 0, "sampler": 0}],
              samplers=[{"wrapS": CLAMP, "wrapT": MIRROR}],
              images=[image])
    return b, d


def textured_cases():
    png = png_bytes(2, 2, QUAD_TEXELS)
    png_uri = "data:image/png;base64," + base64.b64encode(png).decode()
    b, d = textured_quad({"uri": png_uri})
    write_gltf("textured.gltf", d, b.bin)
    # The image in a buffer view of a .glb, as the Khronos Duck holds it.
    b, d = textured_quad({"bufferView": 0, "mimeType": "image/png"})
    view = b.view(png)
    d["bufferViews"] = b.views
    d["images"][0]["bufferView"] = view
    d["buffers"] = [{"byteLength": len(b.bin)}]
    write_bytes("textured.glb", glb_bytes(d, b.bin))
    # Beside the file.
    write_bytes("textured_external.png", png)
    b, d = textured_quad({"uri": "textured_external.png"})
    write_gltf("textured_external.gltf", d, b.bin)
    # KHR_texture_transform: u + 0.5 (and REPEAT would wrap; CLAMP_TO_EDGE is what the sampler says).
    b, d = textured_quad({"uri": png_uri}, transform={"offset": [0.5, 0], "scale": [2, 1]})
    write_gltf("textured_transform.gltf", d, b.bin)
    # A quarter turn and an offset, as the extension's own example: uv' = (v, 1 - u), the image
    # turned clockwise on the quad (tests/trace/test_textures.cpp checks the corners' texels).
    b, d = textured_quad({"uri": png_uri}, transform={"offset": [0, 1], "rotation": math.pi / 2})
    write_gltf("textured_rotation.gltf", d, b.bin)
    # Bad: a missing file, bytes that are no image, a PNG cut short, a TEXCOORD_0 of VEC3.
    b, d = textured_quad({"uri": "no_such_texture.png"})
    write_gltf("texture_missing.gltf", d, b.bin)
    b, d = textured_quad({"uri": "data:image/png;base64," + base64.b64encode(b"not an image").decode()})
    write_gltf("texture_not_an_image.gltf", d, b.bin)
    b, d = textured_quad({"uri": "data:image/png;base64," + base64.b64encode(png[:40]).decode()})
    write_gltf("texture_truncated.gltf", d, b.bin)
    b, d = textured_quad({"uri": png_uri}, uv_type="VEC3")
    write_gltf("texcoord_vec3.gltf", d, b.bin)

def floats(b, values, type_):
    """A float accessor of SCALAR, VEC3 or VEC4 elements (animation inputs and outputs)."""
    n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[type_]
    flat = [c for v in values for c in ((v,) if n == 1 else v)]
    data = struct.pack("<%df" % len(flat), *flat)
    extra = {"min": [min(values)], "max": [max(values)]} if n == 1 else None
    return b.accessor(b.view(data), FLOAT, type_, len(values), extra=extra)


def cube_points(half):
    """A non-indexed axis-aligned cube, 12 triangles counter-clockwise seen from outside."""
    corners = [(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    pts = []
    for a, b_, c, d in faces:
        pts += [corners[a], corners[b_], corners[c], corners[a], corners[c], corners[d]]
    return pts


def animated_case():
    # A floor (triangles 0-1), a body cube (2-13) and a head cube (14-25, the body's child), a
    # camera and a light. Animation 0 "move": the body slides (LINEAR, keys at 1 s and 3 s) and
    # turns a quarter about +Y (LINEAR, slerp), the head halves its scale at 2 s (STEP);
    # animation 1 "bounce": the head's translation as a CUBICSPLINE over [0, 1] s.
    b = Builder()
    floor = {"attributes": {"POSITION": b.vec3([(-5, 0, -5), (-5, 0, 5), (5, 0, 5), (5, 0, -5)])},
             "indices": b.indices([0, 1, 2, 0, 2, 3])}
    cube = {"attributes": {"POSITION": b.vec3(cube_points(0.5))}}
    s = math.sqrt(0.5)
    move = {"name": "move", "samplers": [
        {"input": floats(b, [1, 3], "SCALAR"),
         "output": floats(b, [(0, 0.5, 0), (2, 0.5, 0)], "VEC3")},
        {"input": floats(b, [1, 3], "SCALAR"),
         "output": floats(b, [(0, 0, 0, 1), (0, s, 0, s)], "VEC4")},
        {"input": floats(b, [0, 2], "SCALAR"), "interpolation": "STEP",
         "output": floats(b, [(0.5, 0.5, 0.5), (0.25, 0.25, 0.25)], "VEC3")}],
        "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}},
                     {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
                     {"sampler": 2, "target": {"node": 2, "path": "scale"}}]}
    bounce = {"name": "bounce", "samplers": [
        {"input": floats(b, [0, 1], "SCALAR"), "interpolation": "CUBICSPLINE",
         "output": floats(b, [(0, 0, 0), (0, 1, 0), (0, 2, 0), (0, -2, 0), (0, 1, 0), (0, 0, 0)],
                          "VEC3")}],
        "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}]}
    nodes = [
        {"name": "floor", "mesh": 0},
        {"name": "body", "mesh": 1, "translation": [0, 0.5, 0], "children": [2]},
        {"name": "head", "mesh": 1, "translation": [0, 1, 0], "scale": [0.5, 0.5, 0.5]},
        {"name": "camera", "camera": 0, "translation": [0, 1.5, 7]},
        {"name": "light", "translation": [2, 6, 4], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    ]
    d = b.doc(scene=0, scenes=[{"nodes": [0, 1, 3, 4]}], nodes=nodes,
              meshes=[{"primitives": [floor]}, {"primitives": [cube]}],
              cameras=[{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
              extensionsUsed=["KHR_lights_punctual"],
              extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}},
              animations=[move, bounce])
    write_gltf("animated.gltf", d, b.bin)

    two_animations_case()

    # Features a frame at time T cannot honour: a skinned mesh, morph-target weights.
    b, d = simple(TRI, idx=[0, 1, 2])
    d["nodes"] = [{"mesh": 0, "skin": 0}, {"name": "joint", "translation": [0, 1, 0]}]
    d["scenes"] = [{"nodes": [0, 1]}]
    d["skins"] = [{"joints": [1]}]
    d["animations"] = [{"samplers": [{"input": floats(b, [0, 1], "SCALAR"),
                                      "output": floats(b, [(0, 1, 0), (1, 1, 0)], "VEC3")}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}]
    write_gltf("skinned.gltf", b.doc(**{k: v for k, v in d.items() if k not in (
        "asset", "buffers", "bufferViews", "accessors")}), b.bin)
    b, d = simple(TRI, idx=[0, 1, 2])
    d["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": b.vec3([(0, 0, 1)] * 3)}]
    d["meshes"][0]["weights"] = [0]
    d["animations"] = [{"name": "breathe",
                        "samplers": [{"input": floats(b, [0, 1], "SCALAR"),
                                      "output": floats(b, [0, 1], "SCALAR")}],
                        "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
    write_gltf("morph_weights.gltf", b.doc(**{k: v for k, v in d.items() if k not in (
        "asset", "buffers", "bufferViews", "accessors")}), b.bin)

    # A channel of another path without a node (KHR_animation_pointer): refused, not ignored.
    b, d = simple(TRI, idx=[0, 1, 2])
    d["extensionsUsed"] = ["KHR_animation_pointer"]
    d["animations"] = [{"samplers": [{"input": floats(b, [0, 1], "SCALAR"),
                                      "output": floats(b, [(0, 0, 0), (1, 0, 0)], "VEC3")}],
                        "channels": [{"sampler": 0, "target": {
                            "path": "pointer", "extensions": {"KHR_animation_pointer": {
                                "pointer": "/nodes/0/translation"}}}}]}]
    write_gltf("animation_pointer.gltf", b.doc(**{k: v for k, v in d.items() if k not in (
        "asset", "buffers", "bufferViews", "accessors")}), b.bin)

    # Broken: key times that go back.
    b, d = simple(TRI, idx=[0, 1, 2])
    d["animations"] = [{"samplers": [{"input": floats(b, [0, 2, 1], "SCALAR"),
                                      "output": floats(b, [(0, 0, 0)] * 3, "VEC3")}],
                        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}]
    write_gltf("animation_times_back.gltf", b.doc(**{k: v for k, v in d.items() if k not in (
        "asset", "buffers", "bufferViews", "accessors")}), b.bin)


def f32(x):
    """x as the float an accessor stores, then read back (a double, written exactly by json)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def two_animations_case():
    # As exporters from COLLADA write them (the Khronos sample BoxAnimated): one animation per
    # animated node, meant to play together. A floor (triangles 0-1), an outer cube (2-13) and
    # an inner cube (14-25, the outer's child, half size, 1.25 above it). Animation 0 "rise": the
    # outer cube's translation, LINEAR from (0, 0.5, 0) at 0 s to (0, 1.5, 0) at 2 s. Animation 1
    # "spin": the inner cube's rotation about +X, LINEAR from an eighth of a turn (45 degrees) at
    # 1 s to a half turn at 3 s. Played together they span 0 to 3 s.
    b = Builder()
    floor = {"attributes": {"POSITION": b.vec3([(-5, 0, -5), (-5, 0, 5), (5, 0, 5), (5, 0, -5)])},
             "indices": b.indices([0, 1, 2, 0, 2, 3])}
    cube = {"attributes": {"POSITION": b.vec3(cube_points(0.5))}}
    c8, s8 = math.cos(math.pi / 8), math.sin(math.pi / 8)  # 45 degrees: half-angle pi / 8
    rise = {"name": "rise", "samplers": [
        {"input": floats(b, [0, 2], "SCALAR"),
         "output": floats(b, [(0, 0.5, 0), (0, 1.5, 0)], "VEC3")}],
        "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}
    spin = {"name": "spin", "samplers": [
        {"input": floats(b, [1, 3], "SCALAR"),
         "output": floats(b, [(s8, 0, 0, c8), (1, 0, 0, 0)], "VEC4")}],
        "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]}

    def nodes(outer_y, inner_rotation):
        inner = {"name": "inner", "mesh": 1, "translation": [0, 1.25, 0], "scale": [0.5] * 3}
        if inner_rotation:
            inner["rotation"] = inner_rotation
        return [
            {"name": "floor", "mesh": 0},
            {"name": "outer", "mesh": 1, "translation": [0, outer_y, 0], "children": [2]},
            inner,
            {"name": "camera", "camera": 0, "translation": [0, 1.5, 7]},
            {"name": "light", "translation": [2, 6, 4],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ]

    def doc(outer_y, inner_rotation, animations):
        parts = dict(scene=0, scenes=[{"nodes": [0, 1, 3, 4]}], nodes=nodes(outer_y, inner_rotation),
                     meshes=[{"primitives": [floor]}, {"primitives": [cube]}],
                     cameras=[{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
                     extensionsUsed=["KHR_lights_punctual"],
                     extensions={"KHR_lights_punctual": {"lights": [{"type": "point",
                                                                     "intensity": 1}]}})
        if animations:
            parts["animations"] = animations
        return b.doc(**parts)

    write_gltf("two_animations.gltf", doc(0.5, None, [rise, spin]), b.bin)
    # The same scene posed by hand, without animations, at 1 s and at 3 s. At 1 s "rise" is
    # halfway (u = 1/2): 0.5 + (1.5 - 0.5) / 2 = 1.0; "spin" is on its first key, the eighth of a
    # turn as the accessor stores it (floats). At 3 s both are on their last keys: 1.5, a half turn.
    write_gltf("two_animations_at_1s.gltf", doc(1.0, [f32(s8), 0, 0, f32(c8)], None), b.bin)
    write_gltf("two_animations_at_3s.gltf", doc(1.5, [1, 0, 0, 0], None), b.bin)

    # Two animations of one node's translation: alternatives, not parts (a walk and a run).
    b, d = simple(TRI, idx=[0, 1, 2])
    d["animations"] = [{"name": name,
                        "samplers": [{"input": floats(b, [0, 1], "SCALAR"),
                                      "output": floats(b, [(0, 0, 0), (dx, 0, 0)], "VEC3")}],
                        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}
                       for name, dx in (("left", -1), ("right", 1))]
    write_gltf("animations_clash.gltf", b.doc(**{k: v for k, v in d.items() if k not in (
        "asset", "buffers", "bufferViews", "accessors")}), b.bin)


def animated_normals_case():
    # A quad in the plane z = 0 whose file normals lean away from the face normal (+Z), on a node
    # that turns an eighth of a turn about +Z per second while stretching along its own x (scale
    # (1, 1, 1) to (3, 1, 1) over [0, 2] s). A stretch changes normals by the inverse transpose,
    # not by the matrix itself: tests/trace/test_animation_frames.cpp and
    # tests/scene/test_animation.cpp compare the posed normals with ones made by hand.
    b = Builder()
    n = [(-0.6, 0, 0.8), (0.6, 0, 0.8), (0, 0.6, 0.8), (0, -0.6, 0.8)]
    quad = {"attributes": {"POSITION": b.vec3([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]),
                           "NORMAL": b.vec3(n)},
            "indices": b.indices([0, 1, 2, 0, 2, 3])}
    s = math.sqrt(0.5)
    tilt = {"name": "tilt", "samplers": [
        {"input": floats(b, [0, 2], "SCALAR"),
         "output": floats(b, [(0, 0, 0, 1), (0, 0, s, s)], "VEC4")},
        {"input": floats(b, [0, 2], "SCALAR"),
         "output": floats(b, [(1, 1, 1), (3, 1, 1)], "VEC3")}],
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}},
                     {"sampler": 1, "target": {"node": 0, "path": "scale"}}]}
    nodes = [
        {"name": "pane", "mesh": 0},
        {"name": "camera", "camera": 0, "translation": [0, 0, 6]},
        {"name": "light", "translation": [1, 2, 5], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    ]
    d = b.doc(scene=0, scenes=[{"nodes": [0, 1, 2]}], nodes=nodes,
              meshes=[{"primitives": [quad]}],
              cameras=[{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
              extensionsUsed=["KHR_lights_punctual"],
              extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}},
              animations=[tilt])
    write_gltf("animated_normals.gltf", d, b.bin)


if __name__ == "__main__":
    textured_cases()
    triangle_cases()
    hierarchy_case()
    roots_case()
    strip_fan_case()
    index_types_case()
    non_indexed_case()
    quantized_case()
    no_normals_case()
    degenerate_case()
    cameras_case()
    ortho_case()
    lights_case()
    materials_case()
    glass_case()
    modes_case()
    bad_cases()
    animated_case()
    animated_normals_case()
