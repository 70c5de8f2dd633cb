#!/bin/bash
# How a frame's cost grows (issue 50, docs/studies/scale.md), on the GPU host: frame time against
# triangles (heightfields of 10k to 4M, made here by scripts/scenes/scale_scenes.py with the
# host's python3) and against pixels (the bunny, 64x64 to 3840x2160), per structure (grid,
# grid2, bvh, kdtree) and walk (multipass, looping): the emulator on 16 threads (SCALE_THREADS)
# and on 1 (multipass), the GL device on the card the host lends, each run's --stats-json kept
# (its predicted_ms gives the modeled gf6600 and h200 frames of the same counters). Also runs on
# a machine without a GPU (the emulator's phases; SCALE_THREADS=2 on two cores).
# Run from the repository's root with build/host/vgpu-rt and .gl carried:
#   scripts/h200/scale.sh PHASE...   PHASE: scenes tris pixels gl-tris gl-pixels
# Writes $out/json/NAME.json (one per run) and $out/runs.csv (name, exit status, wall ms); a
# run that is refused (exit 2) or fails leaves its line with the status.
set -uo pipefail
out=${OUT:-results/scale}
mkdir -p "$out/json"
# The GPU host's GL libraries and clock log (not on a machine without NVIDIA's driver).
if command -v nvidia-smi > /dev/null; then . scripts/h200/env.sh; fi
vgpu=${VGPU_RT:-build/host/vgpu-rt}
scenes=${SCALE_SCENES:-/tmp/scale}
accels=${SCALE_ACCELS:-grid grid2 bvh kdtree}
tris=${SCALE_TRIS:-10k 100k 320k 1M 4M}
sizes=${SCALE_SIZES:-64x64 256x256 1024x1024 1920x1080 3840x2160}
budget_s=${SCALE_BUDGET_S:-540}  # stop starting runs past this many seconds
many=${SCALE_THREADS:-16}         # the many-thread runs' threads (the host's cores)
one=${SCALE_ONE_THREAD:-1}        # 0: no one-thread runs (the memory sweep needs none)
start=$(date +%s)

# run NAME ARGS...: one frame, its statistics as $out/json/NAME.json.
run() {
  local name=$1
  shift
  if (($(date +%s) - start > budget_s)); then
    echo "$name,skipped,0" >> "$out/runs.csv"
    return
  fi
  local s=$(date +%s%N)
  timeout 300 $vgpu render "$@" --stats none --stats-json "$out/json/$name.json" --quiet \
    2> "$out/json/$name.err"
  local rc=$?
  echo "$name,$rc,$((($(date +%s%N) - s) / 1000000))" >> "$out/runs.csv"
  echo "$name: exit $rc, $((($(date +%s%N) - s) / 1000000)) ms"
}

frame="--bounces 0 --shadows off --profile ${SCALE_PROFILE:-h200}"
for phase in "$@"; do
  case $phase in
    scenes)
      python3 scripts/scenes/scale_scenes.py "$scenes" --heightfields "${tris// /,}" \
        --objects 1M
      ;;
    tris)
      for n in $tris; do
        for a in $accels; do
          run "tris-$n-$a-multipass-t$many" "$scenes/heightfield-$n.gltf" --accel $a $frame \
            --size 256x256 --threads $many
          run "tris-$n-$a-looping-t$many" "$scenes/heightfield-$n.gltf" --accel $a $frame \
            --size 256x256 --threads $many --kernels looping
          if ((one)); then
            run "tris-$n-$a-multipass-t1" "$scenes/heightfield-$n.gltf" --accel $a $frame \
              --size 256x256 --threads 1
          fi
        done
      done
      ;;
    pixels)
      for z in $sizes; do
        for a in $accels; do
          run "pixels-$z-$a-multipass-t$many" scenes/bunny.gltf --accel $a $frame --size $z \
            --threads $many
          run "pixels-$z-$a-looping-t$many" scenes/bunny.gltf --accel $a $frame --size $z \
            --threads $many --kernels looping
          if ((one)); then
            run "pixels-$z-$a-multipass-t1" scenes/bunny.gltf --accel $a $frame --size $z \
              --threads 1
          fi
        done
      done
      ;;
    gl-tris)
      for n in $tris; do
        for a in $accels; do
          for k in multipass looping; do
            run "gl-tris-$n-$a-$k" "$scenes/heightfield-$n.gltf" --accel $a $frame \
              --size 256x256 --engine gl --kernels $k
          done
        done
      done
      ;;
    gl-pixels)
      for z in $sizes; do
        for a in $accels; do
          for k in multipass looping; do
            run "gl-pixels-$z-$a-$k" scenes/bunny.gltf --accel $a $frame --size $z --engine gl \
              --kernels $k
          done
        done
      done
      ;;
    *)
      echo "scale.sh: unknown phase '$phase' (scenes tris pixels gl-tris gl-pixels)" >&2
      exit 2
      ;;
  esac
done
