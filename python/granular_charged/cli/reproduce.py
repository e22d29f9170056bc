"""``granular-charged reproduce``: the paper's scaling claims at reduced size."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..run.runner import Runner
from . import options
from .figures import draw_study

DESCRIPTION = """The paper's scaling claims tested in this model, resumable:
the charge series q = 0, 100, 200, 260, 300, 400, 450 e0 at the Fig. 2 case (phi_0/phi - 1 vs
q: log-log slope with a bootstrap uncertainty over the seeds; the paper: 2), neutral cases at
U_0 = 0.5, 0.707, 1.414, 2 m/s, gamma = 5, 20 mJ/m^2 and r_p = 1 um (phi and <Z> vs Ad*, the
collapse of the charged cases quantified; the paper's Fig. 9), and the Table 2 check. N = 500
in L = 14 r_p, or with --quick N = 200 in L = 9 r_p and five charges (the paper's particles per floor area),
three seeds, one particle per r_p of fall (doc/deposition.md)."""


def register(subparsers):
    p = options.add_command(subparsers, "reproduce",
                            help="the paper's scaling claims at reduced size: q^2 law, Ad* "
                                 "collapse, Table 2 (--quick: under 15 min)",
                            description=DESCRIPTION,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    options.study_options(p, "reproduce", "deck variables for every run (e.g. --var theta_crit "
                          "0.04)", "the tables, claims and figures of the runs finished in --out "
                          "so far (a study that grows run by run)")
    p.add_argument("--size", choices=["demo", "quick", "paper"], default="demo",
                   help="demo: N = 500 in L = 14 r_p (default); quick: N = 200 in L = 9 r_p, "
                        "charges 0 200 300 400 450, Table 2 at 400 only; paper: N = 2000 in "
                        "L = 28 r_p, the paper's cases (sweep --preset paper and neutral cases "
                        "to Ad = 20) with the deck's default protocols (many CPU hours)")
    p.add_argument("--quick", action="store_const", const="quick", dest="size",
                   help="the same as --size quick")
    p.add_argument("--checkpoint", type=options.count_or_zero, default=0, metavar="K",
                   help="plane-rain runs (the charged ones) leave a restart point every K "
                        "particles; a study interrupted mid-run goes on from each run's last "
                        "one when started again (0: none; an interrupted run starts over)")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the study loads pandas and matplotlib: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..studies.reproduce import Reproduction, report
    fields, extra = options.deck_vars(a, "reproduce")
    study = Reproduction(out=options.out_dir(a.out), size_name=a.size, seeds=tuple(a.seeds),
                         extra=extra, fields=fields, jobs=a.jobs, progress=a.progress,
                         finished_only=a.finished_only, engine=options.engine(a))
    for p in study.params(True):
        Runner.check(p, study.tracer(p))
    res = study.run(options.runner(a, not a.no_render))
    draw_study(res, study.jobs)
    text = report(res, study)
    (Path(res["out"]) / "report.txt").write_text(text + "\n")
    print(text)
    return 0 if res["complete"] or a.finished_only else 1
