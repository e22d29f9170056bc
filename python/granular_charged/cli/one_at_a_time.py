"""``granular-charged one-at-a-time``: the one-at-a-time limit at paper size against the default
plane rain (doc/reproduction.md)."""
from __future__ import annotations

from . import fixed_study


def register(subparsers):
    p = fixed_study.add_parser(
        subparsers, "one-at-a-time", "the tables of the runs finished in --out so far",
        help="the one-at-a-time limit at paper size against the default plane rain "
             "(doc/reproduction.md), resumable",
        description="inject sequential (each particle once the previous one has landed) at 260 "
                    "and 400 e0 against the deck's default plane rain at the same charges and the "
                    "neutral rain, (2 um, 1 m/s, 10 mJ/m^2), N = 2000 in L = 28 r_p, three seeds: "
                    "phi, <Z> and phi_0/phi - 1 per protocol (OUT/one_at_a_time.csv) and their "
                    "differences in standard errors. The default runs are those of `reproduce "
                    "--size paper` (the same folders under OUT/runs). A sequential run is hours "
                    "of CPU: it leaves a restart point every --checkpoint particles and an "
                    "interrupted one goes on from there.")
    p.add_argument("--checkpoint", type=int, default=50, metavar="K",
                   help="particles between restart points (0: none)")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the study loads pandas: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..studies import one_at_a_time as study
    out, params, results = fixed_study.checked_study(a, "one-at-a-time", study.study_params)
    if not results:
        return 1
    t = study.case_table(study.run_frame(results))
    d = study.differences(t)
    t.to_csv(out / "one_at_a_time.csv", index=False)
    d.to_csv(out / "one_at_a_time_differences.csv", index=False)
    return fixed_study.report(a, out, "one_at_a_time", params, results, study.format_table(t),
                              study.format_differences(d))
