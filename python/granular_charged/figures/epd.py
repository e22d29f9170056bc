"""The electrophoretic deposition study's pictures (doc/epd.md): the packings side by side and the
contacts' orientation against the field."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd

from ..analysis import measures, packing
from .base import PAPER_STYLE, new_figure, save, z_colorbar
from .packings import packing_panel

log = logging.getLogger(__name__)


def epd_figures(results: list[dict], out: Path) -> list[Path]:
    """The study's pictures in OUT: packings.png, the first seed of each (E_0, eps_p) side by
    side coloured by Z (packings.packing_panel: LAMMPS's render, or the side view from the dump),
    and orientation.png, the distribution of |cos theta| of the contacts against the field per
    case (mean over the seeds; isotropic contacts: uniform, density 1). Data beside as CSV."""
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
    fig = new_figure(3.4 * n + 1.0, 4.3)
    axes = [fig.add_subplot(1, n, k + 1) for k in range(n)]
    fig.subplots_adjust(top=0.80)
    for ax, c in zip(axes, cases):
        packing_panel(fig, ax, first[c])
        ax.set_title(f"E0 = {c[0]:.0e} V/m, eps_p = {c[1]:g}, seed {first[c]['params']['seed']}\n"
                     + ax.get_title(), fontsize=7)
    z_colorbar(fig, axes)
    fig.suptitle("EPD (doc/epd.md): 400 e0, r_p = 2 um, electrode at z = 0, field along -z",
                 fontsize=8, y=0.99)
    panels = pd.DataFrame([dict(E0=c[0], eps_p=c[1], seed=first[c]["params"]["seed"],
                                phi=first[c]["phi"], Z=first[c]["Z"]) for c in cases])
    paths = [save(fig, out / "packings.png", panels, tight=False)]

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
        fig = new_figure(5.0, 3.6)
        ax = fig.add_subplot(111)
        for (e0, eps), d in g.groupby(["E0", "eps_p"]):
            ax.errorbar(d["abs_cos"], d["density"], yerr=d["sd"].fillna(0.0), marker="o", ms=3,
                        capsize=2, label=f"E0 {e0:.0e} V/m, eps_p {eps:g} ({int(d['seeds'].iloc[0])} seeds)")
        ax.axhline(1.0, **PAPER_STYLE, label="isotropic")
        ax.set_xlabel("|cos theta| of a contact against the field")
        ax.set_ylabel("density")
        ax.legend(fontsize=7)
        paths.append(save(fig, out / "orientation.png", g))
    return paths
