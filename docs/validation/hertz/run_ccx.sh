#!/bin/sh
# run the given decks one after the other, single-threaded and niced
for name in "$@"; do
  OMP_NUM_THREADS=1 nice -n 10 /usr/bin/time -v ccx -i $name > $name.log 2> $name.time
done
