#!/usr/bin/env bash
# The settled paper-size bed (as anchor.sh) with two builds started together, one per core, so
# that both see the same machine: prints the Pair time of each and their ratio, REPS times.
#   bench/kernels/ab_bed.sh <build before> <build after> [pair style, default granular/opt]
# e.g. REPS=3 bench/kernels/ab_bed.sh /tmp/before build granular/opt
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
before=$(cd "$1" && pwd); after=$(cd "$2" && pwd)
pair=${3:-granular/opt}
steps=${STEPS:-3000}
reps=${REPS:-2}
run=$(mktemp -d); trap 'rm -rf "$run"' EXIT
bed=$here/../../doc/data/paper-size/runs/rp2um_U1_g10mJ_q0_N2000_s1
zcat "$bed/final.dump.gz" > "$run/final.dump"
step=$(sed -n 2p "$run/final.dump")
pair_seconds() {    # build-dir: the "Pair" time of the timed run
  (cd "$run" && LD_LIBRARY_PATH="$1${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$1/lmp" -log none \
     -echo none -in "$here/in.bed" -var dump final.dump -var step "$step" -var pair "$pair" \
     -var steps "$steps") | awk '/^Pair / {p = $3} END {print p}'
}
for rep in $(seq "$reps"); do
  pair_seconds "$before" > "$run/before" &
  pair_seconds "$after" > "$run/after" &
  wait
  b=$(cat "$run/before"); a=$(cat "$run/after")
  echo "$pair rep $rep: Pair before $b s, after $a s, after / before $(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.3f", a / b}')"
done
