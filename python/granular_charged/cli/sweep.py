"""``granular-charged sweep``: many depositions (every combination of the values and seeds),
resumable."""
from __future__ import annotations

import logging

from ..run.population import is_charged
from ..run.runner import Runner
from ..studies.axes import announce, sweep_params, var_axes
from ..studies.sweep import PAPER_SETS, Sweep, load_results
from . import options
from .figures import draw

log = logging.getLogger("granular_charged")


def register(subparsers):
    p = options.add_command(subparsers, "sweep", help="many depositions, resumable",
                            description="Every combination of the given values and seeds, one "
                                        "folder each under --out; finished runs are skipped, so "
                                        "an interrupted sweep resumes where it stopped.")
    p.add_argument("--out", required=True, help="results folder (one sub-folder per run)")
    p.add_argument("--preset", choices=["paper"], help="the paper's full set of cases")
    p.add_argument("--seeds", type=options.count, nargs="+", default=[4711],
                   help="seeds of the injection positions")
    options.engine_options(p)
    p.add_argument("--figures", default=None, metavar="DIR", help="then draw the figures here")
    options.deck_options(p, many=True)
    p.set_defaults(handler=run)


def run(a) -> int:
    single, axes = var_axes(a.var, "sweep")
    sets = PAPER_SETS if a.preset == "paper" else [dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q)]
    params = sweep_params(sets, single, axes, options.population_vars(a), options.refused("sweep"),
                          a.N, a.seeds)
    for p in params:
        Runner.check(p, a.tracer)
        options.check_species_values(p)
    announce(params, a.out, a.inject)
    out = options.out_dir(a.out)
    figs = options.out_dir(a.figures, "--figures") if a.figures else None
    runner = options.runner(a, not a.no_render)
    if not runner.build.capabilities["coul/fmm"]:
        skip = [p for p in params if is_charged(p.deck_vars())]
        if skip:
            log.warning("%d charged runs NOT run: fix coul/fmm is absent from %s", len(skip),
                        runner.build.path)
        params = [p for p in params if not is_charged(p.deck_vars())]
    res = Sweep(runner, out, engine=options.engine(a)).run(params, a.tracer)
    if figs is not None and params:
        # pandas only when figures are drawn: the command line starts without it
        from ..analysis.tables import variant
        draw(load_results(out), figs, None, variant(vars(params[0])))
    return 0 if len(res) == len(params) else 1
