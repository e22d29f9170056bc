"""What every figure shares: a figure without pyplot, saving it with its data as CSV, the
colours of Z, whether the paper's values are drawn (PAPER) and the series' labels.

Object-oriented matplotlib only (``Figure`` + ``FigureCanvasAgg``; no pyplot, no global backend
switch). Every figure that has a number in the paper's text shows it beside ours
(:mod:`granular_charged.paper`) when the runs are of the paper's material."""
from __future__ import annotations

import math
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure

from .. import paper
from ..analysis import tables
from ..params import DepositionParams

PAPER_STYLE = MappingProxyType(dict(color="k", ls=":", lw=1.0))   # read-only


def new_figure(w: float, h: float, layout: str | None = None) -> Figure:
    """A figure of w x h inches; layout "constrained": titles, labels and legends fit in it
    (do not call tight_layout on it)."""
    fig = Figure(figsize=(w, h), layout=layout)
    FigureCanvasAgg(fig)
    return fig


def save(fig: Figure, path: Path, data: pd.DataFrame | None = None, tight: bool = True) -> Path:
    """PNG (130 dpi) and, when given, the plotted data as CSV with the same stem."""
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=130)
    if data is not None:
        data.to_csv(Path(path).with_suffix(".csv"), index=False)
    return Path(path)


def z_colormap():
    """Colour map and norm of the coordination number: one colour per Z (paper.Z_COLORS), the
    last for Z >= its index; the same colours LAMMPS's dump image used."""
    n = len(paper.Z_COLORS)
    return ListedColormap(paper.Z_COLORS), BoundaryNorm(np.arange(-0.5, n), n)


def z_colorbar(fig, ax):
    cmap, norm = z_colormap()
    n = len(paper.Z_COLORS)
    cb = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, ticks=range(n), shrink=0.8,
                      pad=0.02)
    cb.ax.set_yticklabels([str(k) for k in range(n - 1)] + [f">={n - 1}"])
    cb.set_label("coordination number Z")
    return cb


# the paper's values and annotations: only for runs of the paper's material and one kind of
# particle (set by all_figures); material: the user's material, prefixed to the series labels
PAPER = {"on": True, "material": ""}


def paper_notes() -> bool:
    return PAPER["on"]


def material_label(results) -> str:
    """The material of the runs as a label ('' for the paper's): the values that differ from
    the paper's Table 1 and the population (its rules), e.g. 'rho 3000, E 1e+08, uniform radii'."""
    parts = {}
    for r in results:
        p = r["params"]
        for k in ("rho", "E", "nu", "e", "mu"):
            if p.get(k, getattr(DepositionParams, k)) != getattr(DepositionParams, k):
                parts[k] = f"{k} {p[k]:g}"
        ex = p.get("extra") or {}
        if int(float(ex.get("species", 1))) > 1:
            parts["species"] = f"{ex['species']} species"
        if ex.get("r_dist", "one") != "one":
            parts["r_dist"] = f"{ex['r_dist']} radii"
        if ex.get("q_dist", "fixed") != "fixed":
            parts["q_dist"] = f"{ex['q_dist']} charges"
    return ", ".join(parts.values())


def series_label(key):
    rp, U0, gamma = key
    pre = f"{PAPER['material']}: " if PAPER["material"] else ""
    return pre + f"r_p = {rp:g} um, U0 = {U0:g} m/s, gamma = {gamma:g} mJ/m2"


def finished(results):
    return [r for r in results if r.get("phi") is not None and not math.isnan(r["phi"])]


def biggest_series(ok):
    """The series (r_p, U_0, gamma) with the most charges: (its key, its runs by charge)."""
    df = tables.runs_frame(ok)
    key = df.groupby(["rp_um", "U0", "gamma_mJ"])["q"].nunique().idxmax()
    sel = [r for r in ok if (r["params"]["rp"] * 1e6, r["params"]["U0"],
                             r["params"]["gamma"] * 1e3) == key]
    byq = {}
    for r in sel:
        byq.setdefault(r["params"]["q"], []).append(r)
    return key, dict(sorted(byq.items()))
