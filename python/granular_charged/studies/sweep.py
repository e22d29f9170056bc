"""Parameter sweeps over q, r_p, U_0, gamma (and seeds): one folder and one result.json per run,
run by the workflow engine (granular_charged.studies.engine): finished runs kept (resumable), a
progress bar with runs done/total, elapsed time and ETA, and one log line per finished run.

The paper's full set (its Figs. 2, 3a-c, 5a-c, 9, 10; N = 2000, L = 28 r_p, hours):
  granular-charged sweep --preset paper --N 2000 --seeds 1 2 3 --out paper-results --figures paper-figures
(`granular-charged reproduce --size paper` runs these and more neutral cases, then the claims).
"""
from __future__ import annotations

import itertools
import logging
from pathlib import Path
from types import MappingProxyType

from ..params import DepositionParams
from ..run.runner import Runner, load_result_files, read_result, run_folder
from .engine import Engine, deposition_cases

log = logging.getLogger(__name__)

# The paper's cases (its Figs. 2, 3a-c, 5a-c, 9, 10), N = 2000, L = 28 r_p, H = 160 r_p.
# Charges stay below E* = 1 (doc/theory.md, eq. (2.3)) for each (r_p, U_0).
PAPER_SETS = tuple(MappingProxyType(s) for s in (
    dict(rp=2e-6, U0=1.0, gamma=0.010, q=[0, 100, 200, 260, 330, 400]),   # Figs. 2, 3c, 4, 5a, 7
    dict(rp=1e-6, U0=1.0, gamma=0.010, q=[0, 30, 60, 90, 120]),           # Figs. 3a, 5c
    dict(rp=1e-6, U0=2.0, gamma=0.010, q=[0, 60, 120, 180, 240]),         # Fig. 3b
    dict(rp=2e-6, U0=0.5, gamma=0.010, q=[0, 100, 200]),                  # Fig. 5b
    dict(rp=2e-6, U0=1.0, gamma=0.015, q=[0, 260, 400]),                  # Ad* spread (Fig. 9)
    dict(rp=5e-6, U0=1.0, gamma=0.010, q=[0, 1000, 2000]),                # r_p = 5 um (Table 1)
))


def expand(sets, N, seeds, extra, fields=None) -> list[DepositionParams]:
    """Every combination of each set's values and the seeds, as DepositionParams (each run
    once). ``fields``: other DepositionParams fields for every run (e.g. rho)."""
    def as_list(v):
        return list(v) if isinstance(v, (list, tuple)) else [v]
    out = []
    for s in sets:
        for rp, U0, gamma, q, seed in itertools.product(
                as_list(s["rp"]), as_list(s["U0"]), as_list(s["gamma"]), as_list(s["q"]), seeds):
            out.append(DepositionParams(rp=rp, U0=U0, gamma=gamma, q=q, N=N, seed=seed,
                                        extra=dict(extra), **(fields or {})))
    # a value given twice (--q 0 0, or in two sets) is one run, counted once in the tables
    return list({p.key(): p for p in out}.values())


class Sweep:
    """Runs a list of depositions into ``out`` (one folder each) through the workflow engine
    (engine.Engine: locally ``jobs`` at a time, or on a cluster); finished runs are kept."""

    def __init__(self, runner: Runner, out: Path, jobs: int = 1, keep_going: bool = True,
                 progress: bool = True, engine: Engine | None = None):
        self.runner = runner
        self.out = Path(out)
        self.engine = engine or Engine(jobs=max(1, jobs), progress=progress)
        self.engine.keep_going = keep_going

    def run(self, params: list[DepositionParams], tracer=0) -> list[dict]:
        """Run every parameter set not finished before; return all results (finished before
        and new) in the order of params, failed runs left out (logged). ``tracer``: particle id
        to follow, or a function of the DepositionParams giving it."""
        for p in params:          # every run checked before the first starts
            self.runner.check(p, tracer(p) if callable(tracer) else tracer)
        cases = in_run_folders(deposition_cases(params, "", self.runner.np_ranks, tracer,
                                                [self.out]), params, self.out)
        self.engine.run(self.out, cases, self.runner, describe=describe_result)
        return finished_results(params, self.out)


def in_run_folders(cases, params, root: Path) -> list:
    """The deposition cases (of params, in that order) in their runs' folders under root
    (runner.run_folder: a run kept under the long key of earlier versions is resumed there)."""
    for c, p in zip(cases, params):
        parent = str(Path(c.folder).parent)
        name = run_folder(p, root).name
        c.folder = name if parent == "." else f"{parent}/{name}"
    return cases


def finished_results(params, out: Path) -> list[dict]:
    """The finished results of params in their folders under out (runner.run_folder), each
    with 'dir', in the order of params."""
    results = []
    for p in params:
        wd = run_folder(p, out)
        r = read_result(wd / "result.json")
        if r is not None:
            r["dir"] = str(wd)
            results.append(r)
    return results


def describe_result(path: Path) -> str | None:
    """The log line of a finished run: its key, time, phi, <Z>, lost and flying particles."""
    r = read_result(path)
    if r is None:
        return None
    return (f"{r['key']}  {r['wall_s']:6.1f} s  phi = {fmt(r['phi'], '.4f')}  <Z> = "
            f"{fmt(r['Z'], '.3f')}  lost {r['lost']}  flying {r['flying']}")


def fmt(v, spec: str) -> str:
    """A number for a log line; 'none' for a missing one (a bed too thin for the slab)."""
    return "none" if v is None or v != v else format(v, spec)


def load_results(out: Path) -> list[dict]:
    """Every complete, usable result.json under out/*/ (with 'dir', its folder); the others are
    named in a warning and left out."""
    return [r for r in load_result_files(Path(out).glob("*/result.json")) if r.get("complete")]

