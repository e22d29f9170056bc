#!/usr/bin/env bash
# The Table 2 relaxation (in.charged-after-formation) with the demo's former fixed Coulomb
# interval (every 10, no near refresh, no adaptation) and with the deck's defaults, started
# together (one per core): user CPU of each, their ratio, phi after and the measured
# time-stepping error (coul_check; 0 when not asked for).
#   bench/deposition/table2_ab.sh <final.restart of a neutral deposition> [-var NAME VALUE ...]
# e.g. bench/deposition/table2_ab.sh run/final.restart -var q_after 400 -var coul_check 97
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/../../python/granular_charged/decks/in.charged-after-formation
lmp=${LMP:-$here/../../build/lmp}
restart=$(realpath "$1"); shift
vars=("$@")
out=$(mktemp -d)
run() {    # tag extra-vars...
  local tag=$1; shift
  mkdir -p "$out/$tag"
  local TIMEFORMAT=%U
  { time LD_LIBRARY_PATH="$(dirname "$lmp")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
      "$lmp" -in "$deck" -var restart "$restart" -var out "$out/$tag" -log "$out/$tag/log.lammps" \
      -screen none "${vars[@]}" "$@"; } 2> "$out/$tag/user"
}
run every10 -var coul_every 10 -var coul_tol 0 -var coul_near 0 &
run defaults &
wait
for tag in every10 defaults; do
  phi=$(sed -n 's/^GC AFTER .* phi_after \([^ ]*\) .*/\1/p' "$out/$tag/log.lammps" | tail -n 1)
  # the last thermo line before "Loop time": f_coul[7] (error of all checks), [8] interval, [10] evaluations
  tail=$(grep -B1 '^Loop time' "$out/$tag/log.lammps" | tail -n 2 | head -n 1 | awk '{print $(NF-2), $(NF-1), $NF}')
  echo "$tag: $(tail -n 1 "$out/$tag/user") s user CPU, phi after $phi, error / interval / evaluations: $tail"
done
awk -v a="$(tail -n 1 "$out/defaults/user")" -v b="$(tail -n 1 "$out/every10/user")" 'BEGIN {printf "defaults / every10 %.3f\n", a/b}'
rm -rf "$out"
