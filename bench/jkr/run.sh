#!/usr/bin/env bash
# Time per step of the package's five JKR/Marshall sub-models vs LAMMPS's built-in adhesive
# set (jkr + viscoelastic damping + mindlin + rolling sds + twisting marshall), same system,
# same run, alternating 3 times; prints the ratio of the best times.
# (LAMMPS 4Feb2025 refuses damping coeff_restitution with jkr: "Cannot use coeff_restitution
#  model with a cohesive normal model", so viscoelastic is the built-in damping used.)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
steps=${STEPS:-2000}
package="jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr"
builtin="jkr 2e8 0.1 0.33 0.01 damping viscoelastic tangential mindlin NULL 1.0 0.3 rolling sds 1e-3 1e-3 0.1 twisting marshall"
best() { sort -g | head -n 1; }
t_pkg=(); t_bi=()
for rep in 1 2 3; do
  for which in package builtin; do
    model=${!which}
    out=$("$lmp" -log none -echo none -in "$here/in.packing" -var model "$model" -var steps "$steps")
    t=$(echo "$out" | awk '/^Loop time/ {t=$4} END {print t}')
    nc=$(echo "$out" | awk '/^ *[0-9]+ +[0-9]/ {nc=$2} END {print nc}')
    if [[ $which == package ]]; then t_pkg+=("$t"); else t_bi+=("$t"); fi
    echo "rep $rep $which: ${t} s for $steps steps, contacts at end: $nc"
  done
done
tp=$(printf '%s\n' "${t_pkg[@]}" | best); tb=$(printf '%s\n' "${t_bi[@]}" | best)
awk -v a="$tp" -v b="$tb" -v s="$steps" 'BEGIN {printf "package %.3f ms/step, built-in %.3f ms/step, ratio %.3f\n", 1e3*a/s, 1e3*b/s, a/b}'
