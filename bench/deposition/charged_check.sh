#!/usr/bin/env bash
# The Coulomb time stepping's measured error over a whole charged deposition: the deck at demo
# size with fix coul/fmm's check keyword (a fresh evaluation every `every` steps compared with
# the field applied), and the last, largest and overall relative RMS error it measured, against
# the tolerance (deck default coul_tol 2e-4). The deck is copied with one print line added after
# its GC COUL line (the loop's thermo does not show the check columns).
#   bench/deposition/charged_check.sh <build-dir> [seed] [every] [-var NAME VALUE ...]
# e.g. with buried sleepers: ... build 1 4099 -var sleep yes -var sleep_bury yes -var sleep_depth 6
# (env N=500 L_RP=14 Q=400: the run's size and charge; KEEP=<folder>: the run's log is kept there)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$(realpath "$here/../../python/granular_charged/decks/in.deposition")
build=$(cd "$1" && pwd); seed=${2:-1}; every=${3:-4099}
shift $(( $# < 3 ? $# : 3 )); extra=("$@")
out=$(mktemp -d)
awk '{print} /^if .*GC COUL evaluations/ {print "print \"GC CHECK last $(f_coul[5]) max $(f_coul[6]) overall $(f_coul[7]) checks every '"$every"'\""}' \
  "$deck" > "$out/in.check"
grep -q 'GC CHECK' "$out/in.check" || { echo "GC COUL line not found in $deck"; exit 1; }
LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$build/lmp" -in "$out/in.check" \
  -var out "$out" -log "$out/log.lammps" -screen none -var N "${N:-500}" -var L_rp "${L_RP:-14}" -var q "${Q:-400}" \
  -var seed "$seed" -var coul_check "$every" "${extra[@]}"
grep -E '^GC (CHECK|COUL|RESULT)' "$out/log.lammps"
[ -n "${KEEP:-}" ] && mkdir -p "$KEEP" && cp "$out/log.lammps" "$KEEP/"
rm -rf "$out"
