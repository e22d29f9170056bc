"""One runner for the studies of the command line (``demo`` and ``reproduce``): the depositions
of a list of cases and seeds (a resumable sweep), runs.csv and summary.csv, the Table 2 check on
the first neutral packing of the Fig. 2 case (or on each, :meth:`Study.table2_seeds`), all in
one folder: one workflow of the engine (granular_charged.studies.engine), in which the Table 2
runs start as soon as their packing is there, beside the remaining depositions. The command
line draws the figures of the result in the same folder (granular_charged.cli.figures).

A study says which runs it wants (:meth:`Study.params`), which particle to follow
(:meth:`Study.tracer`), the charges of its Table 2 check (:meth:`Study.table2_charges`) and what
it computes from the runs besides the summary (:meth:`Study.analyse`); :meth:`Study.run` is the
rest, the same for every study.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..analysis import tables
from ..params import DepositionParams
from ..run.after_formation import load_table2
from ..run.runner import Runner
from .engine import MIN_MINUTES, Engine, deposition_cases, table2_case
from .sweep import describe_result, finished_results, in_run_folders

log = logging.getLogger(__name__)

# the paper's Fig. 2 case, whose first neutral packing the Table 2 check charges
FIG2_CASE = {"rp": DepositionParams.rp, "U0": DepositionParams.U0,
             "gamma": DepositionParams.gamma, "q": 0.0}


def table2_folder(out: Path, seed: int | None) -> Path:
    """Where the Table 2 check of a packing goes: table2/ for the first packing (so a study
    that checks one packing has table2/ alone), table2-s<seed>/ for the others."""
    return Path(out) / ("table2" if seed is None else f"table2-s{seed}")


def table2_folders(out: Path) -> list[Path]:
    """The Table 2 folders under out: table2/ first, then table2-s<seed>/ by seed."""
    others = sorted((d for d in Path(out).glob("table2-s*") if d.is_dir()
                     and d.name[len("table2-s"):].isdigit()),
                    key=lambda d: int(d.name[len("table2-s"):]))
    return [d for d in [Path(out) / "table2"] if d.is_dir()] + others


@dataclass
class Study:
    """Depositions for cases and seeds, then tables and the Table 2 check."""
    out: Path
    seeds: tuple = (1, 2, 3)
    table2_qs: tuple = (0.0, 260.0, 400.0)
    extra: dict = field(default_factory=dict)    # deck variables for every run
    fields: dict = field(default_factory=dict)   # DepositionParams fields for every run (rho, ...)
    jobs: int = 1
    progress: bool = True
    finished_only: bool = False   # run nothing: analyse the runs finished in out so far
    engine: Engine | None = None  # how the runs run (None: locally, `jobs` at a time)

    def __post_init__(self):
        if self.engine is None:
            self.engine = Engine(jobs=self.jobs, progress=self.progress)

    # ---- what a study chooses ----------------------------------------------------------------
    def params(self, have_fmm: bool) -> list[DepositionParams]:
        """The depositions (charged ones only when the build has fix coul/fmm)."""
        raise NotImplementedError

    def tracer(self, p: DepositionParams) -> int:
        """Particle id to follow in run p (0: none)."""
        return 0

    def table2_charges(self) -> tuple:
        return tuple(self.table2_qs)

    def table2_seeds(self) -> tuple:
        """The seeds whose neutral Fig. 2 packings the Table 2 check charges: the first."""
        return tuple(self.seeds[:1])

    def analyse(self, runs, summary, out: Path, results: list[dict]) -> dict:
        """The study's own analyses of the runs (written under out); entries of run()'s result.
        results: the runs' result dicts (with 'dir', their folders)."""
        return {}

    # ---- the same for every study -----------------------------------------------------------
    def run(self, runner: Runner) -> dict:
        t0 = time.monotonic()
        out = Path(self.out).resolve()
        out.mkdir(parents=True, exist_ok=True)
        have_fmm = runner.build.capabilities["coul/fmm"]
        if not have_fmm:
            log.warning("fix coul/fmm is NOT in this build: only the neutral cases run; the "
                        "charged cases need fix coul/fmm (they are not faked)")
        params = self.params(have_fmm)
        t2 = []
        if self.finished_only:
            found = [runner.finished(p, out / "runs") for p in params]
            results = [dict(r, dir=str(runner.workdir(p, out / "runs")))
                       for p, r in zip(params, found) if r is not None]
            log.info("%d of the study's %d runs are finished in %s (--finished-only: nothing "
                     "is run)", len(results), len(params), out / "runs")
            for d in table2_folders(out):
                t2 += load_table2(d)
        else:
            results, t2 = self._run_all(runner, params, out, have_fmm)
        runs = tables.runs_frame(results)
        summ = tables.summary(runs)
        runs.drop(columns=["dir"]).to_csv(out / "runs.csv", index=False)
        summ.to_csv(out / "summary.csv", index=False)
        res = {"out": out, "results": results, "runs": runs, "summary": summ,
               "have_fmm": have_fmm, **self.analyse(runs, summ, out, results)}
        res["table2"] = tables.table2_frame(t2) if t2 else None
        res["table2_rows"] = t2
        res["wall_s"] = time.monotonic() - t0
        res["complete"] = len(results) == len(params)
        res["missing"] = len(params) - len(results)
        return res

    def _run_all(self, runner: Runner, params, out: Path, have_fmm: bool):
        """The depositions and the Table 2 check of each chosen packing, one workflow (the
        engine starts a check as soon as its packing is there, beside the remaining
        depositions); returns the deposition results and the Table 2 rows (packings by seed)."""
        qs = self.table2_charges()
        seeds = self.table2_seeds() if have_fmm and qs else ()
        for p in params:
            runner.check(p, self.tracer(p))
        cases = in_run_folders(deposition_cases(params, "runs", runner.np_ranks, self.tracer,
                                                [out / "runs"]), params, out / "runs")
        checks = []
        for seed in seeds:
            formed = next((c for p, c in zip(params, cases) if p.seed == seed and all(
                getattr(p, k) == v for k, v in FIG2_CASE.items())), None)
            if formed is None:
                log.error("Table 2 check not run for seed %d: its neutral packing of the "
                          "paper's Fig. 2 case is not in this study", seed)
                continue
            folder = table2_folder(Path(""), None if seed == seeds[0] else seed)
            # a relaxation of the formed bed per charge: about a tenth of a deposition each
            checks.append(table2_case(str(folder), formed.folder, qs, {}, runner.np_ranks,
                                      max(MIN_MINUTES, formed.minutes * len(qs) // 10)))
        self.engine.run(out, cases + checks, runner, describe=describe_result)
        results = finished_results(params, out / "runs")
        t2 = []
        for c in checks:
            if (out / c.target).exists():
                t2 += load_table2(out / c.folder)
            else:
                log.error("Table 2 check FAILED or not run: %s", out / c.folder)
        return results, t2
