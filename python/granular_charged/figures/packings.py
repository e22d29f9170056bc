"""The packings (the paper's Fig. 2): each run's final packing coloured by Z, and the
packings of one series side by side."""
from __future__ import annotations

import logging
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
from matplotlib.collections import EllipseCollection

from .. import paper
from ..analysis import packing, tables
from ..params import series_name
from .base import finished, new_figure, paper_notes, save, series_label, z_colorbar, z_colormap

log = logging.getLogger(__name__)


def _draw_spheres(ax, snap, Z, view_axis=1):
    """Fallback renderer (a build without dump image/PNG): orthographic side view along y,
    spheres as discs at true size drawn far to near (painter's order), darker with depth."""
    cmap, norm = z_colormap()
    depth = snap["y"] if view_axis == 1 else snap["x"]
    order = np.argsort(-depth)
    rgb = cmap(norm(np.minimum(Z, len(paper.Z_COLORS) - 1)))[:, :3]
    shade = 0.55 + 0.45 * (1 - (depth - depth.min()) / max(np.ptp(depth), 1e-300))
    col = np.clip(rgb * shade[:, None], 0, 1)[order]
    rp = float(snap["radius"].mean())
    d = 2 * snap["radius"][order] / rp
    ec = EllipseCollection(d, d, np.zeros_like(d), units="xy", offsets=np.column_stack(
        [snap["x"][order] / rp, snap["z"][order] / rp]), offset_transform=ax.transData,
        facecolors=col, edgecolors="k", linewidths=0.2)
    ax.add_collection(ec)
    ax.set_xlim(snap.box[0] / rp)
    ax.set_ylim(0, float((snap["z"] + snap["radius"]).max()) / rp * 1.02)
    ax.set_aspect("equal")


def packing_image_names(results: list[dict]) -> list[str]:
    """The file name of each run's packing image: packing_q<q>_s<seed>.png when the runs are of
    one series (r_p, U_0, gamma), else with the series in front, packing_rp<r_p>um_U<U_0>_g
    <gamma>mJ_q<q>_s<seed>.png (with the short names, the nine neutral cases of the paper-size
    study wrote one file, packing_q0_s1.png, in turn)."""

    def series(p):
        return series_name(p["rp"], p["U0"], p["gamma"]) + "_"
    several = len({series(r["params"]) for r in results}) > 1
    return [f"packing_{series(r['params']) if several else ''}q{r['params']['q']:g}"
            f"_s{r['params']['seed']}.png" for r in results]


def packing_image(result: dict, out: Path, name: str | None = None) -> Path:
    """The final packing at true sphere size coloured by Z with a colour bar: LAMMPS's render
    (packing.png of the run, dump image) framed with matplotlib; the fallback renderer when the
    build could not render."""
    name = name or packing_image_names([result])[0]
    p = result["params"]
    fig = new_figure(5.6, 5.0)
    fig.suptitle(f"r_p = {p['rp'] * 1e6:g} um, U_0 = {p['U0']:g} m/s, gamma = "
                 f"{p['gamma'] * 1e3:g} mJ/m^2, seed {p['seed']}", fontsize=9)
    ax = fig.add_subplot(111)
    packing_panel(fig, ax, result)
    z_colorbar(fig, ax)
    return save(fig, Path(out) / name)


def _crop_white(img, pad=8):
    """The rendered image without its white margins (dump image frames the whole box)."""
    mask = img[..., :3].min(axis=-1) < 0.97
    if not mask.any():
        return img
    r = np.flatnonzero(mask.any(axis=1))
    c = np.flatnonzero(mask.any(axis=0))
    return img[max(r[0] - pad, 0): r[-1] + pad + 1, max(c[0] - pad, 0): c[-1] + pad + 1]


def packing_panel(fig, ax, result):
    p = result["params"]
    img = Path(result["dir"]) / "packing.png"
    if img.exists():
        ax.imshow(_crop_white(mpimg.imread(img)))
        ax.set_axis_off()
        how = "LAMMPS dump image"
    else:
        snap = packing.read_dump(Path(result["dir"]) / "final.dump", last_only=True)
        _draw_spheres(ax, snap, packing.coordination(snap))
        ax.set_xlabel("x / r_p")
        ax.set_ylabel("z / r_p")
        how = "side view (no dump image in the build)"
    ax.set_title(f"q = {p['q']:g} e0: phi = {result['phi']:.3f}, <Z> = {result['Z']:.2f}\n"
                 f"N = {result['natoms']}, L = {p['extra'].get('L_rp', 28)} r_p ({how})",
                 fontsize=8)


def packings_panel(results: list[dict], out: Path) -> Path | None:
    """The paper's Fig. 2: one packing per charge side by side (first seed of each q of the
    series with most charges), with the paper's neutral numbers for reference."""
    ok = finished(results)
    if not ok:
        log.warning("figure packings: no finished run")
        return None
    df = tables.runs_frame(ok)
    key = df.groupby(["rp_um", "U0", "gamma_mJ"])["q"].nunique().idxmax()
    sel = df[(df[["rp_um", "U0", "gamma_mJ"]] == pd.Series(key, index=["rp_um", "U0", "gamma_mJ"])).all(axis=1)]
    picks = sel.sort_values(["q", "seed"]).groupby("q").head(1)
    byk = {r["key"]: r for r in ok}
    n = len(picks)
    fig = new_figure(3.4 * n + 1.0, 4.3)
    axes = [fig.add_subplot(1, n, k + 1) for k in range(n)]
    for ax, (_, row), lab in zip(axes, picks.iterrows(), "abcdefgh"):
        packing_panel(fig, ax, byk[row["key"]])
        ax.set_title(f"({lab}) " + ax.get_title(), fontsize=7)
    z_colorbar(fig, axes)
    fig.suptitle(f"{series_label(key)}. Paper (Fig. 2, Table 2; N = 2000, L = 28 r_p): neutral "
                 f"phi = {paper.TABLE2[0][1]}, <Z> = {paper.TABLE2[0][2]}" if paper_notes() else
                 series_label(key), fontsize=8)
    return save(fig, Path(out) / "packings.png", picks.drop(columns=["dir"]), tight=False)
