"""Tables of runs through pandas: one row per run, summaries per case with groupby().agg."""
from __future__ import annotations

import numpy as np
from scipy.stats import bootstrap
import pandas as pd

from .. import paper
from ..params import MATERIAL, DepositionParams, ParamError
from .status import run_status

CASE = ("rp_um", "U0", "gamma_mJ", "q")    # a case of one variant: everything but the seed


def _value(v) -> str:
    try:
        return f"{float(v):g}"
    except (TypeError, ValueError):
        return str(v)


def variant(params: dict) -> str:
    """What a run's case (r_p, U_0, gamma, q) and seed leave out of its parameters, as 'N=2000
    inject=sequential': N, the material and far-field values that differ from the deck's
    defaults, the other deck variables. The tables average over the seeds of a case, so they
    may hold runs of one variant only (a folder can hold several: the paper-size runs, the
    rolling-limit and the one-at-a-time studies share one)."""
    parts = [f"N={_value(params['N'])}"]
    parts += [f"{k}={_value(params[k])}" for k in MATERIAL
              if k in params and params[k] != getattr(DepositionParams, k)]
    parts += [f"{k}={_value(v)}" for k, v in sorted(params.get("extra", {}).items())]
    return " ".join(parts)


def one_variant(results: list[dict], chosen: str | None = None) -> list[dict]:
    """The results of one variant: all of them when they are of one, else those of `chosen`;
    ParamError naming the variants (with their run counts) when several are there and none,
    or one that is not there, is chosen."""
    groups: dict[str, list[dict]] = {}
    for r in results:
        groups.setdefault(variant(r["params"]), []).append(r)
    if chosen is None and len(groups) <= 1:
        return list(results)
    if chosen in groups:
        return groups[chosen]
    listed = "; ".join(f"'{v}' ({len(rs)} runs)" for v, rs in sorted(groups.items()))
    what = (f"--variant '{chosen}' is not among them" if chosen is not None
            else "their seeds cannot be averaged together: choose one with --variant")
    raise ParamError(f"the runs are of {len(groups)} variants ({listed}); {what}")


