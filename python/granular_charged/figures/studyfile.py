"""The figures of a study file (doc/populations.md): phi and <Z> against each grid axis, f(Z) and
g(r) of the first seed of each grid point, titled with the study's name (no paper annotation)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis import packing
from ..analysis.tables import grid_value
from .base import material_label, new_figure


def study_label(d: dict, results: list[dict]) -> str:
    """The figures' title: the study's name, its material (what differs from the paper's, the
    population's rules, gamma, U0), the protocols and N."""
    if not results:
        return d["name"]
    p0 = results[0]["params"]
    protos = sorted({str(r.get("protocol")) for r in results})
    mat = ", ".join(x for x in (material_label(results), f"gamma {p0['gamma']:g}",
                                f"U0 {p0['U0']:g}") if x)
    return f"{d['name']} ({mat}; {', '.join(protos)}; N = {p0['N']})"


def study_figures(d: dict, results: list[dict], out: Path) -> list[Path]:
    """The study's figures, each titled with its name and protocol (no paper annotation)."""
    out.mkdir(parents=True, exist_ok=True)
    label = study_label(d, results)
    name = d["name"]
    paths = []
    for axis in d.get("grid", {}):
        xs = sorted({grid_value(r, axis) for r in results}, key=lambda v: float(v))
        fig = new_figure(8, 3.4)
        a1, a2 = fig.subplots(1, 2)
        for ax, k in ((a1, "phi"), (a2, "Z")):
            m = [np.nanmean([r[k] for r in results if grid_value(r, axis) == x and r[k] is not None] or [np.nan]) for x in xs]
            s = [np.nanstd([r[k] for r in results if grid_value(r, axis) == x and r[k] is not None] or [np.nan], ddof=1) if
                 sum(grid_value(r, axis) == x for r in results) > 1 else 0.0 for x in xs]
            ax.errorbar([float(x) for x in xs], m, yerr=s, marker="o", capsize=3)
            ax.set_xlabel(axis)
            ax.set_ylabel("phi" if k == "phi" else "<Z>")
        fig.suptitle(f"{label}\nmean +- sd over the seeds", fontsize=8)
        fig.tight_layout()
        paths.append(out / f"phi_Z_vs_{axis}.png")
        fig.savefig(paths[-1], dpi=120)
    # f(Z) and g(r) of the first seed of each grid point
    first = {}
    for r in results:
        first.setdefault(tuple(grid_value(r, a) for a in d.get("grid", {})), r)
    fig = new_figure(12, 3.4)
    a1, a2, a3 = fig.subplots(1, 3)
    for key, r in first.items():
        lab = ", ".join(f"{a} = {v}" for a, v in zip(d.get("grid", {}), key)) or name
        if r["fZ"]:
            a1.plot(range(len(r["fZ"])), r["fZ"], marker=".", label=lab)
        snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
        zlo, zhi = r["zlo"], r["zhi"]
        if zhi is None or zlo is None or zhi <= zlo:
            continue
        dm = 2.0 * snap["radius"][(snap["z"] >= zlo) & (snap["z"] <= zhi)].mean()
        rc, g = packing.rdf_slab(snap, zlo, zhi, 4.0 * dm, 120)
        a2.plot(rc / dm, g, lw=0.8, label=lab)
        xc, gx = packing.rdf_contact(snap, zlo, zhi, 4.0, 120)
        a3.plot(xc, gx, lw=0.8, label=lab)
    a1.set_xlabel("Z")
    a1.set_ylabel("f(Z)")
    a1.set_xlim(-0.5, 10.5)
    a2.set_xlabel("r / <d>")
    a2.set_ylabel("g(r)")
    a3.set_xlabel("r / (r_i + r_j)")
    a3.set_ylabel("g")
    a1.legend(fontsize=6)
    fig.suptitle(f"{label}\nf(Z) and g(r) of the analysis slab (first seed)", fontsize=8)
    fig.tight_layout()
    paths.append(out / "fZ_gr.png")
    fig.savefig(paths[-1], dpi=120)
    return paths
