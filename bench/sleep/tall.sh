#!/usr/bin/env bash
# CPU per step of a charged deposition onto a bed of 1 and COPIES (default 10) stacked copies of
# a paper-size bed (in.tall), sleeping on, for each value of fix sleep/gran's keyword pairs in
# PAIRS (default "all awake"), all runs started together; prints the ratios and LAMMPS's timers.
#   bench/sleep/tall.sh <run folder of a paper-size q = 400 run (final.dump, particle.mol)> [build-dir]
# e.g. COPIES=10 STEPS=5000 bench/sleep/tall.sh /tmp/q400run
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
run=$(cd "$1" && pwd); build=$(cd "${2:-$here/../../build}" && pwd)
copies=${COPIES:-10}; steps=${STEPS:-20000}; pairs=${PAIRS:-all awake}
export LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
out=$(mktemp -d)
# the data file of `c` copies of the final packing, stacked in z (stack_bed.py)
stack() { /usr/bin/python3 "$here/stack_bed.py" "$run/final.dump" "$1" "$2"; }
for c in 1 "$copies"; do stack "$c" "$out/tall.$c.data"; done
for p in $pairs; do
  for c in 1 "$copies"; do
    "$build/lmp" -in "$here/in.tall" -log "$out/log.$p.$c" -screen none -var data "$out/tall.$c.data" \
      -var molfile "$run/particle.mol" -var steps "$steps" -var sleep "${SLEEP:-yes}" -var pairs "$p" &
  done
done
wait
# the measured run is the last "Loop time" of each log, and its timer table the last; CPU per
# step: the wall time times the run's "% CPU use" (on a busy machine a run also waits for a core)
per_step() { awk '/^Loop time of/ {t=$4; n=$9} END {printf "%.4f", 1e3*t/n}' "$1"; }
cpu_per_step() {
  awk '/^Loop time of/ {t=$4; n=$9} /% CPU use with/ {c=$1+0} END {printf "%.4f", 1e3*t*c/100/n}' "$1"
}
first=${pairs%% *}
for p in $pairs; do
  for c in 1 "$copies"; do
    echo "$(grep -h '^TALL' "$out/log.$p.$c") ms_per_step $(per_step "$out/log.$p.$c") cpu_ms_per_step $(cpu_per_step "$out/log.$p.$c")"
  done
  awk -v a="$(per_step "$out/log.$p.1")" -v b="$(per_step "$out/log.$p.$copies")" -v c="$copies" -v p="$p" \
    -v ca="$(cpu_per_step "$out/log.$p.1")" -v cb="$(cpu_per_step "$out/log.$p.$copies")" \
    'BEGIN {printf "pairs %s: per-step time, %s copies / 1 copy: %.2f (CPU %.2f)\n", p, c, b/a, cb/ca}'
done
for p in $pairs; do
  [[ $p == "$first" ]] && continue
  for c in 1 "$copies"; do
    awk -v a="$(per_step "$out/log.$first.$c")" -v b="$(per_step "$out/log.$p.$c")" \
      -v ca="$(cpu_per_step "$out/log.$first.$c")" -v cb="$(cpu_per_step "$out/log.$p.$c")" -v c="$c" -v p="$p" -v f="$first" \
      'BEGIN {printf "%s copies: per-step time, pairs %s / pairs %s: %.2f (CPU %.2f)\n", c, p, f, b/a, cb/ca}'
  done
done
for p in $pairs; do
  for c in 1 "$copies"; do
    echo "--- pairs $p, $c copies: $(grep -h '% CPU use' "$out/log.$p.$c" | tail -1)"
    awk '/^Section/ {n = 0; s = ""} /^Section/, /^Total/ {if (n++ < 12) s = s $0 "\n"} END {printf "%s", s}' \
      "$out/log.$p.$c" | grep -v '^Total'
  done
done
rm -rf "$out"
