# Sourced by the H200 measurement scripts (scripts/h200/*.sh) on the GPU host, from the
# repository's root, after `out` is set: installs the carried glvnd GL libraries (.gl/*.deb,
# the device has no Debian packages), points EGL at NVIDIA's vendor file, and logs the SM clock
# to $out/clocks.csv in the background every CLOCK_MS ms (default 500; 500 where nvidia-smi
# refuses a shorter interval), stopped when the script exits.
if [ -d .gl ]; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
j=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$j" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$j"
if command -v nvidia-smi > /dev/null; then
  q=timestamp,clocks.sm,clocks.mem,utilization.gpu
  nvidia-smi --query-gpu=$q --format=csv -lms "${CLOCK_MS:-500}" > "$out/clocks.csv" &
  sampler=$!
  sleep 1
  if ! kill -0 $sampler 2> /dev/null; then
    nvidia-smi --query-gpu=$q --format=csv -lms 500 > "$out/clocks.csv" &
    sampler=$!
  fi
  trap 'kill $sampler 2>/dev/null || true' EXIT
fi
