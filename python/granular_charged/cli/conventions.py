"""``granular-charged conventions``: the phi_0 question at paper size (doc/reproduction.md)."""
from __future__ import annotations

from . import fixed_study


def register(subparsers):
    fixed_study.add_parser(
        subparsers, "conventions", "the tables of the runs finished in --out so far",
        help="the phi_0 question at paper size: the paper's open conventions "
             "(doc/reproduction.md), resumable",
        description="Which convention the paper leaves open gives its Table 2, its neutral "
                    "phi_0 range and its charge effect together: the rolling limit theta_crit "
                    "0.01 (the deck's), 0.02, 0.04 at the three neutral series of Fig. 3 and at "
                    "400 e0 (2 um, 1 m/s), N = 2000 in L = 28 r_p, three seeds; phi in the slab "
                    "or over the whole bed (H_p = mean surface height or highest top), <Z> in the "
                    "slab or over all particles. Prints the per-case means "
                    "(OUT/conventions.csv) and the checks per convention "
                    "(OUT/conventions_checks.csv). The theta_crit 0.01 runs are those of "
                    "`reproduce --size paper` (the same folders under OUT/runs)."
    ).set_defaults(handler=run)


def run(a) -> int:
    # the study loads pandas and matplotlib: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..analysis.conventions import case_table, run_frame
    from ..figures.conventions import phi0_question
    from ..studies import conventions
    out, params, results = fixed_study.checked_study(a, "conventions", conventions.study_params)
    if not results:
        return 1
    t = case_table(run_frame(results))
    c = conventions.checks(t)
    t.to_csv(out / "conventions.csv", index=False)
    c.to_csv(out / "conventions_checks.csv", index=False)
    status = fixed_study.report(a, out, "conventions", params, results,
                                conventions.format_cases(t), conventions.format_checks(c),
                                conventions.verdict(c))
    path = phi0_question(t, out / "figures")
    if path:
        print(f"figure: {path}")
    return status
