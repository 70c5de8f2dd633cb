#!/usr/bin/env bash
# Shadow rays that end at the light (docs/studies/groups.md, "Shadow rays end at the light") on an H200
# through the GL device: classic and hop with the light moved among the objects
# (scripts/scenes/lamp_scenes.py), 256x256, primary and shadow rays (--bounces 0 --shadows), the
# uniform and the two-level grid (--grid auto), multipass and looping kernels; each frame warm
# (WARMUP ms of frames of the same configuration before timing), the median of RUNS timed frames,
# beside the cost model's h200 prediction from the emulator's statistics of the same frame. Two
# builds of bench_gl: the one before the change (walks on to the grid's face) and after. Prepare
# here, from the repository root:
#   scripts/scenes/lamp_scenes.py .h200/scenes
#   cmake --build build --target bench_gl && cp build/bench/bench_gl .h200/
#   cp BUILD_BEFORE/bench/bench_gl .h200/bench_gl_before   (the tree before the change)
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/shadow_tmax.sh   (SIZE=32 RUNS=1 WARMUP=0: the end-to-end check)
# then copy DIR's files to results/shadows/ (shadow_tmax_h200_{before,after}_SCENE.json,
# clocks.csv).
set -u
out="${OUT:?set OUT to a folder}"
size="${SIZE:-256}"
runs="${RUNS:-5}"
h200="${H200:-.h200}"
mkdir -p "$out"
. scripts/h200/env.sh
common="--runs $runs --sizes $size --threads 16 --readback-wait poll --grid auto --no-fixed"
common="$common --accel grid grid2 --variants multipass looping --bounces 0 --shadows"
common="$common --warmup-ms ${WARMUP:-2000}"
status=0
for scene in ${SCENES:-classic-lamp hop-lamp}; do
  for build in before after; do
    bin="$h200/bench_gl"
    [ "$build" = before ] && bin="$h200/bench_gl_before"
    "$bin" $common --scenes "$h200/scenes/$scene.gltf" \
      --json "$out/shadow_tmax_h200_${build}_$scene.json" || status=1
  done
done
exit $status
