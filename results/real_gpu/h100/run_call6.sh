# The sixth call (issue 51): does a card's texture cache care where a warp's fetches go? The
# BVH's looping walk runs at 0.79-0.92 of its price and the two-level grid's at 1.09-1.34 while
# the vgpu counts them alike (docs/studies/real_gpu_notes.md). bench_gl --coherence times one
# pass of 64 independent fetches a fragment four times, changing only where the fragments
# fetch. Run from the repository's root on the GPU host with bench_gl in .scalebin/ (this
# commit's) and the glvnd packages in .gl/; the files are tarred to $OUT as call6.tgz.
set -u
out=/tmp/o; mkdir -p $out
. scripts/h200/env.sh
B=.scalebin/bench_gl
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv > $out/gpu.csv; cat $out/gpu.csv
for i in 1 2; do
  timeout 120 $B --no-frames --no-fixed --coherence --runs 9 --warmup-ms 500 --json $out/coherence_$i.json > $out/coherence_$i.log 2>&1
  echo "coherence_$i rc=$?"; cat $out/coherence_$i.log
done
kill $sampler 2>/dev/null; mv $out/clocks.csv $out/clocks_call6.csv; tar czf $OUT/call6.tgz -C $out .; ls -la $OUT
