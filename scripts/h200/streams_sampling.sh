#!/usr/bin/env bash
# Glass's ray streams and the sampling modes on an H200 through the GL device (docs/studies/materials.md,
# docs/studies/sampling.md): warm frames at 256x256 beside the cost model's h200 prediction from the
# emulator's statistics of the same frame (bench/bench_gl.cpp). Prepare here, from the root:
#   cmake --build build --target bench_gl && mkdir -p .h200 && cp build/bench/bench_gl .h200/
#   /usr/bin/python3 scripts/docs/materials.py --opaque-copy .h200/glass-opaque.gltf
#   mkdir -p .gl && (cd .gl && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0)
# copy the repository with .h200 and .gl to the GPU host and run there, from its root:
#   OUT=DIR scripts/h200/streams_sampling.sh     (SIZE=64 RUNS=1: the end-to-end check on llvmpipe;
#                                                  H200=DIR: bench_gl and the copy are in DIR)
# then copy DIR's JSON files to results/materials/ and results/sampling/ (clocks.csv to results/sampling/streams_sampling_h200_clocks.csv) and
# run here:
#   /usr/bin/python3 scripts/docs/materials.py --h200 results/materials/materials_h200_glass.json \
#     results/materials/materials_h200_streams.json
#   /usr/bin/python3 scripts/docs/sampling.py --h200 results/sampling/sampling_h200.json \
#     results/sampling/sampling_h200_bunny.json
set -u
out="${OUT:?set OUT to a folder}"
size="${SIZE:-256}"
runs="${RUNS:-5}"
h200="${H200:-.h200}"
# The GL libraries, EGL and the SM clock every 500 ms.
. scripts/h200/env.sh
# The CLI's defaults (2 bounces, Phong, shadows), the paper's grid (auto resolution); multipass
# frames run the paper's kernels on gf5700, looping frames the looping walk on h200.
common="--runs $runs --sizes $size --threads 16 --readback-wait poll --grid auto --no-fixed"
common="$common --shadows --bounces 2 --variants multipass looping"
# Glass (always ray streams) and its opaque copy (every transmissionFactor 0: the paper's frame).
"$h200/bench_gl" $common --scenes scenes/glass.gltf "$h200/glass-opaque.gltf" \
  --json "$out/materials_h200_glass.json"
# The paper's reflections with and without the streams.
"$h200/bench_gl" $common --ray-streams off on --scenes scenes/bunny-refl.gltf \
  --json "$out/materials_h200_streams.json"
# The sampling modes against one ray per pixel, on classic and (a call of its own: its looping
# grid's triangle lists are 16,641 texels wide, past llvmpipe's 16,384) on bunny.
modes="spp:1 spp:4 adaptive:16 undersample:2"
"$h200/bench_gl" $common --sampling $modes --scenes scenes/classic.gltf \
  --json "$out/sampling_h200.json"
"$h200/bench_gl" $common --sampling $modes --scenes scenes/bunny.gltf \
  --json "$out/sampling_h200_bunny.json"
