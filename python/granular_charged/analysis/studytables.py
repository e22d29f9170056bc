"""The tables of a study file (doc/populations.md, "Study files"), each with the study's name in
a column `study`: runs.csv (one row per run: the grid values, seed, particles asked and made,
settled, phi, <Z>, ...), summary.csv (mean and sd over the seeds per grid point, with the runs
that did not settle or made fewer particles than asked), species.csv and species_summary.csv
(per species of every run and grid point: its share of the particles, its contribution to phi,
its <Z> and f(Z)), classes.csv (<Z> per species and size class); with contact charging
(tribo yes) charges.csv, charges_summary.csv, charge_depth.csv and charge_depth_summary.csv
(charge_tables).

Also what the study's figures share: the names of the grid's axes (grid_names), a run's point
on the grid (point, point_label) and the unit of a deck variable (unit, axis_label)."""
from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd

from ..params import population_charged
from . import packing, status
from .tables import grid_value

log = logging.getLogger(__name__)

# units of the deck's variables (SI, as in.deposition takes them); a species' variable (name_2,
# name_3) has its base name's unit; "-": dimensionless
UNITS = {"rp": "m", "rp_lo": "m", "rp_hi": "m", "radii": "m", "U0": "m/s", "gamma": "J/m^2",
         "q": "e0", "q_sigma": "C/m^2", "q_sd": "e0 or C/m^2", "rho": "kg/m^3", "E": "Pa",
         "g": "m/s^2", "nu": "-", "e": "-", "mu": "-", "theta_crit": "rad", "rp_gsd": "-",
         "frac": "-", "rfrac": "-", "q_pos": "-", "L_rp": "r_p", "H_rp": "r_p", "gap_rp": "r_p",
         "seq_gap_rp": "r_p", "zlo_rp": "r_p", "top_rp": "r_p", "seq_dz_L": "L", "dt_div": "-",
         "ke_stop": "-", "settle_max": "r_p/U0", "N": "particles", "species": "-",
         "seed": "-", "tribo_V": "V", "tribo_V_wall": "V", "tribo_z0": "m"}


def unit(name: str) -> str:
    """The unit of a deck variable or DepositionParams field ('SI' when not listed)."""
    base = name
    for suf in ("_2", "_3"):
        if name.endswith(suf) and name[:-2] in UNITS:
            base = name[:-2]
    return UNITS.get(base, "SI")


def axis_label(name: str) -> str:
    u = unit(name)
    return f"{name} [{'dimensionless' if u == '-' else u}]"


def grid_names(d: dict) -> list[str]:
    """The varied parameters of a study's grid, in order: each key of [grid] with a list of
    values; the parameters of a table of co-varied values (a key whose value is a table of
    lists, or a list of tables)."""
    names = []
    for k, v in (d.get("grid") or {}).items():
        if isinstance(v, dict):
            names += [n for n in v if n not in names]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for x in v:
                names += [n for n in x if n not in names]
        elif k not in names:
            names.append(k)
    return names


