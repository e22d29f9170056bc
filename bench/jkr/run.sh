#!/usr/bin/env bash
# Time per step of the package's five JKR/Marshall sub-models vs LAMMPS's built-in adhesive
# set (jkr + viscoelastic damping + mindlin + rolling sds + twisting marshall), same system,
# same run, alternating 3 times; prints the ratio of the best times.
# (LAMMPS 4Feb2025 refuses damping coeff_restitution with jkr: "Cannot use coeff_restitution
#  model with a cohesive normal model", so viscoelastic is the built-in damping used.)
# LMP_BEFORE=<another build's lmp> adds the package's sub-models of that build to each round
# (e.g. a copy of the build before a change), so a change is measured in the same run.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
before=${LMP_BEFORE:-}
steps=${STEPS:-2000}
package="jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr"
builtin="jkr 2e8 0.1 0.33 0.01 damping viscoelastic tangential mindlin NULL 1.0 0.3 rolling sds 1e-3 1e-3 0.1 twisting marshall"
best() { sort -g | head -n 1; }
loop_time() {    # <lmp> <model>: loop time of the timed run
  LD_LIBRARY_PATH="$(dirname "$1")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
    "$1" -log none -echo none -in "$here/in.packing" -var model "$2" -var steps "$steps" |
    awk '/^Loop time/ {t=$4} END {print t}'
}
t_pkg=(); t_bi=(); t_before=()
for rep in 1 2 3; do
  t=$(loop_time "$lmp" "$package"); t_pkg+=("$t"); echo "rep $rep package: $t s for $steps steps"
  t=$(loop_time "$lmp" "$builtin"); t_bi+=("$t"); echo "rep $rep built-in: $t s"
  if [[ -n $before ]]; then
    t=$(loop_time "$before" "$package"); t_before+=("$t"); echo "rep $rep package of $before: $t s"
  fi
done
tp=$(printf '%s\n' "${t_pkg[@]}" | best); tb=$(printf '%s\n' "${t_bi[@]}" | best)
awk -v a="$tp" -v b="$tb" -v s="$steps" 'BEGIN {printf "package %.3f ms/step, built-in %.3f ms/step, ratio %.3f\n", 1e3*a/s, 1e3*b/s, a/b}'
if [[ -n $before ]]; then
  to=$(printf '%s\n' "${t_before[@]}" | best)
  awk -v a="$tp" -v o="$to" -v b="$tb" -v s="$steps" 'BEGIN {printf "before: package %.3f ms/step, ratio to built-in %.3f; now / before %.3f\n", 1e3*o/s, o/b, a/o}'
fi
