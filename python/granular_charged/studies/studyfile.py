"""A study of one's own powder from a TOML file: ``granular-charged study FILE``.

The file names the material(s), the population, the protocol, the grid and the seeds
(doc/populations.md, "Study files"); every combination of the grid's values and the seeds is
one run of in.deposition (resumable: finished runs are skipped), then the tables (runs.csv,
summary.csv, classes.csv per species and size class) and the figures (phi and <Z> against each
grid axis, f(Z), g(r) in units of the mean diameter and of r_i + r_j), labelled with the
study's name. No value or annotation of the paper appears in them.
"""
from __future__ import annotations

import itertools
import logging
import tomllib
from pathlib import Path

import pandas as pd

from ..analysis.tables import grid_value
from ..figures.studyfile import study_figures
from ..params import DepositionParams, ParamError, param_names
from ..run import population
from ..run.runner import RESERVED
from .axes import announce, deck_params
from .sweep import Sweep

log = logging.getLogger(__name__)

TOP_KEYS = {"name", "out", "seeds", "N", "protocol", "deck", "material", "population",
            "species", "grid"}


def load(path) -> dict:
    """The study file, checked: unknown keys and malformed entries are a ParamError."""
    try:
        with open(path, "rb") as fh:
            d = tomllib.load(fh)
    except tomllib.TOMLDecodeError as e:
        raise ParamError(f"{path}: not valid TOML: {e}") from None
    unknown = sorted(set(d) - TOP_KEYS)
    if unknown:
        raise ParamError(f"{path}: unknown keys {', '.join(unknown)} (a study file has "
                         f"{', '.join(sorted(TOP_KEYS))})")
    if "population" in d and "species" in d:
        raise ParamError(f"{path}: give [population] (one species) or [[species]] (a mixture)")
    d.setdefault("name", Path(path).stem)
    d.setdefault("out", str(Path(path).with_suffix("")) + "-output")
    d.setdefault("seeds", [1, 2, 3])
    d.setdefault("protocol", "auto")
    seeds = d["seeds"]
    if not (isinstance(seeds, list) and seeds and all(
            isinstance(s, int) and not isinstance(s, bool) and 1 <= s <= 900000000 for s in seeds)):
        raise ParamError(f"{path}: seeds = {seeds!r}: must be a list of whole numbers "
                         "1 .. 900000000, e.g. seeds = [1, 2, 3]")
    if d["protocol"] not in ("auto", "rain", "plane", "sequential"):
        raise ParamError(f"{path}: protocol must be auto, rain, plane or sequential")
    for k, v in d.get("grid", {}).items():
        if not isinstance(v, list) or not v:
            raise ParamError(f"{path}: grid.{k} must be a non-empty list of values")
    return d


def params(d: dict) -> list[DepositionParams]:
    """Every run of the study (grid x seeds)."""
    species = d.get("species")
    if species is None:
        pop = dict(d.get("population", {}))
        species = [{"size": pop.pop("size", {"dist": "one", "r": d.get("deck", {}).get("rp", DepositionParams.rp)}),
                    **({"charge": pop.pop("charge")} if "charge" in pop else {}),
                    "material": d.get("material", {})}]
        if pop:
            raise ParamError(f"population: unknown keys {', '.join(sorted(pop))} (size, charge)")
    elif "material" in d:
        raise ParamError("a mixture gives each species its material ([[species]] material = ...)")
    popvars = population.mixture_vars(species)
    if d["protocol"] != "auto":
        popvars["inject"] = d["protocol"]
    base = {"rp": DepositionParams.rp, "U0": DepositionParams.U0,
            "gamma": DepositionParams.gamma, "q": DepositionParams.q}
    fixed = dict(d.get("deck", {}))
    for k in ("rp", "U0", "gamma", "q"):
        if k in fixed:
            base[k] = fixed.pop(k)
    N = fixed.pop("N", d.get("N", 500))
    refused = dict(RESERVED, seed="seeds = [...] of the study file")
    grid = d.get("grid", {})
    names = list(grid)
    out = []
    for vals in itertools.product(*grid.values()):
        for seed in d["seeds"]:
            b = dict(base)
            pairs = [(k, str(v)) for k, v in fixed.items()]
            pv = dict(popvars)
            for k, v in zip(names, vals):
                if k in ("U0", "gamma", "q", "rp") and k not in pv:
                    b[k] = v
                elif k in pv or k in param_names():
                    pv[k] = str(v)
                else:
                    pairs.append((k, str(v)))
            out.append(deck_params(pairs, b, pv, refused, N, int(seed)))
    return list({p.key(): p for p in out}.values())


def tables(d: dict, results: list[dict], out: Path):
    """runs.csv, summary.csv (mean +- sd over the seeds per grid point) and classes.csv."""
    names = list(d.get("grid", {}))
    rows, cls = [], []
    for r in results:
        row = {k: grid_value(r, k) for k in names}
        row.update(seed=r["params"]["seed"], N=r["params"]["N"], protocol=r.get("protocol"),
                   phi=r["phi"], Z=r["Z"], phi_python=r["python"]["phi"],
                   Z_python=r["python"]["Z"], natoms=r["natoms"],
                   mean_diameter=r["python"].get("mean_diameter"), key=r["key"])
        rows.append(row)
        for c in r["python"].get("classes", []):
            cls.append({**{k: grid_value(r, k) for k in names}, "seed": r["params"]["seed"],
                        **{k: c[k] for k in ("species", "class", "r_lo", "r_hi", "n", "Z")}})
    runs = pd.DataFrame(rows)
    for k in names:                  # numbers as numbers (sorted by value, not as text)
        try:
            runs[k] = runs[k].astype(float)
        except (ValueError, TypeError):
            pass
    if names and len(runs):
        runs = runs.sort_values(names + ["seed"], kind="stable")
    runs.to_csv(out / "runs.csv", index=False)
    if names and len(runs):
        g = runs.groupby(names, dropna=False)
        summ = g.agg(runs=("seed", "count"), phi=("phi", "mean"), phi_sd=("phi", "std"),
                     Z=("Z", "mean"), Z_sd=("Z", "std")).reset_index()
    else:
        summ = pd.DataFrame([{"runs": len(runs), "phi": runs["phi"].mean() if len(runs) else None,
                              "phi_sd": runs["phi"].std() if len(runs) else None,
                              "Z": runs["Z"].mean() if len(runs) else None,
                              "Z_sd": runs["Z"].std() if len(runs) else None}])
    summ.to_csv(out / "summary.csv", index=False)
    pd.DataFrame(cls).to_csv(out / "classes.csv", index=False)
    return runs, summ


def run(path, runner, jobs: int = 1, progress: bool = True, engine=None) -> dict:
    """Run a study file: the runs (resumable), then tables and figures under its out folder."""
    d = load(path)
    ps = params(d)
    for p in ps:
        runner.check(p)
    out = Path(d["out"])
    log.info("study %r: %d runs (%d seeds) in %s", d["name"], len(ps), len(d["seeds"]), out)
    announce(ps, out / "runs", d["protocol"])
    results = Sweep(runner, out / "runs", jobs=jobs, progress=progress, engine=engine).run(ps)
    out.mkdir(parents=True, exist_ok=True)
    runs, summ = tables(d, results, out)
    figs = study_figures(d, results, out / "figures") if results else []
    return {"study": d, "results": results, "runs": runs, "summary": summ, "figures": figs,
            "complete": len(results) == len(ps)}
