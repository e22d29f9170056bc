"""The paper's figures from the package's own runs: PNG, with the plotted data as CSV beside it.

Object-oriented matplotlib only (``Figure`` + ``FigureCanvasAgg``; no pyplot, no global backend
switch). Every figure that has a number in the paper's text shows it beside ours
(:mod:`granular_charged.paper`). Functions take result dicts (``Runner.deposition`` /
``sweep.load_results``; each has ``dir``, the run folder) and an output folder and return the PNG
path, or None when the runs needed are missing (the reason is logged).
"""
from __future__ import annotations

import logging
import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from types import MappingProxyType

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..analysis import measures, packing, tables
from .. import paper
from ..params import jkr_scales, pair_modulus

log = logging.getLogger(__name__)

G2_NOTE = ("Eqs. 9-10 of the paper (Edwards volume-function equation of state) are not drawn: "
           "they need the g_2(r, Z) model of Liu et al., Soft Matter 11 (2015) 6492, which is "
           "not implemented here.")
PAPER_STYLE = MappingProxyType(dict(color="k", ls=":", lw=1.0))   # read-only


def new_figure(w: float, h: float) -> Figure:
    fig = Figure(figsize=(w, h))
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


def _paper() -> bool:
    return PAPER["on"]


def material_label(results) -> str:
    """The material of the runs as a label ('' for the paper's): the values that differ from
    the paper's Table 1 and the population (its rules), e.g. 'rho 3000, E 1e+08, uniform radii'."""
    from ..params import DepositionParams as D
    parts = {}
    for r in results:
        p = r["params"]
        for k in ("rho", "E", "nu", "e", "mu"):
            if p.get(k, getattr(D, k)) != getattr(D, k):
                parts[k] = f"{k} {p[k]:g}"
        ex = p.get("extra") or {}
        if int(float(ex.get("species", 1))) > 1:
            parts["species"] = f"{ex['species']} species"
        if ex.get("r_dist", "one") != "one":
            parts["r_dist"] = f"{ex['r_dist']} radii"
        if ex.get("q_dist", "fixed") != "fixed":
            parts["q_dist"] = f"{ex['q_dist']} charges"
    return ", ".join(parts.values())


def _label(key):
    rp, U0, gamma = key
    pre = f"{PAPER['material']}: " if PAPER["material"] else ""
    return pre + f"r_p = {rp:g} um, U0 = {U0:g} m/s, gamma = {gamma:g} mJ/m2"


def _ok(results):
    return [r for r in results if r.get("phi") is not None and not math.isnan(r["phi"])]


# ---- the packings (Fig. 2) ------------------------------------------------------------------

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
    from ..params import series_name

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
    ok = _ok(results)
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
    fig.suptitle(f"{_label(key)}. Paper (Fig. 2, Table 2; N = 2000, L = 28 r_p): neutral "
                 f"phi = {paper.TABLE2[0][1]}, <Z> = {paper.TABLE2[0][2]}" if _paper() else
                 _label(key), fontsize=8)
    return save(fig, Path(out) / "packings.png", picks.drop(columns=["dir"]), tight=False)


# ---- force network (Fig. 6) -----------------------------------------------------------------

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
        f" (the paper's Fig. 6; paper: |F_n / F_C| < {paper.FORCE_RANGE})" if _paper()
        else f" ({PAPER['material']})"), fontsize=9)
    fig.tight_layout(rect=(0, 0.05, 1, 0.95))
    return save(fig, Path(out) / name, pd.concat(frames), tight=False)


# ---- phi, expansion, Table 2 (Fig. 3, Table 2) ------------------------------------------------

