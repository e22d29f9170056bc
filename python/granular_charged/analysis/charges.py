"""The charges of a deposited bed: per species (the dump's type) the distribution of the final
charges, and the mean charge against the depth below the bed top (doc/populations.md,
"Contact charging").

Charges are in elementary charges e_0 (the dump's q in C divided by e_0). The bed top is
h = 2 <z> (the height of a uniform bed with the same centroid, the reference of the decks'
analysis slab, packing.analysis_slab); a particle's depth is h - z_i, negative for the rough
top above h. Depth bins are ``depth_rp`` r_p wide, from the floor of the smallest depth.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..params import E0
from . import packing

DEPTH_RP = 2.0          # default width of a depth bin [r_p]: one particle diameter
HIST_BINS = 30


def particles(snap: packing.Snapshot, rp: float) -> dict:
    """The particles as columns {'species', 'q_e0', 'depth_rp'} (arrays): each one's species
    (the dump's type; 1 without a type column), its charge [e_0] and its depth below the bed
    top [r_p]. ValueError when the dump has no column q."""
    if "q" not in snap.cols:
        raise ValueError("the dump has no column q (the particles' charges)")
    if not rp > 0:
        raise ValueError(f"r_p = {rp}: must be > 0")
    sp = snap["type"].astype(int) if "type" in snap.cols else np.ones(snap.n, dtype=int)
    return {"species": sp, "q_e0": np.asarray(snap["q"], dtype=float) / E0,
            "depth_rp": (bed_top(snap) - np.asarray(snap["z"], dtype=float)) / rp}


def pooled(tables: list[dict]) -> dict:
    """The particles of several beds (particles() of each) as one set of columns."""
    return {k: np.concatenate([t[k] for t in tables]) for k in ("species", "q_e0", "depth_rp")}


def bed_top(snap: packing.Snapshot) -> float:
    """h = 2 <z>: the bed top of the depth profile (module docstring)."""
    return 2.0 * float(np.mean(snap["z"]))


def _stats(q: np.ndarray) -> dict:
    """n, mean, sd (n - 1; 0 for one particle), median, min, max, the fractions of negative
    and positive particles and the total of charges q [e_0]."""
    q = np.asarray(q, dtype=float)
    n = len(q)
    if n == 0:
        nan = float("nan")
        return {"n": 0, "q_mean_e0": nan, "q_sd_e0": nan, "q_median_e0": nan, "q_min_e0": nan,
                "q_max_e0": nan, "frac_negative": nan, "frac_positive": nan, "q_total_e0": 0.0}
    return {"n": n, "q_mean_e0": float(q.mean()),
            "q_sd_e0": float(q.std(ddof=1)) if n > 1 else 0.0,
            "q_median_e0": float(np.median(q)), "q_min_e0": float(q.min()),
            "q_max_e0": float(q.max()), "frac_negative": float((q < 0).mean()),
            "frac_positive": float((q > 0).mean()), "q_total_e0": float(q.sum())}


def _groups(df: dict):
    """(label, columns) per species, then ("all", every particle)."""
    for t in np.unique(df["species"]):
        m = df["species"] == t
        yield int(t), {k: v[m] for k, v in df.items()}
    yield "all", df


def stats(df: dict) -> list[dict]:
    """Per species, then all particles (species "all"): the statistics of _stats."""
    return [{"species": label, **_stats(g["q_e0"])} for label, g in _groups(df)]


def depth_profile(df: dict, depth_rp: float = DEPTH_RP) -> list[dict]:
    """The mean charge against the depth below the bed top, per species and for all particles:
    rows {'species', 'depth_lo_rp', 'depth_hi_rp', 'depth_rp' (the bin's centre), 'n',
    'q_mean_e0', 'q_sd_e0', 'frac_negative'} for every bin holding particles; bins depth_rp
    wide, their edges multiples of depth_rp."""
    if not depth_rp > 0:
        raise ValueError(f"depth bins of {depth_rp} r_p: must be > 0")
    rows = []
    for label, g in _groups(df):
        k = np.floor(g["depth_rp"] / depth_rp).astype(int)
        q = g["q_e0"]
        for b in np.unique(k):
            st = _stats(q[k == b])
            rows.append({"species": label, "depth_lo_rp": b * depth_rp,
                         "depth_hi_rp": (b + 1) * depth_rp, "depth_rp": (b + 0.5) * depth_rp,
                         "n": st["n"], "q_mean_e0": st["q_mean_e0"], "q_sd_e0": st["q_sd_e0"],
                         "frac_negative": st["frac_negative"]})
    return rows


def histogram(df: dict, bins: int = HIST_BINS) -> list[dict]:
    """Counts of the charges per species on bins common to all particles' range: rows
    {'species', 'q_lo_e0', 'q_hi_e0', 'count'} (one bin around q when every charge is equal)."""
    q = df["q_e0"]
    if not len(q):
        return []
    lo, hi = float(q.min()), float(q.max())
    if hi <= lo:
        half = max(abs(lo) * 1e-6, 0.5)
        lo, hi, bins = lo - half, hi + half, 1
    edges = np.linspace(lo, hi, bins + 1)
    rows = []
    for label, g in _groups(df):
        if label == "all":
            continue
        h, _ = np.histogram(g["q_e0"], bins=edges)
        rows += [{"species": label, "q_lo_e0": float(a), "q_hi_e0": float(b), "count": int(c)}
                 for a, b, c in zip(edges[:-1], edges[1:], h)]
    return rows


def analyse(snap: packing.Snapshot, rp: float, depth_rp: float = DEPTH_RP) -> dict:
    """{'bed_top', 'depth_bin_rp', 'stats', 'depth', 'histogram'} of a final snapshot (the
    record of result.json's 'charges')."""
    df = particles(snap, rp)
    return {"bed_top": bed_top(snap), "depth_bin_rp": depth_rp, "stats": stats(df),
            "depth": depth_profile(df, depth_rp), "histogram": histogram(df)}


# the tables of a run's charges, in its folder
TABLES = {"stats": "charges.csv", "depth": "charge_depth.csv", "histogram": "charge_hist.csv"}


def write_table(rows: list[dict], path: Path) -> Path:
    """rows (dicts with the same keys) as a CSV file."""
    path = Path(path)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ["species"])
        w.writeheader()
        w.writerows(rows)
    return path


def write_tables(charges: dict, folder: Path) -> list[Path]:
    """The tables of analyse()'s result in folder (TABLES); returns their paths."""
    return [write_table(charges[key], Path(folder) / name) for key, name in TABLES.items()]
