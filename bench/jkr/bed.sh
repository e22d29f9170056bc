#!/usr/bin/env bash
# Pair time per step of granular and granular/opt on a settled deposition bed (in.bed), alternating
# REPS times, best of each:  bench/jkr/bed.sh <run folder with final.restart>
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
restart=$(cd "$1" && pwd)/final.restart
steps=${STEPS:-2000}
reps=${REPS:-3}
export LD_LIBRARY_PATH="$(dirname "$lmp")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
best() { sort -g | head -n 1; }
pair_time() {
  "$lmp" -log none -echo none -in "$here/in.bed" -var restart "$restart" -var pair "$1" \
    -var steps "$steps" | awk '/^Pair/ {t=$3} END {print t}'
}
t_ref=(); t_opt=()
for rep in $(seq "$reps"); do
  t=$(pair_time granular); t_ref+=("$t"); echo "bed rep $rep granular: pair $t s / $steps steps"
  t=$(pair_time granular/opt); t_opt+=("$t"); echo "bed rep $rep granular/opt: pair $t s"
done
a=$(printf '%s\n' "${t_opt[@]}" | best); b=$(printf '%s\n' "${t_ref[@]}" | best)
awk -v a="$a" -v b="$b" -v s="$steps" 'BEGIN {printf "settled bed: pair %.4f ms/step granular, %.4f granular/opt, opt / granular %.3f\n", 1e3*b/s, 1e3*a/s, a/b}'
