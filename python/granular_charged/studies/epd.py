"""The electrophoretic deposition study (doc/epd.md): charged particles driven by an applied field
E_0 onto a grounded floor electrode, with or without induced dipoles (eps_p), at the paper's
particle set (r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2, q = 400 e_0) and the demo size (N = 500,
L = 14 r_p). Per (E_0, eps_p): phi and <Z> of the analysis slab, the f(Z) populations, and the
contact directions against the field (measures.contact_orientation over the same slab), each a
mean and standard deviation over the seeds."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import measures, packing, tables
from ..params import DepositionParams

log = logging.getLogger(__name__)

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


def figures(results: list[dict], out: Path) -> list[Path]:
    """The study's pictures in OUT: packings.png, the first seed of each (E_0, eps_p) side by
    side coloured by Z (figures.packing_panel: LAMMPS's render, or the side view from the dump),
    and orientation.png, the distribution of |cos theta| of the contacts against the field per
    case (mean over the seeds; isotropic contacts: uniform, density 1). Data beside as CSV."""
    from .. import figures as fg
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ok = [r for r in results if r.get("phi") is not None]
    if not ok:
        log.warning("EPD figures: no finished run")
        return []

    def case(r):
        x = r["params"]["extra"]
        return float(x.get("E0", 0.0)), float(x.get("eps_p", 0.0))

    cases = sorted({case(r) for r in ok})
    def pick(r):    # a run with LAMMPS's render first, then the lowest seed
        return (not (Path(r["dir"]) / "packing.png").exists(), r["params"]["seed"])

    first = {c: min((r for r in ok if case(r) == c), key=pick) for c in cases}
    n = len(cases)
    fig = fg.new_figure(3.4 * n + 1.0, 4.3)
    axes = [fig.add_subplot(1, n, k + 1) for k in range(n)]
    fig.subplots_adjust(top=0.80)
    for ax, c in zip(axes, cases):
        fg.packing_panel(fig, ax, first[c])
        ax.set_title(f"E0 = {c[0]:.0e} V/m, eps_p = {c[1]:g}, seed {first[c]['params']['seed']}\n"
                     + ax.get_title(), fontsize=7)
    fg.z_colorbar(fig, axes)
    fig.suptitle("EPD (doc/epd.md): 400 e0, r_p = 2 um, electrode at z = 0, field along -z",
                 fontsize=8, y=0.99)
    panels = pd.DataFrame([dict(E0=c[0], eps_p=c[1], seed=first[c]["params"]["seed"],
                                phi=first[c]["phi"], Z=first[c]["Z"]) for c in cases])
    paths = [fg.save(fig, out / "packings.png", panels, tight=False)]

    rows = []
    for r in ok:
        zlo, zhi = r.get("zlo"), r.get("zhi")
        if zlo is None or zhi is None or not zhi > zlo:
            continue
        snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
        hist = measures.contact_orientation(snap, zlo, zhi)["abs_cos_hist"]
        for k, h in enumerate(hist):
            rows.append(dict(E0=case(r)[0], eps_p=case(r)[1], seed=r["params"]["seed"],
                             abs_cos=(k + 0.5) / len(hist), density=h))
    if rows:
        df = pd.DataFrame(rows)
        g = df.groupby(["E0", "eps_p", "abs_cos"], as_index=False).agg(
            density=("density", "mean"), sd=("density", "std"), seeds=("seed", "nunique"))
        fig = fg.new_figure(5.0, 3.6)
        ax = fig.add_subplot(111)
        for (e0, eps), d in g.groupby(["E0", "eps_p"]):
            ax.errorbar(d["abs_cos"], d["density"], yerr=d["sd"].fillna(0.0), marker="o", ms=3,
                        capsize=2, label=f"E0 {e0:.0e} V/m, eps_p {eps:g} ({int(d['seeds'].iloc[0])} seeds)")
        ax.axhline(1.0, **fg.PAPER_STYLE, label="isotropic")
        ax.set_xlabel("|cos theta| of a contact against the field")
        ax.set_ylabel("density")
        ax.legend(fontsize=7)
        paths.append(fg.save(fig, out / "orientation.png", g))
    return paths
