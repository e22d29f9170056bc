"""The figures of a study file (doc/populations.md, "Study files"), each a PNG with its plotted
data as CSV beside it (with the study's name in a column `study`):

- phi_Z_vs_<axis>.png per varied parameter: phi and <Z> (mean +- sd over the seeds) against
  it, one series per value of the other axes (parameters varied together with it are one
  axis); for a mixture also each species' contribution to phi and its <Z>;
- fZ_gr.png: f(Z), g(r) in units of the mean diameter and of r_i + r_j, per grid point (its
  first seed);
- force_pdf.png: the pdf of the normal contact forces F_n / F_C per grid point (all seeds);
- point_<k>.png per grid point: f(Z) overall and per species, <Z> per size class, the normal
  force pdf, titled with that point's own grid values and charges;
- charges_<k>.png per grid point whose runs have contact charging (tribo yes): per species the
  histogram of the final charges and the mean charge against the depth below the bed top
  (figures.charges).

Titles name the study, what all runs share (material, protocol, N) and, in each figure of one
point, that point's values; they wrap to the figure's width (constrained layout: nothing
clipped). Every axis carries its unit. No value or annotation of the paper appears.
"""
from __future__ import annotations

import logging
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import measures, packing
from ..analysis.studytables import (axis_groups, axis_label, charge_label, fmt, grid_names,
                                    point, point_label, species_names, species_rows)
from .base import material_label, new_figure

log = logging.getLogger(__name__)

TITLE_SIZE = 8
FORCE_X = "F_n / F_C [dimensionless]\n(> 0 compressive; F_C = 3 pi gamma r_p / 2)"
FORCE_Y = "pdf [1 / unit of F_n / F_C]"
MARKERS = "os^"


def _common(values):
    vals = set(values)
    return next(iter(vals)) if len(vals) == 1 else None


def study_label(d: dict, results: list[dict]) -> str:
    """What every run of the study shares, after its name: the material (the values that
    differ from the paper's, the population's rules; the charges only when every run has the
    same), gamma and U0 when the same for all, the protocols and N."""
    if not results:
        return d["name"]
    per_run = [material_label([r]).split(", ") for r in results]
    parts = [x for x in per_run[0] if x and not x.endswith("charges")
             and all(x in pr for pr in per_run[1:])]
    charges = _common(charge_label(r, species_names(d)) for r in results)
    if charges is not None:
        parts.append(charges)
    for k, u in (("gamma", "J/m^2"), ("U0", "m/s")):
        v = _common(float(r["params"][k]) for r in results)
        if v is not None:
            parts.append(f"{k} {v:g} {u}")
    protos = sorted({str(r.get("protocol")) for r in results})
    n = _common(int(r["params"]["N"]) for r in results)
    tail = ", ".join(protos) + (f"; N = {n}" if n is not None else "")
    return f"{d['name']} ({', '.join(parts + [tail])})"


def _title(fig, text: str, width_in: float):
    """A suptitle wrapped to the figure's width (about 15 characters per inch at size 8)."""
    lines = [textwrap.fill(t, max(30, int(width_in * 15))) for t in text.split("\n")]
    fig.suptitle("\n".join(lines), fontsize=TITLE_SIZE)


def _save(fig, path: Path, data: pd.DataFrame | None, name: str) -> Path:
    fig.savefig(path, dpi=120)
    if data is not None:
        data.insert(0, "study", name)
        data.to_csv(path.with_suffix(".csv"), index=False)
    return path


def _mean_sd(vals):
    """Mean and sd of the finite values (NaN, 0 without any: a bed too thin for the slab)."""
    v = np.array([x for x in vals if x is not None and np.isfinite(x)], dtype=float)
    if not len(v):
        return np.nan, 0.0
    return float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0


def _order(v):
    return (0, v, "") if isinstance(v, float) else (1, 0.0, str(v))


def _points(results, names) -> dict:
    """{point: [runs]} in the order of the grid's values."""
    by = {}
    for r in results:
        by.setdefault(point(r, names), []).append(r)
    return dict(sorted(by.items(), key=lambda kv: [_order(v) for v in kv[0]]))


def _species_of(results) -> dict:
    """{run key: species rows} of the runs (species_rows)."""
    out = {}
    for r in results:
        try:
            out[r["key"]] = species_rows(r)
        except (OSError, ValueError, KeyError, IndexError, TypeError) as e:
            log.warning("%s: no per-species measures (%s)", r.get("key"), e)
            out[r["key"]] = []
    return out


