#!/usr/bin/env bash
# The contact kernels against LAMMPS's own granular benchmark, in one invocation:
#   bench/kernels/anchor.sh [build folder, default build]
# 1. LAMMPS's chute benchmark (bench/in.chute of the LAMMPS source: 32,000 spheres,
#    gran/hooke/history, newton off), run for CHUTE_STEPS steps instead of 100;
# 2. the settled paper-size bed (doc/data/paper-size/runs/rp2um_U1_g10mJ_q0_N2000_s1: 2,000
#    spheres of r_p = 2 um after a neutral deposition), STEPS steps of the deck's time step with
#    - granular/opt and fix wall/gran/opt with the Marshall set (the deck default),
#    - granular and the same Marshall sub-models,
#    - granular and LAMMPS's stock adhesive set (jkr, viscoelastic, mindlin, sds, marshall twist).
# Each case REPS times, alternating, best of each. Prints ns per atom-step (the whole step: the
# "Loop time") and pair ns per contact (the "Pair" time per step over the contacts), and each
# case's atom-step cost over the chute's.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:-$here/../../build}" && pwd)
lmp=$build/lmp
steps=${STEPS:-3000}
chute_steps=${CHUTE_STEPS:-1000}
reps=${REPS:-2}
export LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# the LAMMPS tree the build used: lammps_SOURCE_DIR is its cmake/ folder
lammps_src=$(dirname "$(sed -n 's/^lammps_SOURCE_DIR:[A-Z]*=//p' "$build/CMakeCache.txt")")
[[ -f $lammps_src/bench/in.chute ]] || { echo "anchor.sh: no bench/in.chute under '$lammps_src'" >&2; exit 1; }
run=$(mktemp -d); trap 'rm -rf "$run"' EXIT
bed=$here/../../doc/data/paper-size/runs/rp2um_U1_g10mJ_q0_N2000_s1
zcat "$bed/final.dump.gz" > "$run/final.dump"
step=$(sed -n 2p "$run/final.dump")
sed 's/^run[[:space:]].*/run '"$chute_steps"'/' "$lammps_src/bench/in.chute" > "$run/in.chute"
cp "$lammps_src/bench/data.chute" "$run/"

marshall="jkr/marshall 2.0e8 0.7 0.33 0.010 damping marshall tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr"
# LAMMPS's own adhesive set with the same material; eta_n0, the rolling stiffness and damping are
# of the Marshall set's order at this size (their values do not change the cost)
stock="jkr 2.0e8 5.0e-4 0.33 0.010 damping viscoelastic tangential mindlin NULL 1.0 0.3 rolling sds 5.0e-4 1.0e-9 0.01 twisting marshall"

# prints "loop_s pair_s atoms contacts" of one run: pair style, sub-models, the floor's fix style
measure_bed() {
  (cd "$run" && "$lmp" -log none -echo none -in "$here/in.bed" -var dump final.dump -var step "$step" \
     -var pair "$1" -var contact "$2" -var wall "$3" -var steps "$steps") |
  awk '/^Loop time/ {loop=$4; n=$12} /^Pair / {pair=$3} $1 ~ /^[0-9]+$/ && NF == 4 {nc=$3}
       END {print loop, pair, n, nc / 2}'
}
measure_chute() {
  (cd "$run" && "$lmp" -log none -echo none -in in.chute) |
  awk '/^Loop time/ {loop=$4; n=$12} /^Pair / {pair=$3} END {print loop, pair, n, 0}'
}
declare -A best
keep_best() {  # name "loop pair atoms contacts"
  local old=${best[$1]:-}
  if [[ -z $old ]] || awk -v a="${2%% *}" -v b="${old%% *}" 'BEGIN {exit !(a < b)}'; then best[$1]=$2; fi
}
for rep in $(seq "$reps"); do
  r=$(measure_chute); echo "rep $rep chute: $r"; keep_best chute "$r"
  r=$(measure_bed granular/opt "$marshall" wall/gran/opt); echo "rep $rep granular/opt Marshall: $r"; keep_best opt "$r"
  r=$(measure_bed granular "$marshall" wall/gran); echo "rep $rep granular Marshall: $r"; keep_best granular "$r"
  r=$(measure_bed granular "$stock" wall/gran); echo "rep $rep granular stock jkr: $r"; keep_best stock "$r"
done
chute_ns=$(awk -v s="$chute_steps" '{printf "%.6g", 1e9 * $1 / ($3 * s)}' <<< "${best[chute]}")
printf '\n| kernel | ns per atom-step | / chute | pair ns per contact | contacts |\n|---|---|---|---|---|\n'
printf '| LAMMPS chute benchmark (gran/hooke/history, 32,000 spheres, %s steps) | %.0f | 1 | - | - |\n' "$chute_steps" "$chute_ns"
row() {
  awk -v name="$1" -v s="$steps" -v c="$chute_ns" '{ns = 1e9 * $1 / ($3 * s);
    printf "| %s | %.0f | %.2f | %.0f | %d |\n", name, ns, ns / c, 1e9 * $2 / ($4 * s), $4}' <<< "$2"
}
row "granular/opt + wall/gran/opt, Marshall set (settled bed, $steps steps)" "${best[opt]}"
row "granular, Marshall set" "${best[granular]}"
row "granular, LAMMPS jkr + viscoelastic + mindlin + sds + marshall twist" "${best[stock]}"
