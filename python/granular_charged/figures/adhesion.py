"""phi and <Z> against Ad* (the paper's Fig. 9) and the Z-phi plane (Fig. 10)."""
from __future__ import annotations

import math
from pathlib import Path

from .. import paper
from ..analysis import tables
from .base import PAPER_STYLE, finished, new_figure, paper_notes, save

G2_NOTE = ("Eqs. 9-10 of the paper (Edwards volume-function equation of state) are not drawn: "
           "they need the g_2(r, Z) model of Liu et al., Soft Matter 11 (2015) 6492, which is "
           "not implemented here.")


def vs_adstar(results, out: Path):
    """phi and <Z> vs Ad* (Fig. 9) with the ALP limits, and the Z-phi plane (Fig. 10) with the
    ALP point and the paper's Table 2 neutral packing."""
    ok = [r for r in finished(results) if math.isfinite(r["groups"]["Adstar"])]
    if not ok:
        return None, None
    df = tables.runs_frame(ok)
    p1 = _phi_Z_vs(df, "Adstar", "Ad* (paper: all its cases have Ad* > 1)",
                   Path(out) / "phi_Z_vs_Adstar.png")
    # half the paper's barrier: the rain's charge in flight (doc/reproduction.md, "Ad* collapse")
    mid = df.assign(Adstar_mid=tables.adstar(df, barrier_fraction=0.5))
    _phi_Z_vs(mid, "Adstar_mid", "Ad / (1 - E*/2): half the barrier (the rain's charge in flight)",
              Path(out) / "phi_Z_vs_Adstar_mean_barrier.png")
    return p1, _phase_diagram(df, out)


def _phi_Z_vs(df, col: str, xlabel: str, path: Path):
    fig = new_figure(5.2, 6.0)
    a1, a2 = fig.add_subplot(211), fig.add_subplot(212, sharex=None)
    sc = a1.scatter(df[col], df["phi"], c=df["q"], cmap="plasma")
    a2.scatter(df[col], df["Z"], c=df["q"], cmap="plasma")
    if paper_notes():
        a1.axhline(paper.ALP_PHI, **PAPER_STYLE, label="paper: ALP limit phi = 1/8")
        a2.axhline(paper.ALP_Z, **PAPER_STYLE, label="paper: ALP limit <Z> = 2")
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.axvline(1.0, color="0.6", lw=0.8, ls="--")
        ax.legend(fontsize=6, loc="lower left")
    a1.set_ylabel("phi")
    a2.set_ylabel("<Z>")
    a2.set_xlabel(xlabel)
    fig.colorbar(sc, ax=[a1, a2], label="q / e0")
    return save(fig, path, df.drop(columns=["dir"]), tight=False)


def _phase_diagram(df, out: Path):
    fig = new_figure(5.2, 4.8)
    ax = fig.add_subplot(111)
    sc = ax.scatter(df["Z"], df["phi"], c=df["q"], cmap="plasma", label="this package's runs")
    if paper_notes():
        ax.plot([paper.ALP_Z], [paper.ALP_PHI], "k*", ms=12, label="paper: ALP (Z = 2, phi = 1/8)")
        ax.plot([paper.TABLE2[0][2]], [paper.TABLE2[0][1]], "ks", mfc="none", ms=8,
                label="paper Table 2 neutral packing")
    ax.set_xlim(1.5, 6.5)
    ax.set_ylim(0.1, 0.65)
    ax.set_xlabel("<Z>")
    ax.set_ylabel("phi")
    fig.colorbar(sc, ax=ax, label="q / e0")
    ax.legend(fontsize=7, loc="upper left")
    fig.text(0.01, 0.005, G2_NOTE, fontsize=5.5, va="bottom", wrap=True)
    fig.subplots_adjust(bottom=0.2)
    return save(fig, Path(out) / "phase_diagram_Z_phi.png", df.drop(columns=["dir"]), tight=False)
