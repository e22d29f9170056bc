#!/usr/bin/env bash
# Regenerate the reference trajectories of the DEM harness cases with the built model:
#   unittest/granular/regenerate.sh <build-dir> [tests/<case>.yaml ...]   (default: all cases)
# Each case is run by its LAMMPS driver with -g (newton on; LAMMPS's own way of writing the
# run_pos/run_vel/run_torque/run_omega blocks), the leading comment block of the file is kept.
# Regenerate only after a deliberate model change, and say why in the commit.
set -euo pipefail
build=$(cd "$1" && pwd); shift
here=$(cd "$(dirname "$0")" && pwd)
cases=("$@")
[[ ${#cases[@]} -gt 0 ]] || cases=("$here"/tests/dem*.yaml)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
for yaml in "${cases[@]}"; do
  nn=$(basename "$yaml" | sed -E 's/^dem([0-9][0-9])-.*/\1/')
  driver=$build/unittest/granular/gc_dem_$nn
  tmp=$(mktemp --suffix=.yaml)
  "$driver" "$yaml" -g "$tmp" > /dev/null
  { sed -n '/^#/p;/^---/q' "$yaml" | grep '^#' || true; cat "$tmp"; } > "$yaml.new"
  mv "$yaml.new" "$yaml"
  rm -f "$tmp"
  echo "regenerated $(basename "$yaml")"
done
