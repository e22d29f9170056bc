"""``granular-charged run``: one deposition into a folder."""
from __future__ import annotations

import logging
from pathlib import Path

from ..run import estimate
from ..run.population import protocol
from ..run.runner import RunError, Runner
from ..studies.axes import deck_params, var_axes
from ..studies.sweep import fmt
from . import options

log = logging.getLogger("granular_charged")


def register(subparsers):
    p = options.add_command(subparsers, "run", help="one deposition into a folder",
                            description="Run one deposition (the package's in.deposition deck) in "
                                        "OUT/<key>/ and write result.json there; a finished run is "
                                        "not run again unless --force.")
    p.add_argument("--out", default="runs", help="parent folder of the run folder")
    p.add_argument("--seed", type=options.count, default=4711)
    p.add_argument("--force", action="store_true", help="run again even if finished")
    options.deck_options(p, many=False)
    p.set_defaults(handler=run)


def run(a) -> int:
    single, _ = var_axes(a.var, "run")
    p = deck_params(single, dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q),
                    options.population_vars(a), options.refused("run"), a.N, a.seed)
    Runner.check(p, a.tracer)
    options.check_species_values(p)
    log.info("injection protocol: %s%s", protocol(p.deck_vars()),
             " (auto: rain when no particle is charged, plane when any is)"
             if a.inject == "auto" else "")
    log.info("%s", estimate.describe(estimate.estimate([p], [a.out])))
    out = options.out_dir(a.out)
    runner = options.runner(a, not a.no_render)
    runner.show_progress = a.progress
    log.info("run %s in %s (LAMMPS build %s)", p.key(), runner.workdir(p, out).resolve(),
             runner.build.path)
    try:
        r = runner.deposition(p, out, force=a.force, tracer=a.tracer, lock=True)
    except RunError as e:
        log.error("%s", e)
        return 1
    state = "finished before (not run again)" if r["skipped"] else f"{r['wall_s']:.1f} s"
    log.info("%s: phi = %s, <Z> = %s, %d atoms, lost %d, flying %d (%s)", p.key(),
             fmt(r["phi"], ".4f"), fmt(r["Z"], ".3f"), r["natoms"], r["lost"], r["flying"], state)
    if r.get("tribo"):
        t = r["tribo"]
        log.info("%s: contact charging moved %.4g C between particles, the floor gave %+.4g C "
                 "(%d pair and %d wall charging events)", p.key(), t["moved_C"], t["wall_C"],
                 t["pair_events"], t["wall_events"])
    if r.get("charges"):
        # matplotlib only when there is a figure to draw: the command line starts without it
        from ..figures.charges import run_figure
        log.info("final charges: %s", run_figure(r))
    print((Path(r["dir"]) / "result.json").resolve())
    return 0
