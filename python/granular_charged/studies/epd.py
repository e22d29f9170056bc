"""The electrophoretic deposition study (doc/epd.md): charged particles driven by an applied field
E_0 onto a grounded floor electrode, with or without induced dipoles (eps_p), at the paper's
particle set (r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2, q = 400 e_0) and the demo size (N = 500,
L = 14 r_p). Per (E_0, eps_p): phi and <Z> of the analysis slab, the f(Z) populations, and the
contact directions against the field (measures.contact_orientation over the same slab), each a
mean and standard deviation over the seeds."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import measures, packing, tables
from ..params import DepositionParams

# as the deck's variables are written on a command line (the run folders' keys: `granular-charged
# run --var E0 1e5 ...` makes the same folders)
FIELDS = ("1e5", "3e5")        # E_0 [V/m], along -z
PERMITTIVITIES = ("0", "3.8")  # eps_p: 0 not polarisable, 3.8 silica-like
SIZE = {"N": 500, "L_rp": "14"}
CASE = dict(rp=2e-6, U0=1.0, gamma=0.010, q=400.0)


def study_params(seeds=(1, 2, 3), fields=FIELDS, permittivities=PERMITTIVITIES,
                 size=SIZE) -> list[DepositionParams]:
    """Every (E_0, eps_p, seed) of the study, the electrode on."""
    return [DepositionParams(N=size["N"], seed=s, **CASE,
                             extra={"L_rp": size["L_rp"], "E0": e0, "eps_p": eps, "electrode": "yes"})
            for e0 in fields for eps in permittivities for s in seeds]


def run_measures(result: dict) -> dict:
    """phi, <Z>, f(Z) populations and the contact orientation of one finished run (the slab of
    the deck's analysis; NaN without one)."""
    out = {"E0": float(result["params"]["extra"].get("E0", 0.0)),
           "eps_p": float(result["params"]["extra"].get("eps_p", 0.0)),
           "seed": result["params"]["seed"], "phi": result.get("phi"), "Z": result.get("Z"),
           "cpu_s": result.get("cpu_s", float("nan")),
           **measures.fz_populations(result.get("fZ") or [])}
    out.update(contact_orientation_of_run(result))
    return out


def contact_orientation_of_run(result: dict) -> dict:
    """S, <|cos theta|> and the number of contacts in the analysis slab of one finished run (its
    final.dump, or final.dump.gz as kept; NaN without a slab)."""
    zlo, zhi = result.get("zlo"), result.get("zhi")
    if zlo is None or zhi is None or not zhi > zlo:
        return {"S": float("nan"), "mean_abs_cos": float("nan"), "contacts": 0}
    snap = packing.read_dump(Path(result["dir"]) / "final.dump", last_only=True)
    o = measures.contact_orientation(snap, zlo, zhi)
    return {"S": o["S"], "mean_abs_cos": o["mean_abs_cos"], "contacts": o["contacts"]}


def table(results: list[dict]) -> pd.DataFrame:
    """Mean and standard deviation over the seeds of every measure, per (E_0, eps_p)."""
    df = pd.DataFrame([run_measures(r) for r in results])
    for c in ("phi", "Z", "cpu_s"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    keys = ["phi", "Z", "fZ_1_2", "fZ_4_6", "S", "mean_abs_cos", "cpu_s"]
    agg = {"runs": ("seed", "count")}
    for k in keys:
        agg[k] = (k, "mean")
        agg[k + "_sd"] = (k, "std")
    return df.groupby(["E0", "eps_p"], as_index=False).agg(**agg)


def format_table(t: pd.DataFrame) -> str:
    """The table as printed: each measure as mean +- sd with the digits the seeds' scatter allows
    (tables.with_uncertainty; one seed: 3 significant digits, no sd), CPU seconds per run."""
    cols = {"phi": "phi", "Z": "<Z>", "fZ_1_2": "f(Z=1-2)", "fZ_4_6": "f(Z=4-6)",
            "S": "S (contacts vs field)"}
    shown = pd.DataFrame({"E0 [V/m]": [f"{v:.0e}" for v in t["E0"]],
                          "eps_p": [f"{v:g}" for v in t["eps_p"]], "runs": t["runs"].astype(int)})
    for k, head in cols.items():
        shown[head] = [tables.with_uncertainty(v, sd) for v, sd in zip(t[k], t[k + "_sd"])]
    shown["CPU s/run"] = [f"{v:.0f}" if np.isfinite(v) else "-" for v in t["cpu_s"]]
    return tables.format_table(shown)
