#!/usr/bin/env bash
# Sampling that saves time (issue 35, docs/studies/sampling.md) on an H200 through the GL device: warm
# frames at 256x256 of the one-ray frame, uniform 16 samples, and adaptive 16 and undersampling
# (K = 2) as dense streams and as the gated frames of before (":gated", --compact off), beside
# the cost model's h200 prediction from the emulator's statistics of the same frame
# (bench/bench_gl.cpp). Prepare here, from the root:
#   cmake --build build --target bench_gl && mkdir -p .h200 && cp build/bench/bench_gl .h200/
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/compact_sampling.sh   (SIZE=64 RUNS=1: the end-to-end check on llvmpipe)
# then copy DIR's JSON files to results/sampling/ and run here:
#   /usr/bin/python3 scripts/docs/sampling.py --h200-compact results/sampling/compact_h200_*.json
set -u
out="${OUT:?set OUT to a folder}"
size="${SIZE:-256}"
runs="${RUNS:-5}"
h200="${H200:-.h200}"
. scripts/h200/env.sh
# The CLI's defaults (2 bounces, Phong, shadows), the paper's grid and multipass kernels.
common="--runs $runs --sizes $size --threads 16 --readback-wait poll --grid auto --no-fixed"
common="$common --shadows --bounces 2 --variants multipass --warmup-ms 2000"
# MODES and PREFIX: other modes into other files (scripts/h200/budget_sampling.sh).
modes="${MODES:-spp:1 spp:16 adaptive:16 adaptive:16:gated undersample:2 undersample:2:gated}"
for scene in classic bunny; do
  "$h200/bench_gl" $common --sampling $modes --scenes "scenes/$scene.gltf" \
    --json "$out/${PREFIX:-compact_h200}_$scene.json"
done
