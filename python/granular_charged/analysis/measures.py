"""Per-run measures of the paper's claims beyond phi and <Z> of the analysis slab, from a finished
run folder (final.dump, forces.dump, tracer.dump, result.json), cached in its measures.json:

- the conventions the paper leaves open (doc/reproduction.md, "The phi_0 gap"): phi of the whole
  bed V / (L^2 H_p) with H_p the highest particle top, 2 <z>, or the mean top of 2 r_p x 2 r_p
  columns (area independent); <Z> over all particles, with or without floor contacts;
- f(Z) populations of the slab: Z = 1-2 (chains) and Z = 4-6 (compact cells; Fig. 5);
- g(r) of the slab: the area of each peak the paper names above a straight baseline, at
  r / 2 r_p = sqrt 3 (edge-sharing triangles, which "vanishes for charged packing"), sqrt 2 and
  sqrt 5 (crystal peaks, absent; Fig. 4);
- the normal-force pdf F_n / F_C of the contacts: mean (a shift to tension is negative), sd and
  the fraction inside the paper's |F_n / F_C| < 0.1 (Fig. 7);
- the incident particle's E_k / E_k0 just before its first contact (Fig. 8), when it was followed.

One home for each of these measures: the figures and the studies read them from here.
"""
from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np

from ..params import jkr_scales, pair_modulus
from . import packing

log = logging.getLogger(__name__)

MEASURES_VERSION = 2
# g(r) peaks the paper names, in r / 2 r_p; the peak's area is that of g in a window of half
# width RDF_HALF_WIDTH above the straight line through the mean of g in the two flanks of width
# RDF_FLANK beside it (means over bins, not single bins: one run's g(r) scatters by ~0.1 per
# bin of 0.01). The windows and flanks stay clear of the contact peak at 1, of the peak at 2
# and of each other.
RDF_PEAKS = {"sqrt2": math.sqrt(2.0), "sqrt3": math.sqrt(3.0), "sqrt5": math.sqrt(5.0)}
RDF_HALF_WIDTH = 0.06
RDF_FLANK = 0.05
RDF_BIN = 0.01          # bin width in r / 2 r_p
FORCE_RANGE = 0.1       # the paper's |F_n / F_C| < 0.1 (paper.FORCE_RANGE)


def conventions(snap: packing.Snapshot, rp: float) -> dict:
    """phi and <Z> by the definitions the paper leaves open (module docstring)."""
    z, r = snap["z"], snap["radius"]
    vol = float((4.0 / 3.0 * np.pi * r ** 3).sum())
    area = snap.lx * snap.ly
    Z = packing.coordination(snap)
    floor = z - r < 1e-3 * rp          # touching the floor wall
    return {
        "phi_bed_top": vol / (area * float((z + r).max())),
        "phi_bed_2z": vol / (area * 2.0 * float(z.mean())),
        "phi_bed_surface": vol / (area * float(np.nanmean(packing.surface_heights(snap, 2 * rp)))),
        "Z_all": float(Z.mean()),
        "Z_all_floor": float((Z + floor).mean()),
    }


ORIENTATION_BINS = 10   # bins of |cos theta| in [0, 1]


def contact_orientation(snap: packing.Snapshot, zlo: float | None = None,
                        zhi: float | None = None) -> dict:
    """Directions of the geometric contacts against the z axis (the applied field of an
    electrophoretic deposition, doc/epd.md), of the contacts whose midpoint lies in [zlo, zhi]
    (default: all): the order parameter S = <3 cos^2 theta - 1> / 2 (isotropic 0, all along z
    1, all across -1/2), the mean |cos theta| (isotropic 1/2) and the histogram of |cos theta|
    (isotropic: uniform, density 1)."""
    pairs, n = packing.contact_normals(snap)
    zmid = 0.5 * (snap["z"][pairs[:, 0]] + snap["z"][pairs[:, 1]]) if len(pairs) else np.zeros(0)
    keep = (zmid >= (-np.inf if zlo is None else zlo)) & (zmid <= (np.inf if zhi is None else zhi))
    c = np.abs(n[keep, 2])
    hist, _ = np.histogram(c, bins=ORIENTATION_BINS, range=(0.0, 1.0), density=True)
    return {"contacts": int(len(c)),
            "S": float(np.mean(1.5 * c * c - 0.5)) if len(c) else float("nan"),
            "mean_abs_cos": float(c.mean()) if len(c) else float("nan"),
            "abs_cos_hist": hist.tolist() if len(c) else [float("nan")] * ORIENTATION_BINS}


def fz_populations(fZ) -> dict:
    """Shares of Z = 1-2 and Z = 4-6 in f(Z) (bins Z = 0, 1, ...)."""
    f = np.asarray(fZ, dtype=float)
    if f.size == 0:
        return {"fZ_1_2": float("nan"), "fZ_4_6": float("nan")}
    return {"fZ_1_2": float(f[1:3].sum()), "fZ_4_6": float(f[4:7].sum())}


