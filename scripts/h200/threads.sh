#!/bin/bash
# The emulator's thread scaling on the GPU host's 16 CPU cores (issue 50; no GPU needed):
# bench_threads on bunny-refl at 1024x1024, walks in batches (the default) and pass by pass,
# 1 to 16 threads, and the command line's own frame at 1 and 16 threads. Run from the
# repository's root with build/bench/bench_threads and build/host/vgpu-rt carried; writes
# $out/threads.txt. Figures in docs/studies/speed.md ("Threads").
set -euo pipefail
out=${OUT:-results/threads}
mkdir -p "$out"
{
  echo "# $(nproc) CPUs: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
  echo "## walks in batches"
  build/bench/bench_threads --scene scenes/bunny-refl.gltf --size 1024x1024 \
    --threads 1,2,4,8,12,16 --reps 3 2> /dev/null
  echo "## walks pass by pass"
  build/bench/bench_threads --scene scenes/bunny-refl.gltf --size 1024x1024 \
    --threads 1,2,4,8,16 --reps 1 --render-option=--walk --render-option=passes 2> /dev/null
  echo "## the command line, wall time of the process (no image written)"
  for t in 1 16 1 16; do
    s=$(date +%s%N)
    build/host/vgpu-rt render scenes/bunny-refl.gltf --size 1024x1024 --threads $t --quiet |
      grep '^initialization'
    echo "threads $t: wall $(((($(date +%s%N) - s) / 1000000))) ms"
  done
} | tee "$out/threads.txt"