def vs_axis(d, results, out: Path, axis: str, label: str, per_species: dict) -> Path:
    """phi and <Z> against one varied parameter (module docstring)."""
    names = grid_names(d)
    # the series: the values of the other axes (a parameter varied together with this one is
    # not another series)
    same = next((g for g in axis_groups(d) if axis in g), [axis])
    others = [n for n in names if n not in same]
    spn = species_names(d)
    nsp = max((len(v) for v in per_species.values()), default=0)
    mixture = nsp > 1
    w = 10.0 if mixture else 8.0
    fig = new_figure(w, 6.4 if mixture else 3.6, layout="constrained")
    axes = fig.subplots(2 if mixture else 1, 2, squeeze=False)
    rows = []
    series = {}
    for r in results:
        pt = dict(zip(names, point(r, names)))
        series.setdefault(tuple(pt[n] for n in others), {}).setdefault(pt[axis], []).append(r)
    for skey, byx in series.items():
        xs = sorted(byx, key=_order)
        numeric = all(isinstance(x, float) for x in xs)
        xplot = xs if numeric else list(range(len(xs)))
        slab = point_label(others, skey)
        for k, (key, name) in enumerate((("phi", "phi"), ("Z", "<Z>"))):
            ms = [_mean_sd([r[key] for r in byx[x]]) for x in xs]
            axes[0][k].errorbar(xplot, [m for m, _ in ms], yerr=[s for _, s in ms], marker="o",
                                capsize=3, label=slab or None)
            axes[0][k].set_ylabel(f"{name} of the analysis slab [dimensionless]")
            for x, (m, s) in zip(xs, ms):
                rows.append({**dict(zip(others, skey)), axis: x, "species": "all",
                             "measure": key, "mean": m, "sd": s, "runs": len(byx[x])})
        if mixture:
            for s in range(1, nsp + 1):
                for k, key in enumerate(("phi", "Z")):
                    ms = [_mean_sd([sr[key] for r in byx[x] for sr in per_species.get(r["key"], [])
                                    if sr["species"] == s]) for x in xs]
                    lab = spn.get(s, f"species {s}") + (f", {slab}" if slab else "")
                    axes[1][k].errorbar(xplot, [m for m, _ in ms], yerr=[e for _, e in ms],
                                        marker=MARKERS[(s - 1) % 3], capsize=3, label=lab)
                    for x, (m, e) in zip(xs, ms):
                        rows.append({**dict(zip(others, skey)), axis: x,
                                     "species": spn.get(s, f"species {s}"), "measure": key,
                                     "mean": m, "sd": e, "runs": len(byx[x])})
        if not numeric:
            for row in axes:
                for ax in row:
                    ax.set_xticks(xplot, [fmt(x) for x in xs])
    if mixture:
        axes[1][0].set_ylabel("species' contribution to phi [dimensionless]")
        axes[1][1].set_ylabel("<Z> of the species [dimensionless]")
    for row in axes:
        for ax in row:
            ax.set_xlabel(axis_label(axis))
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6)
    _title(fig, f"{label}\nphi and <Z> against {axis}: mean +- sd over the seeds", w)
    return _save(fig, out / f"phi_Z_vs_{axis}.png", pd.DataFrame(rows), d["name"])


def fz_gr(d, out: Path, label: str, pts: dict) -> Path:
    """f(Z) and g(r) of the first seed of each grid point."""
    names = grid_names(d)
    fig = new_figure(12, 3.8, layout="constrained")
    a1, a2, a3 = fig.subplots(1, 3)
    data = []
    for key, runs in pts.items():
        r = runs[0]
        lab = point_label(names, key) or d["name"]
        at = {**dict(zip(names, key)), "seed": r["params"]["seed"]}
        if r.get("fZ"):
            a1.plot(range(len(r["fZ"])), r["fZ"], marker=".", label=lab)
            data += [{**at, "curve": "f(Z)", "x": z, "y": f} for z, f in enumerate(r["fZ"])]
        zlo, zhi = r.get("zlo"), r.get("zhi")
        if zhi is None or zlo is None or zhi <= zlo:
            continue
        snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
        dm = 2.0 * snap["radius"][(snap["z"] >= zlo) & (snap["z"] <= zhi)].mean()
        rc, g = packing.rdf_slab(snap, zlo, zhi, 4.0 * dm, 120)
        a2.plot(rc / dm, g, lw=0.8, label=lab)
        xc, gx = packing.rdf_contact(snap, zlo, zhi, 4.0, 120)
        a3.plot(xc, gx, lw=0.8, label=lab)
        data += [{**at, "curve": "g(r/<d>)", "x": x, "y": y} for x, y in zip(rc / dm, g)]
        data += [{**at, "curve": "g(r/(r_i+r_j))", "x": x, "y": y} for x, y in zip(xc, gx)]
    a1.set_xlabel("coordination number Z [contacts]")
    a1.set_ylabel("f(Z) [fraction of the slab's particles]")
    a1.set_xlim(-0.5, 10.5)
    a2.set_xlabel("r / <d> [dimensionless]")
    a2.set_ylabel("g(r) [dimensionless]")
    a3.set_xlabel("r / (r_i + r_j) [dimensionless]")
    a3.set_ylabel("g [dimensionless]")
    if a1.get_legend_handles_labels()[0]:
        a1.legend(fontsize=6)
    _title(fig, f"{label}\nf(Z) and g(r) of the analysis slab (first seed of each point)", 12)
    return _save(fig, out / "fZ_gr.png", pd.DataFrame(data), d["name"])


