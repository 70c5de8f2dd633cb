#!/usr/bin/env bash
# The H200 measurement of docs/studies/real_gpu.md, as one command for a GPU host that has an NVIDIA
# driver and none of this project's packages. Prepare on a Debian 12 machine:
#   cmake --build build --target bench_gl && mkdir -p .bin && cp build/bench/bench_gl .bin/
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .bin and .gl to the GPU host and run there, from its root:
#   scripts/h200/real_gpu.sh OUTPUT_DIR
# then copy OUTPUT_DIR's real_gpu_CARD.json (CARD: h200 or h100, the card the device gave) and
# gpu_clocks.csv to results/real_gpu/ (the clocks as real_gpu_CARD_clocks.csv) and run here
# (results/real_gpu/README.md has the command with both cards):
#   /usr/bin/python3 scripts/docs/real_gpu.py --reuse --add h200=results/real_gpu/real_gpu_h200.json \
#     --add-variants h200=results/real_gpu/real_gpu_h200_variants.json --add-run h200-run1=results/real_gpu/real_gpu_h200_run1.json
set -euo pipefail
out="${1:?usage: scripts/h200/real_gpu.sh OUTPUT_DIR [all|frames|variants|texture-io]}"
phase="${2:-all}"
cd "$(dirname "$0")/../.."
if [ -d .gl ]; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
nvidia_json=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$nvidia_json" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$nvidia_json"
smi() { command -v nvidia-smi >/dev/null && nvidia-smi "$@" || true; }
# The card the device gave (an H100 or an H200): the files are named after its profile, which
# bench_gl also records as card_profile (vgpu::profile_for_renderer).
case "$(smi --query-gpu=name --format=csv,noheader | head -1)" in
  "NVIDIA H100 80GB HBM3"*) card=h100 ;;
  "NVIDIA H200"*) card=h200 ;;
  *) card=h200 ;;  # no profile was measured on this card: named as the first one was
esac
echo "card: $card"
smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.draw --format=csv \
  > "$out/gpu_before.csv"
# The GPU clock while measured: sampled every 200 ms in the background.
smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu --format=csv -lms 200 \
  > "$out/gpu_clocks.csv" &
sampler=$!
trap 'kill $sampler 2>/dev/null || true' EXIT
if [ "$phase" = all ] || [ "$phase" = frames ]; then
# Frames with both read-back waits (the emulator's counts and the predictions are the same on
# every machine: scripts/docs/real_gpu.py computes them here with --readback-wait none).
.bin/bench_gl --runs 5 --sizes 256 1024 --threads 16 --no-stream --readback-wait both --grid 15 \
  --scenes scenes/sphere-alone.gltf scenes/bunny.gltf scenes/bunny-mirror.gltf \
  --json "$out/real_gpu_$card.json" 2>&1 | tee "$out/bench_gl.log"
# NVIDIA's driver reads __GL_YIELD for how a waiting thread yields; NOTHING never yields.
__GL_YIELD=NOTHING .bin/bench_gl --runs 5 --sizes 256 --no-stream --readback-wait block --grid 15 \
  --micro-passes 50 --scenes scenes/bunny.gltf --json "$out/real_gpu_${card}_yield.json" 2>&1 |
  tee "$out/bench_gl_yield.log"
fi
# The paper's future work executed on the GPU: MRT fused passes and the looping kernels beside
# the multipass pipeline, polled read-backs (real_gpu.py: --variants).
if [ "$phase" = all ] || [ "$phase" = variants ]; then
  .bin/bench_gl --runs 5 --sizes 256 1024 --threads 16 --no-stream --readback-wait poll \
    --variants multipass mrt looping --micro-passes 50 --grid 15 \
    --scenes scenes/sphere-alone.gltf scenes/bunny.gltf scenes/bunny-mirror.gltf \
    --json "$out/real_gpu_${card}_variants.json" 2>&1 | tee "$out/bench_gl_variants.log"
fi
# Texture work outside passes (clears, read-backs of a frame's image to the host), for the cost
# model's download term; the fixed costs again beside them.
if [ "$phase" = all ] || [ "$phase" = texture-io ]; then
  .bin/bench_gl --runs 5 --micro-passes 50 --no-frames --readback-wait block \
    --json "$out/real_gpu_${card}_texture_io.json" 2>&1 | tee "$out/bench_gl_texture_io.log"
fi
