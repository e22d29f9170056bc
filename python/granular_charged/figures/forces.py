"""Contact forces: the force network (the paper's Fig. 6) and the pdf of the normal
contact forces (Fig. 7)."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.lines import Line2D

from .. import paper
from ..analysis import measures, packing
from ..params import jkr_scales, pair_modulus
from .base import PAPER, PAPER_STYLE, new_figure, paper_notes, save

log = logging.getLogger(__name__)


def read_pair_forces(final_dump: Path, forces_dump: Path):
    """Snapshot and the pairs with a non-zero normal force: (snap, i, j, F) with i, j indices
    into the snapshot (sorted by id), F > 0 compressive (compute pair/local 'force')."""
    snap = packing.read_dump(final_dump, last_only=True)
    f = packing.read_dump(forces_dump, last_only=True)
    c = f.cols
    if "c_pa[1]" not in c:
        raise ValueError(f"{forces_dump}: no atom ids (c_pa[1], c_pa[2]); made by an older deck")
    F = c["c_pl[2]"]
    nz = F != 0.0
    i = np.searchsorted(snap["id"], c["c_pa[1]"][nz].astype(int))
    j = np.searchsorted(snap["id"], c["c_pa[2]"][nz].astype(int))
    return snap, i, j, F[nz]


def _force_panel(ax, snap, i, j, F, FC, rp, wmax, title, ztop):
    """Lines between centres of the pairs of a slice of width 3 r_p (|y - L_y/2| <= 1.5 r_p,
    both particles), x-z plane in units of r_p; red compressive, blue tensile, width
    proportional to |F_n|."""
    yc = snap.box[1].mean()
    dy_i = snap["y"] - yc
    dy_i -= snap.ly * np.round(dy_i / snap.ly)
    ins = np.abs(dy_i) <= 1.5 * rp
    keep = ins[i] & ins[j]
    i, j, F = i[keep], j[keep], F[keep]
    x, z = snap["x"] / rp, snap["z"] / rp
    lx = snap.lx / rp
    dx = x[j] - x[i]
    dx -= lx * np.round(dx / lx)          # minimum image across the periodic x
    seg = np.stack([np.column_stack([x[i], z[i]]), np.column_stack([x[i] + dx, z[j]])], axis=1)
    # particles of the slice as faint outlines, for orientation
    d = 2 * snap["radius"][ins] / rp
    ax.add_collection(EllipseCollection(d, d, np.zeros_like(d), units="xy",
                                        offsets=np.column_stack([x[ins], z[ins]]),
                                        offset_transform=ax.transData, facecolors="none",
                                        edgecolors="0.8", linewidths=0.3))
    col = np.where(F[:, None] > 0, [[0.85, 0.1, 0.1]], [[0.1, 0.25, 0.9]])
    lw = 0.3 + 4.0 * np.abs(F) / wmax
    ax.add_collection(LineCollection(seg, colors=col, linewidths=lw, capstyle="round"))
    ax.set_xlim(snap.box[0] / rp)
    ax.set_ylim(0, ztop / rp)
    ax.set_aspect("equal")
    ax.set_xlabel("x / r_p")
    ax.set_ylabel("z / r_p")
    ncomp, nten = int((F > 0).sum()), int((F < 0).sum())
    ax.set_title(f"{title}\n{ncomp} compressive, {nten} tensile\ncontacts in the slice",
                 fontsize=7)
    return pd.DataFrame({"id_i": snap["id"][i], "id_j": snap["id"][j], "x_i_rp": x[i],
                         "z_i_rp": z[i], "x_j_rp": x[i] + dx, "z_j_rp": z[j], "Fn": F,
                         "Fn_over_FC": F / FC})


def force_network(panels: list[tuple[str, Path, Path]], params: dict, out: Path,
                  name: str = "force_network.png") -> Path | None:
    """The paper's Fig. 6: normal contact forces in a slice of width 3 r_p as lines between
    centres, red compressive, blue tensile, width proportional to |F_n| (one scale for all
    panels). panels: (title, final dump, forces dump) each."""
    loaded = []
    for title, fd, ff in panels:
        if not (packing.dump_exists(fd) and packing.dump_exists(ff)):
            log.warning("figure %s: %s or %s missing", name, fd, ff)
            return None
        loaded.append((title, *read_pair_forces(fd, ff)))
    rp = params["rp"]
    FC = jkr_scales(rp / 2, pair_modulus(params["E"], params["nu"]), params["gamma"])["FC"]
    wmax = max(float(np.abs(F).max()) if len(F) else 0.0 for *_, F in loaded) or 1.0
    snap0 = loaded[0][1]
    # top of the bed: the highest particle in a contact (one still bouncing above is left out)
    ztop = max(float(s["z"][np.concatenate([i, j])].max() + 1.5 * rp) for _, s, i, j, _ in loaded
               if len(i))
    panel_w = 5.0 * snap0.lx / ztop           # panels 5 inches high, true aspect
    fig = new_figure(min(max(len(loaded) * (panel_w + 1.2), 7.0), 16.0), 6.2)
    frames = []
    for k, (title, snap, i, j, F) in enumerate(loaded):
        ax = fig.add_subplot(1, len(loaded), k + 1)
        df = _force_panel(ax, snap, i, j, F, FC, rp, wmax, f"({'abcd'[k]}) {title}", ztop)
        df.insert(0, "panel", title)
        frames.append(df)
    handles = [Line2D([], [], color=(0.85, 0.1, 0.1), lw=2, label="compressive (F_n > 0)"),
               Line2D([], [], color=(0.1, 0.25, 0.9), lw=2, label="tensile (F_n < 0)"),
               Line2D([], [], color="k", lw=4.3, label=f"|F_n| = {wmax / FC:.3g} F_C (widest)")]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.suptitle("Normal contact forces in a slice of width 3 r_p" + (
        f" (the paper's Fig. 6; paper: |F_n / F_C| < {paper.FORCE_RANGE})" if paper_notes()
        else f" ({PAPER['material']})"), fontsize=9)
    fig.tight_layout(rect=(0, 0.05, 1, 0.95))
    return save(fig, Path(out) / name, pd.concat(frames), tight=False)


def force_pdf(panels: list[tuple[str, Path]], params: dict, out: Path, name="force_pdf.png",
              bins=60):
    """pdf of the normal contact forces F_n / F_C (Fig. 7) of forces dumps (compute pair/local:
    signed normal force, > 0 compressive), pairs in contact only; the paper's range |F_n/F_C|
    < 0.1 marked. panels: (label, forces dump) each."""
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    edges = np.linspace(-0.2, 0.2, bins + 1)
    c = 0.5 * (edges[1:] + edges[:-1])
    data = {"Fn_over_FC": c}
    for label, path in panels:
        if not packing.dump_exists(path):
            log.warning("figure %s: %s missing", name, path)
            return None
        v = measures.normal_forces(path, params)
        h, _ = np.histogram(v, bins=edges, density=True)
        ax.plot(c, h, label=f"{label} ({len(v)} contacts, mean {v.mean():+.4f})")
        data[f"pdf {label}"] = h
    if paper_notes():
        for x in (-paper.FORCE_RANGE, paper.FORCE_RANGE):
            ax.axvline(x, **PAPER_STYLE)
        ax.plot([], [], **PAPER_STYLE, label="paper: |F_n / F_C| < 0.1")
    ax.set_xlabel("F_n / F_C  (> 0 compressive)")
    ax.set_ylabel("pdf")
    ax.legend(fontsize=6)
    return save(fig, Path(out) / name, pd.DataFrame(data))
