#!/usr/bin/python3
"""Error of `fix coul/fmm ... every N`: between evaluations the field of the last evaluation is
applied, so the force error after k steps is |q (E(t0 + k dt) - E(t0))|. Measured on the
deposition geometry (bench_coulomb.py's data, N = 2000, q = 400 e_0, r_p = 1 um) with particles
moving at the paper's injection speed U_0 = 1 m/s in random directions and dt = 2e-9 s (the
contact-resolving step of the paper's set-up, doc/theory.md, eq. (1.10)).

Usage: . build/env.sh && /usr/bin/python3 bench/coulomb/every_error.py
"""
import os
import sys
import tempfile

import numpy as np
from lammps import lammps

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_coulomb import write_data  # noqa: E402


def main(n=2000, kmax=50):
    tmp = tempfile.mkdtemp(prefix="gc-every-")
    data = os.path.join(tmp, "data")
    write_data(data, n)
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
    lmp.commands_string(f"""
units si
atom_style charge
atom_modify map array sort 0 0
boundary p p f
read_data {data}
mass * 1.047e-14
velocity all create 1 4711 dist uniform loop geom
fix nve all nve
timestep 2e-9
fix coul all coul/fmm accuracy 1e-6 farfield exact
run 0 post no
""")
    # set every speed to 1 m/s in its random direction
    v = lmp.numpy.extract_atom("v")
    v /= np.linalg.norm(v, axis=1)[:, None]
    q = np.array(lmp.numpy.extract_atom("q"))
    lmp.command("run 0 post no")
    e0 = np.array(lmp.numpy.extract_fix("coul", 1, 2)[:, :3]) * q[:, None]
    print("| steps since evaluation k | time (ns) | relative RMS force error |")
    print("|---|---|---|")
    for k in range(1, kmax + 1):
        lmp.command("run 1 post no")
        ek = np.array(lmp.numpy.extract_fix("coul", 1, 2)[:, :3]) * q[:, None]
        err = np.sqrt(((ek - e0) ** 2).sum() / (ek**2).sum())
        if k in (1, 2, 5, 10, 20, 50):
            print(f"| {k} | {2*k} | {err:.2e} |")
    lmp.close()


if __name__ == "__main__":
    main()
