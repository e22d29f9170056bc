#!/usr/bin/env bash
# The same deposition with two builds, started together (one per core), so that both see the
# same machine: prints the user CPU seconds of each and their ratio, both GC RESULT lines (and
# GC COUL lines: fix coul/fmm's evaluations) and whether they and the final dumps are identical.
#   bench/deposition/ab.sh <build-dir before> <build-dir after> [-var NAME VALUE ...]
# e.g. bench/deposition/ab.sh /tmp/before build -var N 500 -var L_rp 14 -var q 400 -var seed 1
# (a build dir holds lmp and liblammps.so.0; the deck is this checkout's, or for the build
# before DECK_BEFORE=<another deck>: e.g. the same build twice with two decks)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/../../python/granular_charged/decks/in.deposition
deck_before=$(realpath "${DECK_BEFORE:-$deck}")
before=$(cd "$1" && pwd); after=$(cd "$2" && pwd); shift 2
vars=("$@")
out=$(mktemp -d)
run() {    # tag build-dir deck
  mkdir -p "$out/$1"
  local TIMEFORMAT=%U
  { time LD_LIBRARY_PATH="$2${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
      "$2/lmp" -in "$3" -var out "$out/$1" -log "$out/$1/log.lammps" -screen none \
      "${vars[@]}"; } 2> "$out/$1/user"
}
run before "$before" "$deck_before" &
run after "$after" "$deck" &
wait
for tag in before after; do
  steps=$(sed -n 's/^GC RESULT steps \([0-9]*\).*/\1/p' "$out/$tag/log.lammps" | tail -n 1)
  phi=$(sed -n 's/^GC RESULT .* phi \([^ ]*\) Z \([^ ]*\).*/\1, <Z> \2/p' "$out/$tag/log.lammps" | tail -n 1)
  echo "$tag: $(tail -n 1 "$out/$tag/user") s user CPU, $steps steps, phi $phi"
done
for tag in before after; do
  echo "$tag: $(grep '^GC RESULT' "$out/$tag/log.lammps" | tail -n 1)"
done
# fix coul/fmm's evaluations (charged runs only)
for tag in before after; do
  coul=$(grep '^GC COUL' "$out/$tag/log.lammps" | tail -n 1 || true)
  [ -z "$coul" ] || echo "$tag: $coul"
done
if [ "$(grep '^GC RESULT' "$out/before/log.lammps" | tail -n 1)" = \
     "$(grep '^GC RESULT' "$out/after/log.lammps" | tail -n 1)" ]; then
  echo "GC RESULT: identical"
else
  echo "GC RESULT: differs"
fi
if cmp -s "$out/before/final.dump" "$out/after/final.dump"; then
  echo "final.dump: identical"
else
  echo "final.dump: differs"
fi
awk -v a="$(tail -n 1 "$out/after/user")" -v b="$(tail -n 1 "$out/before/user")" 'BEGIN {printf "after / before %.3f\n", a/b}'
rm -rf "$out"
