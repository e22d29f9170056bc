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
import pandas as pd

from .. import paper
from ..analysis import claims, tables
from ..params import DepositionParams
from .demo import STUDY_INJECTION
from .study import Study
from .sweep import PAPER_SETS, expand

CHARGES = (0.0, 100.0, 200.0, 260.0, 300.0, 400.0, 450.0)
QUICK_CHARGES = (0.0, 200.0, 300.0, 400.0, 450.0)      # --quick: fewer charges, same range
# neutral cases that move Ad away from the Fig. 2 case's 2, each by one parameter
NEUTRAL_CASES = ({"U0": 0.5}, {"U0": 0.707}, {"U0": 1.414}, {"U0": 2.0},
                 {"gamma": 0.005}, {"gamma": 0.02}, {"rp": 1.0e-6})
SIZES = {"demo": {"N": 500, "L_rp": 14}, "quick": {"N": 200, "L_rp": 9},
         "paper": {"N": 2000, "L_rp": 28}}
# --size paper: the preset's cases (sweep.PAPER_SETS) and neutral ones that take Ad* over the
# paper's Fig. 9 range (0.5 ... >= 20), each by one parameter from the Fig. 2 case
PAPER_AD_SETS = (dict(rp=2e-6, U0=2.0, gamma=0.010, q=0),      # Ad = 0.5
                 dict(rp=2e-6, U0=1.0, gamma=0.050, q=0),      # Ad = 10
                 dict(rp=2e-6, U0=1.0, gamma=0.100, q=0))      # Ad = 20


def paper_size_params(seeds, extra: dict, fields: dict) -> list[DepositionParams]:
    """The paper-size study (N = 2000, L = 28 r_p, the deck's default protocols), in the order
    it runs: every neutral case first (the cheapest runs, the phi_0 question and the Ad* line),
    then the charged ones series by series, the largest charge first (the largest effect, the
    first resolved). The deck's own L_rp is the paper's 28, so it is not set: the run folders
    are those of `sweep --preset paper --N 2000`."""
    ps = expand(PAPER_SETS + PAPER_AD_SETS, SIZES["paper"]["N"], seeds, extra, fields)
    order = {id(p): k for k, p in enumerate(ps)}
    series = []
    for p in ps:
        if (p.rp, p.U0, p.gamma) not in series:
            series.append((p.rp, p.U0, p.gamma))
    return sorted(ps, key=lambda p: (p.q > 0, series.index((p.rp, p.U0, p.gamma)) if p.q else 0,
                                     -p.q, order[id(p)]))


@dataclass
class Reproduction(Study):
    """The paper's scaling claims at reduced size (the skeleton is :meth:`Study.run`)."""
    size_name: str = "demo"
    charges: tuple = CHARGES

    @property
    def quick(self) -> bool:
        return self.size_name == "quick"

    @property
    def size(self) -> dict:
        return SIZES[self.size_name]

    def params(self, have_fmm: bool) -> list[DepositionParams]:
        if self.size_name == "paper":
            return [p for p in paper_size_params(self.seeds, self.extra, self.fields)
                    if have_fmm or p.q == 0]
        extra = {"L_rp": self.size["L_rp"], **STUDY_INJECTION, **self.extra}
        N = self.size["N"]
        charges = QUICK_CHARGES if self.quick else self.charges
        ps = [DepositionParams(q=q, N=N, seed=s, extra=dict(extra), **self.fields)
              for q in charges if have_fmm or q == 0 for s in self.seeds]
        ps += [DepositionParams(N=N, seed=s, extra=dict(extra), **case, **self.fields)
               for case in NEUTRAL_CASES for s in self.seeds]
        return ps

    def tracer(self, p: DepositionParams) -> int:
        # paper size: the incident particle's E_k/E_k0 (Fig. 8) in the first seed of each case
        return p.N // 2 if self.size_name == "paper" and p.seed == self.seeds[0] else 0

    def table2_charges(self) -> tuple:
        return (0.0, 400.0) if self.quick else tuple(self.table2_qs)

    def table2_seeds(self) -> tuple:
        # paper size: every seed's packing (~1.5 CPU minutes per charge, beside hours of
        # depositions), so the Table 2 row is a mean over seeds as the others are
        return tuple(self.seeds) if self.size_name == "paper" else tuple(self.seeds[:1])

    def analyse(self, runs, summary, out, results) -> dict:
        if not results:      # --finished-only before the first run
            return {"fits": [], "claims": [], "collapse": pd.DataFrame(),
                    "collapse_mid": pd.DataFrame()}
        fits = tables.expansion_fits(runs)
        lines = []
        if results:
            with_measures = claims.runs_with_measures(results)
            claims.case_table(with_measures).to_csv(out / "cases.csv", index=False)
            lines = claims.claim_lines(with_measures)
        (out / "claims.txt").write_text("\n".join(lines) + "\n")
        collapse = tables.adstar_collapse(runs)
        collapse_mid = tables.adstar_collapse(runs, barrier_fraction=0.5)
        collapse.to_csv(out / "collapse.csv", index=False)
        collapse_mid.to_csv(out / "collapse_mean_barrier.csv", index=False)
        (out / "expansion_fit.json").write_text(json.dumps(fits, indent=1))
        return {"fits": fits, "claims": lines, "collapse": collapse, "collapse_mid": collapse_mid}


