"""The paper's figures from the package's own runs (PNG + CSV next to each PNG).

Every function takes result dicts (runner.run_deposition / sweep.load_results; each has 'dir',
the run folder with final.dump, forces.dump and, for tracer runs, tracer.dump) and an output
folder, and returns the PNG path, or None when the runs needed for that figure are missing
(the reason is printed, never papered over).
"""
from __future__ import annotations

import csv
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import packing  # noqa: E402
from .params import jkr_scales, pair_modulus  # noqa: E402

G2_NOTE = ("Eqs. 9-10 of the paper (Edwards volume-function equation of state) are not drawn: "
           "they need the g_2(r, Z) model of Liu et al., Soft Matter 11 (2015) 6492, which was "
           "not available to this package.")


def _csv(path: Path, header, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def _save(fig, path: Path, header, rows, tight=True):
    """Write the figure as PNG and its data as CSV next to it (same stem), close the figure."""
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    _csv(path.with_suffix(".csv"), header, rows)
    return path


def _series_key(r):
    p = r["params"]
    return (p["rp"], p["U0"], p["gamma"])


def _label(key):
    rp, U0, gamma = key
    return f"r_p = {rp * 1e6:g} um, U0 = {U0:g} m/s, gamma = {gamma * 1e3:g} mJ/m2"


def _group(results):
    """(rp, U0, gamma) -> q -> list of results (seeds)."""
    g = defaultdict(lambda: defaultdict(list))
    for r in results:
        if r.get("phi") is not None and not math.isnan(r["phi"]):
            g[_series_key(r)][r["params"]["q"]].append(r)
    return g


def _mean_sd(vals):
    v = np.asarray(vals, dtype=float)
    return float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0


def snapshot(result, out: Path, name="snapshot_Z.png"):
    """Packing coloured by coordination number Z (the paper's Fig. 2)."""
    snap = packing.read_dump(Path(result["dir"]) / "final.dump", last_only=True)
    Z = packing.coordination(snap)
    fig = plt.figure(figsize=(5, 6))
    ax = fig.add_subplot(111, projection="3d")
    rp = result["params"]["rp"]
    sc = ax.scatter(snap["x"] / rp, snap["y"] / rp, snap["z"] / rp, c=Z, cmap="viridis",
                    vmin=0, vmax=max(6, Z.max()), s=12, depthshade=False)
    ax.set_xlabel("x / r_p")
    ax.set_ylabel("y / r_p")
    ax.set_zlabel("z / r_p")
    ax.set_box_aspect((snap.lx, snap.ly, max(np.ptp(snap["z"]) + 2 * rp, snap.lx)))
    fig.colorbar(sc, ax=ax, shrink=0.6, label="Z")
    p = result["params"]
    ax.set_title(f"q = {p['q']:g} e0, N = {p['N']}, phi = {result['phi']:.3f}, <Z> = {result['Z']:.2f}",
                 fontsize=9)
    return _save(fig, out / name, ["id", "x", "y", "z", "radius", "Z"],
                 zip(snap["id"], snap["x"], snap["y"], snap["z"], snap["radius"], Z), tight=False)


def phi_vs_q(results, out: Path):
    """phi vs q (Fig. 3) and phi_0/phi - 1 vs q on log-log with a fitted slope."""
    g = _group(results)
    rows, rows2 = [], []
    fig, ax = plt.subplots(figsize=(5, 4))
    fig2, ax2 = plt.subplots(figsize=(5, 4))
    any_exp = False
    for key, byq in sorted(g.items()):
        qs = sorted(byq)
        m = [_mean_sd([r["phi"] for r in byq[q]]) for q in qs]
        ax.errorbar(qs, [a for a, _ in m], [b for _, b in m], marker="o", capsize=3, label=_label(key))
        for q, (a, b) in zip(qs, m):
            rows.append([*key, q, a, b, len(byq[q])])
        if 0 in byq or 0.0 in byq:
            phi0 = m[qs.index(0)][0]
            qq = [q for q in qs if q > 0]
            y = [phi0 / m[qs.index(q)][0] - 1.0 for q in qq]
            pos = [(q, v) for q, v in zip(qq, y) if v > 0]
            if pos:
                any_exp = True
                lq, ly = np.log10([a for a, _ in pos]), np.log10([b for _, b in pos])
                lbl = _label(key)
                if len(pos) >= 2:
                    slope, icpt = np.polyfit(lq, ly, 1)
                    xs = np.linspace(lq.min(), lq.max(), 20)
                    ax2.plot(10 ** xs, 10 ** (slope * xs + icpt), "--", lw=1)
                    lbl += f" (slope {slope:.2f})"
                ax2.loglog([a for a, _ in pos], [b for _, b in pos], "o", label=lbl)
                for q, v in zip(qq, y):
                    rows2.append([*key, q, v])
    ax.set_xlabel("q / e0")
    ax.set_ylabel("phi")
    ax.legend(fontsize=6)
    p1 = _save(fig, out / "phi_vs_q.png", ["rp", "U0", "gamma", "q_e0", "phi_mean", "phi_sd", "runs"], rows)
    p2 = None
    if any_exp:
        qref = np.array([50, 500])
        ax2.loglog(qref, 1e-3 * (qref / 50) ** 2, "k:", lw=1, label="slope 2 (paper)")
        ax2.set_xlabel("q / e0")
        ax2.set_ylabel("phi_0 / phi - 1")
        ax2.legend(fontsize=6)
        fig2.tight_layout()
        p2 = out / "expansion_loglog.png"
        fig2.savefig(p2, dpi=130)
        _csv(p2.with_suffix(".csv"), ["rp", "U0", "gamma", "q_e0", "phi0_over_phi_minus_1"], rows2)
    else:
        print("figure expansion_loglog: needs a neutral and a looser charged run of one series")
    plt.close(fig2)
    return p1, p2


def rdf(results, out: Path, nbins=150):
    """g(r) of the analysis slab, neutral vs the most charged run of one series (Fig. 4)."""
    g = _group(results)
    if not g:
        print("figure rdf: no run with an analysis slab")
        return None
    key = max(g, key=lambda k: (len(g[k]), k))
    byq = g[key]
    qs = sorted(byq)
    pick = [qs[0]] + ([qs[-1]] if len(qs) > 1 else [])
    fig, ax = plt.subplots(figsize=(5, 4))
    cols = {}
    for q in pick:
        gs = []
        for r in byq[q]:
            snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
            rp = r["params"]["rp"]
            rc, gr = packing.rdf_slab(snap, r["zlo"], r["zhi"], 6.0 * rp, nbins)
            gs.append(gr)
        gm = np.mean(gs, axis=0)
        x = rc / (2 * rp)
        ax.plot(x, gm, label=f"q = {q:g} e0 ({len(gs)} runs)")
        cols[q] = gm
    for v in (1.0, math.sqrt(3), 2.0):
        ax.axvline(v, color="grey", lw=0.5, ls=":")
    ax.set_xlabel("r / 2r_p")
    ax.set_ylabel("g(r)")
    ax.set_xlim(0.8, 3.0)
    ax.set_title(_label(key), fontsize=8)
    ax.legend(fontsize=7)
    path = _save(fig, out / "rdf.png", ["r_over_2rp"] + [f"g_q{q:g}" for q in cols],
                 zip(x, *cols.values()))
    return path


def fZ(results, out: Path):
    """Coordination-number distribution f(Z) vs q (Fig. 5)."""
    g = _group(results)
    fig, ax = plt.subplots(figsize=(5, 4))
    rows = []
    for key, byq in sorted(g.items()):
        for q in sorted(byq):
            f = np.mean([np.pad(r["fZ"], (0, 13 - len(r["fZ"]))) for r in byq[q]], axis=0)
            ax.plot(range(len(f)), f, marker="o", label=f"{_label(key)}, q = {q:g}")
            rows.append([*key, q] + list(f))
    ax.set_xlabel("Z")
    ax.set_ylabel("f(Z)")
    ax.set_xlim(-0.5, 10.5)
    ax.legend(fontsize=5)
    path = _save(fig, out / "fZ.png", ["rp", "U0", "gamma", "q_e0"] + [f"f{z}" for z in range(13)], rows)
    return path


def force_pdf(results, out: Path, bins=60):
    """pdf of the normal contact forces F_n / F_C (Fig. 7), from compute pair/local (the
    deck's forces.dump: distance, signed normal force, > 0 repulsive), all particle pairs."""
    g = _group(results)
    if not g:
        print("figure force_pdf: no run with an analysis slab")
        return None
    key = max(g, key=lambda k: (len(g[k]), k))
    fig, ax = plt.subplots(figsize=(5, 4))
    edges = np.linspace(-0.2, 0.2, bins + 1)
    cols = {}
    for q in sorted(g[key]):
        vals = []
        for r in g[key][q]:
            p = r["params"]
            FC = jkr_scales(p["rp"] / 2, pair_modulus(p["E"], p["nu"]), p["gamma"])["FC"]
            s = packing.read_dump(Path(r["dir"]) / "forces.dump", last_only=True)
            f = s.cols.get("c_pl[2]", np.zeros(0))
            vals.append(f[f != 0.0] / FC)
        v = np.concatenate(vals) if vals else np.zeros(0)
        h, _ = np.histogram(v, bins=edges, density=True)
        c = 0.5 * (edges[1:] + edges[:-1])
        ax.plot(c, h, label=f"q = {q:g} e0 ({len(v)} contacts)")
        cols[q] = h
    ax.set_xlabel("F_n / F_C  (> 0 compressive)")
    ax.set_ylabel("pdf")
    ax.set_title(_label(key), fontsize=8)
    ax.legend(fontsize=7)
    path = _save(fig, out / "force_pdf.png", ["Fn_over_FC"] + [f"pdf_q{q:g}" for q in cols], zip(c, *cols.values()))
    return path


def tracer_energy(results, out: Path):
    """Kinetic energy of an incident particle vs its gap to the nearest earlier particle (Fig. 8).
    The bed is taken from the final configuration (particles with smaller id, which arrived
    before the tracer: hit-and-stick keeps them where they were when the tracer came)."""
    runs = [r for r in results if r.get("tracer") and (Path(r["dir"]) / "tracer.dump").exists()]
    if not runs:
        print("figure tracer_energy: no run with a tracer particle")
        return None
    fig, ax = plt.subplots(figsize=(5, 4))
    rows = []
    for r in sorted(runs, key=lambda r: r["params"]["q"]):
        p = r["params"]
        tid = r["tracer"]
        tr = packing.read_dump(Path(r["dir"]) / "tracer.dump")
        tr = [s for s in tr if s.n == 1]
        fin = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
        bed = fin["id"] < tid
        bx, by, bz = fin["x"][bed], fin["y"][bed], fin["z"][bed]
        m = 4.0 / 3.0 * math.pi * p["rp"] ** 3 * p["rho"]
        ek0 = 0.5 * m * p["U0"] ** 2
        gaps, eks = [], []
        for s in tr:
            dx = bx - s["x"][0]
            dy = by - s["y"][0]
            dx -= fin.lx * np.round(dx / fin.lx)
            dy -= fin.ly * np.round(dy / fin.ly)
            d = np.sqrt(dx * dx + dy * dy + (bz - s["z"][0]) ** 2).min() if len(bx) else s["z"][0]
            gaps.append((d - 2 * p["rp"]) / p["rp"])
            eks.append(0.5 * m * (s["vx"][0] ** 2 + s["vy"][0] ** 2 + s["vz"][0] ** 2) / ek0)
            rows.append([p["q"], gaps[-1], eks[-1]])
        # until the first contact
        k = next((i for i, gp in enumerate(gaps) if gp <= 0), len(gaps))
        ax.plot(gaps[: k + 1], eks[: k + 1], label=f"q = {p['q']:g} e0 (particle {tid})")
    ax.axvline(0, color="grey", ls="--", lw=0.8)
    ax.set_xscale("symlog", linthresh=0.1)
    ax.set_xlabel("gap to nearest deposited particle / r_p")
    ax.set_ylabel("E_k / E_k0")
    ax.legend(fontsize=7)
    path = _save(fig, out / "tracer_energy.png", ["q_e0", "gap_over_rp", "Ek_over_Ek0"], rows)
    return path


def vs_adstar(results, out: Path):
    """phi and <Z> vs Ad* (Fig. 9), and the Z-phi plane with the ALP point (Fig. 10)."""
    ok = [r for r in results if r.get("phi") is not None and not math.isnan(r["phi"])
          and math.isfinite(r["groups"]["Adstar"])]
    if not ok:
        return None, None
    ad = np.array([r["groups"]["Adstar"] for r in ok])
    phi = np.array([r["phi"] for r in ok])
    Z = np.array([r["Z"] for r in ok])
    q = np.array([r["params"]["q"] for r in ok])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(5, 6), sharex=True)
    sc = a1.scatter(ad, phi, c=q, cmap="plasma")
    a2.scatter(ad, Z, c=q, cmap="plasma")
    a1.axhline(1 / 8, color="grey", ls=":", lw=1)
    a2.axhline(2, color="grey", ls=":", lw=1)
    a1.set_xscale("log")
    a1.set_ylabel("phi")
    a2.set_ylabel("<Z>")
    a2.set_xlabel("Ad*")
    fig.colorbar(sc, ax=[a1, a2], label="q / e0")
    p1 = out / "phi_Z_vs_Adstar.png"
    fig.savefig(p1, dpi=130)
    plt.close(fig)
    rows = [[r["params"]["rp"], r["params"]["U0"], r["params"]["gamma"], r["params"]["q"],
             r["params"]["seed"], r["groups"]["Ad"], r["groups"]["Estar"], r["groups"]["Adstar"],
             r["phi"], r["Z"]] for r in ok]
    hdr = ["rp", "U0", "gamma", "q_e0", "seed", "Ad", "Estar", "Adstar", "phi", "Z"]
    _csv(p1.with_suffix(".csv"), hdr, rows)

    fig, ax = plt.subplots(figsize=(5, 4.6))
    sc = ax.scatter(Z, phi, c=q, cmap="plasma", label="this package's runs")
    ax.plot([2], [1 / 8], "k*", ms=12, label="ALP (Z = 2, phi = 1/8)")
    ax.set_xlim(1.5, 6.5)
    ax.set_ylim(0.1, 0.65)
    ax.set_xlabel("<Z>")
    ax.set_ylabel("phi")
    fig.colorbar(sc, ax=ax, label="q / e0")
    ax.legend(fontsize=7, loc="upper left")
    fig.text(0.01, 0.005, "\n".join(_wrap(G2_NOTE, 95)), fontsize=5.5, va="bottom")
    fig.subplots_adjust(bottom=0.2)
    p2 = _save(fig, out / "phase_diagram_Z_phi.png", hdr, rows, tight=False)
    return p1, p2


def _wrap(s, n):
    words, lines, cur = s.split(), [], ""
    for w in words:
        if len(cur) + len(w) + 1 > n:
            lines.append(cur)
            cur = w
        else:
            cur = (cur + " " + w).strip()
    return lines + [cur]


def all_figures(results, out: Path) -> list[Path]:
    """Every figure the given runs allow; returns the PNG paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = [r for r in results if r.get("complete")]
    paths = []
    if not results:
        print("figures: no finished runs")
        return paths
    g = _group(results)
    for key, byq in g.items():
        for qv in sorted(byq):
            r = byq[qv][0]
            p = r["params"]
            paths.append(snapshot(r, out, f"snapshot_Z_rp{p['rp'] * 1e6:g}_U{p['U0']:g}_"
                                          f"g{p['gamma'] * 1e3:g}_q{qv:g}.png"))
    for f in (phi_vs_q, rdf, fZ, force_pdf, tracer_energy, vs_adstar):
        r = f(results, out)
        for p in (r if isinstance(r, tuple) else (r,)):
            if p is not None:
                paths.append(p)
    return paths
