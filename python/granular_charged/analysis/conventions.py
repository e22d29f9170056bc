"""The conventions the paper leaves open (doc/reproduction.md, "The phi_0 question at paper
size") as columns of a table: the measure each definition of phi and <Z> reads, and the runs'
frame and per-case means over the seeds, from which the conventions study checks the paper's
numbers (granular_charged.studies.conventions) and its figure is drawn
(granular_charged.figures.conventions)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import measures

# each definition by name: the column that holds it (phi in the analysis slab or over the whole
# bed up to H_p; <Z> in the slab or over all particles)
PHI_DEFINITIONS = {"slab": "phi", "bed, H_p = mean surface": "phi_bed_surface",
                   "bed, H_p = highest top": "phi_bed_top"}
Z_DEFINITIONS = {"slab": "Z", "all particles": "Z_all"}
# the measures of a run the table holds (the last three from measures.json) and the keys of a
# case: theta_crit and the case (r_p [um], U_0 [m/s], q [e_0])
MEASURES = ("phi", "Z", "phi_bed_surface", "phi_bed_top", "Z_all")
KEYS = ["theta_crit", "rp_um", "U0", "q"]


def run_frame(results: list[dict]) -> pd.DataFrame:
    """One row per finished run: its case, theta_crit, seed and the five measures (the
    whole-bed ones from measures.json, computed once per run)."""
    rows = []
    for r in results:
        p = r["params"]
        m = measures.load(r["dir"], r)
        rows.append({"theta_crit": float(p.get("theta_crit", 0.01)), "rp_um": p["rp"] * 1e6,
                     "U0": p["U0"], "q": p["q"], "seed": p["seed"], "phi": r.get("phi"),
                     "Z": r.get("Z"), **{k: m.get(k, np.nan) for k in MEASURES[2:]},
                     "cpu_s": r.get("cpu_s", np.nan)})
    df = pd.DataFrame(rows, columns=KEYS + ["seed", *MEASURES, "cpu_s"])
    for c in (*MEASURES, "cpu_s"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def case_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (theta_crit, case): runs, and mean, sd and count of every measure over the seeds."""
    agg = {"runs": ("seed", "count"), "cpu_s": ("cpu_s", "mean")}
    for c in MEASURES:
        agg[c] = (c, "mean")
        agg[f"{c}_sd"] = (c, "std")
        agg[f"{c}_n"] = (c, "count")
    return runs.groupby(KEYS, as_index=False).agg(**agg)
