#!/bin/bash
# The sample-step rows of the cost model in docs/cluster.md: a study of two
# sample steps (a C1 posterior, 4 NUTS chains x 1000 draws; an N1 posterior
# through a surrogate of 12 + 4 FE runs on the coarse mesh, the record cut at
# 1 mm, 4 DE-MCz populations x 1000 draws), run once in one process and as N
# shards (separate processes, one rayon thread each, two passes: the N1
# chains need every FE run), then merged and compared.
#   bash docs/cluster-cost-sample.sh 2; bash docs/cluster-cost-sample.sh 4   (from the repository's root)
set -u
PALPATE=$(realpath "${PALPATE:-target/debug/palpate}")
ROOT=$(pwd); N=$1; dir=/tmp/cost-sample; mkdir -p $dir; cd $dir
awk -F, 'NR<=2 || /^#/ || ($1+0)<=1.0' "$ROOT/tests/data/mesa2011/needle-1.csv" > needle-1.csv
cat > sampled.toml <<TOML
[study]
name = "sampled-cost"
seed = 5

[data.compression]
file = "$ROOT/tests/data/mesa2011/c1-compression.csv"
test = "C1"

[data.needle-1]
file = "needle-1.csv"
test = "N1"

[models.nh]
law = "neo-hookean"

[models.nh-axi.n1_needle]
law = "neo-hookean"
mesh = "coarse"

[[steps]]
[steps.sample]
name = "c1-posterior"
model = "nh"
data = ["compression"]
draws = 1000
tune = 1000
chains = 4

[[steps]]
[steps.sample]
name = "n1-posterior"
model = "nh-axi"
data = ["needle-1"]
sampler = "demc"
draws = 1000
tune = 1000
chains = 4
box = { C10 = [0.0002, 0.003] }
design = 12
holdout = 4
TOML
if [ ! -f n1/results.json ]; then
  RAYON_NUM_THREADS=1 /usr/bin/time -f "single: wall %e s, user %U s, sys %S s" $PALPATE run sampled.toml --out n1 > single.log 2>&1
fi
tail -n1 single.log
out=s$N; rm -rf $out
for pass in 1 2; do
  for i in $(seq 0 $((N-1))); do
    RAYON_NUM_THREADS=1 /usr/bin/time -f "pass $pass shard $i/$N: wall %e s, user %U s, sys %S s" $PALPATE run sampled.toml --out $out --shard $i/$N > $out-$pass-$i.log 2>&1 &
  done
  wait
done
RAYON_NUM_THREADS=1 /usr/bin/time -f "merge: wall %e s, user %U s, sys %S s" $PALPATE merge $out > $out-merge.log 2>&1
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
tail -qn1 $out-*.log
cmp n1/results.json $out/results.json && echo "results.json identical to the single run"
