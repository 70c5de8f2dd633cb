#!/bin/bash
# Primary hits of the scale issue's large scenes (issue 50) on every structure, against the CPU
# tracer's: for each scene (default: the 1M and 4M heightfields and the 1M-triangle scene of many
# objects, written by scripts/scenes/scale_scenes.py into SCENES) and each structure, the
# emulator's frame on the h200 profile (--addressing auto: (x, y) where a linear index outgrows
# fp32) and the CPU tracer's, as hit-id AOVs, compared pixel by pixel (vgpu-rt compare at
# threshold 0: a differing pixel hit another triangle). Prints one line per frame: the
# structure's addressing, its texture bytes, the render and the differing pixels.
#   scripts/scenes/scale_hits.sh SCENES [SIZE] [SCENE...]      e.g. /tmp/scale 128x128
set -uo pipefail
dir=${1:?usage: scale_hits.sh SCENES [SIZE] [SCENE...]}
size=${2:-128x128}
shift $(($# < 2 ? $# : 2))
scenes=${*:-heightfield-1M heightfield-4M objects-1M}
vgpu=${VGPU_RT:-build/host/vgpu-rt}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
frame="--size $size --bounces 0 --shadows off --profile h200 --quiet --stats none"
for s in $scenes; do
  f="$dir/$s.gltf"
  $vgpu render "$f" $frame --engine cpu --aov "hit=$tmp/cpu.exr" || {
    echo "$s: the CPU tracer failed"
    continue
  }
  for a in grid grid2 bvh kdtree; do
    t0=$(date +%s%N)
    if ! $vgpu render "$f" $frame --accel $a --aov "hit=$tmp/$a.exr" --stats-json "$tmp/$a.json" \
      2> "$tmp/$a.err"; then
      echo "$s $a: refused: $(cat "$tmp/$a.err")"
      continue
    fi
    ms=$((($(date +%s%N) - t0) / 1000000))
    info=$(/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); \
print(j['accel']['addressing'], j['texture_bytes'], round(j['render_ms']), j['rays_traced'])" \
      "$tmp/$a.json")
    read -r addressing bytes render rays <<< "$info"
    diff=$($vgpu compare "$tmp/cpu.exr" "$tmp/$a.exr" --threshold 0 | head -1)
    echo "$s $a: addressing $addressing, texture bytes $bytes, rays $rays, render $render ms" \
      "(process $ms ms); against the CPU tracer: $diff"
  done
done
