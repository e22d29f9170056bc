"""`granular-charged reproduce`: the paper's scaling claims tested in this model, with seeds.

Runs (resumable, in parallel with --jobs), at the demo's reduced size (N = 500 in L = 14 r_p,
the paper's particles per floor area) or, with --quick, N = 200 in L = 9 r_p with the charges
0, 200, 300, 400, 450 e_0 and the Table 2 check at 400 e_0 only:

- the charge series of the paper's Fig. 2 case (r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2)
  at q = 0, 100, 200, 260, 300, 400, 450 e_0 (E* up to 0.75): phi_0/phi - 1 vs q on log-log,
  the fitted slope with its bootstrap uncertainty over the seeds (the paper: slope 2);
- neutral cases at other Ad = gamma / (rho U_0^2 r_p): U_0 = 0.5, 0.707, 1.414, 2 m/s,
  gamma = 5, 20 mJ/m^2, r_p = 1 um: phi and <Z> vs Ad* with the charged cases on the same
  axes, the collapse quantified (tables.adstar_collapse; the paper's Fig. 9);
- the Table 2 check (charging a formed neutral packing).

Every case has the same seeds (default 1, 2, 3). The numbers of doc/reproduction.md come from
this command; the paper-size rows from `sweep --N 2000`.
"""
from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from . import paper, tables
from .demo import STUDY_INJECTION
from .params import DepositionParams
from .study import Study

CHARGES = (0.0, 100.0, 200.0, 260.0, 300.0, 400.0, 450.0)
QUICK_CHARGES = (0.0, 200.0, 300.0, 400.0, 450.0)      # --quick: fewer charges, same range
# neutral cases that move Ad away from the Fig. 2 case's 2, each by one parameter
NEUTRAL_CASES = ({"U0": 0.5}, {"U0": 0.707}, {"U0": 1.414}, {"U0": 2.0},
                 {"gamma": 0.005}, {"gamma": 0.02}, {"rp": 1.0e-6})
SIZES = {"full": {"N": 500, "L_rp": 14}, "quick": {"N": 200, "L_rp": 9}}


@dataclass
class Reproduction(Study):
    """The paper's scaling claims at reduced size (the skeleton is :meth:`Study.run`)."""
    quick: bool = False
    charges: tuple = CHARGES

    @property
    def size(self) -> dict:
        return SIZES["quick" if self.quick else "full"]

    def params(self, have_fmm: bool) -> list[DepositionParams]:
        extra = {"L_rp": self.size["L_rp"], **STUDY_INJECTION, **self.extra}
        N = self.size["N"]
        charges = QUICK_CHARGES if self.quick else self.charges
        ps = [DepositionParams(q=q, N=N, seed=s, extra=dict(extra), **self.fields)
              for q in charges if have_fmm or q == 0 for s in self.seeds]
        ps += [DepositionParams(N=N, seed=s, extra=dict(extra), **case, **self.fields)
               for case in NEUTRAL_CASES for s in self.seeds]
        return ps

    def table2_charges(self) -> tuple:
        return (0.0, 400.0) if self.quick else tuple(self.table2_qs)

    def analyse(self, runs, summary, out) -> dict:
        fit = tables.expansion_fit(runs)
        collapse = tables.adstar_collapse(runs)
        collapse_mid = tables.adstar_collapse(runs, barrier_fraction=0.5)
        collapse.to_csv(out / "collapse.csv", index=False)
        collapse_mid.to_csv(out / "collapse_mean_barrier.csv", index=False)
        (out / "expansion_fit.json").write_text(json.dumps(fit, indent=1))
        return {"fit": fit, "collapse": collapse, "collapse_mid": collapse_mid}


def report(res: dict, study: Reproduction) -> str:
    s, fit, c = res["summary"], res["fit"], res["collapse"]
    size = study.size
    lines = [f"granular-charged reproduce{' --quick' if study.quick else ''}: N = {size['N']} in "
             f"L = {size['L_rp']} r_p (paper: N = 2000 in L = 28 r_p), seeds "
             f"{', '.join(map(str, study.seeds))}, one particle per r_p of fall", "",
             tables.format_table(s[["rp_um", "U0", "gamma_mJ", "q", "runs", "phi", "phi_sd", "Z",
                                    "Z_sd", "Ad", "Estar", "Adstar", "expansion"]]), ""]
    if fit.get("points", 0) >= 2:
        lines.append(f"phi_0/phi - 1 vs q (r_p = 2 um, U_0 = 1 m/s): log-log slope "
                     f"{fit['slope']:.2f}, bootstrap over seeds {fit['boot_mean']:.2f} +- "
                     f"{fit['sd']:.2f} (16-84%: {fit['p16']:.2f} .. {fit['p84']:.2f}) from "
                     f"{fit['points']} charges with a positive expansion (paper: "
                     f"{paper.EXPANSION_SLOPE:g}); largest expansion "
                     f"{s['expansion'].max():.3f} (paper: up to {paper.MAX_RELATIVE_DECREASE:g})")
    for name, c in (("Ad* (the paper's: the mean barrier of a one-at-a-time deposition)", c),
                    ("Ad* with half that barrier (E*/2: the rain's charge in flight halves it)",
                     res["collapse_mid"])):
        if "phi_dev" not in c or not c["phi_line"].notna().any():
            continue
        ch, ne = c[(c["q"] > 0) & np.isfinite(c["Adstar"])], c[c["q"] == 0]
        lines.append(
            f"collapse on {name}: deviation from the neutral cases' line phi(log Ad*) in "
            "standard errors of the mean, RMS: neutral cases "
            f"{(ne['phi_dev'] ** 2).mean() ** 0.5:.1f}, charged cases "
            f"{(ch['phi_dev'] ** 2).mean() ** 0.5:.1f}; mean charged phi - line "
            f"{(ch['phi'] - ch['phi_line']).mean():+.4f}, <Z> - line "
            f"{(ch['Z'] - ch['Z_line']).mean():+.3f}")
    if res["table2"] is not None:
        t = res["table2"]
        lines.append(f"Table 2: max |phi_after - phi_before| = {t['dphi'].abs().max():.2g}, "
                     f"max |<Z>_after - <Z>_before| = {t['dZ'].abs().max():.2g} (paper: 2e-4, 0)")
    lines += ["", f"tables: {res['out']}/summary.csv, runs.csv, collapse.csv, "
              "expansion_fit.json; figures: " + f"{res['out']}/figures",
              f"wall time: {res['wall_s']:.0f} s"]
    return "\n".join(lines)
