"""Tables of runs through pandas: one row per run, summaries per case with groupby().agg."""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import paper

CASE = ("rp_um", "U0", "gamma_mJ", "q")    # a case: everything but the seed


def runs_frame(results: list[dict]) -> pd.DataFrame:
    """One row per run: parameters, dimensionless groups, phi, <Z> (LAMMPS computes) and the
    Python cross-check, counters, timing, folder."""
    rows = []
    for r in results:
        p, g = r["params"], r["groups"]
        rows.append({
            "rp_um": p["rp"] * 1e6, "U0": p["U0"], "gamma_mJ": p["gamma"] * 1e3, "q": p["q"],
            "seed": p["seed"], "N": p["N"], "Ad": g["Ad"], "Estar": g["Estar"],
            "Adstar": g["Adstar"], "phi": r["phi"], "Z": r["Z"],
            "phi_python": r.get("python", {}).get("phi"), "Z_python": r.get("python", {}).get("Z"),
            "natoms": r["natoms"], "lost": r["lost"], "flying": r["flying"],
            "wall_s": r.get("wall_s"), "key": r["key"], "dir": r.get("dir"),
        })
    cols = list(CASE) + ["seed", "N", "Ad", "Estar", "Adstar", "phi", "Z", "phi_python", "Z_python",
                   "natoms", "lost", "flying", "wall_s", "key", "dir"]
    df = pd.DataFrame(rows, columns=cols)
    # a run without an analysis slab has phi = <Z> = None: NaN, whatever the other runs have
    for c in ("phi", "Z", "phi_python", "Z_python"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Per case (r_p, U_0, gamma, q): runs (those with an analysis slab, which the means and
    standard deviations of phi and <Z> over the seeds are made of), no_slab (the runs whose bed
    was too thin for one), the groups, atoms, particles lost, mean wall time; and phi_0/phi - 1
    against the neutral case of the same (r_p, U_0, gamma) (NaN without one)."""
    s = (runs.groupby(list(CASE), as_index=False)
         .agg(runs=("phi", "count"), no_slab=("phi", lambda v: int(v.isna().sum())),
              phi=("phi", "mean"), phi_sd=("phi", "std"),
              Z=("Z", "mean"), Z_sd=("Z", "std"), Ad=("Ad", "first"), Estar=("Estar", "first"),
              Adstar=("Adstar", "first"), N=("natoms", "mean"), lost=("lost", "sum"),
              wall_s=("wall_s", "mean")))
    series = ["rp_um", "U0", "gamma_mJ"]
    phi0 = s[s["q"] == 0].set_index(series)["phi"].rename("phi0")
    s = s.join(phi0, on=series)
    s["expansion"] = s["phi0"] / s["phi"] - 1.0
    return s.drop(columns="phi0")


def expansion_slope(s: pd.DataFrame) -> pd.DataFrame:
    """Per series, the log-log slope of phi_0/phi - 1 vs q over the charged cases with a
    positive expansion (NaN with fewer than two); the paper's is 2."""
    out = []
    for key, g in s[(s["q"] > 0) & (s["expansion"] > 0)].groupby(["rp_um", "U0", "gamma_mJ"]):
        slope = (np.polyfit(np.log10(g["q"]), np.log10(g["expansion"]), 1)[0]
                 if len(g) >= 2 else np.nan)
        out.append(dict(zip(["rp_um", "U0", "gamma_mJ"], key), points=len(g), slope=slope,
                        paper_slope=paper.EXPANSION_SLOPE))
    return pd.DataFrame(out, columns=["rp_um", "U0", "gamma_mJ", "points", "slope", "paper_slope"])


def expansion_fit(runs: pd.DataFrame, series=(2.0, 1.0, 10.0), n_boot: int = 2000,
                  seed: int = 1) -> dict:
    """The log-log slope of phi_0/phi - 1 vs q for one series (r_p [um], U_0, gamma [mJ]),
    with its uncertainty from the seeds: a bootstrap that redraws the seeds of every charge
    (and of the neutral case) with replacement, recomputes the means and refits; charges whose
    mean expansion is not positive are left out of that fit. Returns the slope of the
    observed means, the bootstrap mean and standard deviation, the 16th-84th percentile range,
    and the points used."""
    sel = runs[(runs["rp_um"] == series[0]) & (runs["U0"] == series[1]) &
               (runs["gamma_mJ"] == series[2])]
    by_q = {q: g["phi"].to_numpy() for q, g in sel.groupby("q")}
    if 0.0 not in by_q or len(by_q) < 3:
        return {"slope": np.nan, "sd": np.nan, "points": 0}

    def fit(means):
        q = np.array([k for k in means if k > 0])
        e = np.array([means[0.0] / means[k] - 1.0 for k in q])
        keep = e > 0
        if keep.sum() < 2:
            return np.nan, int(keep.sum())
        return float(np.polyfit(np.log10(q[keep]), np.log10(e[keep]), 1)[0]), int(keep.sum())

    slope, points = fit({q: v.mean() for q, v in by_q.items()})
    rng = np.random.default_rng(seed)
    boots = []
    for _ in range(n_boot):
        b, _ = fit({q: rng.choice(v, size=len(v), replace=True).mean() for q, v in by_q.items()})
        if np.isfinite(b):
            boots.append(b)
    boots = np.array(boots)
    return {"slope": slope, "boot_mean": float(boots.mean()), "sd": float(boots.std(ddof=1)),
            "p16": float(np.percentile(boots, 16)), "p84": float(np.percentile(boots, 84)),
            "points": points, "charges": sorted(k for k in by_q if k > 0),
            "paper_slope": paper.EXPANSION_SLOPE}


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
    """The charged-after-formation check beside the paper's Table 2 (its N = 2000 packing)."""
    df = pd.DataFrame(rows)[["q", "phi_before", "phi_after", "Z_before", "Z_after", "FC_over_FE"]]
    ref = pd.DataFrame(paper.TABLE2, columns=["q", "paper_phi", "paper_Z"])
    df = df.merge(ref, on="q", how="left")
    df["dphi"] = df["phi_after"] - df["phi_before"]
    df["dZ"] = df["Z_after"] - df["Z_before"]
    return df


def format_table(df: pd.DataFrame, floatfmt: str = "{:.4g}") -> str:
    return df.to_string(index=False, float_format=lambda v: floatfmt.format(v))
