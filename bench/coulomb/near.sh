#!/usr/bin/env bash
# Time per step of fix coul/fmm between evaluations (the near refresh of the pairs closer than
# 3 r_p every step, the far part extrapolated) on in.near; best of 3. LMP_BEFORE=<another
# build's lmp> alternates with that build in the same run and prints the ratio.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
before=${LMP_BEFORE:-}
steps=${STEPS:-2000}
loop_time() {
  LD_LIBRARY_PATH="$(dirname "$1")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
    "$1" -log none -echo none -in "$here/in.near" -var steps "$steps" |
    awk '/^Loop time/ {t=$4} END {print t}'
}
best() { sort -g | head -n 1; }
t_now=(); t_before=()
for rep in 1 2 3; do
  t=$(loop_time "$lmp"); t_now+=("$t"); echo "rep $rep: $t s for $steps steps"
  if [[ -n $before ]]; then
    t=$(loop_time "$before"); t_before+=("$t"); echo "rep $rep, $before: $t s"
  fi
done
tn=$(printf '%s\n' "${t_now[@]}" | best)
awk -v a="$tn" -v s="$steps" 'BEGIN {printf "%.3f ms/step\n", 1e3*a/s}'
if [[ -n $before ]]; then
  tb=$(printf '%s\n' "${t_before[@]}" | best)
  awk -v a="$tn" -v b="$tb" -v s="$steps" 'BEGIN {printf "before %.3f ms/step; now / before %.3f\n", 1e3*b/s, a/b}'
fi
