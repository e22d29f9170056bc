"""The one-at-a-time limit at the paper's size (doc/reproduction.md, "One particle at a time"):
``inject sequential`` (each particle starts once the previous one has landed and the bed is at
rest) against the deck's default plane rain, at the charges where the protocol matters, in the
paper's Fig. 2 case (r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2), N = 2000 in L = 28 r_p.

Runs: q = 260 and 400 e_0 one at a time, the same charges with the default plane rain, and the
neutral default rain (phi_0 of phi_0/phi - 1), three seeds each. The default runs are those of
`reproduce --size paper` (the same folders). A sequential run is ~12 million steps: the study
leaves restart points (``--checkpoint``, default every 50 particles), so that a run cut off by
an interruption goes on from there (doc/deposition.md, "Restart points").

Per charge and protocol: phi and <Z> (analysis slab) as mean +- sd over the seeds,
phi_0/phi - 1 with its standard error, CPU per run; per charge the difference sequential -
plane rain in phi, <Z> and phi_0/phi - 1 in standard errors of the difference (the protocol
is converged where it stays within ~2).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis import tables
from ..params import DepositionParams

CHARGES = (260.0, 400.0)
CASE = {"rp": 2e-6, "U0": 1.0, "gamma": 0.010}
SEQUENTIAL = "one at a time"
DEFAULT = "default (rain / plane rain)"
CHECKPOINT = 50                 # particles between restart points of a sequential run
MEASURES = ("phi", "Z")


def study_params(seeds=(1, 2, 3), N: int = 2000, extra=None, fields=None) -> list[DepositionParams]:
    """The neutral default runs, then per charge the default and the sequential runs, seed by
    seed (``extra``: other deck variables, ``fields``: other DepositionParams fields)."""
    def make(q, inject, s):
        more = {"inject": inject} if inject else {}
        return DepositionParams(q=q, N=N, seed=s, extra={**(extra or {}), **more},
                                **CASE, **(fields or {}))
    ps = [make(0.0, None, s) for s in seeds]
    for q in CHARGES:
        ps += [make(q, None, s) for s in seeds] + [make(q, "sequential", s) for s in seeds]
    return ps


def protocol(params: dict) -> str:
    return SEQUENTIAL if params.get("extra", {}).get("inject") == "sequential" else DEFAULT


def run_frame(results: list[dict]) -> pd.DataFrame:
    """One row per finished run: charge, protocol, seed, phi, <Z>, CPU, pieces."""
    rows = [{"q": r["params"]["q"], "protocol": protocol(r["params"]), "seed": r["params"]["seed"],
             "phi": r.get("phi"), "Z": r.get("Z"), "cpu_s": r.get("cpu_s"),
             "pieces": len(r.get("pieces", [])) or 1} for r in results]
    df = pd.DataFrame(rows, columns=["q", "protocol", "seed", *MEASURES, "cpu_s", "pieces"])
    for c in (*MEASURES, "cpu_s"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def case_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (q, protocol): runs, mean and sd of phi and <Z>, phi_0/phi - 1 against the neutral
    default runs with its standard error (tables.expansion_and_se), mean CPU per run."""
    agg = {"runs": ("seed", "count"), "cpu_s": ("cpu_s", "mean")}
    for c in MEASURES:
        agg[c] = (c, "mean")
        agg[f"{c}_sd"] = (c, "std")
    t = runs.groupby(["q", "protocol"], as_index=False).agg(**agg)
    t["expansion"] = t["expansion_se"] = np.nan
    neutral = t[t["q"] == 0]
    if len(neutral):
        n0 = neutral.iloc[0]
        for i, row in t[t["q"] > 0].iterrows():
            e, se = tables.expansion_and_se(n0["phi"], n0["phi_sd"] / np.sqrt(n0["runs"]),
                                            row["phi"], row["phi_sd"] / np.sqrt(row["runs"]))
            t.loc[i, ["expansion", "expansion_se"]] = e, se
    return t.sort_values(["q", "protocol"]).reset_index(drop=True)


def differences(t: pd.DataFrame) -> pd.DataFrame:
    """Per charge with both protocols: sequential - default in phi, <Z> and phi_0/phi - 1, each
    with the standard error of the difference and their ratio (NaN below 2 seeds a side)."""
    rows = []
    for q in sorted(t.loc[t["q"] > 0, "q"].unique()):
        seq = t[(t["q"] == q) & (t["protocol"] == SEQUENTIAL)]
        dflt = t[(t["q"] == q) & (t["protocol"] == DEFAULT)]
        if seq.empty or dflt.empty:
            continue
        a, b = seq.iloc[0], dflt.iloc[0]
        row = {"q": q, "runs_sequential": int(a["runs"]), "runs_default": int(b["runs"])}
        for c in MEASURES:
            se = np.hypot(a[f"{c}_sd"] / np.sqrt(a["runs"]), b[f"{c}_sd"] / np.sqrt(b["runs"]))
            row[f"d_{c}"] = a[c] - b[c]
            row[f"d_{c}_se"] = se
            row[f"d_{c}_in_se"] = row[f"d_{c}"] / se if se > 0 else np.nan
        se = np.hypot(a["expansion_se"], b["expansion_se"])
        row["d_expansion"] = a["expansion"] - b["expansion"]
        row["d_expansion_se"] = se
        rows.append(row)
    return pd.DataFrame(rows)


def format_table(t: pd.DataFrame) -> str:
    shown = pd.DataFrame({
        "q [e0]": [f"{v:g}" for v in t["q"]], "protocol": t["protocol"],
        "runs": t["runs"].astype(int),
        "phi": [tables.with_uncertainty(v, s) for v, s in zip(t["phi"], t["phi_sd"])],
        "<Z>": [tables.with_uncertainty(v, s) for v, s in zip(t["Z"], t["Z_sd"])],
        "phi_0/phi - 1": ["-" if q == 0 else tables.with_uncertainty(v, s, sig=1)
                          for q, v, s in zip(t["q"], t["expansion"], t["expansion_se"])],
        "CPU s/run": [f"{v:.0f}" if np.isfinite(v) else "-" for v in t["cpu_s"]]})
    return tables.format_table(shown)


def format_differences(d: pd.DataFrame) -> str:
    if d.empty:
        return "one at a time - default: no charge with runs of both protocols yet"
    def in_se(v):
        return f"{v:+.1f}" if np.isfinite(v) else "-"
    lines = ["one at a time - default (in brackets: in standard errors of the difference):"]
    for r in d.itertuples():
        lines.append(
            f"  {r.q:g} e0 ({r.runs_sequential} / {r.runs_default} runs): "
            f"phi {tables.with_uncertainty(r.d_phi, r.d_phi_se, sig=1)} ({in_se(r.d_phi_in_se)}), "
            f"<Z> {tables.with_uncertainty(r.d_Z, r.d_Z_se, sig=1)} ({in_se(r.d_Z_in_se)}), "
            f"phi_0/phi - 1 {tables.with_uncertainty(r.d_expansion, r.d_expansion_se, sig=1)}")
    return "\n".join(lines)
