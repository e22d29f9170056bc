#!/usr/bin/env bash
# pair_style granular/opt (the fused Marshall kernel) against pair_style granular with the same
# sub-models, in one run, alternating REPS times (best of each):
#   (a) pair time per step on a settled adhesive packing (in.packing: 2048 spheres, 12 contacts
#       each, newton off), from LAMMPS's timing breakdown;
#   (b) a demo-size neutral deposition (N = 500, L = 14 r_p, the default deck; or DEPO_VARS),
#       both styles started together (one per core): user CPU, steps, pair time per step, phi.
# LMP=<build>/lmp selects the build; LMP_BEFORE=<another build>/lmp adds that build's
# pair_style granular to each round of (a) and (b) (e.g. the build before a change).
# SKIP_DEPOSITION=1 runs (a) only.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
build=$(cd "$(dirname "$lmp")" && pwd)
steps=${STEPS:-2000}
reps=${REPS:-3}
deck=$here/../../python/granular_charged/decks/in.deposition
read -r -a depo_vars <<< "${DEPO_VARS:--var N 500 -var L_rp 14 -var seed 1}"
model="jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr"
export LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
best() { sort -g | head -n 1; }
before=${LMP_BEFORE:-}
pair_time() {    # <style> [<lmp>]: pair seconds of the timed run of in.packing
  LD_LIBRARY_PATH="$(dirname "${2:-$lmp}")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "${2:-$lmp}" -log none -echo none -in "$here/in.packing" -var model "$model" -var steps "$steps" \
    -var pair "$1" | awk '/^Pair/ {t=$3} END {print t}'
}
t_ref=(); t_opt=(); t_before=()
for rep in $(seq "$reps"); do
  t=$(pair_time granular); t_ref+=("$t"); echo "packing rep $rep granular: pair $t s / $steps steps"
  t=$(pair_time granular/opt); t_opt+=("$t"); echo "packing rep $rep granular/opt: pair $t s"
  if [[ -n $before ]]; then
    t=$(pair_time granular "$before"); t_before+=("$t"); echo "packing rep $rep granular of $before: pair $t s"
  fi
done
a=$(printf '%s\n' "${t_opt[@]}" | best); b=$(printf '%s\n' "${t_ref[@]}" | best)
awk -v a="$a" -v b="$b" -v s="$steps" 'BEGIN {printf "(a) settled packing: pair %.3f ms/step granular, %.3f granular/opt, opt / granular %.3f\n", 1e3*b/s, 1e3*a/s, a/b}'
if [[ -n $before ]]; then
  o=$(printf '%s\n' "${t_before[@]}" | best)
  awk -v a="$a" -v b="$b" -v o="$o" -v s="$steps" 'BEGIN {printf "(a) before: pair %.3f ms/step granular; granular / before %.3f, opt / before %.3f\n", 1e3*o/s, b/o, a/o}'
fi
[[ -n ${SKIP_DEPOSITION:-} ]] && exit 0

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() {    # tag pair_opt
  mkdir -p "$out/$1"
  local TIMEFORMAT=%U
  { time "$lmp" -in "$deck" -var out "$out/$1" -log "$out/$1/log.lammps" -screen none \
      -var pair_opt "$2" "${depo_vars[@]}"; } 2> "$out/$1/user"
}
summary() {    # tag: user CPU, steps, pair seconds (all runs of the deck), phi, <Z>
  local log=$out/$1/log.lammps
  local steps pair
  steps=$(sed -n 's/^GC RESULT steps \([0-9]*\).*/\1/p' "$log" | tail -n 1)
  pair=$(awk '/^Pair  *\|/ {s += $5} END {print s}' "$log")
  phi=$(sed -n 's/^GC RESULT .* phi \([^ ]*\) Z \([^ ]*\).*/\1 \2/p' "$log" | tail -n 1)
  echo "$(tail -n 1 "$out/$1/user") $steps $pair $phi"
}
for rep in $(seq "$reps"); do
  run granular no & run opt yes & wait
  read -r cpu_r steps_r pair_r phi_r z_r <<< "$(summary granular)"
  read -r cpu_o steps_o pair_o phi_o z_o <<< "$(summary opt)"
  echo "deposition rep $rep granular: $cpu_r s user CPU, $steps_r steps, pair $pair_r s, phi $phi_r, <Z> $z_r"
  echo "deposition rep $rep granular/opt: $cpu_o s user CPU, $steps_o steps, pair $pair_o s, phi $phi_o, <Z> $z_o"
  awk -v a="$cpu_o" -v b="$cpu_r" -v pa="$pair_o" -v pb="$pair_r" -v sa="$steps_o" -v sb="$steps_r" \
    'BEGIN {printf "(b) deposition rep: CPU opt / granular %.3f; pair time per step %.4f / %.4f ms, opt / granular %.3f\n", a/b, 1e3*pb/sb, 1e3*pa/sa, (pa/sa)/(pb/sb)}'
done