def rdf_peak_areas(x: np.ndarray, g: np.ndarray) -> dict:
    """Area of g in the window of each peak of RDF_PEAKS above the straight line through the
    mean of g in its two flanks (x = r / 2 r_p, bin centres of equal width)."""
    dx = x[1] - x[0]
    out = {}
    for name, x0 in RDF_PEAKS.items():
        lo, hi = x0 - RDF_HALF_WIDTH, x0 + RDF_HALF_WIDTH
        left = (x >= lo - RDF_FLANK) & (x < lo)
        right = (x > hi) & (x <= hi + RDF_FLANK)
        (xl, gl), (xr, gr) = (x[left].mean(), g[left].mean()), (x[right].mean(), g[right].mean())
        w = (x >= lo) & (x <= hi)
        base = gl + (gr - gl) * (x[w] - xl) / (xr - xl)
        out[f"rdf_{name}"] = float(((g[w] - base) * dx).sum())
    return out


def rdf(snap: packing.Snapshot, rp: float, zlo: float, zhi: float):
    """g(r) of the analysis slab out to r = 6 r_p in bins of RDF_BIN (r / 2 r_p): (x, g)."""
    nbins = int(round(3.0 / RDF_BIN))
    rc, g = packing.rdf_slab(snap, zlo, zhi, 6.0 * rp, nbins)
    return rc / (2.0 * rp), g


def normal_forces(forces_dump: Path, params: dict) -> np.ndarray:
    """F_n / F_C of the pairs with a non-zero normal force (compute pair/local, > 0
    compressive), F_C = 3 pi gamma R_eff of a pair of equal spheres."""
    FC = jkr_scales(params["rp"] / 2, pair_modulus(params["E"], params["nu"]),
                    params["gamma"])["FC"]
    f = packing.read_dump(forces_dump, last_only=True).cols["c_pl[2]"]
    return f[f != 0.0] / FC


def force_stats(fn: np.ndarray) -> dict:
    if fn.size == 0:
        return {"Fn_mean": float("nan"), "Fn_sd": float("nan"), "Fn_inside": float("nan"),
                "Fn_tensile": float("nan")}
    return {"Fn_mean": float(fn.mean()), "Fn_sd": float(fn.std(ddof=1)) if fn.size > 1 else 0.0,
            "Fn_inside": float((np.abs(fn) < FORCE_RANGE).mean()),
            "Fn_tensile": float((fn < 0).mean())}


def tracer_approach(run_dir: Path, result: dict):
    """The followed particle's approach: (gap to the nearest earlier particle or the floor over
    r_p, E_k / E_k0, index of the first contact), or None without a tracer. The bed is the final
    configuration of the particles with smaller id (hit-and-stick keeps them where they were
    when the tracer came)."""
    tid = result.get("tracer")
    path = Path(run_dir) / "tracer.dump"
    if not tid or not packing.dump_exists(path):
        return None
    p = result["params"]
    tr = [s for s in packing.read_dump(path) if s.n == 1]
    if not tr:
        return None
    fin = packing.read_dump(Path(run_dir) / "final.dump", last_only=True)
    bed = fin["id"] < tid
    pos = np.array([[s["x"][0], s["y"][0], s["z"][0]] for s in tr])
    vel = np.array([[s["vx"][0], s["vy"][0], s["vz"][0]] for s in tr])
    if bed.any():
        d = pos[:, None, :] - np.column_stack([fin["x"][bed], fin["y"][bed], fin["z"][bed]])[None]
        d[..., 0] -= fin.lx * np.round(d[..., 0] / fin.lx)
        d[..., 1] -= fin.ly * np.round(d[..., 1] / fin.ly)
        near = np.sqrt((d * d).sum(-1)).min(axis=1)
    else:
        near = np.full(len(pos), np.inf)
    gaps = np.minimum(near - 2 * p["rp"], pos[:, 2] - p["rp"]) / p["rp"]
    eks = (vel * vel).sum(1) / p["U0"] ** 2
    # first contact: the first jump of E_k between samples (> 1 % of E_k0; in free flight,
    # gravity and the Coulomb field change it by ~1e-4 per sample)
    jumps = np.flatnonzero(np.abs(np.diff(eks)) > 0.01)
    k = int(jumps[0]) + 1 if len(jumps) else len(eks) - 1
    return gaps, eks, k


def compute(run_dir: Path, result: dict) -> dict:
    """Every measure of one finished run (module docstring)."""
    run_dir = Path(run_dir)
    p = result["params"]
    snap = packing.read_dump(run_dir / "final.dump", last_only=True)
    out = {"version": MEASURES_VERSION, "key": result["key"], **conventions(snap, p["rp"]),
           **fz_populations(result.get("fZ") or [])}
    zlo, zhi = result.get("zlo"), result.get("zhi")
    if zlo is not None and zhi is not None and zhi > zlo:
        x, g = rdf(snap, p["rp"], zlo, zhi)
        out.update(rdf_peak_areas(x, g))
        out["rdf_x"], out["rdf_g"] = x.tolist(), g.tolist()
    if packing.dump_exists(run_dir / "forces.dump"):
        out.update(force_stats(normal_forces(run_dir / "forces.dump", p)))
    t = tracer_approach(run_dir, result)
    if t is not None:
        _, eks, k = t
        out["Ek_before_contact"] = float(eks[k - 1]) if k >= 1 else float("nan")
    return out


def load(run_dir: Path, result: dict) -> dict:
    """measures.json of the run (computed and written when missing or of another version)."""
    path = Path(run_dir) / "measures.json"
    if path.exists():
        try:
            m = json.loads(path.read_text())
            if m.get("version") == MEASURES_VERSION and m.get("key") == result["key"]:
                return m
        except (OSError, ValueError):
            pass
    m = compute(run_dir, result)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(m))
    tmp.replace(path)
    return m
