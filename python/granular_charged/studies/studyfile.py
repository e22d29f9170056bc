"""A study of one's own powder from a TOML file: ``granular-charged study FILE``.

The file names the material(s), the population, the protocol, the grid and the seeds
(doc/populations.md, "Study files"); every combination of the grid's values and the seeds is
one run of in.deposition (resumable: finished runs are skipped), then the tables (runs.csv,
summary.csv, classes.csv per species and size class), labelled with the study's name. The
command line draws the figures (granular_charged.figures.studyfile). No value or annotation of
the paper appears in them.
"""
from __future__ import annotations

import itertools
import logging
import tomllib
from pathlib import Path

from ..analysis.studytables import study_tables
from ..params import DepositionParams, ParamError, param_names
from ..run import population
from ..run.runner import RESERVED
from .axes import announce, deck_params
from .sweep import Sweep

log = logging.getLogger(__name__)

# the grid's entry whose variables vary together (one axis)
TOGETHER = "together"
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
    if d["protocol"] not in ("auto", "rain", "plane", "sequential"):
        raise ParamError(f"{path}: protocol must be auto, rain, plane or sequential")
    seeds = d["seeds"]
    if not (isinstance(seeds, list) and seeds and all(
            isinstance(s, int) and not isinstance(s, bool) and 1 <= s <= 900000000 for s in seeds)):
        raise ParamError(f"{path}: seeds = {seeds!r}: must be a list of whole numbers "
                         "1 .. 900000000, e.g. seeds = [1, 2, 3]")
    d["axes"] = grid_axes(d.get("grid", {}), path)
    # every varied variable with its values, in the file's order (the tables' and figures' axes)
    d["grid"] = {k: v for axis in d["axes"] for k, v in axis.items()}
    return d


def grid_axes(grid: dict, path) -> list[dict]:
    """The grid's axes, each {name: values}: a plain entry (name = [values]) is an axis of one
    variable; a `together` table ({name = [values], ...}, or a list of such tables) is one axis
    whose variables take their i-th values together. The runs are every combination of the
    axes' points. ParamError for an entry that is not a non-empty list, together lists of
    different lengths, a variable given twice."""
    axes, seen = [], set()

    def values(name, v, where):
        if not isinstance(v, list) or not v:
            raise ParamError(f"{path}: {where}{name} = {v!r}: must be a non-empty list of values")
        if name in seen:
            raise ParamError(f"{path}: grid: {name} is given twice (an axis of its own and "
                             "together, or in two together tables)")
        seen.add(name)
        return v

    for name, v in grid.items():
        if name != TOGETHER:
            axes.append({name: values(name, v, "grid.")})
            continue
        groups = v if isinstance(v, list) else [v]
        for group in groups:
            if not isinstance(group, dict) or not group:
                raise ParamError(f"{path}: grid.{TOGETHER} must be a table of lists of equal "
                                 "length, e.g. together = {q_sigma = [0, -2e-7], "
                                 "q_sigma_2 = [0, 3e-7]}")
            axis = {k: values(k, x, f"grid.{TOGETHER}.") for k, x in group.items()}
            lengths = {k: len(x) for k, x in axis.items()}
            if len(set(lengths.values())) > 1:
                raise ParamError(f"{path}: grid.{TOGETHER}: its lists vary together and need "
                                 "one length each, not "
                                 + ", ".join(f"{k} {n}" for k, n in lengths.items()))
            axes.append(axis)
    return axes


def deck_text(name: str, value) -> str:
    """A study file's value as the deck's text: a number as written back by Python (-2e-07),
    a list as a word list ("2e-06 4e-06"), true/false as yes/no, text unchanged."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, list):
        return " ".join(deck_text(name, v) for v in value)
    if isinstance(value, (int, float, str)):
        return str(value)
    raise ParamError(f"{name} = {value!r}: must be a number, a word or a list of them")


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
            base[k] = fixed.pop(k)          # checked with every value by DepositionParams
    N = fixed.pop("N", d.get("N", 500))
    refused = dict(RESERVED, seed="seeds = [...] of the study file")
    axes = d.get("axes") or grid_axes(d.get("grid", {}), "study")
    # each axis's points: [{name: value}, ...] (a together axis: the i-th values of its lists)
    points = [[dict(zip(axis, vals)) for vals in zip(*axis.values())] for axis in axes]
    out = []
    for combo in itertools.product(*points):
        point = {k: v for p in combo for k, v in p.items()}
        for seed in d["seeds"]:
            b = dict(base)
            pairs = [(k, deck_text(f"deck.{k}", v)) for k, v in fixed.items()]
            pv = dict(popvars)
            for k, v in point.items():
                if k in ("U0", "gamma", "q", "rp") and k not in pv:
                    b[k] = v
                elif k in pv or k in param_names():
                    pv[k] = deck_text(f"grid.{k}", v)
                else:
                    pairs.append((k, deck_text(f"grid.{k}", v)))
            out.append(deck_params(pairs, b, pv, refused, N, int(seed)))
    return list({p.key(): p for p in out}.values())


def run(path, runner, jobs: int = 1, progress: bool = True, engine=None) -> dict:
    """Run a study file: the runs (resumable), then the tables under its out folder."""
    d = load(path)
    ps = params(d)
    for p in ps:
        runner.check(p)
    out = Path(d["out"])
    log.info("study %r: %d runs (%d seeds) in %s", d["name"], len(ps), len(d["seeds"]), out)
    announce(ps, out / "runs", d["protocol"])
    results = Sweep(runner, out / "runs", jobs=jobs, progress=progress, engine=engine).run(ps)
    out.mkdir(parents=True, exist_ok=True)
    runs, summ = study_tables(d, results, out)
    return {"study": d, "results": results, "runs": runs, "summary": summ,
            "complete": len(results) == len(ps)}
