"""The README's demo: a REDUCED version of the paper's Fig. 2 study, and the checks of
``granular-charged reproduce``.

Cases: r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2, q = 0, 260, 400 e_0 (the paper's Fig. 2),
with the paper's H = 160 r_p and material (Table 1), but a box of L = 14 r_p and N = 500
particles instead of L = 28 r_p and N = 2000: the same number of particles per unit floor area
(so the same bed height and the same K_eff = 20 N (L/r_p)^-2 = 51 of the paper's E*), a
quarter of the particles. Then the Table 2 check on the first neutral packing, the tables and
the figures, all in one folder.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

from .. import paper
from ..analysis import claims, tables
from ..params import DepositionParams
from .study import Study

# demo and reproduce: the rain from H at one particle per r_p for every charge: quick, and its
# incident particles come from H (the tracer figure); charged packings are denser than the
# deck's default plane rain gives (doc/deposition.md, "Protocol checks")
STUDY_INJECTION = MappingProxyType({"inject": "rain", "gap_rp": 1})   # read-only
DEMO_VARS = MappingProxyType({"L_rp": 14, **STUDY_INJECTION})        # read-only
FULL_COMMAND = "granular-charged reproduce --size paper --jobs 2 --out paper-size"


@dataclass
class Demo(Study):
    """The reduced Fig. 2 study: depositions for each q and seed, the Table 2 check, tables
    (the skeleton is :meth:`Study.run`; the command line draws the figures)."""
    N: int = 500
    qs: tuple = (0.0, 260.0, 400.0)
    extra: dict = field(default_factory=lambda: dict(DEMO_VARS))
    follow: int | None = None     # particle followed in the first seed's runs (None: N/2)

    def params(self, have_fmm: bool) -> list[DepositionParams]:
        qs = self.qs if have_fmm else [q for q in self.qs if q == 0]
        return [DepositionParams(q=q, N=self.N, seed=s, extra=dict(self.extra),
                                 **self.fields)
                for q in qs for s in self.seeds]

    def tracer(self, p: DepositionParams) -> int:
        return (self.follow or self.N // 2) if p.seed == self.seeds[0] else 0

    def analyse(self, runs, summary, out, results) -> dict:
        return {"fits": tables.expansion_fits(runs)}


def report(res: dict, study: Demo) -> str:
    """The demo's printed summary."""
    s = res["summary"]
    lines = [
        "GRANULAR-CHARGED demo: a REDUCED version of the paper's Fig. 2 study",
        f"  r_p = 2 um, U0 = 1 m/s, gamma = 10 mJ/m^2, N = {study.N} in L = "
        f"{study.extra.get('L_rp')} r_p (paper: N = 2000 in L = 28 r_p, the same particles per "
        f"floor area), H = {study.extra.get('H_rp', 160)} r_p, seeds "
        f"{', '.join(map(str, study.seeds))}",
        "",
        tables.format_table(tables.readable(s[["q", "runs", "phi", "phi_sd", "Z", "Z_sd", "Ad",
                                               "Estar", "Adstar", "expansion", "expansion_se",
                                               "N", "lost", "wall_s"]]), "{:.3g}"),
        "",
        f"paper: neutral phi_0 = {paper.PHI0_RANGE[0]}-{paper.PHI0_RANGE[1]}; charge lowers phi "
        f"and <Z>; phi_0/phi - 1 ~ q^{paper.EXPANSION_SLOPE:g}, up to {paper.MAX_RELATIVE_DECREASE:g}",
    ]
    for fit in res["fits"]:
        lines.append(f"log-log slope of phi_0/phi - 1 vs q (paper {paper.EXPANSION_SLOPE:g}): "
                     + tables.describe_fit(fit))
    if res["table2"] is not None:
        lines += ["", "charged after formation (the paper's Table 2; relaxation 100 r_p/U0):",
                  tables.format_table(res["table2"][["q", "phi_before", "phi_after", "Z_before",
                                                     "Z_after", "FC_over_FE", "paper_phi",
                                                     "paper_Z"]], "{:.5g}")]
    lines += ["", f"tables: {res['out']}/summary.csv, runs.csv"
              + (", table2/table2.csv" if res["table2"] is not None else ""),
              f"figures ({len(res['figures'])} PNG, each with its CSV): {res['out']}/figures",
              f"this was REDUCED (N = {study.N}, L = {study.extra.get('L_rp')} r_p, "
              f"{len(study.seeds)} seed{'s' if len(study.seeds) > 1 else ''}); the paper-size "
              "study (many CPU hours, resumable; doc/data/README.md) is:",
              f"  {FULL_COMMAND}"]
    if not res["have_fmm"]:
        lines.append("NOTE: the charged cases (q != 0) were NOT run: they need fix coul/fmm")
    lines.append(f"wall time: {res['wall_s']:.0f} s")
    return "\n".join(lines)


def claims_report(res: dict) -> str:
    """`reproduce`: the paper's claims, what this package checks of each, and our numbers."""
    s = res["summary"]
    lines = ["The paper's claims and this package's checks:"]
    for claim, status in paper.CLAIMS:
        lines.append(f"  - {claim}\n      {status}")
    lines.append("")
    if res["table2"] is not None:
        t = res["table2"]
        lines.append(f"Table 2 (ours, N = {int(s['N'].max())}): max |phi_after - phi_before| = "
                     f"{t['dphi'].abs().max():.2g}, max |<Z>_after - <Z>_before| = "
                     f"{t['dZ'].abs().max():.2g} (paper: 2e-4 and 0)")
    neutral = s[s["q"] == 0]
    if not neutral.empty:
        lines.append("neutral phi_0 (ours): " + ", ".join(
            tables.with_uncertainty(v, e) for v, e in zip(neutral["phi"], neutral["phi_sd"]))
            + f" (paper: {paper.PHI0_RANGE[0]}-{paper.PHI0_RANGE[1]})")
    with_measures = claims.runs_with_measures(res["results"])
    lines += [f"  {c}" for c in claims.claim_lines(with_measures)]
    ch = s[s["q"] > 0]
    if not ch.empty:
        lines.append("phi vs q (ours): " + ", ".join(
            f"q = {q:g}: {tables.with_uncertainty(p, sd)} (phi_0/phi - 1 = "
            f"{tables.with_uncertainty(e, se, sig=1)})"
            for q, p, sd, e, se in zip(ch["q"], ch["phi"], ch["phi_sd"], ch["expansion"],
                                       ch["expansion_se"])))
    return "\n".join(lines)