def runs_frame(results: list[dict]) -> pd.DataFrame:
    """One row per run: parameters, dimensionless groups, phi, <Z> (LAMMPS computes) and the
    Python cross-check, counters (particles made, whether the bed settled: None for a log
    without the deck's settled field), timing, folder."""
    rows = []
    for r in results:
        p, g = r["params"], r["groups"]
        st = run_status(r)
        rows.append({
            "rp_um": p["rp"] * 1e6, "U0": p["U0"], "gamma_mJ": p["gamma"] * 1e3, "q": p["q"],
            "seed": p["seed"], "N": p["N"], "Ad": g["Ad"], "Estar": g["Estar"],
            "Adstar": g["Adstar"], "phi": r["phi"], "Z": r["Z"],
            "phi_python": r.get("python", {}).get("phi"), "Z_python": r.get("python", {}).get("Z"),
            "natoms": r["natoms"], "lost": r["lost"], "flying": r["flying"],
            "wall_s": r.get("wall_s"), "key": r["key"], "dir": r.get("dir"),
            "made": st["made"], "settled": st["settled"],
        })
    cols = list(CASE) + ["seed", "N", "Ad", "Estar", "Adstar", "phi", "Z", "phi_python", "Z_python",
                   "natoms", "lost", "flying", "wall_s", "key", "dir", "made", "settled"]
    df = pd.DataFrame(rows, columns=cols)
    # a run without an analysis slab has phi = <Z> = None: NaN, whatever the other runs have
    for c in ("phi", "Z", "phi_python", "Z_python"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Per case (r_p, U_0, gamma, q): runs (those with an analysis slab, which the means and
    standard deviations of phi and <Z> over the seeds are made of), no_slab (the runs whose bed
    was too thin for one), the groups, atoms, particles lost, mean wall time, unsettled (runs
    whose bed did not settle); and phi_0/phi - 1
    against the neutral case of the same (r_p, U_0, gamma) (NaN without one)."""
    runs = runs if "settled" in runs else runs.assign(settled=None)
    s = (runs.groupby(list(CASE), as_index=False)
         .agg(runs=("phi", "count"), no_slab=("phi", lambda v: int(v.isna().sum())),
              phi=("phi", "mean"), phi_sd=("phi", "std"),
              Z=("Z", "mean"), Z_sd=("Z", "std"), Ad=("Ad", "first"), Estar=("Estar", "first"),
              Adstar=("Adstar", "first"), N=("natoms", "mean"), lost=("lost", "sum"),
              wall_s=("wall_s", "mean"),
              unsettled=("settled", lambda v: int((v == False).sum()))))  # noqa: E712
    series = ["rp_um", "U0", "gamma_mJ"]
    neutral = s[s["q"] == 0].set_index(series)
    s = s.join(neutral["phi"].rename("phi0"), on=series)
    s = s.join((neutral["phi_sd"] / np.sqrt(neutral["runs"])).rename("phi0_se"), on=series)
    s["expansion"], s["expansion_se"] = expansion_and_se(
        s["phi0"], s["phi0_se"], s["phi"], s["phi_sd"] / np.sqrt(s["runs"]))
    s.loc[s["q"] == 0, "expansion_se"] = np.nan
    return s.drop(columns=["phi0", "phi0_se"])


def expansion_and_se(phi0, phi0_se, phi, phi_se):
    """phi_0/phi - 1 and its standard error from the standard errors of the two means
    (first-order propagation; the seeds of the two cases are independent runs). NaN for a
    mean of one seed, whose standard error is unknown."""
    ratio = phi0 / phi
    return ratio - 1.0, ratio * np.hypot(phi0_se / phi0, phi_se / phi)


# a fitted log-log slope is printed only from this many charges whose expansion exceeds its
# own standard error (fewer: "not resolved at this size")
MIN_RESOLVED_CHARGES = 3
NOT_RESOLVED = "not resolved at this size"


def expansion_fit(runs: pd.DataFrame, series=(2.0, 1.0, 10.0), n_boot: int = 2000,
                  seed: int = 1) -> dict:
    """The log-log slope of phi_0/phi - 1 vs q for one series (r_p [um], U_0, gamma [mJ]),
    from the charges whose mean expansion exceeds its standard error (summary's
    expansion_se), and only when there are MIN_RESOLVED_CHARGES of them ("resolved"; else the
    slope is NaN and "reason" says why). The uncertainty comes from the seeds: a bootstrap
    that redraws the seeds of every charge (and of the neutral case) with replacement,
    recomputes the means and refits those charges (a redraw in which one is no longer
    positive fits without it, and one with fewer than two left is dropped). Returns the
    slope of the observed means, the bootstrap mean and standard deviation, the 16th-84th
    percentile range, the charges used and those left out as unresolved."""
    sel = runs[(runs["rp_um"] == series[0]) & (runs["U0"] == series[1]) &
               (runs["gamma_mJ"] == series[2])]
    base = {"slope": np.nan, "sd": np.nan, "points": 0, "resolved": False, "charges": [],
            "unresolved": [], "series": list(series), "paper_slope": paper.EXPANSION_SLOPE}
    by_q = {float(q): g["phi"].dropna().to_numpy() for q, g in sel.groupby("q")}
    by_q = {q: v for q, v in by_q.items() if len(v)}
    if 0.0 not in by_q:
        return dict(base, reason="no neutral case in this series")

    def mean_se(v):
        return v.mean(), (v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else np.nan)

    m0, se0 = mean_se(by_q[0.0])
    charged = sorted(q for q in by_q if q > 0)
    resolved = []
    for q in charged:
        e, se = expansion_and_se(m0, se0, *mean_se(by_q[q]))
        if e > se:            # False for an unknown (NaN) standard error
            resolved.append(q)
    base.update(points=len(resolved), charges=resolved,
                unresolved=[q for q in charged if q not in resolved])
    if len(resolved) < MIN_RESOLVED_CHARGES:
        return dict(base, reason=f"{len(resolved)} of {len(charged)} charges have phi_0/phi - 1 "
                                 f"above its standard error; a slope needs {MIN_RESOLVED_CHARGES}")
    by_q = {q: v for q, v in by_q.items() if q == 0 or q in resolved}

    def fit(means):
        q = np.array([k for k in means if k > 0])
        e = np.array([means[0.0] / means[k] - 1.0 for k in q])
        keep = e > 0
        if keep.sum() < 2:
            return np.nan
        return float(np.polyfit(np.log10(q[keep]), np.log10(e[keep]), 1)[0])

    slope = fit({q: v.mean() for q, v in by_q.items()})
    qs = list(by_q)
    # every charge's seeds redrawn on their own (scipy's multi-sample bootstrap); the
    # distribution itself, since a redraw without two positive expansions has no slope (NaN)
    redrawn = bootstrap(tuple(by_q[q] for q in qs),
                        lambda *v: fit({q: x.mean() for q, x in zip(qs, v)}),
                        n_resamples=n_boot, vectorized=False, method="percentile",
                        random_state=np.random.default_rng(seed))
    boots = redrawn.bootstrap_distribution
    boots = boots[np.isfinite(boots)]
    return dict(base, resolved=True, slope=slope, boot_mean=float(boots.mean()),
                sd=float(boots.std(ddof=1)), p16=float(np.percentile(boots, 16)),
                p84=float(np.percentile(boots, 84)))


def expansion_fits(runs: pd.DataFrame, **kw) -> list[dict]:
    """expansion_fit for every series (r_p, U_0, gamma) of the runs that has charged cases."""
    keys = runs[runs["q"] > 0][["rp_um", "U0", "gamma_mJ"]].drop_duplicates()
    return [expansion_fit(runs, tuple(float(v) for v in k), **kw)
            for k in keys.itertuples(index=False)]


def describe_fit(fit: dict) -> str:
    """One line for a printed summary: the slope with its interval, or why there is none."""
    if not fit["resolved"]:
        return f"{NOT_RESOLVED} ({fit['reason']})"
    return (f"{fit['slope']:.1f} (bootstrap over seeds 16-84%: {fit['p16']:.1f} .. "
            f"{fit['p84']:.1f}) from q = {', '.join(f'{q:g}' for q in fit['charges'])} e0")


def with_uncertainty(value: float, sd: float, sig: int = 2) -> str:
    """'value +- sd' with sd to `sig` significant digits and value to the same decimal place
    (a value without a finite, positive sd, e.g. of one seed: 3 significant digits)."""
    if not np.isfinite(value):
        return "-"
    if not (np.isfinite(sd) and sd > 0):
        return f"{value:.3g}"
    decimals = max(0, sig - 1 - int(np.floor(np.log10(sd))))
    return f"{value:.{decimals}f} +- {sd:.{decimals}f}"


def readable(s: pd.DataFrame, cols=("phi", "Z")) -> pd.DataFrame:
    """A summary for printing: each of cols as one 'mean +- sd' column (digits the seeds'
    scatter allows) and the expansion with its standard error."""
    out = s.copy()
    for c in cols:
        out[c] = [with_uncertainty(v, e) for v, e in zip(s[c], s[f"{c}_sd"])]
        out = out.drop(columns=f"{c}_sd")
    if "expansion" in s:
        out["expansion"] = [("0" if q == 0 else with_uncertainty(v, e, sig=1))
                            for q, v, e in zip(s["q"], s["expansion"], s["expansion_se"])]
        out = out.drop(columns="expansion_se")
    return out


def adstar(runs: pd.DataFrame, barrier_fraction: float = 1.0) -> pd.Series:
    """Ad / (1 - f E*) per run (f: see adstar_collapse); infinite where the particles cannot
    reach the bed (f E* >= 1)."""
    rest = 1.0 - barrier_fraction * runs["Estar"]
    return (runs["Ad"] / rest).where(rest > 0.0, np.inf)


def adstar_collapse(runs: pd.DataFrame, barrier_fraction: float = 1.0) -> pd.DataFrame:
    """Fig. 9's claim, quantified: a straight line in log10(Ad*) fitted to the neutral cases'
    mean phi (and <Z>); for every case the deviation of its mean from that line, in units of
    the standard error of its mean over the seeds. The charged cases collapse with the neutral
    ones if their deviations are as small as the neutral cases' own.

    Ad* = Ad / (1 - f E*): f = 1 is the paper's, whose E* is the sheet-field barrier over the
    injection height averaged over a one-at-a-time deposition; f = 1/2 fits the rain of one
    particle per r_p, whose charge in flight halves that barrier (doc/reproduction.md, "Ad*
    collapse" and "One particle at a time")."""
    r = runs.assign(Adstar=adstar(runs, barrier_fraction))
    s = (r.groupby(list(CASE), as_index=False)
         .agg(runs=("phi", "count"), Adstar=("Adstar", "first"), phi=("phi", "mean"),
              phi_sd=("phi", "std"), Z=("Z", "mean"), Z_sd=("Z", "std")))
    s = s[np.isfinite(s["Adstar"]) & (s["Adstar"] > 0)].copy()
    neutral = s[s["q"] == 0]
    if len(neutral) < 3:
        return s.assign(phi_line=np.nan, phi_dev=np.nan, Z_line=np.nan, Z_dev=np.nan)
    x = np.log10(s["Adstar"].to_numpy())
    xn = np.log10(neutral["Adstar"].to_numpy())
    for col in ("phi", "Z"):
        c = np.polyfit(xn, neutral[col].to_numpy(), 1)
        s[f"{col}_line"] = np.polyval(c, x)
        sem = s[f"{col}_sd"] / np.sqrt(s["runs"])
        s[f"{col}_dev"] = (s[col] - s[f"{col}_line"]) / sem
    return s


def table2_frame(rows: list[dict]) -> pd.DataFrame:
    """The charged-after-formation check beside the paper's Table 2 (its N = 2000 packing), one
    row per packing (the seed of its deposition) and charge."""
    df = pd.DataFrame(rows)[["q", "phi_before", "phi_after", "Z_before", "Z_after", "FC_over_FE"]]
    df.insert(0, "seed", [(r.get("params") or {}).get("seed") for r in rows])
    ref = pd.DataFrame(paper.TABLE2, columns=["q", "paper_phi", "paper_Z"])
    df = df.merge(ref, on="q", how="left")
    df["dphi"] = df["phi_after"] - df["phi_before"]
    df["dZ"] = df["Z_after"] - df["Z_before"]
    return df


def format_table(df: pd.DataFrame, floatfmt: str = "{:.4g}") -> str:
    return df.to_string(index=False, float_format=lambda v: floatfmt.format(v))


def grid_value(r: dict, name: str):
    """The value of a grid axis in a result (a field, or a deck variable of params.extra)."""
    p = r["params"]
    return p[name] if name in p else (p.get("extra") or {}).get(name)
