"""The paper's claims quantified as it states them, from a study's finished runs: one table of
per-case means and standard deviations over the seeds (phi, <Z> and the measures of
:mod:`measures`) and one printed line per claim, with the paper's number beside ours and only
the conclusions the seeds' scatter allows (a difference is called one when it exceeds twice
its standard error).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .. import paper
from . import measures, packing, tables
from .tables import CASE, with_uncertainty

SERIES = ["rp_um", "U0", "gamma_mJ"]
# the paper's three series of Fig. 3 (r_p [um], U_0 [m/s], gamma [mJ/m^2]): its phi_0 range
FIG3_SERIES = ((1.0, 1.0, 10.0), (1.0, 2.0, 10.0), (2.0, 1.0, 10.0))
FIG2_SERIES = (2.0, 1.0, 10.0)
MEASURE_COLUMNS = ("phi_bed_top", "phi_bed_2z", "phi_bed_surface", "Z_all", "Z_all_floor",
                   "fZ_1_2", "fZ_4_6", "rdf_sqrt2", "rdf_sqrt3", "rdf_sqrt5", "Fn_mean",
                   "Fn_sd", "Fn_inside", "Fn_tensile", "Ek_before_contact")
SIGNIFICANT = 2.0      # a difference is called one beyond this many standard errors


def runs_with_measures(results: list[dict]) -> pd.DataFrame:
    """tables.runs_frame with the measures of every run (measures.json, computed once)."""
    df = tables.runs_frame(results)
    rows = []
    for r in results:
        m = measures.load(r["dir"], r)
        rows.append({c: m.get(c, np.nan) for c in MEASURE_COLUMNS})
    return pd.concat([df.reset_index(drop=True), pd.DataFrame(rows, columns=MEASURE_COLUMNS)],
                     axis=1)


def case_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per case: runs, the groups, and mean and sd over the seeds of phi, <Z> and every
    measure (column and column_sd; *_n: the runs that have the measure)."""
    cols = ["phi", "Z", *MEASURE_COLUMNS]
    agg = {"runs": ("phi", "count"), "Ad": ("Ad", "first"), "Estar": ("Estar", "first"),
           "Adstar": ("Adstar", "first")}
    for c in cols:
        agg[c] = (c, "mean")
        agg[f"{c}_sd"] = (c, "std")
        agg[f"{c}_n"] = (c, "count")
    return runs.groupby(list(CASE), as_index=False).agg(**agg)


def _series(t: pd.DataFrame, key) -> pd.DataFrame:
    return t[(t[SERIES] == pd.Series(dict(zip(SERIES, key)))).all(axis=1)].sort_values("q")


def _pm(row, col, sig=2) -> str:
    return with_uncertainty(row[col], row[f"{col}_sd"], sig)


def _difference(a, b, col) -> tuple[float, float]:
    """b - a of a column and the difference in standard errors of the two means."""
    d = b[col] - a[col]
    se = np.hypot(a[f"{col}_sd"] / np.sqrt(a[f"{col}_n"]), b[f"{col}_sd"] / np.sqrt(b[f"{col}_n"]))
    return d, d / se if se > 0 else np.nan


def _verdict(z: float, what_if_positive: str, what_if_negative: str) -> str:
    if not np.isfinite(z):
        return "not resolved (fewer than 2 seeds)"
    if abs(z) < SIGNIFICANT:
        return f"no difference resolved ({z:+.1f} standard errors)"
    return f"{what_if_positive if z > 0 else what_if_negative} ({z:+.1f} standard errors)"


def _tracers(row) -> str:
    """E_k/E_k0 of a case's tracers: mean +- sd over the seeds that followed one, or the one."""
    n = int(row["Ek_before_contact_n"])
    if n > 1:
        return f"{_pm(row, 'Ek_before_contact')} ({n} tracers)"
    return f"{row['Ek_before_contact']:.2f} (one tracer)"


def _label(key) -> str:
    return f"r_p = {key[0]:g} um, U_0 = {key[1]:g} m/s" + (
        f", gamma = {key[2]:g} mJ/m^2" if key[2] != 10.0 else "")


