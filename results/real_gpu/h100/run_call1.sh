# One device call: the h100 probes, then frames in priority order, each stage within what is left
# of END seconds; per-scene files so a stage cut short keeps what it finished.
set -u
out=/tmp/o; mkdir -p $out
. scripts/h200/env.sh
B=.scalebin/bench_gl
t0=$(date +%s); END=${END:-550}
left() { echo $(( END - ($(date +%s) - t0) )); }
stage() { local name=$1; shift; local l; l=$(left)
  if [ "$l" -lt "${NEED:-15}" ]; then echo "skip $name"; return; fi
  timeout "$l" "$@" > $out/$name.log 2>&1; echo "$name rc=$? at $(( $(date +%s) - t0 )) s"; }
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem,memory.total,pcie.link.gen.max,pcie.link.width.max,power.limit --format=csv > $out/gpu.csv; cat $out/gpu.csv
stage fixed $B --runs 5 --micro-passes 50 --no-frames --readback-wait both --json $out/fixed.json
stage latency $B --latency --no-fixed --no-frames --runs 9 --warmup-ms 1000 --readback-wait poll --json $out/latency.json
for s in sphere-alone bunny bunny-mirror; do
  stage t1_$s $B --runs 5 --sizes 256 1024 --threads 16 --no-stream --readback-wait both --grid 15 --no-fixed --warmup-ms 500 --scenes scenes/$s.gltf --json $out/t1_$s.json; done
S="scenes/sphere.gltf scenes/bunny.gltf scenes/bunny-refl.gltf scenes/classic.gltf scenes/teapot.gltf .scalebin/stadium.gltf .scalebin/scales.gltf .scalebin/gen/heightfield-100k.gltf .scalebin/gen/objects-100k.gltf"
for p in $S; do n=$(basename $p .gltf)
  stage loop_$n $B --runs 5 --sizes 256 --no-stream --readback-wait poll --grid auto --accel grid grid2 bvh kdtree --variants looping --bounces 0 --no-fixed --warmup-ms 1000 --scenes $p --json $out/loop_$n.json; done
stage sizes $B --runs 5 --sizes 8 64 256 512 --no-stream --readback-wait poll --grid auto --accel grid2 bvh kdtree --variants looping --bounces 0 --no-fixed --warmup-ms 300 --scenes scenes/bunny.gltf scenes/classic.gltf scenes/teapot.gltf --json $out/sizes.json
for p in $S; do n=$(basename $p .gltf)
  stage multi_$n $B --runs 3 --sizes 256 --no-stream --readback-wait poll --grid auto --accel grid grid2 bvh kdtree --variants multipass --bounces 0 --no-fixed --warmup-ms 500 --scenes $p --json $out/multi_$n.json; done
for s in bunny classic teapot; do
  stage beams_$s $B --runs 5 --sizes 256 --no-stream --readback-wait poll --grid auto --accel grid bvh kdtree --variants looping multipass --bounces 0 --beams off on --no-fixed --warmup-ms 500 --scenes scenes/$s.gltf --json $out/beams_$s.json; done
for s in classic bunny; do
  stage samp_$s $B --runs 3 --sizes 256 --no-stream --readback-wait poll --grid auto --shadows --bounces 2 --variants multipass looping --sampling spp:1 spp:4 adaptive:16 undersample:2 --no-fixed --warmup-ms 500 --scenes scenes/$s.gltf --json $out/samp_$s.json; done
stage streams $B --runs 3 --sizes 256 --no-stream --readback-wait poll --grid auto --shadows --bounces 2 --variants multipass looping --ray-streams off on --no-fixed --warmup-ms 500 --scenes scenes/bunny-refl.gltf scenes/glass.gltf --json $out/streams.json
for s in sphere-alone bunny bunny-mirror; do
  stage var_$s $B --runs 5 --sizes 256 1024 --no-stream --readback-wait poll --variants mrt looping --micro-passes 50 --grid 15 --no-fixed --warmup-ms 500 --scenes scenes/$s.gltf --json $out/var_$s.json; done
for p in $S; do n=$(basename $p .gltf)
  stage full_$n $B --runs 3 --sizes 256 --no-stream --readback-wait poll --grid auto --accel grid grid2 bvh kdtree --variants multipass looping --bounces 2 --no-fixed --warmup-ms 500 --scenes $p --json $out/full_$n.json; done
kill $sampler 2>/dev/null; tar czf $OUT/h100.tgz -C $out .; ls -la $OUT
