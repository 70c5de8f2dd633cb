#!/usr/bin/env python3
"""Peak memory of a textured render: the textured quad of tests/data/gltf/textured.gltf with its
base colour replaced by a generated WxW PNG (2048 and 4096 by default), rendered at 64x64 on the
gf6600 and h200 profiles. Prints each run's exit status, wall time and peak resident set size
(getrusage's ru_maxrss of the child, through os.wait4). The PNGs are written to a temporary
directory and removed at the end.

  python3 scripts/bench_texture_memory.py build/host/vgpu-rt [--sizes 2048,4096] [-- extra args]
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def png(side):
    """An RGB PNG, side x side: red rises left to right, green top to bottom, blue 64-texel
    checks (rows built as bytes, so a 4096 image takes a second)."""
    def row(y):
        check = bytes(((x // 64 + y // 64) % 2) * 255 for x in range(side))
        red = bytes(x * 255 // side for x in range(side))
        out = bytearray(3 * side + 1)
        out[1::3], out[2::3], out[3::3] = red, bytes([y * 255 // side]) * side, check
        return bytes(out)
    raw = b"".join(row(y) for y in range(side))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", side, side, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("vgpu_rt")
    ap.add_argument("--sizes", default="2048,4096")
    ap.add_argument("--profiles", default="gf6600,h200")
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="vgpu_texmem_") as tmp:
        with open(os.path.join(ROOT, "tests/data/gltf/textured.gltf")) as f:
            doc = json.load(f)
        print("texture  profile  exit  seconds  peak RSS MiB")
        for side in [int(s) for s in a.sizes.split(",")]:
            with open(os.path.join(tmp, f"tex{side}.png"), "wb") as f:
                f.write(png(side))
            doc["images"][0] = {"uri": f"tex{side}.png"}
            scene = os.path.join(tmp, f"tex{side}.gltf")
            with open(scene, "w") as f:
                json.dump(doc, f)
            for profile in a.profiles.split(","):
                cmd = [a.vgpu_rt, "render", scene, "-q", "--stats", "none", "--size", "64x64",
                       "--profile", profile, "--out", os.path.join(tmp, "out.png")] + a.extra
                t0 = time.time()
                p = subprocess.Popen(cmd, stderr=subprocess.PIPE)
                _, status, usage = os.wait4(p.pid, 0)
                err = p.stderr.read().decode().strip()
                p.stderr.close()
                print(f"{side}x{side}  {profile:7s}  {os.waitstatus_to_exitcode(status):4d}  "
                      f"{time.time() - t0:7.2f}  {usage.ru_maxrss / 1024:10.0f}")
                if err:
                    print("    " + err.replace("\n", "\n    "))
    return 0


if __name__ == "__main__":
    sys.exit(main())
