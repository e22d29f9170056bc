"""The README's demo: a REDUCED version of the paper's Fig. 2 study.

  . build/env.sh && /usr/bin/python3 -m granular_charged.demo --build-dir build

Cases: r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2, q = 0, 260, 400 e_0 (the paper's Fig. 2),
with the paper's H = 160 r_p and material (Table 1), but a box of L = 14 r_p and N = 500
particles instead of L = 28 r_p and N = 2000: the same number of particles per unit floor area
(so the same bed height and the same K_eff = 20 N (L/r_p)^-2 = 51 of the paper's E*), a
quarter of the particles. Prints a table and writes the figures into one folder.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from . import figures
from .params import DepositionParams
from .runner import SOURCE_DIR, RunError, find_build, lammps_has
from .sweep import load_results, run_sweep

DEMO_VARS = {"L_rp": 14, "gap_rp": 1, "coul_every": 10}
FULL_COMMAND = ("/usr/bin/python3 -m granular_charged.sweep --preset paper --N 2000 "
                "--seeds 1 2 3 --out paper-results --figures paper-figures")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--build-dir", default=None)
    ap.add_argument("--out", default=str(SOURCE_DIR / "demo-output"))
    ap.add_argument("--N", type=int, default=500)
    ap.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2: both cores)")
    ap.add_argument("--np", type=int, default=1)
    a = ap.parse_args(argv)
    t0 = time.monotonic()
    try:
        build = find_build(a.build_dir)
    except RunError as e:
        print(f"demo: {e}", file=sys.stderr)
        return 2
    out = Path(a.out).resolve()
    runs = out / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    have_fmm = lammps_has(build, "fix", "coul/fmm")
    print("GRANULAR-CHARGED demo: a REDUCED version of the paper's Fig. 2 study")
    print(f"  r_p = 2 um, U0 = 1 m/s, gamma = 10 mJ/m^2, q = {', '.join(f'{q:g}' for q in a.q)} e0;"
          f" N = {a.N} in L = {DEMO_VARS['L_rp']} r_p (paper: N = 2000 in L = 28 r_p, same"
          " particles per floor area), H = 160 r_p,"
          f" seeds {', '.join(map(str, a.seeds))}, {a.jobs} runs at a time")
    if not have_fmm:
        print("  fix coul/fmm is NOT in this build: only the neutral case runs; the charged cases"
              " need fix coul/fmm (they are not faked)")
    qs = a.q if have_fmm else [q for q in a.q if q == 0]
    extra = dict(DEMO_VARS)
    params = [DepositionParams(q=q, N=a.N, seed=s, extra=dict(extra)) for q in qs for s in a.seeds]
    first = a.seeds[0]
    res = run_sweep(params, runs, build, a.np, jobs=a.jobs,
                    tracer=lambda p: a.N // 2 if p.seed == first else 0)
    # figures from these runs only
    keys = {p.key() for p in params}
    results = [r for r in load_results(runs) if r["key"] in keys]
    figdir = out
    paths = figures.all_figures(results, figdir)
    print()
    print(f"{'q/e0':>6} {'runs':>4} {'phi':>7} {'+-sd':>6} {'<Z>':>6} {'+-sd':>6} {'Ad':>6} {'E*':>6} "
          f"{'Ad*':>7} {'N':>5} {'lost':>4} {'wall/s':>7}")
    for q in sorted({r["params"]["q"] for r in results}):
        rs = [r for r in results if r["params"]["q"] == q]
        g = rs[0]["groups"]
        phi = [r["phi"] for r in rs]
        Z = [r["Z"] for r in rs]
        sd = lambda v: statistics.stdev(v) if len(v) > 1 else float("nan")
        print(f"{q:6g} {len(rs):4d} {statistics.fmean(phi):7.4f} {sd(phi):6.4f} "
              f"{statistics.fmean(Z):6.3f} {sd(Z):6.3f} {g['Ad']:6.2f} {g['Estar']:6.3f} "
              f"{g['Adstar']:7.3f} {rs[0]['natoms']:5d} {sum(r['lost'] for r in rs):4d} "
              f"{statistics.fmean(r.get('wall_s') or 0 for r in rs):7.1f}")
    q0 = [r["phi"] for r in results if r["params"]["q"] == 0]
    if q0:
        for q in sorted({r["params"]["q"] for r in results if r["params"]["q"] > 0}):
            phiq = statistics.fmean(r["phi"] for r in results if r["params"]["q"] == q)
            print(f"  q = {q:g} e0: phi_0/phi - 1 = {statistics.fmean(q0) / phiq - 1:+.3f}")
    print()
    print("paper (physics.md sec. 3): neutral phi_0 = 0.270-0.363; charge lowers phi and <Z>;"
          " phi_0/phi - 1 ~ q^2, up to 40 %")
    # the paper's Table 2: charge the formed neutral packing, relax, compare
    neutral = sorted([r for r in results if r["params"]["q"] == 0], key=lambda r: r["params"]["seed"])
    if neutral and have_fmm:
        from .after_formation import run_table2
        print("charged after formation (the paper's Table 2; relaxation 100 r_p/U0 per charge):")
        try:
            rows = run_table2(Path(neutral[0]["dir"]), a.q, out / "table2", build, a.np,
                              {"coul_every": DEMO_VARS["coul_every"]})
            print(f"{'q/e0':>6} {'phi before':>11} {'phi after':>10} {'<Z> before':>11} "
                  f"{'<Z> after':>10} {'F_C/F_E':>9}")
            for r in rows:
                print(f"{r['q']:6g} {r['phi_before']:11.5f} {r['phi_after']:10.5f} "
                      f"{r['Z_before']:11.4f} {r['Z_after']:10.4f} {r['FC_over_FE']:9.3g}")
        except RunError as e:
            print(f"  Table 2 check FAILED: {e}")
        print("paper's Table 2: phi 0.3249 -> 0.3247, <Z> 3.2056 unchanged for q = 0 -> 400 e0")
        print()
    print(f"figures ({len(paths)} PNG + CSV) and tables: {figdir}")
    print(f"this was REDUCED (N = {a.N}, L = {DEMO_VARS['L_rp']} r_p, {len(a.seeds)} seeds, Coulomb force "
          f"recomputed every {DEMO_VARS['coul_every']} steps); the full paper set (N = 2000, "
          "L = 28 r_p, all its cases, 3 seeds; hours) is:")
    print(f"  . build/env.sh && {FULL_COMMAND}")
    if not have_fmm:
        print("NOTE: the charged cases (q != 0) were NOT run: they need fix coul/fmm in the build")
    print(f"demo wall time: {time.monotonic() - t0:.0f} s")
    return 0 if len(results) == len(params) else 1


if __name__ == "__main__":
    sys.exit(main())
