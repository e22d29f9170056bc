#!/usr/bin/env python3
"""Time each packing-analysis compute against 10 steps of pair granular on the same bed.

Usage (from the build folder's environment, e.g. `. build-computes/env.sh`):
    /usr/bin/python3 bench/bench_computes.py [--nx 100] [--nz 20] [--rmax 3] [--reps 3]

For each compute: 'cold' = first invocation after a reneighboring (includes the build of its
occasional neighbor list; rdf/slab's list reaches rmax, 50 bins per diameter), 'warm' = later
invocations before the next reneighboring (the list is reused, as LAMMPS's compute rdf does).
Reference: wall time of `run 10` (10 full MD steps) and LAMMPS's Pair time of those 10 steps
(average over ranks). Best of --reps. Under mpirun, rank 0 reports.
"""
import argparse
import os
import re
import time

from lammps import LMP_STYLE_GLOBAL, LMP_STYLE_ATOM, LMP_TYPE_ARRAY, LMP_TYPE_SCALAR, LMP_TYPE_VECTOR, lammps

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--nx", type=int, default=100)
ap.add_argument("--nz", type=int, default=20)
ap.add_argument("--reps", type=int, default=3)
ap.add_argument("--rmax", type=float, default=3.0, help="rdf/slab range in diameters")
ap.add_argument("--log", default="bench_computes.log")
a = ap.parse_args()

t0 = time.perf_counter()
lmp = lammps(cmdargs=["-log", a.log, "-screen", "none", "-var", "nx", str(a.nx), "-var", "nz", str(a.nz),
                        "-var", "rmax", str(a.rmax)])
lmp.file(os.path.join(here, "bench_computes.in"))
lmp.command("run 0 post no")
natoms = lmp.get_natoms()
me = lmp.extract_setting("world_rank")
nprocs = lmp.extract_setting("world_size")
if me != 0:
    print = lambda *args, **kw: None    # noqa: E731  report from rank 0 only
print(f"{nprocs} MPI rank(s)")
print(f"bed: {natoms} spheres, set-up {time.perf_counter() - t0:.1f} s")

def pair_time_of_last_run():
    with open(a.log) as fh:
        txt = fh.read()
    m = re.findall(r"^Pair\s*\|\s*[\d.eE+-]+\s*\|\s*([\d.eE+-]+)", txt, re.M)
    return float(m[-1])

run10, pair10 = [], []
for _ in range(a.reps):
    t = time.perf_counter()
    lmp.command("run 10 pre no post yes")
    run10.append(time.perf_counter() - t)
    pair10.append(pair_time_of_last_run())

outputs = {"zgeo": (LMP_STYLE_ATOM, LMP_TYPE_VECTOR), "zact": (LMP_STYLE_ATOM, LMP_TYPE_VECTOR),
           "phi": (LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR), "gr": (LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY)}
extra = {"zgeo": (LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY), "zact": (LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY)}
cold = {k: [] for k in outputs}
warm = {k: [] for k in outputs}
for _ in range(a.reps):
    lmp.command("run 0 post no")          # reneighbors: occasional lists must be rebuilt
    for k, (style, typ) in outputs.items():
        t = time.perf_counter()
        lmp.extract_compute(k, style, typ)
        if k in extra:
            lmp.extract_compute(k, *extra[k])
        cold[k].append(time.perf_counter() - t)
    lmp.command("run 1 pre no post no")   # next step, no reneighboring (atoms barely move)
    for k, (style, typ) in outputs.items():
        t = time.perf_counter()
        lmp.extract_compute(k, style, typ)
        if k in extra:
            lmp.extract_compute(k, *extra[k])
        warm[k].append(time.perf_counter() - t)

zg = lmp.extract_compute("zgeo", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR)
za = lmp.extract_compute("zact", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR)
ph = lmp.extract_compute("phi", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR)
print(f"<Z> geometric {zg:.3f}, active {za:.3f}, phi {ph:.4f}")
r10, p10 = min(run10), min(pair10)
print(f"10 steps: run {r10:.3f} s (pair {p10:.3f} s)")
print(f"{'compute':<24}{'cold [s]':>10}{'warm [s]':>10}{'cold/run10':>12}{'cold/pair10':>12}")
names = {"zgeo": "coord/dist geometric", "zact": "coord/dist active", "phi": "packing/slab",
         "gr": f"rdf/slab rmax {a.rmax:g} d"}
for k in outputs:
    c, w = min(cold[k]), min(warm[k])
    print(f"{names[k]:<24}{c:>10.4f}{w:>10.4f}{c / r10:>12.3f}{c / p10:>12.3f}")
lmp.close()
lmp.finalize()
