#!/usr/bin/env bash
# The budget criterion of adaptive sampling (--aa-criterion budget, the default; docs/studies/sampling.md)
# on an H200 through the GL device: warm frames at 256x256 of uniform 16 samples, adaptive 16 by
# the budget and by the image criterion (the default before it), all as dense streams, beside
# the cost model's h200 prediction from the emulator's statistics of the same frame
# (bench/bench_gl.cpp). Prepare here, from the root:
#   cmake --build build --target bench_gl && mkdir -p .h200 && cp build/bench/bench_gl .h200/
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/budget_sampling.sh   (SIZE=64 RUNS=1: the end-to-end check on llvmpipe)
# then copy DIR's JSON files to results/sampling/ and run here:
#   /usr/bin/python3 scripts/docs/sampling.py --h200-budget results/sampling/budget_h200_*.json
# The same frames as scripts/h200/compact_sampling.sh (its options), other modes. (Not textured:
# bench_gl reads glTF images through the image module, libvgpu-image.so with OpenImageIO, which
# the GPU host does not have.)
MODES="spp:16 adaptive:16 adaptive:16:image" PREFIX=budget_h200 \
  exec "$(dirname "$0")/compact_sampling.sh"
