"""Structure of the analysis slab: g(r) (the paper's Fig. 4) and f(Z) (Fig. 5)."""
from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd

from .. import paper
from ..analysis import packing
from .base import PAPER_STYLE, biggest_series, finished, new_figure, paper_notes, save, series_label

log = logging.getLogger(__name__)


def rdf(results, out: Path, nbins=150):
    """g(r) of the analysis slab, neutral vs the most charged case of one series (Fig. 4)."""
    ok = finished(results)
    if not ok:
        log.warning("figure rdf: no run with an analysis slab")
        return None
    key, byq = biggest_series(ok)
    qs = list(byq)
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    data = {}
    for q in [qs[0]] + ([qs[-1]] if len(qs) > 1 else []):
        gs = []
        for r in byq[q]:
            snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
            rp = r["params"]["rp"]
            rc, gr = packing.rdf_slab(snap, r["zlo"], r["zhi"], 6.0 * rp, nbins)
            gs.append(gr)
        x = rc / (2 * rp)
        data["r_over_2rp"] = x
        data[f"g_q{q:g}"] = np.mean(gs, axis=0)
        ax.plot(x, data[f"g_q{q:g}"], label=f"q = {q:g} e0 ({len(gs)} runs)")
    for v, t in ((1.0, "1"), (math.sqrt(3), "sqrt 3"), (2.0, "2")):
        ax.axvline(v, color="grey", lw=0.5, ls=":")
        ax.text(v, 0.98, t, transform=ax.get_xaxis_transform(), fontsize=6, ha="center", va="top")
    ax.set_xlabel("r / 2r_p")
    ax.set_ylabel("g(r)")
    ax.set_xlim(0.8, 3.0)
    ax.set_title(series_label(key) + ("\npaper (Fig. 4): the sqrt 3 peak vanishes when charged"
                                if paper_notes() else ""), fontsize=8)
    ax.legend(fontsize=7)
    return save(fig, Path(out) / "rdf.png", pd.DataFrame(data))


def fZ(results, out: Path):
    """Coordination-number distribution f(Z) per case (Fig. 5), with the paper's neutral <Z>."""
    ok = finished(results)
    if not ok:
        return None
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    rows = []
    groups = {}
    for r in ok:
        p = r["params"]
        groups.setdefault((p["rp"] * 1e6, p["U0"], p["gamma"] * 1e3, p["q"]), []).append(r)
    for (rp, U0, gam, q), rs in sorted(groups.items()):
        n = max(len(r["fZ"]) for r in rs)
        f = np.mean([np.pad(r["fZ"], (0, n - len(r["fZ"]))) for r in rs], axis=0)
        Zm = float(np.mean([r["Z"] for r in rs]))
        line, = ax.plot(range(n), f, marker="o", ms=3,
                        label=f"{series_label((rp, U0, gam))}, q = {q:g}: <Z> = {Zm:.2f}")
        ax.axvline(Zm, color=line.get_color(), lw=0.6, ls="--")
        rows.append(dict(rp_um=rp, U0=U0, gamma_mJ=gam, q=q, runs=len(rs), Z=Zm,
                         **{f"f{z}": v for z, v in enumerate(f)}))
    if paper_notes():
        ax.axvline(paper.TABLE2[0][2], **PAPER_STYLE)
        ax.plot([], [], **PAPER_STYLE, label=f"paper Table 2 neutral <Z> = {paper.TABLE2[0][2]}")
    ax.set_xlabel("Z (last bin of compute coord/dist: Z >= zmax)")
    ax.set_ylabel("f(Z)")
    ax.set_xlim(-0.5, 10.5)
    ax.legend(fontsize=5)
    return save(fig, Path(out) / "fZ.png", pd.DataFrame(rows))
