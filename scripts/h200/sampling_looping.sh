#!/usr/bin/env bash
# The sampling modes' looping frames on an H200 again (docs/studies/sampling.md's H200 section): the
# undersample:2 looping frames of scripts/h200/streams_sampling.sh ran 3-5x slower per pass after
# the GPU idled; here every configuration's GL frames run --warmup-ms of frames before timing,
# beside a control run without (as that script), and the SM clock is logged every 100 ms.
# Prepare .h200/ and .gl/ as scripts/h200/streams_sampling.sh says, copy the repository with them
# to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/sampling_looping.sh   (SIZE=64 SCENES=classic WARMUP=200: the end-to-end
#                                               check on llvmpipe; H200=DIR: bench_gl is in DIR)
# then copy DIR's files to results/sampling/ (sampling_h200_looping*.json, clocks.csv to
# results/sampling/sampling_h200_looping_clocks.csv) and run here:
#   /usr/bin/python3 scripts/docs/sampling.py --h200 results/sampling/sampling_h200.json \
#     results/sampling/sampling_h200_bunny.json --h200-looping results/sampling/sampling_h200_looping.json \
#     results/sampling/sampling_h200_looping_bunny.json --h200-looping-control \
#     results/sampling/sampling_h200_looping_nowarm.json results/sampling/sampling_h200_looping_nowarm_bunny.json
set -u
out="${OUT:?set OUT to a folder}"
size="${SIZE:-256}"
runs="${RUNS:-5}"
warmup="${WARMUP:-2000}"
scenes="${SCENES:-classic bunny}"
h200="${H200:-.h200}"
# The GL libraries, EGL and the SM clock every 100 ms.
CLOCK_MS=100 . scripts/h200/env.sh
# scripts/h200/streams_sampling.sh's options, looping frames only.
common="--runs $runs --sizes $size --threads 16 --readback-wait poll --grid auto --no-fixed"
common="$common --shadows --bounces 2 --variants looping"
common="$common --sampling spp:1 spp:4 adaptive:16 undersample:2"
# Each scene a call of its own (bunny's looping triangle lists are past llvmpipe's 16,384 texels):
# first the control without warm-up, then the warmed frames.
for s in $scenes; do
  suffix=$([ "$s" = classic ] || echo "_$s")
  "$h200/bench_gl" $common --warmup-ms 0 --scenes "scenes/$s.gltf" \
    --json "$out/sampling_h200_looping_nowarm$suffix.json"
  "$h200/bench_gl" $common --warmup-ms "$warmup" --scenes "scenes/$s.gltf" \
    --json "$out/sampling_h200_looping$suffix.json"
done
