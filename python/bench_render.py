"""A frame's time through Python (vgpu_rt.render) beside the library call it wraps (cli::run_render,
timed in C++ in the same process), and reading a 256x256 texture as an array.

    PYTHONPATH=build/python /usr/bin/python3 python/bench_render.py [--scene bunny] [--size 256x256]

Python adds turning the keyword arguments into the command line's, the statistics' JSON text
into a dict and the image's buffers into arrays (no copies). Each figure is the median of
--repeats runs, the two interleaved so that the machine's load falls on both alike.
"""

import argparse
import statistics
import time

import numpy as np

import vgpu_rt


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="bunny")
    ap.add_argument("--size", default="256x256")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    options = dict(size=a.size)
    args = vgpu_rt._arguments(a.scene, options)
    vgpu_rt.render(a.scene, **options)  # warm: the scene file, the programs' first recordings
    py_ms, lib_ms = [], []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        vgpu_rt.render(a.scene, **options)
        py_ms.append(1e3 * (time.perf_counter() - t0))
        lib_ms.append(vgpu_rt._ext.library_render_ms(args))
    py, lib = statistics.median(py_ms), statistics.median(lib_ms)
    print(f"{a.scene} {a.size}, median of {a.repeats}:")
    print(f"  library call (cli::run_render, C++): {lib:8.1f} ms")
    print(f"  vgpu_rt.render (Python):             {py:8.1f} ms  ({100 * (py / lib - 1):+.1f}%)")
    t = vgpu_rt.Device("gf5700").texture("t", 256, 256, 4)
    reads = 10000
    t0 = time.perf_counter()
    for _ in range(reads):
        view = t.array
    us = 1e6 * (time.perf_counter() - t0) / reads
    print(f"  a 256x256x4 fp32 texture as an array: {us:.2f} us, owns its data: "
          f"{view.flags['OWNDATA']} (no copy of its {t.width * t.height * 16} bytes)")
    assert isinstance(view, np.ndarray)


if __name__ == "__main__":
    main()
