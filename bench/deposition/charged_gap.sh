#!/usr/bin/env bash
# Where the cost of a charged deposition step goes against a neutral one: the same deck at
# demo size run one after the other with one build, printing user CPU, steps and us per step of
#   neutral          q 0 (rain, the neutral protocol)
#   neutral-plane    q 0 with the charged runs' protocol (plane injection, gap 2)
#   neutral-ghost    as neutral-plane with the ghost cutoff fix coul/fmm sets for the deck's
#                    coul_near (near + skin, the deck copied with a comm_modify cutoff line; the
#                    same as neutral-plane while near + skin is within the pair's cutoff)
#   charged          q 400 (fix coul/fmm: plane injection, near list, evaluations)
# and the ratio of each to the neutral step.
#   bench/deposition/charged_gap.sh <build-dir> [seed] [variant ...]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$(realpath "$here/../../python/granular_charged/decks/in.deposition")
build=$(cd "$1" && pwd); seed=${2:-1}; shift $(( $# >= 2 ? 2 : 1 ))
variants=("$@"); [ ${#variants[@]} -gt 0 ] || variants=(neutral neutral-plane neutral-ghost charged)
out=$(mktemp -d)
# the deck with the ghost cutoff of its near list (near + skin) and nothing else changed
sed 's/^comm_modify     vel yes$/comm_modify     vel yes cutoff $(v_coul_near*v_rp+v_skin)/' "$deck" > "$out/in.ghost"
grep -q 'cutoff \$(v_coul_near\*v_rp+v_skin)' "$out/in.ghost" || { echo "comm_modify line not found in $deck"; exit 1; }
common=(-var N 500 -var L_rp 14 -var seed "$seed")
base=""
for v in "${variants[@]}"; do
  case $v in
    neutral) d=$deck; vars=(-var q 0) ;;
    neutral-plane) d=$deck; vars=(-var q 0 -var inject plane -var gap_rp 2) ;;
    neutral-ghost) d=$out/in.ghost; vars=(-var q 0 -var inject plane -var gap_rp 2) ;;
    charged) d=$deck; vars=(-var q 400) ;;
    *) echo "unknown variant $v"; exit 1 ;;
  esac
  mkdir -p "$out/$v"
  TIMEFORMAT=%U
  { time LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$build/lmp" -in "$d" \
      -var out "$out/$v" -log "$out/$v/log.lammps" -screen none "${common[@]}" "${vars[@]}"; } \
      2> "$out/$v/user"
  user=$(tail -n 1 "$out/$v/user")
  steps=$(sed -n 's/^GC RESULT steps \([0-9]*\).*/\1/p' "$out/$v/log.lammps" | tail -n 1)
  phi=$(sed -n 's/^GC RESULT .* phi \([^ ]*\) Z \([^ ]*\).*/phi \1 <Z> \2/p' "$out/$v/log.lammps" | tail -n 1)
  us=$(awk -v u="$user" -v s="$steps" 'BEGIN {printf "%.1f", 1e6*u/s}')
  [ -n "$base" ] || base=$us
  printf '%-14s %8s s user %9s steps %7s us/step  x%.2f  %s\n' "$v" "$user" "$steps" "$us" \
    "$(awk -v a="$us" -v b="$base" 'BEGIN {print a/b}')" "$phi"
done
rm -rf "$out"
