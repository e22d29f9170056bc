#!/usr/bin/env bash
# CPU of the deposition deck against N at a fixed floor area, sleeping off and on, the two runs
# of each N started together (one per core, so both see the same machine).
#   bench/sleep/growth.sh [build-dir] [-var NAME VALUE ...]      (env NS="250 1000", L_RP=10,
#   DECK=another deck, SLEEPS="no yes": the deck's sleep values of the two series; "no auto" makes
#   the second the deck's defaults)
# Prints per N: user CPU, steps, CPU per step of each setting, and CPU(N) / CPU(N_first) of each.
# With sleeping on, also the cost per step against the number of awake atoms, from the thermo
# lines (CPU and f_sleep columns) of the largest N.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=${DECK:-$here/../../python/granular_charged/decks/in.deposition}
build=$(cd "${1:-$here/../../build}" && pwd); shift || true
vars=("$@")
ns=(${NS:-250 1000}); L=${L_RP:-10}
sl=(${SLEEPS:-no yes}); [ ${#sl[@]} -eq 2 ] || { echo "SLEEPS needs two values"; exit 1; }
out=$(mktemp -d)
run() {    # tag N sleep
  mkdir -p "$out/$1"
  local TIMEFORMAT=%U
  { time LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$build/lmp" -in "$deck" \
      -var out "$out/$1" -log "$out/$1/log.lammps" -screen none -var N "$2" -var L_rp "$L" \
      -var seed 1 -var sleep "$3" "${vars[@]}"; } 2> "$out/$1/user"
}
for n in "${ns[@]}"; do
  run "${sl[0]}$n" "$n" "${sl[0]}" &
  run "${sl[1]}$n" "$n" "${sl[1]}" &
  wait
done
for s in "${sl[@]}"; do
  first=""
  for n in "${ns[@]}"; do
    u=$(tail -n 1 "$out/$s$n/user")
    steps=$(sed -n 's/^GC RESULT steps \([0-9]*\).*/\1/p' "$out/$s$n/log.lammps" | tail -n 1)
    res=$(sed -n 's/^GC RESULT .* phi \([^ ]*\) Z \([^ ]*\).*/phi \1 <Z> \2/p' "$out/$s$n/log.lammps" | tail -n 1)
    [ -z "$first" ] && first=$u
    awk -v s=$s -v n=$n -v u=$u -v st=$steps -v f=$first -v r="$res" -v L=$L \
      'BEGIN {printf "sleep %-3s N %6d L %s r_p: %8.2f s user CPU, %8d steps, %.4f ms/step, CPU / CPU(first N) %.2f, %s\n", s, n, L, u, st, 1e3*u/st, u/f, r}'
  done
done
# cost per step against awake atoms (second series, largest N): thermo rows step ... cpu f_sleep
n=${ns[-1]}
echo "cost per step vs awake atoms (sleep ${sl[1]}, N = $n): awake  ms/step"
awk '/^ *Step/ {h=1; next} /^Loop time/ {h=0} h && NF >= 9 && $1 ~ /^[0-9]+$/ {
       if (ps != "" && $1 > ps && $8 >= pc) printf "  %6d  %.4f\n", $9, 1e3*($8-pc)/($1-ps); ps=$1; pc=$8 }' \
  "$out/${sl[1]}$n/log.lammps" | head -60
rm -rf "$out"
