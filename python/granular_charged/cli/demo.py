"""``granular-charged demo``: the README's demo, a reduced Fig. 2 study."""
from __future__ import annotations

import argparse

from ..run.runner import Runner
from . import options
from .figures import draw_study

DESCRIPTION = """A REDUCED version of the paper's Fig. 2 study, in one folder:
depositions with r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2 and q = 0, 260, 400 e0 (the paper's
Fig. 2) for three seeds, with the paper's H = 160 r_p and material (Table 1) but N = 500 in a box
of L = 14 r_p instead of N = 2000 in L = 28 r_p (the same particles per floor area, so the same
bed height and K_eff = 51); then the Table 2 check (charge the first neutral packing, relax),
the tables (summary.csv, runs.csv, table2/table2.csv) and the figures (figures/*.png + CSV).
Finished runs are reused: an interrupted demo resumes."""


def register(subparsers):
    p = options.add_command(subparsers, "demo",
                            help="the reduced Fig. 2 study: runs, table, Table 2, figures",
                            description=DESCRIPTION,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    options.study_options(p, "demo", "deck variables besides the demo's L_rp 14, inject rain, "
                          "gap_rp 1")
    p.add_argument("--N", type=options.count, default=500, help="particles per run")
    p.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0],
                   help="charges [e0]")
    p.add_argument("--table2-q", type=float, nargs="*", default=[0.0, 260.0, 400.0],
                   help="charges of the Table 2 check (none: skip it)")
    p.add_argument("--tracer", type=int, default=None,
                   help="particle id to follow in the first seed's runs (default: N/2)")
    p.add_argument("--claims", action="store_true",
                   help="then list the paper's claims with what this package checks of each")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the study loads pandas and matplotlib: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..studies.demo import DEMO_VARS, Demo, claims_report, report
    fields, extra = options.deck_vars(a, "demo")
    study = Demo(out=options.out_dir(a.out), N=a.N, qs=tuple(a.q), seeds=tuple(a.seeds),
                 table2_qs=tuple(a.table2_q), extra={**DEMO_VARS, **extra}, fields=fields,
                 jobs=a.jobs, progress=a.progress, follow=a.tracer, engine=options.engine(a))
    for p in study.params(True):
        Runner.check(p, study.tracer(p))
    res = study.run(options.runner(a, not a.no_render))
    draw_study(res, study.jobs)
    print(report(res, study))
    if a.claims:
        print()
        print(claims_report(res))
    return 0 if res["complete"] else 1
