#!/usr/bin/env bash
# The H200 measurement of docs/real_gpu.md, as one command for a GPU host that has a driver and
# nothing of this project's packages (the workplace's device machine). Prepare here:
#   cmake --build build --target bench_gl && mkdir -p .bin && cp build/bench/bench_gl .bin/
#   (and the glvnd GL/EGL .deb files in .gl/, as the device notes say)
# then run there, from the repository root, carrying .bin and .gl:
#   scripts/h200_bench.sh "$OUT"
# and here:  /usr/bin/python3 scripts/real_gpu.py --reuse --add h200=docs/real_gpu_h200.json
set -euo pipefail
out="${1:?usage: scripts/h200_bench.sh OUTPUT_DIR}"
cd "$(dirname "$0")/.."
if [ -d .gl ]; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
nvidia_json=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$nvidia_json" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$nvidia_json"
smi() { command -v nvidia-smi >/dev/null && nvidia-smi "$@" || true; }
smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.draw --format=csv \
  > "$out/gpu_before.csv"
# The GPU clock while measured: sampled every 200 ms in the background.
smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu --format=csv -lms 200 \
  > "$out/gpu_clocks.csv" &
sampler=$!
trap 'kill $sampler 2>/dev/null || true' EXIT
.bin/bench_gl --runs 5 --sizes 256 1024 --threads 16 \
  --scenes scenes/sphere-alone.gltf scenes/bunny.gltf scenes/bunny-mirror.gltf \
  --json "$out/real_gpu_h200.json" 2>&1 | tee "$out/bench_gl.log"
