"""phi against the charge and the expansion phi_0/phi - 1 (the paper's Fig. 3), and the
Table 2 check."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from .. import paper
from ..analysis import tables
from .base import PAPER_STYLE, finished, new_figure, paper_notes, save, series_label

log = logging.getLogger(__name__)


def phi_vs_q(results, out: Path):
    """phi vs q (Fig. 3) with the paper's neutral range; phi_0/phi - 1 vs q on log-log with
    our fitted slope and the paper's slope 2 and maximum 0.4."""
    ok = finished(results)
    if not ok:
        log.warning("figure phi_vs_q: no finished run")
        return None, None
    s = tables.summary(tables.runs_frame(ok))
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    if paper_notes():
        ax.axhspan(*paper.PHI0_RANGE, color="0.88", label="paper: neutral phi_0 = 0.270-0.363")
    for key, g in s.groupby(["rp_um", "U0", "gamma_mJ"]):
        ax.errorbar(g["q"], g["phi"], g["phi_sd"].fillna(0), marker="o", capsize=3,
                    label=series_label(key) + f" (N = {g['N'].iloc[0]:.0f})")
    ax.set_xlabel("q / e0")
    ax.set_ylabel("phi")
    ax.legend(fontsize=6)
    p1 = save(fig, Path(out) / "phi_vs_q.png", s)

    fits = {tuple(f["series"]): f for f in tables.expansion_fits(tables.runs_frame(ok))}
    pos = s[(s["q"] > 0) & (s["expansion"] > 0)]
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    if pos.empty:
        # still a figure (with the paper's reference), saying why there are no points: a
        # log-log plot needs a neutral run and a looser charged run of one series
        log.warning("figure expansion_loglog: no charged run is looser than its neutral run")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.text(0.5, 0.5, "no charged run looser than its neutral run\n(phi_0/phi - 1 <= 0)",
                transform=ax.transAxes, ha="center", va="center", fontsize=9)
        if paper_notes():
            ax.axhline(paper.MAX_RELATIVE_DECREASE, color="0.5", ls="--", lw=0.8,
                       label="paper: maximum phi_0/phi - 1 = 0.4")
        ax.set_xlabel("q / e0")
        ax.set_ylabel("phi_0 / phi - 1")
        ax.legend(fontsize=6)
        return p1, save(fig, Path(out) / "expansion_loglog.png", s)
    rows = []
    for key, g in pos.groupby(["rp_um", "U0", "gamma_mJ"]):
        f = fits.get(tuple(float(v) for v in key))
        # a slope only where the rule of tables.expansion_fit allows one
        lbl = series_label(key) + (f": slope {f['slope']:.1f} ({f['p16']:.1f}-{f['p84']:.1f})"
                             if f and f["resolved"] else f": slope {tables.NOT_RESOLVED}")
        ax.errorbar(g["q"], g["expansion"], g["expansion_se"].fillna(0), fmt="o", capsize=3,
                    label=lbl)
        rows.append(dict(zip(["rp_um", "U0", "gamma_mJ"], key),
                         slope=f["slope"] if f else np.nan, p16=f.get("p16") if f else np.nan,
                         p84=f.get("p84") if f else np.nan))
        # the paper's slope 2 through the geometric centre of our points
        lq, le = np.log10(g["q"]).mean(), np.log10(g["expansion"]).mean()
        qq = np.array([g["q"].min() / 1.5, g["q"].max() * 1.5])
        if paper_notes():
            ax.loglog(qq, 10 ** (le + paper.EXPANSION_SLOPE * (np.log10(qq) - lq)), **PAPER_STYLE)
    if paper_notes():
        ax.plot([], [], **PAPER_STYLE, label="paper: slope 2 (through our points)")
        ax.axhline(paper.MAX_RELATIVE_DECREASE, color="0.5", ls="--", lw=0.8,
                   label="paper: maximum phi_0/phi - 1 = 0.4")
    ax.set_xlabel("q / e0")
    ax.set_ylabel("phi_0 / phi - 1")
    ax.legend(fontsize=6)
    ax.set_yscale("log")
    ax.set_xscale("log")
    p2 = save(fig, Path(out) / "expansion_loglog.png",
              pos.merge(pd.DataFrame(rows), how="left") if rows else pos)
    return p1, p2


def table2(rows: list[dict], out: Path) -> Path | None:
    """The charged-after-formation check (Table 2): phi and <Z> before and after charging,
    ours and the paper's."""
    if not rows:
        return None
    df = tables.table2_frame(rows)
    fig = new_figure(7.5, 3.4)
    a1, a2 = fig.add_subplot(121), fig.add_subplot(122)
    for ax, k, ref in ((a1, "phi", "paper_phi"), (a2, "Z", "paper_Z")):
        ax.plot(df["q"], df[f"{k}_before"], "o", mfc="none", ms=9, label="ours, before charging")
        ax.plot(df["q"], df[f"{k}_after"], "x", ms=8, label="ours, after charging + relaxing")
        pq, pv = [t[0] for t in paper.TABLE2], [t[1 if k == "phi" else 2] for t in paper.TABLE2]
        ax.plot(pq, pv, "k*", ms=9, label="paper Table 2 (N = 2000)")
        ax.set_xlabel("q / e0 (given after formation)")
        ax.set_ylabel("phi" if k == "phi" else "<Z>")
        lo = min(min(pv), df[f"{k}_before"].min())
        hi = max(max(pv), df[f"{k}_before"].max())
        ax.set_ylim(lo - 0.15 * (hi - lo) - 0.01, hi + 0.35 * (hi - lo) + 0.01)
    a1.legend(fontsize=6, loc="upper left")
    a2.set_title(f"max |d<Z>| = {df['dZ'].abs().max():.2g}", fontsize=8)
    a1.set_title(f"max |dphi| = {df['dphi'].abs().max():.2g}", fontsize=8)
    return save(fig, Path(out) / "table2.png", df)
