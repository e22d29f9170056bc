"""``granular-charged epd``: the electrophoretic deposition study (doc/epd.md)."""
from __future__ import annotations

from ..run.runner import Runner
from . import fixed_study, options


def register(subparsers):
    p = fixed_study.add_parser(
        subparsers, "epd", "the table of the runs finished in --out so far",
        help="the electrophoretic deposition study (doc/epd.md), resumable",
        description="Charged particles (2 um, 1 m/s, 10 mJ/m^2, 400 e0) driven by an applied "
                    "field onto a grounded floor electrode, E0 = 1e5 and 3e5 V/m, eps_p = 0 (not "
                    "polarisable) and 3.8, N = 500 in L = 14 r_p, three seeds: phi, <Z>, f(Z) and "
                    "the contact directions against the field, mean +- sd over the seeds "
                    "(printed and in OUT/epd.csv).")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the study loads pandas and matplotlib: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..figures.epd import epd_figures
    from ..studies import epd
    _, extra = options.deck_vars(a, "epd")
    params = epd.study_params(tuple(a.seeds))
    for p in params:
        p.extra.update(extra)
        Runner.check(p, 0)
    out, results = fixed_study.study_runs(a, params)
    if not results:
        return 1
    t = epd.table(results)
    t.to_csv(out / "epd.csv", index=False)
    print(epd.format_table(t))
    for path in epd_figures(results, out / "figures"):
        print(f"figure: {path}")
    return 0 if a.finished_only or len(results) == len(params) else 1
