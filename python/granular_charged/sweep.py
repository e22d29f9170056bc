"""Parameter sweeps over q, r_p, U_0, gamma (and seeds): one folder and one result.json per
run, finished runs skipped (resumable), a progress line per run.

  /usr/bin/python3 -m granular_charged.sweep --out results --rp 2e-6 --U0 1 --gamma 0.01 \
      --q 0 260 400 --N 2000 --seeds 1 2 3 [--np 2] [--figures figs]
  /usr/bin/python3 -m granular_charged.sweep --preset paper --out paper-results --figures paper-figs
"""
from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from .params import DepositionParams
from .runner import RunError, find_build, lammps_has, run_deposition

# The paper's cases (its Figs. 2, 3a-c, 5a-c, 9, 10), N = 2000, L = 28 r_p, H = 160 r_p.
# Charges stay below E* = 1 (physics.md sec. 2) for each (r_p, U_0).
PAPER_SETS = [
    dict(rp=2e-6, U0=1.0, gamma=0.010, q=[0, 100, 200, 260, 330, 400]),   # Figs. 2, 3c, 4, 5a, 7
    dict(rp=1e-6, U0=1.0, gamma=0.010, q=[0, 30, 60, 90, 120]),           # Figs. 3a, 5c
    dict(rp=1e-6, U0=2.0, gamma=0.010, q=[0, 60, 120, 180, 240]),         # Fig. 3b
    dict(rp=2e-6, U0=0.5, gamma=0.010, q=[0, 100, 200]),                  # Fig. 5b
    dict(rp=2e-6, U0=1.0, gamma=0.015, q=[0, 260, 400]),                  # Ad* spread (Fig. 9)
    dict(rp=5e-6, U0=1.0, gamma=0.010, q=[0, 1000, 2000]),                # r_p = 5 um (Table 1)
]


def expand(sets, N, seeds, extra) -> list[DepositionParams]:
    out = []
    for s in sets:
        for rp, U0, gamma, q, seed in itertools.product(
                _l(s["rp"]), _l(s["U0"]), _l(s["gamma"]), _l(s["q"]), seeds):
            out.append(DepositionParams(rp=rp, U0=U0, gamma=gamma, q=q, N=N, seed=seed,
                                        extra=dict(extra)))
    return out


def _l(v):
    return v if isinstance(v, (list, tuple)) else [v]


def run_sweep(params: list[DepositionParams], out: Path, build=None, np_ranks=1,
              tracer=0, stream=sys.stdout, keep_going=True, jobs=1) -> list[dict]:
    """Run every parameter set not yet finished in out/ (``jobs`` runs at a time, each with
    ``np_ranks`` MPI ranks); print one progress line per run as it finishes."""
    build = find_build(build)
    have_fmm = lammps_has(build, "fix", "coul/fmm")
    results = []
    t_start = time.monotonic()
    n = len(params)
    todo = []
    for k, p in enumerate(params, 1):
        if p.q and not have_fmm:
            print(f"[{k:>3}/{n}] {p.key():<48} NOT RUN: charged runs need fix coul/fmm, absent "
                  f"from {build}", file=stream, flush=True)
        else:
            todo.append((k, p))
    done = 0

    def one(kp):
        k, p = kp
        tr = tracer(p) if callable(tracer) else tracer
        return k, p, run_deposition(p, out, build, np_ranks=np_ranks, tracer=tr)

    with ThreadPoolExecutor(max(1, jobs)) as ex:
        futs = [ex.submit(one, kp) for kp in todo]
        for f in as_completed(futs):
            done += 1
            try:
                k, p, r = f.result()
            except RunError as e:
                print(f"[{done:>3}/{len(todo)}] FAILED: {str(e).splitlines()[0]}", file=stream,
                      flush=True)
                if not keep_going:
                    raise
                continue
            results.append(r)
            el = time.monotonic() - t_start
            state = "skipped (finished before)" if r.get("skipped") else f"{r['wall_s']:7.1f} s"
            print(f"[{done:>3}/{len(todo)}] {p.key():<48} {state}  phi = {r['phi']:.4f}  "
                  f"<Z> = {r['Z']:.3f}  lost {r['lost']}  flying {int(r['deck'].get('flying') or 0)}"
                  f"  | elapsed {el:6.0f} s", file=stream, flush=True)
    return results


def load_results(out: Path) -> list[dict]:
    res = []
    for f in sorted(Path(out).glob("*/result.json")):
        r = json.loads(f.read_text())
        r["dir"] = str(f.parent)
        res.append(r)
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", required=True, help="results folder (one sub-folder per run)")
    ap.add_argument("--build-dir", default=None, help="LAMMPS build (default $GC_BUILD_DIR or build)")
    ap.add_argument("--preset", choices=["paper"], help="the paper's full set of cases")
    ap.add_argument("--rp", type=float, nargs="+", default=[2e-6])
    ap.add_argument("--U0", type=float, nargs="+", default=[1.0])
    ap.add_argument("--gamma", type=float, nargs="+", default=[0.010])
    ap.add_argument("--q", type=float, nargs="+", default=[0.0], help="charges in e_0")
    ap.add_argument("--N", type=int, default=2000)
    ap.add_argument("--seeds", type=int, nargs="+", default=[4711])
    ap.add_argument("--np", type=int, default=1, help="MPI ranks per run (mpirun)")
    ap.add_argument("--jobs", type=int, default=1, help="runs at a time")
    ap.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                    help="any other deck variable, e.g. --var farfield average --var L_rp 14")
    ap.add_argument("--tracer", type=int, default=0, help="follow this particle id (Fig. 8)")
    ap.add_argument("--figures", default=None, help="write the figures of all results here")
    a = ap.parse_args(argv)
    extra = {k: v for k, v in a.var}
    if a.preset == "paper":
        params = expand(PAPER_SETS, a.N, a.seeds, extra)
    else:
        params = expand([dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q)], a.N, a.seeds, extra)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    run_sweep(params, out, a.build_dir, a.np, a.tracer, jobs=a.jobs)
    if a.figures:
        from . import figures
        figures.all_figures(load_results(out), Path(a.figures))
        print(f"figures: {Path(a.figures).resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
