#!/bin/bash
# The cost model of docs/cluster.md: N shards of studies/gap-dev.toml as
# separate processes (one rayon thread each), then the merge; compared with
# a single run in /tmp/cost/n1 (palpate run studies/gap-dev.toml --out /tmp/cost/n1).
#   bash docs/cluster-cost.sh 2; bash docs/cluster-cost.sh 4      (from the repository's root)
set -u
PALPATE=${PALPATE:-target/debug/palpate}
N=$1; out=/tmp/cost/s$N; rm -rf $out
start=$(date +%s.%N)
for i in $(seq 0 $((N-1))); do
  RAYON_NUM_THREADS=1 /usr/bin/time -f "shard $i/$N: wall %e s, user %U s, sys %S s" $PALPATE run studies/gap-dev.toml --out $out --shard $i/$N > /tmp/cost/s$N-$i.log 2>&1 &
done
wait
mid=$(date +%s.%N)
RAYON_NUM_THREADS=1 /usr/bin/time -f "merge: wall %e s, user %U s, sys %S s" $PALPATE merge $out > /tmp/cost/s$N-merge.log 2>&1
end=$(date +%s.%N)
echo "N=$N shards wall $(echo "$mid - $start" | bc) s, merge $(echo "$end - $mid" | bc) s, total $(echo "$end - $start" | bc) s; load: $(cut -d' ' -f1-3 /proc/loadavg)"
tail -qn1 /tmp/cost/s$N-*.log
cmp /tmp/cost/n1/results.json $out/results.json && echo "results.json identical to the single run"