def phi_vs_q(results, out: Path):
    """phi vs q (Fig. 3) with the paper's neutral range; phi_0/phi - 1 vs q on log-log with
    our fitted slope and the paper's slope 2 and maximum 0.4."""
    ok = _ok(results)
    if not ok:
        log.warning("figure phi_vs_q: no finished run")
        return None, None
    s = tables.summary(tables.runs_frame(ok))
    fig = new_figure(5.2, 4.0)
    ax = fig.add_subplot(111)
    if _paper():
        ax.axhspan(*paper.PHI0_RANGE, color="0.88", label="paper: neutral phi_0 = 0.270-0.363")
    for key, g in s.groupby(["rp_um", "U0", "gamma_mJ"]):
        ax.errorbar(g["q"], g["phi"], g["phi_sd"].fillna(0), marker="o", capsize=3,
                    label=_label(key) + f" (N = {g['N'].iloc[0]:.0f})")
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
        if _paper():
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
        lbl = _label(key) + (f": slope {f['slope']:.1f} ({f['p16']:.1f}-{f['p84']:.1f})"
                             if f and f["resolved"] else f": slope {tables.NOT_RESOLVED}")
        ax.errorbar(g["q"], g["expansion"], g["expansion_se"].fillna(0), fmt="o", capsize=3,
                    label=lbl)
        rows.append(dict(zip(["rp_um", "U0", "gamma_mJ"], key),
                         slope=f["slope"] if f else np.nan, p16=f.get("p16") if f else np.nan,
                         p84=f.get("p84") if f else np.nan))
        # the paper's slope 2 through the geometric centre of our points
        lq, le = np.log10(g["q"]).mean(), np.log10(g["expansion"]).mean()
        qq = np.array([g["q"].min() / 1.5, g["q"].max() * 1.5])
        if _paper():
            ax.loglog(qq, 10 ** (le + paper.EXPANSION_SLOPE * (np.log10(qq) - lq)), **PAPER_STYLE)
    if _paper():
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


# ---- structure (Figs. 4, 5, 7) -------------------------------------------------------------

def _biggest_series(ok):
    df = tables.runs_frame(ok)
    key = df.groupby(["rp_um", "U0", "gamma_mJ"])["q"].nunique().idxmax()
    sel = [r for r in ok if (r["params"]["rp"] * 1e6, r["params"]["U0"],
                             r["params"]["gamma"] * 1e3) == key]
    byq = {}
    for r in sel:
        byq.setdefault(r["params"]["q"], []).append(r)
    return key, dict(sorted(byq.items()))


def rdf(results, out: Path, nbins=150):
    """g(r) of the analysis slab, neutral vs the most charged case of one series (Fig. 4)."""
    ok = _ok(results)
    if not ok:
        log.warning("figure rdf: no run with an analysis slab")
        return None
    key, byq = _biggest_series(ok)
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
    ax.set_title(_label(key) + ("\npaper (Fig. 4): the sqrt 3 peak vanishes when charged"
                                if _paper() else ""), fontsize=8)
    ax.legend(fontsize=7)
    return save(fig, Path(out) / "rdf.png", pd.DataFrame(data))


def fZ(results, out: Path):
    """Coordination-number distribution f(Z) per case (Fig. 5), with the paper's neutral <Z>."""
    ok = _ok(results)
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
                        label=f"{_label((rp, U0, gam))}, q = {q:g}: <Z> = {Zm:.2f}")
        ax.axvline(Zm, color=line.get_color(), lw=0.6, ls="--")
        rows.append(dict(rp_um=rp, U0=U0, gamma_mJ=gam, q=q, runs=len(rs), Z=Zm,
                         **{f"f{z}": v for z, v in enumerate(f)}))
    if _paper():
        ax.axvline(paper.TABLE2[0][2], **PAPER_STYLE)
        ax.plot([], [], **PAPER_STYLE, label=f"paper Table 2 neutral <Z> = {paper.TABLE2[0][2]}")
    ax.set_xlabel("Z (last bin of compute coord/dist: Z >= zmax)")
    ax.set_ylabel("f(Z)")
    ax.set_xlim(-0.5, 10.5)
    ax.legend(fontsize=5)
    return save(fig, Path(out) / "fZ.png", pd.DataFrame(rows))


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
    if _paper():
        for x in (-paper.FORCE_RANGE, paper.FORCE_RANGE):
            ax.axvline(x, **PAPER_STYLE)
        ax.plot([], [], **PAPER_STYLE, label="paper: |F_n / F_C| < 0.1")
    ax.set_xlabel("F_n / F_C  (> 0 compressive)")
    ax.set_ylabel("pdf")
    ax.legend(fontsize=6)
    return save(fig, Path(out) / name, pd.DataFrame(data))


