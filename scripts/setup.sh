#!/usr/bin/env bash
# Installs everything vgpu-rt needs on a fresh Debian 12 machine (run as root or with sudo).
# EGL, glvnd's libOpenGL and Mesa (llvmpipe) are for the GL device (--engine gl) and its tests;
# pybind11 and NumPy for the Python module (python/), nbclient and ipykernel for its notebooks.
# Idempotent: skips apt when every package is already present.
set -euo pipefail
pkgs=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libopenimageio-dev openimageio-tools libtinygltf-dev libstb-dev nlohmann-json3-dev
  doctest-dev libbenchmark-dev libcli11-dev libmeshoptimizer-dev
  clang libclang-rt-14-dev clang-format  # clang: the fuzzer and the sanitizer build (.ci/run)
  python3-matplotlib
  pybind11-dev python3-dev python3-numpy python3-nbclient python3-nbformat python3-ipykernel
  libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
  zlib1g-dev ccache
  help2man dpkg-dev python3-venv python3-pip python3-wheel python3-setuptools  # installing (README)
  chromium
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# node and npm for the report's JS (below): Debian's, unless some node is installed already.
command -v npm >/dev/null || missing+=(nodejs npm)
if ((${#missing[@]})); then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "setup: installing ${missing[*]}" >&2
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The HTML report's vendored JS (host/report/package-lock.json): Chart.js, embedded into every
# report by the build, and playwright-core, which drives chromium in the report's browser test.
report_dir="$(dirname "$0")/../host/report"
if [ ! -f "$report_dir/node_modules/chart.js/dist/chart.umd.js" ] || [ ! -d "$report_dir/node_modules/playwright-core" ]; then
  echo "setup: npm ci in host/report" >&2
  (cd "$report_dir" && npm ci --no-audit --no-fund --loglevel=error)
fi
