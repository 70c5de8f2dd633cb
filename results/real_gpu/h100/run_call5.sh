# The fifth call (issue 51): the dense sampling frames again after the host's per-pixel loops
# were made cheap (adaptive_rays built its list of levels once per pixel; undersampling's loops
# called on_lattice and lattice_cell per pixel), and a second measurement of the looping frames
# of every structure on the scenes whose cells missed (the primary BVH and two-level grid
# frames), to see how far a frame moves between two sessions. Run from the repository's root on
# the GPU host with bench_gl in .scalebin/ (this commit's) and the glvnd packages in .gl/; the
# files are tarred to $OUT as call5.tgz. The card is whatever the device gives: gpu.csv names it.
set -u
out=/tmp/o; mkdir -p $out
. scripts/h200/env.sh
B=.scalebin/bench_gl
t0=$(date +%s); END=${END:-400}
left() { echo $(( END - ($(date +%s) - t0) )); }
stage() { local name=$1; shift; local l; l=$(left)
  if [ "$l" -lt "${NEED:-15}" ]; then echo "skip $name"; return; fi
  timeout "$l" "$@" > $out/$name.log 2>&1; echo "$name rc=$? at $(( $(date +%s) - t0 )) s"; }
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv > $out/gpu.csv; cat $out/gpu.csv
common="--no-stream --readback-wait poll --no-fixed --sizes 256 --grid auto"
for s in bunny classic; do
  stage host_samp_$s $B $common --runs 5 --shadows --bounces 2 --variants looping --sampling spp:1 spp:4 adaptive:16 undersample:2 --warmup-ms 300 --scenes scenes/$s.gltf --json $out/host_samp_$s.json; done
for s in scenes/bunny.gltf scenes/classic.gltf scenes/sphere.gltf scenes/teapot.gltf .scalebin/stadium.gltf .scalebin/scales.gltf .scalebin/gen/heightfield-100k.gltf; do
  n=$(basename $s .gltf)
  stage again_$n $B $common --runs 5 --accel grid grid2 bvh kdtree --variants looping --bounces 0 --warmup-ms 300 --scenes $s --json $out/again_$n.json; done
kill $sampler 2>/dev/null; mv $out/clocks.csv $out/clocks_call5.csv; tar czf $OUT/call5.tgz -C $out .; ls -la $OUT
