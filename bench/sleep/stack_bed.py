#!/usr/bin/python3
"""A LAMMPS data file of COPIES copies of a deposition's final packing stacked in z: each copy
2 r_p above the top of the one below, with 40 r_p of room above the top (the tall-bed benches
tall.sh and bury.sh).

    bench/sleep/stack_bed.py <final.dump (id type x y z radius q)> COPIES <out.data>
"""
import sys

import numpy as np


def main(dump: str, copies: int, out: str):
    with open(dump) as f:
        lines = f.readlines()
    box = [list(map(float, lines[5 + k].split()[:2])) for k in range(3)]
    a = np.loadtxt(lines[9:], ndmin=2)
    rp = a[:, 5].max()
    dz = a[:, 4].max() + 2.0 * rp
    rows = []
    for c in range(copies):
        for r in a:
            rows.append((len(rows) + 1, int(r[1]), r[2], r[3], r[4] + c * dz, 2.0 * r[5], 2500.0,
                         r[6]))
    ztop = max(r[4] for r in rows) + 40.0 * rp
    with open(out, "w") as f:
        f.write(f"stacked bed: {copies} copies of {dump}\n\n{len(rows)} atoms\n1 atom types\n\n")
        f.write(f"{box[0][0]!r} {box[0][1]!r} xlo xhi\n{box[1][0]!r} {box[1][1]!r} ylo yhi\n"
                f"0.0 {ztop!r} zlo zhi\n\nAtoms # hybrid\n\n")
        for r in rows:
            f.write("%d %d %.12g %.12g %.12g %.12g %.12g %.12g\n" % r)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3])