def claim_lines(runs: pd.DataFrame) -> list[str]:
    """One line (or a few) per claim of the paper, ours beside its numbers."""
    t = case_table(runs)
    lines = []
    neutral = t[t["q"] == 0]

    # phi_0 range over the three series of Fig. 3, by each convention
    fig3 = [r for _, r in neutral.iterrows() if tuple(r[SERIES]) in FIG3_SERIES]
    if fig3:
        parts = []
        for col, name in (("phi", "analysis slab"), ("phi_bed_top", "whole bed, H_p = highest top"),
                          ("phi_bed_surface", "whole bed, H_p = mean surface height")):
            vals = [_pm(r, col) for r in fig3]
            parts.append(f"{name}: " + ", ".join(vals))
        lines.append(f"phi_0 of the Fig. 3 series ({'; '.join(_label(tuple(r[SERIES])) for r in fig3)})"
                     f" - paper {paper.PHI0_RANGE[0]}-{paper.PHI0_RANGE[1]}: " + " | ".join(parts))
    f2 = _series(t, FIG2_SERIES)
    n2 = f2[f2["q"] == 0]
    if len(n2):
        r = n2.iloc[0]
        lines.append(f"Table 2 neutral packing (r_p = 2 um, U_0 = 1 m/s) - paper phi "
                     f"{paper.TABLE2[0][1]}, <Z> {paper.TABLE2[0][2]}: ours phi (slab) "
                     f"{_pm(r, 'phi')}, (whole bed, highest top) {_pm(r, 'phi_bed_top')}; <Z> "
                     f"(slab) {_pm(r, 'Z')}, (all particles) {_pm(r, 'Z_all')}")

    # per charged series: the structure measures, neutral against the most charged case
    for key, g in t[t["q"] > 0].groupby(SERIES):
        s = _series(t, key)
        base, top = s[s["q"] == 0], s.iloc[-1]
        if base.empty:
            continue
        b = base.iloc[0]
        head = f"{_label(key)}, q = 0 -> {top['q']:g} e0:"
        d, z = _difference(b, top, "rdf_sqrt3")
        lines.append(f"{head} g(r) peak area at r/2r_p = sqrt 3 {_pm(b, 'rdf_sqrt3', 1)} -> "
                     f"{_pm(top, 'rdf_sqrt3', 1)} (paper: vanishes when charged): "
                     + _verdict(z, "grows", "shrinks"))
        lines.append(f"{head} crystal peaks sqrt 2 / sqrt 5 (paper: absent): "
                     f"{_pm(b, 'rdf_sqrt2', 1)} / {_pm(b, 'rdf_sqrt5', 1)} -> "
                     f"{_pm(top, 'rdf_sqrt2', 1)} / {_pm(top, 'rdf_sqrt5', 1)}")
        d12, z12 = _difference(b, top, "fZ_1_2")
        d46, z46 = _difference(b, top, "fZ_4_6")
        dZ, zZ = _difference(b, top, "Z")
        lines.append(f"{head} f(Z): <Z> {_pm(b, 'Z')} -> {_pm(top, 'Z')} "
                     f"({_verdict(zZ, 'higher', 'lower')}); Z = 1-2 {_pm(b, 'fZ_1_2')} -> "
                     f"{_pm(top, 'fZ_1_2')} ({_verdict(z12, 'grows', 'shrinks')}); Z = 4-6 "
                     f"{_pm(b, 'fZ_4_6')} -> {_pm(top, 'fZ_4_6')} "
                     f"({_verdict(z46, 'grows', 'shrinks')}) (paper: 1-2 grow, 4-6 shrink)")
        dm, zm = _difference(b, top, "Fn_mean")
        lines.append(f"{head} normal forces F_n/F_C: sd {_pm(b, 'Fn_sd', 1)} -> "
                     f"{_pm(top, 'Fn_sd', 1)}, inside |F_n/F_C| < {paper.FORCE_RANGE:g} "
                     f"{_pm(b, 'Fn_inside', 1)} -> {_pm(top, 'Fn_inside', 1)} (paper: all), mean "
                     f"{_pm(b, 'Fn_mean', 1)} -> {_pm(top, 'Fn_mean', 1)} "
                     f"({_verdict(zm, 'towards compression', 'towards tension')})")
        ek = s[np.isfinite(s["Ek_before_contact"])]
        if len(ek):
            line = (f"{_label(key)}: incident particle's E_k/E_k0 before its first contact: "
                    + ", ".join(f"q = {r['q']:g}: {_tracers(r)}" for _, r in ek.iterrows()))
            if ek.iloc[0]["q"] == 0 and len(ek) > 1:
                _, z = _difference(ek.iloc[0], ek.iloc[-1], "Ek_before_contact")
                line += f"; 0 -> {ek.iloc[-1]['q']:g} e0: " + _verdict(z, "higher", "lower")
            lines.append(line + " (paper, Fig. 8: falls with q)")

    # f(Z) vs r_p and U_0 among the neutral cases (Fig. 5: smaller r_p or U_0 move it left)
    ref = neutral[(neutral[SERIES] == pd.Series(dict(zip(SERIES, FIG2_SERIES)))).all(axis=1)]
    if len(ref):
        b = ref.iloc[0]
        for key, what in (((1.0, 1.0, 10.0), "smaller r_p"), ((2.0, 0.5, 10.0), "smaller U_0")):
            o = neutral[(neutral[SERIES] == pd.Series(dict(zip(SERIES, key)))).all(axis=1)]
            if len(o):
                o = o.iloc[0]
                _, zZ = _difference(b, o, "Z")
                lines.append(f"neutral, {what} ({_label(key)} against {_label(FIG2_SERIES)}): "
                             f"<Z> {_pm(b, 'Z')} -> {_pm(o, 'Z')}, Z = 1-2 {_pm(b, 'fZ_1_2')} -> "
                             f"{_pm(o, 'fZ_1_2')} (paper: moves f(Z) left like charge): "
                             + _verdict(zZ, "higher <Z>", "lower <Z>"))

    # (Z, phi) towards the ALP point: a straight line through the case means, read at Z = 2
    ok = t[np.isfinite(t["phi"]) & np.isfinite(t["Z"])]
    if len(ok) >= 3:
        c = np.polyfit(ok["Z"], ok["phi"], 1)
        lines.append(f"(<Z>, phi) of {len(ok)} cases: phi = {c[1]:.3f} + {c[0]:.3f} <Z>, at <Z> = "
                     f"{paper.ALP_Z:g}: phi = {np.polyval(c, paper.ALP_Z):.3f} (paper's ALP limit "
                     f"{paper.ALP_PHI:g})")
    return lines


