#!/usr/bin/python3
"""Sleeping on vs off: the packing measures of finished deposition runs, per variant, as mean
+- standard deviation over the seeds, and each variant's difference from the reference in units
of its standard error. Measures: phi and <Z> of the analysis slab (result.json), f(Z) at
Z = 1-2 and 4-6, g(r) of the slab averaged over [1.95, 2.05] r_p... at r = 2 r_p (contact
peak) and at 2 sqrt(3) r_p, the normal-force pdf (mean and standard deviation of F_n / F_C
over the contacts with a force) and the CPU seconds. With --slabs: phi, <Z> and f(Z) of the
bottom, middle and top thirds of the analysis slab apart (a tall bed's sleepers lie in its bottom
and middle, its last arrivals in its top), from the final dump with the definitions of the deck's
computes.

    bench/sleep/physics.py [--slabs] REF_FOLDER VARIANT_FOLDER [...]    (folders of `granular-charged run --out`)
"""
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from granular_charged.analysis import packing  # noqa: E402
from granular_charged.params import jkr_scales, pair_modulus  # noqa: E402


SLABS = {"bot": (0.0, 1.0 / 3.0), "mid": (1.0 / 3.0, 2.0 / 3.0), "top": (2.0 / 3.0, 1.0)}


def slab_measures(snap, zlo: float, zhi: float) -> dict:
    """phi, <Z>, f(Z = 1-2) and f(Z = 4-6) of the three thirds of [zlo, zhi]."""
    out = {}
    for name, (a, b) in SLABS.items():
        lo, hi = zlo + a * (zhi - zlo), zlo + b * (zhi - zlo)
        cs = packing.coordination_stats(snap, lo, hi)
        fz = np.asarray(cs["fZ"])
        out.update({f"phi_{name}": packing.phi_slab(snap, lo, hi), f"Z_{name}": cs["Z"],
                    f"fZ12_{name}": float(fz[1:3].sum()), f"fZ46_{name}": float(fz[4:7].sum())})
    return out


def measures(run: Path, slabs: bool = False) -> dict | None:
    res = json.loads((run / "result.json").read_text())
    if res.get("phi") is None:
        return None
    p = res["params"]
    rp = p["rp"]
    snap = packing.read_dump(run / "final.dump", last_only=True)
    zlo, zhi = res["zlo"], res["zhi"]
    if slabs:
        return {**slab_measures(snap, zlo, zhi), "cpu": res.get("cpu_s", float("nan"))}
    r, g = packing.rdf_slab(snap, zlo, zhi, rmax=4.0 * rp, nbins=400)
    def g_at(x, w=0.05):
        sel = (r >= (x - w) * rp) & (r <= (x + w) * rp)
        return float(g[sel].mean())
    fz = np.asarray(res["fZ"])
    FC = jkr_scales(rp / 2, pair_modulus(p["E"], p["nu"]), p["gamma"])["FC"]
    f = packing.read_dump(run / "forces.dump", last_only=True).cols["c_pl[2]"]
    v = f[f != 0.0] / FC
    return {"phi": res["phi"], "Z": res["Z"], "fZ12": float(fz[1:3].sum()),
            "fZ46": float(fz[4:7].sum()), "g2": g_at(2.0), "g2s3": g_at(2.0 * math.sqrt(3.0)),
            "Fmean": float(v.mean()), "Fsd": float(v.std()), "cpu": res.get("cpu_s", float("nan"))}


def folder(path: str, slabs: bool = False) -> dict:
    runs = [measures(d, slabs) for d in sorted(Path(path).iterdir())
            if (d / "result.json").exists()]
    runs = [m for m in runs if m]
    keys = runs[0].keys() if runs else []
    return {"n": len(runs), **{k: np.array([m[k] for m in runs]) for k in keys}}


def main(argv):
    slabs = "--slabs" in argv
    argv = [a for a in argv if a != "--slabs"]
    cols = ["phi", "Z", "fZ12", "fZ46", "g2", "g2s3", "Fmean", "Fsd", "cpu"]
    fmt = {"phi": 4, "Z": 3, "fZ12": 3, "fZ46": 3, "g2": 2, "g2s3": 3, "Fmean": 4, "Fsd": 4, "cpu": 0}
    if slabs:
        cols = [f"{m}_{n}" for n in SLABS for m in ("phi", "Z", "fZ12", "fZ46")] + ["cpu"]
        fmt = {c: fmt[c.split("_")[0]] for c in cols}
    ref = folder(argv[1], slabs)
    print("| variant | seeds | " + " | ".join(cols) + " |")
    print("|---" * (len(cols) + 2) + "|")
    for path in argv[1:]:
        v = ref if path == argv[1] else folder(path, slabs)
        if v["n"] == 0:
            continue
        cells = []
        for c in cols:
            m, s = v[c].mean(), (v[c].std(ddof=1) if v["n"] > 1 else float("nan"))
            cell = f"{m:.{fmt[c]}f} +- {s:.{fmt[c]}f}"
            if path != argv[1] and c != "cpu" and v["n"] > 1 and ref["n"] > 1:
                se = math.sqrt(v[c].var(ddof=1) / v["n"] + ref[c].var(ddof=1) / ref["n"])
                cell += f" ({(m - ref[c].mean()) / se:+.1f})" if se > 0 else ""
            cells.append(cell)
        print(f"| {Path(path).name} | {v['n']} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv)
