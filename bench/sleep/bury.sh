#!/usr/bin/env bash
# CPU per step and LAMMPS's timer sections of a charged deposition onto a bed of 1 and COPIES
# (default 10) stacked copies of a paper-size bed (in.bury), fix bury/gran off and on: the four
# runs started together; prints each run's per-step time and sections, and the ratios.
#   bench/sleep/bury.sh <run folder of a paper-size q = 400 run (final.dump, particle.mol)> [build-dir]
# STEPS (default 5000) and WARMUP (default 4000) set the measured run and the warm-up.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
run=$(cd "$1" && pwd); build=$(cd "${2:-$here/../../build}" && pwd)
copies=${COPIES:-10}; steps=${STEPS:-5000}; warmup=${WARMUP:-4000}
export LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
out=$(mktemp -d)
# the data file of `c` copies of the final packing, stacked in z (stack_bed.py)
stack() { /usr/bin/python3 "$here/stack_bed.py" "$run/final.dump" "$1" "$2"; }
for c in 1 "$copies"; do
  stack "$c" "$out/tall.$c.data"
  for b in no yes; do
    "$build/lmp" -in "$here/in.bury" -log "$out/log.$c.$b" -screen none -var data "$out/tall.$c.data" \
      -var molfile "$run/particle.mol" -var steps "$steps" -var warmup "$warmup" -var bury "$b" &
  done
done
wait
# the measured run is the last "Loop time" of each log; a section's time is its avg column
per_step() { awk '/^Loop time of/ {t=$4; n=$9} END {printf "%.4f", 1e3*t/n}' "$1"; }
section() { awk -v s="$2" '$1 == s && $2 == "|" {t=$5} /^Loop time of/ {n=$9} END {printf "%.4f", 1e3*t/n}' "$1"; }
printf "%-7s %-5s %8s %11s %8s %8s %8s %8s\n" copies bury atoms ms/step Pair Neigh Comm Modify
for c in 1 "$copies"; do
  for b in no yes; do
    f="$out/log.$c.$b"
    printf "%-7s %-5s %8s %11s %8s %8s %8s %8s\n" "$c" "$b" "$(awk '/^BURY/ {print $5}' "$f")" \
      "$(per_step "$f")" "$(section "$f" Pair)" "$(section "$f" Neigh)" "$(section "$f" Comm)" \
      "$(section "$f" Modify)"
  done
done
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", b/a}'; }
for b in no yes; do
  echo "bury $b, $copies copies / 1 copy: per step $(ratio "$(per_step "$out/log.1.$b")" "$(per_step "$out/log.$copies.$b")")," \
    "Pair $(ratio "$(section "$out/log.1.$b" Pair)" "$(section "$out/log.$copies.$b" Pair)")," \
    "Neigh $(ratio "$(section "$out/log.1.$b" Neigh)" "$(section "$out/log.$copies.$b" Neigh)")," \
    "Comm $(ratio "$(section "$out/log.1.$b" Comm)" "$(section "$out/log.$copies.$b" Comm)")," \
    "Modify $(ratio "$(section "$out/log.1.$b" Modify)" "$(section "$out/log.$copies.$b" Modify)")"
done
for c in 1 "$copies"; do
  echo "$c copies, bury yes / no: per step $(ratio "$(per_step "$out/log.$c.no")" "$(per_step "$out/log.$c.yes")")"
  grep -h '^BURY bury yes' "$out/log.$c.yes"
done
rm -rf "$out"