def axis_groups(d: dict) -> list[list[str]]:
    """The grid's axes as lists of names: the parameters of a co-varied axis together (the
    study's 'axes' when loaded, else its grid's entries), each other parameter alone."""
    if d.get("axes"):
        return [list(a) for a in d["axes"]]
    out = []
    for k, v in (d.get("grid") or {}).items():
        if isinstance(v, dict):
            out.append(list(v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            out += [list(x) for x in v]
        else:
            out.append([k])
    return out


def _num(v):
    try:
        x = float(v)
        return x if math.isfinite(x) else v
    except (TypeError, ValueError):
        return v


def point(r: dict, names) -> tuple:
    """The run's values of the grid's parameters (numbers as floats)."""
    return tuple(_num(grid_value(r, n)) for n in names)


def fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def point_label(names, values) -> str:
    """'q_sigma = 5e-07 C/m^2, gamma = 0.02 J/m^2' (dimensionless values without a unit)."""
    parts = []
    for n, v in zip(names, values):
        u = unit(n)
        parts.append(f"{n} = {fmt(v)}" + ("" if u in ("-", "SI") else f" {u}"))
    return ", ".join(parts)


def deck_vars(r: dict) -> dict:
    """The deck variables of a result's run {name: text} (its fields and extra)."""
    p = r.get("params") or {}
    v = {k: str(x) for k, x in p.items() if k != "extra"}
    v.update({k: str(x) for k, x in (p.get("extra") or {}).items()})
    return v


def is_population(v: dict) -> bool:
    """The deck's rule (its variable pop): more than one species, a size or a charge rule."""
    return (int(float(v.get("species", 1))) != 1 or v.get("r_dist", "one") != "one"
            or v.get("q_dist", "fixed") != "fixed")


def is_charged(v: dict) -> bool:
    return population_charged(v) if is_population(v) else float(v.get("q", 0)) != 0


def charges(v: dict) -> list[dict]:
    """The charge rule of each species {'dist', 'q', 'sigma', 'sd', 'pos'} from deck variables
    (species s > 1: name_s, else species 1's value, as the deck reads them)."""
    out = []
    for s in range(1, int(float(v.get("species", 1))) + 1):
        def g(name, default):
            return v.get(f"{name}_{s}", v.get(name, default)) if s > 1 else v.get(name, default)
        out.append({"dist": g("q_dist", "fixed"), "q": float(g("q", 0.0)),
                    "sigma": float(g("q_sigma", 0.0)), "sd": float(g("q_sd", 0.0)),
                    "pos": float(g("q_pos", 0.5))})
    return out


def charge_label(r: dict, names: dict | None = None) -> str:
    """The charges of a run, as the run has them: 'uncharged', or per species (named by names,
    {species number: name}) the rule and its value (e.g. 'area sigma -2e-07 C/m^2'); with
    contact charging (tribo yes) the injected charges so, then 'charged by contacts'."""
    label = _injected_charges(r, names)
    if str(deck_vars(r).get("tribo", "no")) == "yes":
        return f"injected {label}, charged by contacts"
    return label


def _injected_charges(r: dict, names: dict | None = None) -> str:
    v = deck_vars(r)
    try:
        if not is_charged(v):
            return "uncharged"
        sp = charges(v)
    except (TypeError, ValueError):     # a label never stops the tables
        return "charged"
    parts = []
    for s, c in enumerate(sp, start=1):
        d = c["dist"]
        if d == "fixed":
            txt = f"q {c['q']:g} e0"
        elif d == "area":
            txt = f"area sigma {c['sigma']:g} C/m^2"
        elif d == "gauss":
            txt = (f"gauss sigma {c['sigma']:g} C/m^2 sd {c['sd']:g}" if c["sigma"]
                   else f"gauss q {c['q']:g} sd {c['sd']:g} e0")
        else:
            txt = (f"bipolar {'sigma %g C/m^2' % c['sigma'] if c['sigma'] else 'q %g e0' % c['q']}"
                   f", {c['pos']:g} positive")
        parts.append(txt if len(sp) == 1 else f"{(names or {}).get(s, f'species {s}')}: {txt}")
    return "; ".join(parts)


def species_names(d: dict) -> dict[int, str]:
    """{species number: its name} of a study's [[species]] (name = ... or 'species s')."""
    out = {}
    for s, sp in enumerate(d.get("species") or [{}], start=1):
        out[s] = str(sp.get("name") or f"species {s}") if isinstance(sp, dict) else f"species {s}"
    return out


def species_rows(r: dict) -> list[dict]:
    """Per species of a finished run (the dump's type) in its analysis slab: particles in the
    slab (n) and their share, the species' contribution to phi (its spheres' volume in the slab
    over the slab's; the contributions add up to phi), <Z> and f(Z). [] without a slab."""
    zlo, zhi = r.get("zlo"), r.get("zhi")
    if zlo is None or zhi is None or not zhi > zlo:
        return []
    snap = packing.read_dump(Path(r["dir"]) / "final.dump", last_only=True)
    Z = packing.coordination(snap)
    sel = (snap["z"] >= zlo) & (snap["z"] <= zhi)
    types = snap["type"].astype(int) if "type" in snap.cols else np.ones(snap.n, dtype=int)
    vol = packing.sphere_slab_volume(snap["z"], snap["radius"], zlo, zhi)
    slab = snap.lx * snap.ly * (zhi - zlo)
    zmax = len(r.get("fZ") or []) - 1 if r.get("fZ") else packing.ZMAX_DEFAULT
    rows = []
    n_all = max(int(sel.sum()), 1)
    for t in sorted(set(types.tolist())):
        st = sel & (types == t)
        fz = packing.fz_histogram(Z[st], zmax) if st.any() else np.zeros(zmax + 1)
        rows.append({"species": int(t), "n": int(st.sum()), "number_share": st.sum() / n_all,
                     "phi": float(vol[types == t].sum() / slab),
                     "Z": float(Z[st].mean()) if st.any() else float("nan"),
                     "fZ": [float(x) for x in fz]})
    return rows


def _status_cols(r: dict) -> dict:
    st = status.run_status(r)
    return {"made": st["made"], "settled": st["settled"], "complete_deposit": not st["short"],
            "warning": st["warning"] or ""}


def study_tables(d: dict, results: list[dict], out: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Write the study's tables (module docstring) in out; returns (runs, summary). Logs a
    warning per run that did not settle or deposited fewer particles than asked."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    name = d["name"]
    names = grid_names(d)
    spn = species_names(d)
    rows, cls, spr, chg, dep = [], [], [], [], []
    for r in results:
        py = r.get("python") or {}
        gv = dict(zip(names, point(r, names)))
        base = {"study": name, **gv, "seed": r["params"]["seed"]}
        row = dict(base, N=r["params"]["N"], **_status_cols(r), protocol=r.get("protocol"),
                   charges=charge_label(r, spn), phi=r["phi"], Z=r["Z"], phi_python=py.get("phi"),
                   Z_python=py.get("Z"), natoms=r.get("natoms"), lost=r.get("lost"),
                   flying=r.get("flying"), mean_diameter=py.get("mean_diameter"), key=r["key"])
        rows.append(row)
        if row["warning"]:
            log.warning("%s (%s): %s", r["key"], point_label(names, gv.values()), row["warning"])
        for c in (r.get("charges") or {}).get("stats", []):
            chg.append({**base, "species_name": _species_name(c["species"], spn), **c})
        for c in (r.get("charges") or {}).get("depth", []):
            dep.append({**base, "species_name": _species_name(c["species"], spn), **c})
        for c in py.get("classes", []):
            cls.append({**base, "species_name": spn.get(int(c["species"]), f"species {c['species']}"),
                        **{k: c[k] for k in ("species", "class", "r_lo", "r_hi", "n", "Z")}})
        if r.get("dir") and (len(spn) > 1 or is_population(deck_vars(r))):
            try:
                srows = species_rows(r)
            except (OSError, ValueError, KeyError, IndexError) as e:
                log.warning("%s: no per-species table (%s)", r["key"], e)
                srows = []
            for s in srows:
                fz = {f"fZ_{k}": v for k, v in enumerate(s.pop("fZ"))}
                spr.append({**base, "species_name": spn.get(s["species"], f"species {s['species']}"),
                            **s, **fz})
    runs = pd.DataFrame(rows)
    for k in names:                  # numbers as numbers (sorted by value, not as text)
        if k in runs:
            try:
                runs[k] = runs[k].astype(float)
            except (ValueError, TypeError):
                pass
    if names and len(runs):
        runs = runs.sort_values(names + ["seed"], kind="stable")
    runs.to_csv(out / "runs.csv", index=False)
    if len(runs):
        keys = ["study"] + names
        g = runs.groupby(keys, dropna=False, sort=True)
        summ = g.agg(runs=("seed", "count"), phi=("phi", "mean"), phi_sd=("phi", "std"),
                     Z=("Z", "mean"), Z_sd=("Z", "std"),
                     made=("made", "mean"), N=("N", "first"),
                     unsettled=("settled", lambda v: int((v == False).sum())),  # noqa: E712
                     short=("complete_deposit", lambda v: int((~v.astype(bool)).sum()))
                     ).reset_index()
    else:
        summ = pd.DataFrame(columns=["study", *names, "runs", "phi", "phi_sd", "Z", "Z_sd"])
    summ.to_csv(out / "summary.csv", index=False)
    pd.DataFrame(cls).to_csv(out / "classes.csv", index=False)
    sp = pd.DataFrame(spr)
    if len(sp):
        sp.to_csv(out / "species.csv", index=False)
        ss = (sp.groupby(["study", *names, "species", "species_name"], dropna=False)
              .agg(runs=("seed", "count"), number_share=("number_share", "mean"),
                   phi=("phi", "mean"), phi_sd=("phi", "std"), Z=("Z", "mean"),
                   Z_sd=("Z", "std")).reset_index())
        ss.to_csv(out / "species_summary.csv", index=False)
    charge_tables(chg, dep, names, out)
    return runs, summ


def _species_name(s, spn: dict) -> str:
    return "all" if s == "all" else spn.get(int(s), f"species {s}")


def charge_tables(chg: list[dict], dep: list[dict], names: list[str], out: Path):
    """The final charges of the runs with contact charging (result.json's 'charges'):
    charges.csv (per run and species: n, mean, sd, median, extremes, fractions negative and
    positive, total [e0]), charge_depth.csv (per run, species and depth bin), and over the seeds
    charges_summary.csv (per grid point and species: the mean of the runs' mean charges, their
    sd over the seeds, the mean sd within a run, the mean fraction negative) and
    charge_depth_summary.csv (per grid point, species and depth bin: the particles' mean charge,
    pooled over the seeds). Nothing without such runs."""
    if not chg:
        return
    keys = ["study", *names, "species", "species_name"]
    c = pd.DataFrame(chg)
    c["species"] = c["species"].astype(str)
    c.to_csv(out / "charges.csv", index=False)
    (c.groupby(keys, dropna=False, sort=True)
     .agg(runs=("seed", "count"), n=("n", "sum"), q_mean_e0=("q_mean_e0", "mean"),
          q_mean_sd_e0=("q_mean_e0", "std"), q_sd_e0=("q_sd_e0", "mean"),
          frac_negative=("frac_negative", "mean"))
     .reset_index().to_csv(out / "charges_summary.csv", index=False))
    d = pd.DataFrame(dep)
    d["species"] = d["species"].astype(str)
    d.to_csv(out / "charge_depth.csv", index=False)
    d["q_sum"] = d["q_mean_e0"] * d["n"]
    g = (d.groupby(keys + ["depth_lo_rp", "depth_hi_rp", "depth_rp"], dropna=False, sort=True)
         .agg(runs=("seed", "count"), n=("n", "sum"), q_sum=("q_sum", "sum")).reset_index())
    g["q_mean_e0"] = g["q_sum"] / g["n"]
    g.drop(columns=["q_sum"]).to_csv(out / "charge_depth_summary.csv", index=False)
