"""The figure of a bed's final charges (contact charging, doc/populations.md): per species the
histogram of the charges and the mean charge against the depth below the bed top, with the
plotted data as CSV beside it. One run (``granular-charged run`` draws it in the run's folder)
or the pooled runs of a study's grid point (all its seeds)."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import charges
from ..analysis.packing import read_dump
from .base import new_figure

MARKERS = "os^"
TITLE_SIZE = 8


def particles_of(results: list[dict]) -> dict:
    """The particles (charges.particles) of the runs' final.dump, pooled."""
    return charges.pooled([charges.particles(read_dump(Path(r["dir"]) / "final.dump",
                                                       last_only=True), float(r["params"]["rp"]))
                           for r in results])


def charge_figure(df: dict, path: Path, title: str, names: dict | None = None,
                  depth_rp: float = charges.DEPTH_RP, study: str | None = None) -> Path:
    """The two panels (module docstring) of the particles df (charges.particles or pooled)
    in path (PNG) and its data in path with .csv (a column `study` first when given). names:
    {species: name}."""
    names = names or {}
    fig = new_figure(10, 3.8, layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    data = []
    hist = charges.histogram(df)
    st = {r["species"]: r for r in charges.stats(df)}
    for s in sorted({r["species"] for r in hist}):
        rows = [r for r in hist if r["species"] == s]
        name = names.get(s, f"species {s}")
        edges = [rows[0]["q_lo_e0"]] + [r["q_hi_e0"] for r in rows]
        a1.stairs([r["count"] for r in rows], edges,
                  label=f"{name}: mean {st[s]['q_mean_e0']:+.3g}, sd {st[s]['q_sd_e0']:.3g} e0, "
                        f"{st[s]['frac_negative']:.0%} negative")
        data += [{"panel": "histogram", "species": name, "x": 0.5 * (r["q_lo_e0"] + r["q_hi_e0"]),
                  "y": r["count"], "x_lo": r["q_lo_e0"], "x_hi": r["q_hi_e0"]} for r in rows]
    a1.axvline(0.0, color="0.6", lw=0.6)
    a1.set_xlabel("final charge q [e0]")
    a1.set_ylabel("particles [count]")
    prof = charges.depth_profile(df, depth_rp)
    for label in [*sorted({r["species"] for r in prof if r["species"] != "all"}), "all"]:
        rows = [r for r in prof if r["species"] == label]
        if label == "all" and len({r["species"] for r in prof}) <= 2:
            continue            # one species: its curve is the all-particles curve
        lab = "all particles" if label == "all" else names.get(label, f"species {label}")
        marker = "." if label == "all" else MARKERS[(label - 1) % 3]
        x = [r["q_mean_e0"] for r in rows]
        y = [r["depth_rp"] for r in rows]
        err = [r["q_sd_e0"] / np.sqrt(r["n"]) for r in rows]
        a2.errorbar(x, y, xerr=err, marker=marker, capsize=2, lw=0.8, label=lab,
                    color="k" if label == "all" else None)
        data += [{"panel": "depth", "species": lab, "x": r["q_mean_e0"], "y": r["depth_rp"],
                  "n": r["n"], "sd": r["q_sd_e0"], "frac_negative": r["frac_negative"]}
                 for r in rows]
    a2.axvline(0.0, color="0.6", lw=0.6)
    a2.invert_yaxis()
    a2.set_xlabel("mean charge of the depth bin [e0] (bars: standard error)")
    a2.set_ylabel(f"depth below the bed top 2<z> [r_p] (bins of {depth_rp:g} r_p)")
    for ax in (a1, a2):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6)
    fig.suptitle(textwrap.fill(title, 150), fontsize=TITLE_SIZE)
    path = Path(path)
    fig.savefig(path, dpi=120)
    table = pd.DataFrame(data)
    if study is not None:
        table.insert(0, "study", study)
    table.to_csv(path.with_suffix(".csv"), index=False)
    return path


def run_figure(result: dict) -> Path | None:
    """charge_distribution.png (its data in charge_distribution.csv) in a finished run's folder
    (a run with contact charging; None otherwise)."""
    if not result.get("charges"):
        return None
    t = result.get("tribo") or {}
    e0 = charges.E0
    title = (f"{result['key']}: final charges after contact charging (moved "
             f"{t.get('moved_C', float('nan')) / e0:.4g} e0 between particles, the floor gave "
             f"{t.get('wall_C', float('nan')) / e0:+.4g} e0)")
    return charge_figure(particles_of([result]), Path(result["dir"]) / "charge_distribution.png",
                         title)
