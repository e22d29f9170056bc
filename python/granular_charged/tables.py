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
    return pd.DataFrame(rows, columns=cols)


def summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Per case (r_p, U_0, gamma, q): runs, mean and standard deviation of phi and <Z> over the
    seeds, the groups, atoms, particles lost, mean wall time; and phi_0/phi - 1 against the
    neutral case of the same (r_p, U_0, gamma) (NaN without one)."""
    s = (runs.groupby(list(CASE), as_index=False)
         .agg(runs=("phi", "size"), phi=("phi", "mean"), phi_sd=("phi", "std"),
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