def _forces(runs) -> np.ndarray:
    """F_n / F_C of the contacts of the runs (their forces.dump), pooled."""
    vals = []
    for r in runs:
        path = Path(r["dir"]) / "forces.dump"
        if packing.dump_exists(path):
            vals.append(measures.normal_forces(path, r["params"]))
    return np.concatenate(vals) if vals else np.zeros(0)


def _force_edges(all_vals) -> np.ndarray:
    """Bins symmetric about 0 out to the 99th percentile of |F_n / F_C|, about 20 contacts per
    bin (10 to 60 bins)."""
    v = [x for x in all_vals if len(x)]
    bins = int(min(60, max(10, min((len(x) for x in v), default=0) // 20)))
    lim = float(np.percentile(np.abs(np.concatenate(v)), 99.0)) if v else 0.2
    return np.linspace(-lim, lim, bins + 1) if lim > 0 else np.linspace(-0.2, 0.2, bins + 1)


def force_figure(d, out: Path, label: str, pts: dict, forces: dict) -> Path | None:
    """The pdf of the normal contact forces of each grid point (all its seeds)."""
    names = grid_names(d)
    if not any(len(v) for v in forces.values()):
        log.warning("study figure force_pdf: no forces.dump in the runs")
        return None
    edges = _force_edges(list(forces.values()))
    c = 0.5 * (edges[1:] + edges[:-1])
    fig = new_figure(6.4, 4.4, layout="constrained")
    ax = fig.add_subplot(111)
    data = {"Fn_over_FC": c}
    for key in pts:
        v = forces[key]
        if not len(v):
            continue
        h, _ = np.histogram(v, bins=edges, density=True)
        lab = point_label(names, key) or d["name"]
        ax.plot(c, h, label=f"{lab} ({len(v)} contacts, mean {v.mean():+.3g})")
        data[f"pdf {lab}"] = h
    ax.set_yscale("log")
    ax.set_xlabel(FORCE_X)
    ax.set_ylabel(FORCE_Y)
    ax.legend(fontsize=6)
    _title(fig, f"{label}\nnormal contact forces, all seeds of each point", 6.4)
    return _save(fig, out / "force_pdf.png", pd.DataFrame(data), d["name"])


def point_figure(d, out: Path, k: int, key: tuple, runs: list[dict], per_species: dict,
                 forces: np.ndarray) -> Path:
    """One grid point: f(Z) overall and per species, <Z> per size class of each species, the
    normal-force pdf; titled with the point's own values and charges."""
    names = grid_names(d)
    spn = species_names(d)
    r0 = runs[0]
    fig = new_figure(12, 4.2, layout="constrained")
    a1, a2, a3 = fig.subplots(1, 3)
    data = []
    fzs = [r["fZ"] for r in runs if r.get("fZ")]
    if fzs:
        n = min(len(f) for f in fzs)
        f = np.mean([x[:n] for x in fzs], axis=0)
        a1.plot(range(n), f, "k.-", label="all particles")
        data += [{"panel": "f(Z)", "species": "all", "x": z, "y": y} for z, y in enumerate(f)]
    by_s = {}
    for r in runs:
        for sr in per_species.get(r["key"], []):
            by_s.setdefault(sr["species"], []).append(sr["fZ"])
    if len(by_s) > 1:
        for s, fl in sorted(by_s.items()):
            n = min(len(x) for x in fl)
            f = np.mean([x[:n] for x in fl], axis=0)
            a1.plot(range(n), f, marker=MARKERS[(s - 1) % 3], lw=0.8,
                    label=spn.get(s, f"species {s}"))
            data += [{"panel": "f(Z)", "species": spn.get(s, f"species {s}"), "x": z, "y": y}
                     for z, y in enumerate(f)]
    a1.set_xlim(-0.5, 10.5)
    a1.set_xlabel("coordination number Z [contacts]")
    a1.set_ylabel("f(Z) [fraction of the slab's particles]")
    if a1.get_legend_handles_labels()[0]:
        a1.legend(fontsize=6)
    else:
        a1.text(0.5, 0.5, "no analysis slab (bed too thin)", ha="center", va="center",
                transform=a1.transAxes, fontsize=7)
    # <Z> per size class of each species (means over the seeds of the classes' radius and <Z>)
    cls = {}
    for r in runs:
        for c in (r.get("python") or {}).get("classes", []):
            if c.get("class") != "all":
                cls.setdefault((int(c["species"]), c["class"]), []).append(c)
    for s in sorted({s for s, _ in cls}):
        ks = sorted(k for t, k in cls if t == s)
        x = [1e6 * np.mean([0.5 * (c["r_lo"] + c["r_hi"]) for c in cls[(s, k)]]) for k in ks]
        y = [np.mean([c["Z"] for c in cls[(s, k)]]) for k in ks]
        a2.plot(x, y, marker=MARKERS[(s - 1) % 3], label=spn.get(s, f"species {s}"))
        data += [{"panel": "<Z> by size class", "species": spn.get(s, f"species {s}"),
                  "x": xi, "y": yi} for xi, yi in zip(x, y)]
    a2.set_xlabel("radius of the size class [um]")
    a2.set_ylabel("<Z> of the class [contacts]")
    if a2.get_legend_handles_labels()[0]:
        a2.legend(fontsize=6)
    else:
        a2.text(0.5, 0.5, "no size classes (one radius, or no analysis slab)", ha="center",
                va="center",
                transform=a2.transAxes, fontsize=7)
    if len(forces):
        edges = _force_edges([forces])
        c = 0.5 * (edges[1:] + edges[:-1])
        h, _ = np.histogram(forces, bins=edges, density=True)
        a3.plot(c, h, "k-", label=f"{len(forces)} contacts, mean {forces.mean():+.3g}")
        a3.set_yscale("log")
        a3.legend(fontsize=6)
        data += [{"panel": "force pdf", "species": "all", "x": xi, "y": yi}
                 for xi, yi in zip(c, h)]
    a3.set_xlabel(FORCE_X)
    a3.set_ylabel(FORCE_Y)
    plab = point_label(names, key)
    protos = ", ".join(sorted({str(r.get("protocol")) for r in runs}))
    seeds = ", ".join(str(r["params"]["seed"]) for r in runs)
    title = (f"{d['name']}: {plab + '; ' if plab else ''}{charge_label(r0, spn)}\n"
             f"{protos}; N = {r0['params']['N']}; seeds {seeds} (f(Z), classes: mean over "
             "the seeds; forces: all seeds)")
    _title(fig, title, 12)
    df = pd.DataFrame(data)
    for n, v in reversed(list(zip(names, key))):
        df.insert(0, n, v)
    return _save(fig, out / f"point_{k}.png", df, d["name"])


def study_figures(d: dict, results: list[dict], out: Path) -> list[Path]:
    """The study's figures (module docstring); returns the PNG paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = [r for r in results if r.get("complete", True)]
    if not results:
        return []
    label = study_label(d, results)
    names = grid_names(d)
    pts = _points(results, names)
    per_species = _species_of(results)
    paths = [vs_axis(d, results, out, axis, label, per_species) for axis in names]
    paths.append(fz_gr(d, out, label, pts))
    forces = {}
    for key, runs in pts.items():
        try:
            forces[key] = _forces(runs)
        except (OSError, ValueError, KeyError, IndexError) as e:
            log.warning("study figure force_pdf: %s", e)
            forces[key] = np.zeros(0)
    paths.append(force_figure(d, out, label, pts, forces))
    for k, (key, runs) in enumerate(pts.items(), start=1):
        paths.append(point_figure(d, out, k, key, runs, per_species, forces[key]))
        if any(r.get("charges") for r in runs):
            paths.append(charges_figure(d, out, k, key, [r for r in runs if r.get("charges")]))
    return [p for p in paths if p is not None]


def charges_figure(d, out: Path, k: int, key: tuple, runs: list[dict]) -> Path | None:
    """charges_<k>.png: the final charges of a grid point's runs with contact charging (their
    particles pooled over the seeds), per species (figures.charges)."""
    from .charges import charge_figure, particles_of
    names = grid_names(d)
    try:
        df = particles_of(runs)
    except (OSError, ValueError, KeyError, IndexError) as e:
        log.warning("study figure charges_%d: %s", k, e)
        return None
    plab = point_label(names, key)
    seeds = ", ".join(str(r["params"]["seed"]) for r in runs)
    title = (f"{d['name']}: {plab + '; ' if plab else ''}final charges after contact charging, "
             f"seeds {seeds} pooled")
    return charge_figure(df, out / f"charges_{k}.png", title, species_names(d), study=d["name"])