def tracer_energy(results, out: Path):
    """The incident particle's kinetic energy (Fig. 8). Left: E_k/E_k0 against its gap to the
    nearest earlier particle or the floor, one tracer per charge (the lowest seed's) of the
    series with the most charges, the paper's figure. Right: E_k/E_k0 just before the first
    contact against q for every series with a charged tracer, mean +- sd over the seeds that
    followed one (tracer_energy_before_contact.csv has every tracer's value). The
    bed is taken from the final configuration (particles with smaller id, which arrived before
    the tracer: hit-and-stick keeps them where they were when the tracer came)."""
    runs = [r for r in _ok(results)
            if r.get("tracer") and packing.dump_exists(Path(r["dir"]) / "tracer.dump")]
    if not runs:
        log.warning("figure tracer_energy: no run with a tracer particle")
        return None
    fig = new_figure(13.0, 4.2)
    ax, axq = fig.add_subplot(121), fig.add_subplot(122)
    key, byq = _biggest_series(runs)
    frames = []
    for q, rs in byq.items():
        r = min(rs, key=lambda r: r["params"]["seed"])
        t = measures.tracer_approach(Path(r["dir"]), r)
        if t is None:
            continue
        gaps, eks, k = t
        line, = ax.plot(gaps[: k + 1], eks[: k + 1], label=f"q = {q:g} e0: E_k/E_k0 = "
                        f"{eks[k - 1]:.3f} before the first contact")
        ax.plot(gaps[k - 1], eks[k - 1], "o", color=line.get_color())
        frames.append(pd.DataFrame({"q": q, "seed": r["params"]["seed"], "gap_over_rp": gaps,
                                    "Ek_over_Ek0": eks}))
    ax.axvline(0, color="grey", ls="--", lw=0.8)
    ax.set_xscale("symlog", linthresh=0.1)
    ax.set_xlabel("gap to the nearest deposited particle or the floor / r_p")
    ax.set_ylabel("E_k / E_k0")
    ax.set_title(f"{_label(key)}, one tracer per q", fontsize=9)
    ax.legend(fontsize=7)
    # right: every series, the value before the first contact over the seeds
    before = tables.runs_frame(runs)[[*tables.CASE, "seed"]]
    before["Ek_before_contact"] = [measures.load(r["dir"], r).get("Ek_before_contact", np.nan)
                                   for r in runs]
    before = before.dropna(subset=["Ek_before_contact"])
    for skey, g in before.groupby(list(tables.CASE[:3])):
        if not (g["q"] > 0).any():
            continue                     # a neutral case alone: no trend to draw
        m = g.groupby("q")["Ek_before_contact"].agg(["mean", "std", "count"]).reset_index()
        axq.errorbar(m["q"], m["mean"], yerr=m["std"].fillna(0.0), marker="o", capsize=3,
                     label=_label(skey) + (f" (up to {m['count'].max()} tracers per q)"
                                                  if m["count"].max() > 1 else ""))
    axq.set_xscale("symlog", linthresh=30.0)    # the series' charges span 30-2000 e0
    axq.set_xlabel("q / e0")
    axq.set_ylabel("E_k / E_k0 before the first contact")
    axq.set_title("mean +- sd over the seeds that followed a tracer", fontsize=9)
    axq.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    before.to_csv(Path(out) / "tracer_energy_before_contact.csv", index=False)
    return save(fig, Path(out) / "tracer_energy.png", pd.concat(frames) if frames else None)


def vs_adstar(results, out: Path):
    """phi and <Z> vs Ad* (Fig. 9) with the ALP limits, and the Z-phi plane (Fig. 10) with the
    ALP point and the paper's Table 2 neutral packing."""
    ok = [r for r in _ok(results) if math.isfinite(r["groups"]["Adstar"])]
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
    if _paper():
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
    if _paper():
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


# ---- the phi_0 question: conventions (doc/reproduction.md, "The phi_0 gap") ------------------

