# The fourth call (issue 51, where the dense sampling streams' looping frames spend the wall time
# the model does not price): bench_gl with each frame's wall time split by the GL device's calls
# (host_split_ms: draw, query_wait, download, upload, clear, settle, between_calls) and the GL
# objects made in timed frames. Run from the repository's root on the GPU host with bench_gl in
# .scalebin/ and the glvnd packages in .gl/; the files are tarred to $OUT as split.tgz. The card
# is whatever the device gives: gpu.csv names it. .scalebin/bench_gl_before is bench_gl of commit
# 54e0641 (the split, without the GLSL kept per uniform set); bench_gl is of commit 47fb4ce.
set -u
out=/tmp/o; mkdir -p $out
. scripts/h200/env.sh
B=.scalebin/bench_gl
t0=$(date +%s); END=${END:-420}
left() { echo $(( END - ($(date +%s) - t0) )); }
stage() { local name=$1; shift; local l; l=$(left)
  if [ "$l" -lt "${NEED:-15}" ]; then echo "skip $name"; return; fi
  timeout "$l" "$@" > $out/$name.log 2>&1; echo "$name rc=$? at $(( $(date +%s) - t0 )) s"; }
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv > $out/gpu.csv; cat $out/gpu.csv
common="--no-stream --readback-wait poll --no-fixed --sizes 256"
# The GL device before it kept each program's GLSL per uniform set (bench_gl_before: it printed
# the GLSL again at every uniform change), against it, alternated: the dense looping frames. The
# undersampled frames' difference is the GLSL's alone; the adaptive frames' also holds 47fb4ce's
# jitter table (before it, two GL textures made a frame).
# Only where bench_gl_before was carried (the session that ran this call carried none: the
# stored H100 runs, made before 54e0641, are the before).
[ -x ${B}_before ] && for i in 1 2; do for b in before after; do bin=$B; [ $b = before ] && bin=${B}_before
  stage glsl_${b}_$i $bin $common --runs 5 --grid auto --shadows --bounces 2 --variants looping --sampling undersample:2 adaptive:16 --warmup-ms 200 --scenes scenes/bunny.gltf scenes/classic.gltf --json $out/glsl_${b}_$i.json; done; done
for s in bunny classic; do
  stage split_samp_$s $B $common --runs 5 --grid auto --shadows --bounces 2 --variants looping multipass --sampling spp:1 spp:4 adaptive:16 undersample:2 --warmup-ms 300 --scenes scenes/$s.gltf --json $out/split_samp_$s.json; done
stage split_streams $B $common --runs 5 --grid auto --shadows --bounces 2 --variants looping multipass --ray-streams off on --warmup-ms 300 --scenes scenes/bunny-refl.gltf scenes/glass.gltf --json $out/split_streams.json
for s in bunny classic; do
  stage split_loop_$s $B $common --runs 5 --grid auto --accel grid grid2 bvh kdtree --variants looping --bounces 0 --warmup-ms 300 --scenes scenes/$s.gltf --json $out/split_loop_$s.json; done
kill $sampler 2>/dev/null; mv $out/clocks.csv $out/clocks_call4.csv; tar czf $OUT/split.tgz -C $out .; ls -la $OUT
