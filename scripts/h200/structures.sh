#!/usr/bin/env bash
# The structures on an H200 through the GL device (docs/studies/structures.md). Prepare here (Debian 12),
# from the repository root:
#   cmake --build build --target bench_gl && mkdir -p .h200 && cp build/bench/bench_gl .h200/
#   scripts/scenes/uneven_scenes.py .h200
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/structures.sh              (ACCELS="grid2" measures only those structures)
#   OUT=DIR SIZES=1 scripts/h200/structures.sh      (the same frames at 8x8 to 512x512 instead:
#                                                    what grows with the image, docs/studies/structures.md)
#   OUT=DIR PROGRAMS=1 scripts/h200/structures.sh   (the looping traversal kernels' compiled
#                                   assembly: results/structures/h200_programs/*.nvfp, --h200-programs)
#   OUT=DIR LOOPING=1 CLOCK_MS=100 scripts/h200/structures.sh   (the looping walks again, each
#                                   warmed up WARMUP ms: results/structures/structures_h200_looping_warm.json,
#                                   read by scripts/docs/structures.py --h200-looping; RUNS=15 times
#                                   15 frames each instead of 5: results/structures/structures_h200_looping_warm2.json,
#                                   read by --h200-looping-again)
#   OUT=DIR CLOCK_MS=100 LATENCY=1 scripts/h200/structures.sh   (one fragment's fetch and
#                                   operation latencies, bench_gl --latency: the h200 profile's
#                                   fetch_latency_clocks and operation_latency_clocks, from
#                                   results/structures/structures_h200_latency.json, --h200-latency)
#   OUT=DIR GRID_SIZES=1 scripts/h200/structures.sh   (the grid's looping walk at 8x8, 64x64 and
#                                   512x512: results/structures/structures_h200_sizes_looping_grid.json,
#                                   --h200-sizes-grid)
# then copy DIR's files to results/structures/structures_h200_{primary,full}.json and _clocks.csv, and run here:
#   /usr/bin/python3 scripts/docs/structures.py --h200 results/structures/structures_h200_primary.json \
#     results/structures/structures_h200_full.json
# (with SIZES=1: results/structures/structures_h200_sizes_{looping,multipass}.json and _clocks.csv, read by
# scripts/docs/structures.py --h200-sizes)
set -u
accels="${ACCELS:-grid grid2 bvh kdtree}"
out="${OUT:?set OUT to a folder}"
# The GL libraries, EGL and the SM clock every 500 ms.
. scripts/h200/env.sh
S="scenes/sphere.gltf scenes/bunny.gltf scenes/bunny-refl.gltf scenes/classic.gltf"
S="$S scenes/teapot.gltf .h200/stadium.gltf .h200/scales.gltf"
if [ -n "${SIZES:-}" ]; then
  # Looping walks from 8x8 (a frame of little more than its fixed costs) to 512x512, and
  # multipass frames at 8x8 and 64x64: one constant per frame stays, a cost per pixel grows.
  .h200/bench_gl --runs 5 --sizes 8 64 256 512 --threads 16 --readback-wait poll --grid auto \
    --accel grid2 bvh kdtree --variants looping --bounces 0 --micro-passes 20 --scenes $S \
    --json "$out/structures_sizes_looping.json"
  .h200/bench_gl --runs 3 --sizes 8 64 --threads 16 --readback-wait poll --grid auto \
    --accel grid2 bvh --variants multipass --bounces 0 --micro-passes 10 \
    --scenes scenes/bunny.gltf scenes/classic.gltf scenes/teapot.gltf \
    --json "$out/structures_sizes_multipass.json"
  exit 0
fi
if [ -n "${LATENCY:-}" ]; then
  .h200/bench_gl --latency --no-fixed --no-frames --runs 9 --warmup-ms 1000 \
    --readback-wait poll --json "$out/structures_latency.json"
  exit 0
fi
if [ -n "${GRID_SIZES:-}" ]; then
  .h200/bench_gl --runs 5 --sizes 8 64 512 --threads 16 --readback-wait poll --grid auto \
    --accel grid --variants looping --bounces 0 --no-fixed --warmup-ms 500 --scenes $S \
    --json "$out/structures_sizes_looping_grid.json"
  exit 0
fi
if [ -n "${PROGRAMS:-}" ]; then
  # The looping traversal kernels as the driver compiled them: bench_gl --dump-programs writes
  # each program's binary, whose NV_gpu_program5 assembly is text (results/structures/h200_programs/*.nvfp,
  # read by scripts/docs/structures.py --h200-programs).
  d=$(mktemp -d)
  .h200/bench_gl --runs 1 --sizes 64 --readback-wait poll --grid auto --accel grid grid2 bvh \
    kdtree --variants looping --bounces 0 --no-fixed --no-stream --scenes scenes/bunny.gltf \
    --dump-programs "$d"
  for a in grid grid2 bvh kdtree; do
    f=$(ls "$d/bunny_${a}_looping/"*looping_traversal.bin)
    strings -n 3 "$f" | sed -n '/^!!NVfp5.0/,/^END$/p' > "$out/${a}_looping_traversal.nvfp"
  done
  exit 0
fi
if [ -n "${LOOPING:-}" ]; then
  # The looping walks' primary frames again, each configuration's GL frames warmed up for
  # WARMUP ms (default 2000) before timing: a GPU idle while the emulator runs lowers its clock
  # (docs/studies/sampling.md's H200 section). results/structures/structures_h200_looping_warm.json and _clocks.csv,
  # read by scripts/docs/structures.py --h200-looping.
  # RUNS (default 5) timed frames each; the JSON keeps every frame's wall and GPU time.
  .h200/bench_gl --runs "${RUNS:-5}" --sizes 256 --threads 16 --readback-wait poll --grid auto \
    --accel $accels --variants looping --bounces 0 --no-fixed --warmup-ms "${WARMUP:-2000}" \
    --scenes $S --json "$out/structures_looping_warm.json"
  exit 0
fi
.h200/bench_gl --runs 3 --sizes 256 --threads 16 --readback-wait poll --grid auto \
  --accel $accels --variants multipass looping --bounces 0 --scenes $S \
  --json "$out/structures_primary.json"
.h200/bench_gl --runs 3 --sizes 256 --threads 16 --readback-wait poll --grid auto \
  --accel $accels --variants multipass --bounces 2 --micro-passes 10 --scenes $S \
  --json "$out/structures_full.json"
