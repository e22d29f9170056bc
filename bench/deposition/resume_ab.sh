#!/usr/bin/env bash
# Two builds continue the same deposition from one of its restart points, side by side (one per
# core), for the next K particles: the cost of a late stretch of a long run (a paper-size
# one-at-a-time deposition spends most of its hours there, with a tall bed at rest). Prints the
# user CPU seconds of each, their ratio, and whether the two continuations ended in the same
# state (final positions identical when both builds compute the same numbers).
#   bench/deposition/resume_ab.sh <run folder with a restart point> <build before> <build after>
#                                 [K (default 50)] [-var NAME VALUE ...: the run's deck variables]
# The continuations stop at the first restart point at or after particle k + K (restart points
# every `checkpoint` particles: pass -var checkpoint to choose).
# The run folder is that of a `granular-charged run --checkpoint` still under way (its
# checkpoint.vars and checkpoint-<k>.restart are copied, not changed); the deck variables must be
# the run's own (its log.lammps shows them, or result.json's params), e.g. for a sequential run
#   bench/deposition/resume_ab.sh runs/rp2um_U1_g10mJ_q400_N2000_s2_exact_injectsequential \
#     /tmp/before build 50 -var rp 2e-06 -var U0 1.0 -var gamma 0.01 -var q 400.0 -var N 2000 \
#     -var seed 2 -var inject sequential -var checkpoint 50
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/../../python/granular_charged/decks/in.deposition
src=$(cd "$1" && pwd)
before=$(cd "$2" && pwd); after=$(cd "$3" && pwd); shift 3
count=50
if [[ $# -gt 0 && $1 != -var ]]; then count=$1; shift; fi
vars=("$@")
k=$(sed -n 's/^variable ck_k equal \([0-9]*\)$/\1/p' "$src/checkpoint.vars")
[[ -n $k && -f $src/checkpoint-$k.restart ]] || { echo "no restart point in $src" >&2; exit 1; }
out=$(mktemp -d)
run() {    # tag build-dir
  mkdir -p "$out/$1"
  cp "$src/checkpoint.vars" "$src/checkpoint-$k.restart" "$out/$1/"
  local TIMEFORMAT=%U
  { time (cd "$out/$1" && LD_LIBRARY_PATH="$2${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
      "$2/lmp" -in "$deck" -var out . -log log.lammps -screen none \
      "${vars[@]}" -var resume yes -var checkpoint_stop $((k + count))); } 2> "$out/$1/user"
}
run before "$before" &
run after "$after" &
wait
ck() { sed -n "s/^variable $2 equal \\([0-9]*\\)$/\\1/p" "$1/checkpoint.vars"; }
for tag in before after; do
  grep -q "GC CHECKPOINT STOP" "$out/$tag/log.lammps" || { echo "$tag did not reach particle $((k + count)):" >&2; tail -n 5 "$out/$tag/log.lammps" >&2; exit 1; }
  # the run stops at the first restart point at or after k + count (every `checkpoint` particles)
  last=$(ck "$out/$tag" ck_k)
  echo "$tag: $(tail -n 1 "$out/$tag/user") s user CPU, particles $((k + 1))-$last, steps $(ck "$src" ck_step)-$(ck "$out/$tag" ck_step)"
done
if cmp -s "$out/before/checkpoint-$last.restart" "$out/after/checkpoint-$last.restart"; then
  echo "same restart file at particle $last"
else
  echo "restart files at particle $last differ"
fi
awk -v a="$(tail -n 1 "$out/after/user")" -v b="$(tail -n 1 "$out/before/user")" 'BEGIN {printf "after / before %.3f\n", a/b}'
rm -rf "$out"