def table2_lines(rows: list[dict]) -> list[str]:
    """The paper's Fig. 7 on its Table 2 packing: the normal-force pdf after the relaxation
    without and with charge (width, the share inside |F_n/F_C| < 0.1, the shift of the mean to
    tension). The baseline is the q = 0 control of the same packing after the same relaxation
    (the relaxation alone moves the forces too); without the control, the packing before it.
    Several packings (one per seed): mean +- sd over them."""
    from pathlib import Path
    stats = {}          # q -> [(baseline stats, charged stats)] over the packings
    what = set()
    for formed in dict.fromkeys(r.get("formed") for r in rows):
        mine = [r for r in rows if r.get("formed") == formed]
        control = [r for r in mine if r["q"] == 0]
        for r in mine:
            if r["q"] == 0:
                continue
            d = Path(r["dir"])
            base = (Path(control[0]["dir"]) / "forces_after.dump" if control
                    else d / "forces_before.dump")
            if not (packing.dump_exists(base) and packing.dump_exists(d / "forces_after.dump")):
                continue
            what.add("q = 0 control" if control else "before charging")
            stats.setdefault(r["q"], []).append(
                (measures.force_stats(measures.normal_forces(base, r["params"])),
                 measures.force_stats(measures.normal_forces(d / "forces_after.dump", r["params"]))))
    lines = []
    for q in sorted(stats):
        pairs = stats[q]
        n = len(pairs)

        def show(k, fmt, when):
            v = np.array([p[when][k] for p in pairs])
            if n == 1:
                return fmt.format(v[0])
            return with_uncertainty(v.mean(), v.std(ddof=1))

        def change(k, fmt):
            return f"{show(k, fmt, 0)} -> {show(k, fmt, 1)}"

        def paired(k):
            # the packings differ more from each other than charge changes one: the change
            # packing by packing, mean +- sd
            d = np.array([p[1][k] - p[0][k] for p in pairs])
            return with_uncertainty(d.mean(), d.std(ddof=1))

        packings = "one packing" if n == 1 else f"mean +- sd over {n} packings"
        lines.append(
            f"Table 2 packing charged to {q:g} e0 against the {' / '.join(sorted(what))} "
            f"({packings}): F_n/F_C sd {change('Fn_sd', '{:.3f}')}, inside |F_n/F_C| < "
            f"{paper.FORCE_RANGE:g} {change('Fn_inside', '{:.3f}')} (paper: all), mean "
            f"{change('Fn_mean', '{:+.5f}')}, tensile share {change('Fn_tensile', '{:.3f}')} "
            "(paper: shifts to tension)"
            + (f"; change packing by packing: mean {paired('Fn_mean')}, tensile share "
               f"{paired('Fn_tensile')}" if n > 1 else ""))
    return lines