def report(res: dict, study: Reproduction) -> str:
    s, c = res["summary"], res["collapse"]
    size = study.size
    protocol = ("the deck's default protocols (neutral: rain, one particle per r_p of fall; "
                "charged: plane rain)" if study.size_name == "paper"
                else "one particle per r_p of fall")
    lines = [f"granular-charged reproduce --size {study.size_name}: N = {size['N']} in "
             f"L = {size['L_rp']} r_p (paper: N = 2000 in L = 28 r_p), seeds "
             f"{', '.join(map(str, study.seeds))}, {protocol}", "",
             tables.format_table(tables.readable(s[["rp_um", "U0", "gamma_mJ", "q", "runs", "phi",
                                                    "phi_sd", "Z", "Z_sd", "Ad", "Estar",
                                                    "Adstar", "expansion", "expansion_se"]]),
                                 "{:.3g}"), ""]
    if res.get("missing"):
        lines.append(f"{res['missing']} of the study's runs are not finished (--finished-only)")
    for f in res["fits"]:
        rp, u0, g = f["series"]
        lines.append(f"phi_0/phi - 1 vs q (r_p = {rp:g} um, U_0 = {u0:g} m/s, gamma = {g:g} "
                     f"mJ/m^2): log-log slope {tables.describe_fit(f)} (paper: "
                     f"{paper.EXPANSION_SLOPE:g})")
    if (s["q"] > 0).any() and s.loc[s["q"] > 0, "expansion"].notna().any():
        k = s.loc[s["q"] > 0, "expansion"].idxmax()
        lines.append(f"largest phi_0/phi - 1: {tables.with_uncertainty(s.loc[k, 'expansion'], s.loc[k, 'expansion_se'], sig=1)}"
                     f" at q = {s.loc[k, 'q']:g} e0, r_p = {s.loc[k, 'rp_um']:g} um, U_0 = "
                     f"{s.loc[k, 'U0']:g} m/s (paper: up to {paper.MAX_RELATIVE_DECREASE:g})")
    for name, c in (("Ad* (the paper's: the mean barrier of a one-at-a-time deposition)", c),
                    ("Ad* with half that barrier (E*/2: the rain's charge in flight halves it)",
                     res["collapse_mid"])):
        if "phi_dev" not in c or not c["phi_line"].notna().any():
            continue
        ch, ne = c[(c["q"] > 0) & np.isfinite(c["Adstar"])], c[c["q"] == 0]
        charged = (f"charged cases {(ch['phi_dev'] ** 2).mean() ** 0.5:.1f}; mean charged phi - "
                   f"line {(ch['phi'] - ch['phi_line']).mean():+.4f}, <Z> - line "
                   f"{(ch['Z'] - ch['Z_line']).mean():+.3f}" if len(ch) else
                   "no charged case finished")
        lines.append(
            f"collapse on {name}: deviation from the neutral cases' line phi(log Ad*) in "
            "standard errors of the mean, RMS: neutral cases "
            f"{(ne['phi_dev'] ** 2).mean() ** 0.5:.1f}, {charged}")
        if not len(ch):
            break     # the second barrier convention differs only for charged cases
    lines += ["", "The paper's claims, ours beside its numbers (mean +- sd over the seeds):"]
    lines += [f"  - {c}" for c in res["claims"]]
    lines += [f"  - {c}" for c in claims.table2_lines(res.get("table2_rows") or [])]
    if res["table2"] is not None:
        t = res["table2"]
        n = t["seed"].nunique()
        lines.append(f"Table 2: max |phi_after - phi_before| = {t['dphi'].abs().max():.2g}, "
                     f"max |<Z>_after - <Z>_before| = {t['dZ'].abs().max():.2g} (paper: 2e-4, 0)"
                     + (f" over {n} packings" if n > 1 else ""))
        if n > 1:
            for q, d in t.groupby("q"):
                lines.append(f"Table 2 at {q:g} e0 over {n} packings: phi "
                             f"{tables.with_uncertainty(d['phi_before'].mean(), d['phi_before'].std())} -> "
                             f"{tables.with_uncertainty(d['phi_after'].mean(), d['phi_after'].std())}, <Z> "
                             f"{tables.with_uncertainty(d['Z_before'].mean(), d['Z_before'].std())} -> "
                             f"{tables.with_uncertainty(d['Z_after'].mean(), d['Z_after'].std())} (paper: "
                             f"{d['paper_phi'].iloc[0]:g}, {d['paper_Z'].iloc[0]:g})")
    lines += ["", f"tables: {res['out']}/summary.csv, runs.csv, collapse.csv, "
              "expansion_fit.json, cases.csv, claims.txt, report.txt; figures: " + f"{res['out']}/figures",
              f"wall time: {res['wall_s']:.0f} s"]
    return "\n".join(lines)
