#!/usr/bin/env bash
# The README's test command on a busy machine: `make test` with two CPU-bound processes beside
# it (one per core of a 2-core machine), as a hang-guard check of the per-test timeouts. Prints
# the wall time and make's exit status; the busy processes end with the script.
#   scripts/test_loaded.sh [make arguments, e.g. LAMMPS_VERSION=20250204]
set -uo pipefail
cd "$(dirname "$0")/.."
busy=()
for _ in 1 2; do
  ( while :; do :; done ) &
  busy+=($!)
done
trap 'kill "${busy[@]}" 2>/dev/null' EXIT
start=$(date +%s)
make test "$@"
status=$?
echo "make test with two CPU-bound processes beside it: exit $status after $(( $(date +%s) - start )) s"
exit $status
