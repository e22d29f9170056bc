#!/usr/bin/env bash
# Rebound speed of one adhesive floor impact (in.rebound) for time steps t_c / dt_div and
# impact speeds U; the last column is the relative deviation from dt_div 160.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
echo "| U (m/s) | dt_div | rebound speed (m/s) | vs dt_div 160 |"
echo "|---|---|---|---|"
for U in 1.0 0.7 0.5; do
  ref=$("$lmp" -in "$here/in.rebound" -var dt_div 160 -var U "$U" -log none -echo none | awk '/^RESULT/ {print $9}')
  for d in 10 15 20 40 80 160; do
    v=$("$lmp" -in "$here/in.rebound" -var dt_div "$d" -var U "$U" -log none -echo none | awk '/^RESULT/ {print $9}')
    awk -v U="$U" -v d="$d" -v v="$v" -v r="$ref" 'BEGIN {printf "| %s | %s | %.4f | %+.1f%% |\n", U, d, v, 100 * (v - r) / r}'
  done
done
