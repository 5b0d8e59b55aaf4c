#!/bin/sh
# Run CalculiX decks one after the other, single-threaded and niced, each in
# the directory of its deck; CPU and wall time go to NAME.time.
# usage: run.sh DECK.inp ...
for deck in "$@"; do
  dir=$(dirname "$deck"); name=$(basename "$deck" .inp)
  (cd "$dir" && OMP_NUM_THREADS=1 nice -n 10 /usr/bin/time -v ccx -i "$name" > "$name.log" 2> "$name.time")
done
