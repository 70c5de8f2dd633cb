#!/usr/bin/env bash
# The structures on an H200 through the GL device (docs/structures.md): every scene x structure x
# rays x kernels, 3 runs each. Prepare here (Debian 12), from the repository root:
#   cmake --build build --target vgpu-rt && mkdir -p .h200 && cp build/host/vgpu-rt .h200/
#   scripts/uneven_scenes.py .h200
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/structures_h200.sh
# then here: /usr/bin/python3 scripts/structures.py --h200-runs DIR/r (it writes
# docs/structures_h200.json from the runs and the document from it).
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
j=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$j" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$j"
mkdir -p "$OUT/r"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv > "$OUT/r/gpu.csv" 2>&1
.h200/vgpu-rt gl-devices > "$OUT/r/devices.txt" 2>&1
for s in sphere bunny bunny-refl classic teapot .h200/stadium.gltf .h200/scales.gltf; do
  n=$(basename "$s" .gltf)
  for acc in grid bvh kdtree; do
    for mode in primary full looping; do
      case $mode in
        primary) o="--bounces 0 --shadows off";;
        full) o="";;
        looping) o="--bounces 0 --shadows off --kernels looping";;
      esac
      for r in 1 2 3; do
        timeout 120 .h200/vgpu-rt render "$s" --engine gl --profile h200 --accel $acc $o \
          --gl-readback poll --threads 16 --stats none -q \
          --stats-json "$OUT/r/${n}_${acc}_${mode}_r$r.json" 2>>"$OUT/r/errors.txt" ||
          echo "$n $acc $mode $r failed: $?" >> "$OUT/r/errors.txt"
      done
      echo "$n $acc $mode done $(date +%T)"
    done
  done
done