CONVENTION_BARS = ((("phi", "slab"), ("phi_bed_top", "whole bed, H_p = highest top"),
                    ("phi_bed_surface", "whole bed, H_p = mean surface")),
                   (("Z", "slab"), ("Z_all", "all particles"),
                    ("Z_all_floor", "all, floor contacts counted")))


def conventions(results, out: Path):
    """phi and <Z> of every neutral case by the conventions the paper leaves open (mean +- sd
    over the seeds), beside the paper's neutral range of phi_0 and its Table 2 packing."""
    from ..analysis import claims
    neutral = [r for r in _ok(results) if r["params"]["q"] == 0]
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
    if _paper():
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


# ---- everything -----------------------------------------------------------------------------

def all_figures(results, out: Path, table2_rows: list[dict] | None = None,
                table2_dir: Path | None = None, jobs: int = 1,
                paper_notes: bool | None = None) -> list[Path]:
    """Every figure the given runs allow; returns the PNG paths written. jobs > 1: drawn by
    that many processes (each figure is independent of the others). paper_notes: draw the
    paper's values and annotations (None: when the runs are of the paper's material with one
    kind of particle); otherwise the series are labelled with the runs' material."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = [r for r in results if r.get("complete")]
    if not results:
        log.warning("figures: no finished runs")
        return []
    mat = material_label(results)
    PAPER["on"] = (not mat) if paper_notes is None else paper_notes
    PAPER["material"] = mat
    tasks = figure_tasks(results, out, table2_rows)
    if jobs > 1 and len(tasks) > 1:
        # fork: the workers start at once with this process's modules (no re-import)
        with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork")) as ex:
            drawn = list(ex.map(_draw, tasks))
    else:
        drawn = [_draw(t) for t in tasks]
    paths = [q for d in drawn for q in (d if isinstance(d, (tuple, list)) else (d,))]
    return [q for q in paths if q is not None]


def _draw(task):
    fn, args = task
    return fn(*args)


def figure_tasks(results, out: Path, table2_rows: list[dict] | None) -> list[tuple]:
    """The figures of all_figures as (function, arguments), in the order of their paths."""
    tasks = []
    ok = _ok(results)
    for r, name in zip(ok, packing_image_names(ok)):
        tasks.append((packing_image, (r, out, name)))
    tasks += [(packings_panel, (results, out)), (phi_vs_q, (results, out)),
              (rdf, (results, out)), (fZ, (results, out)), (tracer_energy, (results, out)),
              (conventions, (results, out)), (vs_adstar, (results, out))]
    if ok:
        key, byq = _biggest_series(ok)
        qs = list(byq)
        picks = [byq[qs[0]][0]] + ([byq[qs[-1]][0]] if len(qs) > 1 else [])
        params = picks[0]["params"]
        tasks.append((force_network, (
            [(f"deposited with q = {r['params']['q']:g} e0", Path(r["dir"]) / "final.dump",
              Path(r["dir"]) / "forces.dump") for r in picks], params, out,
            "force_network_deposition.png")))
        tasks.append((force_pdf, ([(f"deposited with q = {q:g} e0", Path(r["dir"]) / "forces.dump")
                                   for q in qs for r in byq[q][:1]], params, out)))
    if table2_rows:
        tasks.append((table2, (table2_rows, out)))
        # the paper's Figs. 6 and 7 proper: the Table 2 packing before and after charging (of
        # the first seed when several packings were checked)
        first = min((r.get("params") or {}).get("seed", 0) for r in table2_rows)
        last = max((r for r in table2_rows if (r.get("params") or {}).get("seed", 0) == first),
                   key=lambda r: r["q"])
        d = Path(last["dir"])
        params = last["params"]
        tasks.append((force_network, (
            [("neutral packing (formed with q = 0)", d / "before.dump", d / "forces_before.dump"),
             (f"after charging to q = {last['q']:g} e0 and relaxing", d / "after.dump",
              d / "forces_after.dump")], params, out, "force_network.png")))
        tasks.append((force_pdf, ([("neutral packing", d / "forces_before.dump"),
                                   (f"charged after formation, q = {last['q']:g} e0",
                                    d / "forces_after.dump")], params, out,
                                  "force_pdf_table2.png")))
    return tasks
