#!/usr/bin/env bash
# The settled paper-size bed (as anchor.sh) with two builds started together, one per core, so
# that both see the same machine: prints the Pair time of each and their ratio, REPS times.
# The Pair time is given twice: wall clock and CPU (LAMMPS's "timer full": the wall time times
# its %CPU), the CPU one unaffected by the time the process waits for a core on a busy machine.
# ALTERNATE=1 runs them one after the other instead (before, after, before, ...), for a machine
# whose other jobs load one core: each run then has a core to itself when the other is busy.
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
pair_seconds() {    # build-dir: "wall CPU", the "Pair" times of the timed run
  (cd "$run" && LD_LIBRARY_PATH="$1${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$1/lmp" -log none \
     -echo none -in "$here/in.bed" -var dump final.dump -var step "$step" -var pair "$pair" \
     -var steps "$steps" -var timer full) |
  awk '/^Pair / {p = $5; c = $5 * $11 / 100} END {printf "%.6g %.6g\n", p, c}'
}
for rep in $(seq "$reps"); do
  if [[ ${ALTERNATE:-0} == 1 ]]; then
    pair_seconds "$before" > "$run/before"
    pair_seconds "$after" > "$run/after"
  else
    pair_seconds "$before" > "$run/before" &
    pair_seconds "$after" > "$run/after" &
    wait
  fi
  read -r bw bc < "$run/before"; read -r aw ac < "$run/after"
  echo "$pair rep $rep: Pair wall before $bw s, after $aw s, after / before $(awk -v a="$aw" -v b="$bw" 'BEGIN {printf "%.3f", a / b}'); CPU before $bc s, after $ac s, after / before $(awk -v a="$ac" -v b="$bc" 'BEGIN {printf "%.3f", a / b}')"
done
