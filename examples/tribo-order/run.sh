#!/bin/bash
# The order of charging: a binary powder (species 1 at contact potential 0 V, species 2 at
# 0.01 V, the floor at 0.005 V; both r_p = 2 um, half and half) deposited on the plane protocol
# (N = 500, L = 14 r_p, seeds 1-3) once injected uncharged and charged by its contacts
# ("tribo"), once with charges given at injection from the distributions the first set ended
# with ("assigned": per species a Gaussian of that mean and standard deviation).
# Usage: run.sh <lmp> <in.deposition> [jobs]; then /usr/bin/python3 analyse.py
set -euo pipefail
lmp=$1; deck=$2; jobs=${3:-2}
common="-var N 500 -var L_rp 14 -var species 2 -var frac 1 -var frac_2 1 -var inject plane"
one() {  # variant seed extra...
  local v=$1 s=$2; shift 2
  mkdir -p "$v-$s"
  (cd "$v-$s" && /usr/bin/time -f "%U" -o cpu.txt "$lmp" -in "$deck" -log log.lammps -screen none \
     $common -var seed "$s" "$@" > /dev/null)
}
export -f one; export lmp deck common
printf '%s\n' 1 2 3 | xargs -P "$jobs" -I{} bash -c \
  'one tribo {} -var tribo yes -var tribo_V 0 -var tribo_V_2 0.01 -var tribo_V_wall 0.005'
# the charges the contacts gave, per species, become the injected ones
read -r q1 sd1 q2 sd2 < <(/usr/bin/python3 "$(dirname "$0")/analyse.py" --final-charges .)
printf '%s\n' 1 2 3 | xargs -P "$jobs" -I{} bash -c \
  "one assigned {} -var q_dist gauss -var q $q1 -var q_sd $sd1 -var q_dist_2 gauss -var q_2 $q2 -var q_sd_2 $sd2"
/usr/bin/python3 "$(dirname "$0")/analyse.py" .
