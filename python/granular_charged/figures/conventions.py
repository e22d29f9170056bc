"""The phi_0 question (doc/reproduction.md): phi and <Z> of the neutral cases by the conventions the
paper leaves open (conventions, a figure of every result set), and the conventions study's
phi_0 against the rolling limit (phi0_question)."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from .. import paper
from ..analysis import claims
from ..analysis.conventions import KEYS, MEASURES, PHI_DEFINITIONS, Z_DEFINITIONS
from .base import PAPER_STYLE, finished, new_figure, paper_notes, save

log = logging.getLogger(__name__)


CONVENTION_BARS = ((("phi", "slab"), ("phi_bed_top", "whole bed, H_p = highest top"),
                    ("phi_bed_surface", "whole bed, H_p = mean surface")),
                   (("Z", "slab"), ("Z_all", "all particles"),
                    ("Z_all_floor", "all, floor contacts counted")))


def conventions(results, out: Path):
    """phi and <Z> of every neutral case by the conventions the paper leaves open (mean +- sd
    over the seeds), beside the paper's neutral range of phi_0 and its Table 2 packing."""
    neutral = [r for r in finished(results) if r["params"]["q"] == 0]
    if not neutral:
        log.warning("figure conventions: no neutral run")
        return None
    t = claims.case_table(claims.runs_with_measures(neutral)).sort_values("Ad")
    fig = new_figure(6.4, 6.0)
    axes = fig.add_subplot(211), fig.add_subplot(212)
    x = np.arange(len(t))
    for ax, bars in zip(axes, CONVENTION_BARS):
        w = 0.8 / len(bars)
        for k, (col, name) in enumerate(bars):
            ax.bar(x + (k - (len(bars) - 1) / 2) * w, t[col], w, yerr=t[f"{col}_sd"].fillna(0),
                   capsize=2, label=name)
        ax.set_xticks(x)
        ax.set_xticklabels([f"{a:g} um, {b:g} m/s\n{c:g} mJ/m2\nAd = {ad:.2g}" for a, b, c, ad in
                            zip(t["rp_um"], t["U0"], t["gamma_mJ"], t["Ad"])], fontsize=5)
    if paper_notes():
        axes[0].axhspan(*paper.PHI0_RANGE, color="0.88", zorder=0,
                        label=f"paper: phi_0 = {paper.PHI0_RANGE[0]}-{paper.PHI0_RANGE[1]}")
        axes[0].axhline(paper.TABLE2[0][1], **PAPER_STYLE,
                        label=f"paper Table 2 (2 um, 1 m/s): {paper.TABLE2[0][1]}")
        axes[1].axhline(paper.TABLE2[0][2], **PAPER_STYLE,
                        label=f"paper Table 2 (2 um, 1 m/s): {paper.TABLE2[0][2]}")
    axes[0].set_ylabel("phi")
    axes[1].set_ylabel("<Z>")
    axes[0].set_ylim(0.2, None)
    axes[1].set_ylim(2.0, None)
    for ax in axes:
        ax.legend(fontsize=5, ncol=2)
    n = int(t["runs"].min())
    fig.suptitle(f"neutral packings by convention, N = {int(neutral[0]['natoms'])}, "
                 f">= {n} seed{'s' if n > 1 else ''} per case", fontsize=8)
    cols = ["rp_um", "U0", "gamma_mJ", "Ad", "runs"] + [f"{c}{sfx}" for bars in CONVENTION_BARS
                                                       for c, _ in bars for sfx in ("", "_sd")]
    return save(fig, Path(out) / "conventions.png", t[cols])


def _rolling_axis(ax, thetas):
    ax.set_xscale("log")
    ax.set_xticks(thetas, [f"{v:g}" for v in thetas])
    ax.minorticks_off()
    ax.set_xlabel("theta_crit (rolling limit)")


def phi0_question(t: pd.DataFrame, out) -> Path | None:
    """phi0_question.png in OUT (beside reproduce's conventions.png, which compares the cases at the
    deck's rolling limit): per phi definition, the neutral phi_0 of the three series against
    the rolling limit (mean +- sd over the seeds) with the paper's range as a band and its Table
    2 phi_0 as a star at every theta_crit; beside it <Z>_0 of the Table 2 case (slab and all
    particles) with the paper's 3.2056. The plotted means beside it as CSV."""
    neutral = t[t["q"] == 0]
    if neutral.empty:
        return None
    fig = new_figure(3.0 * (len(PHI_DEFINITIONS) + 1), 3.3)
    lo, hi = paper.PHI0_RANGE
    thetas = sorted(neutral["theta_crit"].unique())
    for k, (name, col) in enumerate(PHI_DEFINITIONS.items()):
        ax = fig.add_subplot(1, len(PHI_DEFINITIONS) + 1, k + 1)
        ax.axhspan(lo, hi, color="0.85", label=f"paper: phi_0 {lo}-{hi}")
        ax.plot(thetas, [paper.TABLE2[0][1]] * len(thetas), "k*", ms=8,
                label=f"paper Table 2: {paper.TABLE2[0][1]}")
        for (rp, u0), d in neutral.groupby(["rp_um", "U0"]):
            d = d.sort_values("theta_crit")
            ax.errorbar(d["theta_crit"], d[col], yerr=d[f"{col}_sd"].fillna(0.0), marker="o",
                        ms=3, capsize=2, label=f"{rp:g} um, {u0:g} m/s")
        _rolling_axis(ax, thetas)
        ax.set_ylabel("phi_0")
        ax.set_title(f"phi: {name}", fontsize=8)
        if k == 0:
            ax.legend(fontsize=6)
    ax = fig.add_subplot(1, len(PHI_DEFINITIONS) + 1, len(PHI_DEFINITIONS) + 1)
    fig2 = neutral[np.isclose(neutral["rp_um"], paper.TABLE2_CASE[0])
                   & np.isclose(neutral["U0"], paper.TABLE2_CASE[1])]
    fig2 = fig2.sort_values("theta_crit")
    ax.axhline(paper.TABLE2[0][2], color="k", ls="--", label=f"paper Table 2: {paper.TABLE2[0][2]}")
    for name, col in Z_DEFINITIONS.items():
        ax.errorbar(fig2["theta_crit"], fig2[col], yerr=fig2[f"{col}_sd"].fillna(0.0), marker="o",
                    ms=3, capsize=2, label=f"<Z> {name}")
    _rolling_axis(ax, thetas)
    ax.set_ylabel("<Z>_0, 2 um, 1 m/s")
    ax.legend(fontsize=6)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    cols = KEYS + ["runs"] + [c for m in MEASURES for c in (m, f"{m}_sd")]
    return save(fig, out / "phi0_question.png", t[cols])
