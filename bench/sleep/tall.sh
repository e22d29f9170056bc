#!/usr/bin/env bash
# CPU per step of a charged deposition onto a bed of 1 and COPIES (default 10) stacked copies of
# a paper-size bed (in.tall), sleeping on, both started together; prints the ratio.
#   bench/sleep/tall.sh <run folder of a paper-size q = 400 run (final.restart, particle.mol)> [build-dir]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
run=$(cd "$1" && pwd); build=$(cd "${2:-$here/../../build}" && pwd)
copies=${COPIES:-10}; steps=${STEPS:-20000}
export LD_LIBRARY_PATH="$build${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
out=$(mktemp -d)
# the data file of `c` copies of the final packing (final.dump: id type x y z radius q), each copy
# 2 r_p above the top of the one below, with 40 r_p of room above the top
stack() {
  /usr/bin/python3 - "$run/final.dump" "$1" "$2" <<'PY'
import sys, numpy as np
dump, copies, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
with open(dump) as f:
    lines = f.readlines()
box = [list(map(float, lines[5 + k].split()[:2])) for k in range(3)]
a = np.loadtxt(lines[9:], ndmin=2)
rp = a[:, 5].max()
dz = a[:, 4].max() + 2.0 * rp
rows = []
for c in range(copies):
    for r in a:
        rows.append((len(rows) + 1, int(r[1]), r[2], r[3], r[4] + c * dz, 2.0 * r[5], 2500.0, r[6]))
ztop = max(r[4] for r in rows) + 40.0 * rp
with open(out, "w") as f:
    f.write(f"stacked bed: {copies} copies of {dump}\n\n{len(rows)} atoms\n1 atom types\n\n")
    f.write(f"{box[0][0]!r} {box[0][1]!r} xlo xhi\n{box[1][0]!r} {box[1][1]!r} ylo yhi\n0.0 {ztop!r} zlo zhi\n\nAtoms # hybrid\n\n")
    for r in rows:
        f.write("%d %d %.12g %.12g %.12g %.12g %.12g %.12g\n" % r)
PY
}
for c in 1 "$copies"; do
  stack "$c" "$out/tall.$c.data"
  "$build/lmp" -in "$here/in.tall" -log "$out/log.$c" -screen none -var data "$out/tall.$c.data" \
    -var molfile "$run/particle.mol" -var steps "$steps" -var sleep "${SLEEP:-yes}" &
done
wait
# the measured run is the last "Loop time" of each log
per_step() { awk '/^Loop time of/ {t=$4; n=$9} END {printf "%.4f", 1e3*t/n}' "$1"; }
a=$(per_step "$out/log.1"); b=$(per_step "$out/log.$copies")
for c in 1 "$copies"; do echo "$(grep -h '^TALL' "$out/log.$c") ms_per_step $(per_step "$out/log.$c")"; done
awk -v a="$a" -v b="$b" -v c="$copies" 'BEGIN {printf "per-step time, %s copies / 1 copy: %.2f\n", c, b/a}'
for c in 1 "$copies"; do echo "--- $c copies"; grep -A12 "^Section" "$out/log.$c" | tail -12; done
rm -rf "$out"
