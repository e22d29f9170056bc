#!/usr/bin/env bash
# `make demo`'s command with two versions of the Python package (and one build), in turn, on an
# otherwise quiet machine: before, after, before, after ... (PAIRS pairs, default 2), each from
# an empty output folder. Prints each demo's wall time, the ratio after / before pair by pair,
# and whether the two demos' tables (summary.csv, table2.csv) are the same.
#   bench/demo/ab.sh <package dir before> <package dir after> <build dir> [demo args ...]
# e.g. git worktree add /tmp/before HEAD~1 && bench/demo/ab.sh /tmp/before/python python build
set -euo pipefail
before=$(cd "$1" && pwd); after=$(cd "$2" && pwd); build=$(cd "$3" && pwd); shift 3
args=("$@")
out=$(mktemp -d)
demo() {    # tag package-dir pair
  local dir=$out/$1.$3
  local t0
  t0=$(date +%s.%N)
  PATH="$build:$PATH" PYTHONPATH="$build/python:$2" OMPI_ALLOW_RUN_AS_ROOT=1 \
    OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 /usr/bin/python3 -m granular_charged demo \
    --build-dir "$build" --jobs 2 --out "$dir" "${args[@]}" > "$dir.log" 2>&1
  awk -v t0="$t0" -v t1="$(date +%s.%N)" 'BEGIN {print t1 - t0}'
}
for pair in $(seq "${PAIRS:-2}"); do
  b=$(demo before "$before" "$pair" "$@")
  a=$(demo after "$after" "$pair" "$@")
  awk -v p="$pair" -v a="$a" -v b="$b" \
    'BEGIN {printf "pair %d: before %.1f s, after %.1f s, after / before %.3f\n", p, b, a, a / b}'
done
# the same tables, wall times aside
/usr/bin/python3 - "$out/before.1" "$out/after.1" <<'PY'
import sys
import pandas as pd
for f in ("summary.csv", "table2/table2.csv"):
    a, b = (pd.read_csv(f"{d}/{f}") for d in sys.argv[1:3])
    a, b = (t.drop(columns=[c for c in t.columns if c.startswith("wall")]) for t in (a, b))
    print(f"{f}:", "the same" if a.equals(b) else f"differs ({sys.argv[1]}, {sys.argv[2]})")
PY
