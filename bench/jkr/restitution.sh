#!/usr/bin/env bash
# Apparent restitution of damping marshall without adhesion (gamma = 0): a sphere hits the
# jkr/marshall floor head-on at 1 m/s (in.rebound, dt = t_c / 160); rebound speed / impact
# speed for restitution coefficients e from 0 to 0.9.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lmp=${LMP:-$here/../../build/lmp}
echo "| e | rebound / impact |"
echo "|---|---|"
for e in 0 0.01 0.02 0.05 0.1 0.2 0.3 0.5 0.7 0.9; do
  v=$("$lmp" -in "$here/in.rebound" -var dt_div 160 -var U 1.0 -var gamma 0 -var e "$e" -log none -echo none | awk '/^RESULT/ {print $9}')
  awk -v e="$e" -v v="$v" 'BEGIN {printf "| %s | %.4f |\n", e, v}'
done
