"""Reads the OpenEXR files vgpu-rt writes (--out x.exr, --aov NAME=x.exr), for the tests that
compare them with the Python module's arrays bit for bit, without an OpenEXR module: scanline
files of 32-bit float channels, stored uncompressed or with ZIP (16 lines a block) or ZIPS (1)
compression, which is what OpenImageIO writes by default. Anything else raises ValueError.
"""

import struct
import zlib

import numpy as np

_LINES_PER_BLOCK = {0: 1, 2: 1, 3: 16}  # NO_COMPRESSION, ZIPS_COMPRESSION, ZIP_COMPRESSION
_FLOAT = 2  # the pixel type of a 32-bit float channel


def _unzip(raw, size):
    """A ZIP block's bytes: inflated, the predictor undone (each byte the sum of the differences
    before it, less 128 each), then the two halves interleaved back (even bytes first)."""
    t = np.frombuffer(zlib.decompress(raw), np.uint8).astype(np.int64)
    if t.size != size:
        raise ValueError(f"a block inflates to {t.size} bytes, not {size}")
    d = t.copy()
    d[1:] -= 128
    t = (np.cumsum(d) & 0xFF).astype(np.uint8)
    out = np.empty_like(t)
    half = (t.size + 1) // 2
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def read(path):
    """The file's channels by name, each a (height, width) float32 array, row 0 at the top."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    if data[5] & 0x02:  # the version's flags: tiled
        raise ValueError(f"{path}: tiled, not scanline")
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        attrs[data[pos:name_end].decode()] = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    pos += 1
    channels, chlist, p = [], attrs["channels"], 0
    while chlist[p] != 0:
        end = chlist.index(b"\0", p)
        (pixel_type,) = struct.unpack_from("<i", chlist, end + 1)
        if pixel_type != _FLOAT:
            raise ValueError(f"{path}: channel {chlist[p:end].decode()} is not 32-bit float")
        channels.append(chlist[p:end].decode())
        p = end + 1 + 16  # type, linearity and reserved bytes, x and y sampling
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    compression = attrs["compression"][0]
    if compression not in _LINES_PER_BLOCK:
        raise ValueError(f"{path}: compression {compression} is not read here")
    lines = _LINES_PER_BLOCK[compression]
    blocks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{blocks}Q", data, pos)
    # Per line, the channels in the file's (alphabetical) order, each a run of `width` floats.
    out = np.zeros((height, len(channels), width), np.float32)
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        n = min(lines, y1 + 1 - y)
        full = n * len(channels) * width * 4
        raw = data[offset + 8:offset + 8 + size]
        if compression != 0 and size < full:  # a block that would not shrink is stored as it is
            raw = _unzip(raw, full)
        out[y - y0:y - y0 + n] = np.frombuffer(raw, "<f4").reshape(n, len(channels), width)
    return {name: out[:, i, :] for i, name in enumerate(channels)}
