# The third H100 call (issue 51, the L2 term checked at sizes it was not fitted on): run from the
# repository's root on the GPU host with the binaries in .scalebin/ (bench_gl), the glvnd
# packages in .gl/ and the generated 100k heightfield in .scalebin/gen/
# (scripts/scenes/scale_scenes.py --heightfields 100k). Each stage within what is left of END
# seconds; the files are tarred to $OUT. The predictions of these frames were made before the
# call (bench_gl --readback-wait none with the same options, the model of commit bd4bc6a).
set -u
out=/tmp/o; mkdir -p $out
. scripts/h200/env.sh
B=.scalebin/bench_gl
t0=$(date +%s); END=${END:-540}
left() { echo $(( END - ($(date +%s) - t0) )); }
stage() { local name=$1; shift; local l; l=$(left)
  if [ "$l" -lt "${NEED:-15}" ]; then echo "skip $name"; return; fi
  timeout "$l" "$@" > $out/$name.log 2>&1; echo "$name rc=$? at $(( $(date +%s) - t0 )) s"; }
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv > $out/gpu.csv
common="--no-stream --readback-wait poll --no-fixed"
for s in bunny sphere-alone; do
  stage l2_sizes_$s $B $common --runs 3 --sizes 384 512 640 768 --grid 15 --variants multipass --bounces 2 --warmup-ms 500 --scenes scenes/$s.gltf --json $out/l2_sizes_$s.json; done
for s in bunny classic; do
  stage l2_loop_$s $B $common --runs 3 --sizes 512 768 1024 --grid auto --accel grid grid2 bvh kdtree --variants looping --bounces 0 --warmup-ms 300 --scenes scenes/$s.gltf --json $out/l2_loop_$s.json; done
stage l2_loop_heightfield-100k $B $common --runs 3 --sizes 1024 --grid auto --accel grid grid2 bvh kdtree --variants looping --bounces 0 --warmup-ms 300 --scenes .scalebin/gen/heightfield-100k.gltf --json $out/l2_loop_heightfield-100k.json
stage l2_variants_bunny $B $common --runs 3 --sizes 512 768 --grid 15 --variants mrt looping --bounces 2 --warmup-ms 300 --scenes scenes/bunny.gltf --json $out/l2_variants_bunny.json
stage l2_multi_classic $B $common --runs 3 --sizes 1024 --grid auto --accel grid2 bvh kdtree --variants multipass --bounces 0 --warmup-ms 300 --scenes scenes/classic.gltf --json $out/l2_multi_classic.json
stage l2_full_teapot $B $common --runs 3 --sizes 768 --grid auto --accel grid bvh --variants multipass looping --bounces 2 --shadows --warmup-ms 300 --scenes scenes/teapot.gltf --json $out/l2_full_teapot.json
kill $sampler 2>/dev/null; mv $out/clocks.csv $out/clocks_call3.csv; tar czf $OUT/h100.tgz -C $out .; ls -la $OUT
