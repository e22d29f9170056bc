"""Parameter sweeps over q, r_p, U_0, gamma (and seeds): one folder and one result.json per run,
finished runs skipped (resumable), a progress bar with runs done/total, elapsed time and ETA,
and one log line per finished run.

The paper's full set (its Figs. 2, 3a-c, 5a-c, 9, 10; N = 2000, L = 28 r_p, hours):
  granular-charged sweep --preset paper --N 2000 --seeds 1 2 3 --out paper-results --figures paper-figures
(`granular-charged reproduce --size paper` runs these and more neutral cases, then the claims).
"""
from __future__ import annotations

import itertools
import logging
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path
from types import MappingProxyType

from tqdm import tqdm
from tqdm.contrib.logging import logging_redirect_tqdm

from .params import DepositionParams
from .runner import RunError, Runner, load_result_files

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
    """Runs a list of depositions into ``out`` (one folder each), resumably."""

    def __init__(self, runner: Runner, out: Path, jobs: int = 1, keep_going: bool = True,
                 progress: bool = True):
        self.runner = runner
        self.out = Path(out)
        self.jobs = max(1, jobs)
        self.keep_going = keep_going
        self.progress = progress

    def run(self, params: list[DepositionParams], tracer=0, on_result=None) -> list[dict]:
        """Run every parameter set not finished before; return all results (finished before
        and new) in the order of params, failed runs left out (logged). ``tracer``: particle id
        to follow, or a function of the DepositionParams giving it. ``on_result(p, result)``:
        called in this thread for each result as soon as it is there (finished before: first)."""
        on_result = on_result or (lambda p, r: None)
        for p in params:          # every run checked before the first starts
            self.runner.check(p, tracer(p) if callable(tracer) else tracer)
        self.out.mkdir(parents=True, exist_ok=True)
        results: dict[int, dict] = {}
        todo = []
        for k, p in enumerate(params):
            r = self.runner.finished(p, self.out)
            if r is not None:
                r["skipped"] = True
                r["dir"] = str(self.runner.workdir(p, self.out))
                results[k] = r
                on_result(p, r)
            else:
                todo.append((k, p))
        n = len(params)
        log.info("sweep: %d runs, %d finished before (skipped), %d to run, %d at a time, "
                 "%d MPI rank(s) each, in %s", n, n - len(todo), len(todo), self.jobs,
                 self.runner.np_ranks, self.out)

        def one(kp):
            k, p = kp
            tr = tracer(p) if callable(tracer) else tracer
            return k, p, self.runner.deposition(p, self.out, tracer=tr)

        failed = []
        t0 = time.monotonic()
        new_done = 0

        def eta() -> str:
            # runs done/total, elapsed, ETA from the mean time of this session's runs
            el = time.monotonic() - t0
            left = len(todo) - new_done
            rem = el / new_done * left if new_done else float("nan")
            return (f"[{n - left}/{n} runs, elapsed {tqdm.format_interval(el)}, ETA "
                    f"{tqdm.format_interval(rem) if new_done else '?'}]")

        # tqdm: runs done/total, elapsed and ETA; finished-before runs are the bar's initial
        # count, so they do not make the rate (and the ETA) look faster than it is
        with logging_redirect_tqdm(), tqdm(total=n, initial=n - len(todo), unit="run",
                                           desc="sweep", disable=not self.progress or not todo,
                                           dynamic_ncols=True) as bar:
            def finished(k, p, r, err):
                nonlocal new_done
                new_done += 1
                bar.update(1)
                if err is not None:
                    failed.append(str(err))
                    log.error("run FAILED %s: %s", eta(), err)
                    if not self.keep_going:
                        raise err
                    return
                results[k] = r
                on_result(p, r)
                log.info("%s %s  %6.1f s  phi = %s  <Z> = %s  lost %d  flying %d", eta(),
                         p.key(), r["wall_s"], fmt(r["phi"], ".4f"), fmt(r["Z"], ".3f"),
                         r["lost"], r["flying"])

            if self.jobs == 1:
                # in this thread: Ctrl-C (KeyboardInterrupt) stops the running LAMMPS child
                # (subprocess.run kills it) and leaves its folder without result.json
                for kp in todo:
                    try:
                        done = one(kp)
                    except RunError as e:
                        finished(*kp, None, e)
                        continue
                    finished(*done, None)
            else:
                ex = ThreadPoolExecutor(self.jobs)
                try:
                    futs = {ex.submit(one, kp): kp for kp in todo}
                    for f in as_completed(futs):
                        try:
                            done = f.result()
                        except RunError as e:
                            finished(*futs[f], None, e)
                            continue
                        finished(*done, None)
                finally:
                    ex.shutdown(wait=True, cancel_futures=True)
        if failed:
            log.warning("sweep: %d of %d runs failed", len(failed), n)
        return [results[k] for k in sorted(results)]


def fmt(v, spec: str) -> str:
    """A number for a log line; 'none' for a missing one (a bed too thin for the slab)."""
    return "none" if v is None or v != v else format(v, spec)


def load_results(out: Path) -> list[dict]:
    """Every complete, usable result.json under out/*/ (with 'dir', its folder); the others are
    named in a warning and left out."""
    return [r for r in load_result_files(Path(out).glob("*/result.json")) if r.get("complete")]

