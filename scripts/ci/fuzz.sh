#!/usr/bin/env bash
# Fuzzes the glTF loader: builds tests/fuzz (clang, libFuzzer + ASan + UBSan) in build-fuzz and
# runs it for DURATION seconds (default 60) on a scratch copy of tests/fuzz/corpus, so the
# committed seeds stay as they are. Crash inputs are written to build-fuzz/artifacts/.
# Usage: scripts/ci/fuzz.sh [DURATION]
# With VGPU_FUZZ_BUILD=DIR it uses a build folder configured already with clang and
# -DVGPU_FUZZ=ON (CI's sanitizer build, .ci/run), instead of configuring build-fuzz.
set -euo pipefail

duration=${1:-60}
root=$(cd "$(dirname "$0")/../.." && pwd)
if [ -n "${VGPU_FUZZ_BUILD:-}" ]; then
  build=$(cd "$VGPU_FUZZ_BUILD" && pwd)
else
  build=$root/build-fuzz
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DVGPU_FUZZ=ON -DVGPU_BENCH=OFF \
    -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" -j2 --target fuzz_gltf_loader

corpus=$build/corpus
rm -rf "$corpus"
mkdir -p "$corpus" "$build/artifacts"
cp "$root"/tests/fuzz/corpus/* "$corpus"/
exec "$build/tests/fuzz/fuzz_gltf_loader" -max_total_time="$duration" -timeout=10 \
  -rss_limit_mb=2048 -dict="$root/tests/fuzz/gltf.dict" -artifact_prefix="$build/artifacts/" \
  "$corpus"
