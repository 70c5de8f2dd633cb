#!/usr/bin/env bash
# Beams over tiles (issue 35, docs/studies/groups.md) on an H200 through the GL device: bunny, classic
# and hop at 256x256, primary rays alone (--bounces 0, no shadows), the uniform grid (--grid
# auto, as the CLI builds it), the paper's multipass kernels, beams off and on; each frame warm
# (frames of the same configuration for WARMUP ms before timing: a GPU left idle lowers its
# clock), the median of RUNS timed frames (default 5), beside the cost model's h200 prediction
# from the emulator's statistics of the same frame (bench/bench_gl.cpp). Prepare here, from the
# repository root:
#   cmake --build build --target bench_gl && mkdir -p .h200 && cp build/bench/bench_gl .h200/
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/beams.sh       (SIZE=32 RUNS=1 WARMUP=0: the end-to-end check on llvmpipe)
# (ACCEL=kdtree, bvh or grid2: through that structure instead, into beams_h200_ACCEL_SCENE.json;
#  VARIANT=looping: the looping kernels, into beams_h200_[ACCEL_]looping_SCENE.json)
# then copy DIR's files to results/beams/ (beams_h200_SCENE.json and clocks.csv).
set -u
out="${OUT:?set OUT to a folder}"
size="${SIZE:-256}"
runs="${RUNS:-5}"
h200="${H200:-.h200}"
mkdir -p "$out"
# The GL libraries, EGL and the SM clock every 500 ms.
. scripts/h200/env.sh
common="--runs $runs --sizes $size --threads 16 --readback-wait poll --grid auto --no-fixed"
accel="${ACCEL:-grid}"
variant="${VARIANT:-multipass}"
tag=""
[ "$accel" = grid ] || tag="${accel}_"
[ "$variant" = multipass ] || tag="${tag}${variant}_"
common="$common --accel $accel --variants $variant --bounces 0 --warmup-ms ${WARMUP:-2000}"
status=0
for scene in ${SCENES:-bunny classic hop}; do
  "$h200/bench_gl" $common --beams off on --scenes "scenes/$scene.gltf" \
    --json "$out/beams_h200_$tag$scene.json" || status=1
done
exit $status
