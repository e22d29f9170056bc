"""Runs from options: --var axes (NAME V1 V2 ...), population variables and the base fields as
DepositionParams, and what a sweep or a study says before it starts (protocols, cost)."""
from __future__ import annotations

import itertools
import logging

from ..params import DepositionParams, ParamError, param_names, split_deck_vars
from ..run import estimate
from ..run.deckfile import deck_variables
from ..run.population import protocol

log = logging.getLogger("granular_charged")


def deck_params(pairs, base: dict, popvars: dict, refused: dict, N: int, seed: int):
    """One DepositionParams from --var pairs, the base fields (rp, U0, gamma, q) and population
    variables (which set rp and q when they name them)."""
    names = {n for n, _ in pairs}
    clash = sorted(names & set(popvars))
    if clash:
        raise ParamError(f"--var {clash[0]}: set by --size/--charge/--inject/--tribo* or the "
                         "population")
    fields, extra = split_deck_vars(list(pairs), deck_variables("in.deposition"), refused)
    fields = dict(base, **fields)
    for k, v in popvars.items():
        if k == "farfield" or k not in param_names():
            (fields if k == "farfield" else extra)[k] = v
            continue
        try:
            fields[k] = type(getattr(DepositionParams, k))(float(v))
        except (TypeError, ValueError):
            raise ParamError(f"{k} = {v!r}: must be a number") from None
    return DepositionParams(N=N, seed=seed, extra=extra, **fields)


def var_axes(items, command: str):
    """--var NAME V1 [V2 ...] items as (single pairs, axes [(name, values)]); several values only
    where the command sweeps."""
    single, axes = [], []
    for item in items:
        if len(item) < 2:
            raise ParamError(f"--var {item[0]}: needs a value")
        if len(item) == 2:
            single.append((item[0], item[1]))
        elif command != "sweep":
            raise ParamError(f"--var {item[0]}: {command} takes one value (several: sweep)")
        else:
            axes.append((item[0], item[1:]))
    return single, axes


def sweep_params(sets, single, axes, popvars, refused, N, seeds):
    """Every combination of the sets' values (rp, U0, gamma, q), the --var axes and the seeds,
    each run once."""
    out = []
    names = [n for n, _ in axes]
    for s in sets:
        lists = [s[k] if isinstance(s[k], (list, tuple)) else [s[k]] for k in ("rp", "U0", "gamma", "q")]
        for rp, U0, gamma, q, *vals in itertools.product(*lists, *[v for _, v in axes]):
            for seed in seeds:
                pairs = list(single) + list(zip(names, vals))
                out.append(deck_params(pairs, dict(rp=rp, U0=U0, gamma=gamma, q=q), popvars,
                                       refused, N, seed))
    return list({p.key(): p for p in out}.values())


def announce(params, out, inject: str = "auto"):
    """Before a sweep or study: the protocols its runs will use (a warning when they differ, so
    that a charge series does not compare two protocols unknowingly) and the estimated cost."""
    by = {}
    for p in params:
        by.setdefault(protocol(p.deck_vars()), []).append(p)
    if len(by) > 1:
        log.warning("these runs use DIFFERENT injection protocols (inject auto: rain when no "
                    "particle is charged, plane when any is): %s. Pass --inject PROTOCOL (or "
                    "protocol = ... in a study file) to use one for all.",
                    "; ".join(f"{k} for {len(v)} runs" for k, v in by.items()))
    else:
        log.info("injection protocol of every run: %s", next(iter(by), "none"))
    log.info("%d runs; %s", len(params), estimate.describe(estimate.estimate(params, [out])))
