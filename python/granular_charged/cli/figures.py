"""``granular-charged figures``: the figures and summary table of finished runs (also drawn by
``sweep --figures``); the figures of the studies ``demo`` and ``reproduce`` (draw_study) and of
a study file (draw_study_file)."""
from __future__ import annotations

import logging
import time
from pathlib import Path

from ..run.after_formation import load_table2
from ..studies.sweep import load_results
from . import options

log = logging.getLogger("granular_charged")


def register(subparsers):
    p = options.add_command(subparsers, "figures", help="figures and tables of finished runs",
                            description="The paper's figures (PNG + CSV) and the summary table "
                                        "of every finished run under RESULTS (and, with --table2, "
                                        "of a charged-after-formation folder).")
    p.add_argument("results", help="folder of run folders (sweep --out)")
    p.add_argument("--out", required=True, help="folder for the figures")
    p.add_argument("--table2", default=None, metavar="DIR",
                   help="a folder of charged-after-formation runs (demo-output/table2)")
    p.add_argument("--variant", default=None,
                   help="when RESULTS holds runs of several variants (N, non-default material "
                        "or deck variables, e.g. 'N=2000 inject=sequential'): the one to show")
    p.set_defaults(handler=run)


def draw(results, out: Path, t2dir: Path | None, variant: str | None = None):
    """summary.csv (printed) and every figure the runs of one variant allow, in out."""
    # pandas and matplotlib only when figures are drawn: the command line starts without them
    from ..analysis import tables
    from ..figures.plan import all_figures
    results = tables.one_variant(results, variant)
    rows = load_table2(t2dir) if t2dir is not None else []
    out.mkdir(parents=True, exist_ok=True)
    if results:
        s = tables.summary(tables.runs_frame(results))
        s.to_csv(out / "summary.csv", index=False)
        print(tables.format_table(s[["rp_um", "U0", "gamma_mJ", "q", "runs", "phi", "phi_sd", "Z",
                                     "Z_sd", "Adstar", "expansion"]]))
    paths = all_figures(results, out, rows)
    log.info("%d figures in %s", len(paths), out.resolve())
    return paths


def draw_study(res: dict, jobs: int) -> None:
    """The figures of a study's result (Study.run) in its out/figures, by `jobs` processes:
    their paths in res["figures"], their drawing time added to res["wall_s"] (the study's wall
    time is that of the whole command)."""
    from ..figures.plan import all_figures
    t0 = time.monotonic()
    res["figures"] = all_figures(res["results"], Path(res["out"]) / "figures", res["table2_rows"],
                                 jobs=jobs)
    res["wall_s"] += time.monotonic() - t0


def draw_study_file(res: dict) -> None:
    """The figures of a study file's result (studyfile.run) in its out/figures, labelled with
    its name: their paths in res["figures"] (none without finished runs)."""
    from ..figures.studyfile import study_figures
    d = res["study"]
    res["figures"] = (study_figures(d, res["results"], Path(d["out"]) / "figures")
                      if res["results"] else [])


def run(a) -> int:
    out = options.out_dir(a.out)
    results = load_results(Path(a.results))
    if not results:
        log.error("no finished runs (*/result.json) in %s", a.results)
        return 1
    draw(results, out, Path(a.table2) if a.table2 else None, a.variant)
    return 0
