"""The cost of a run before it starts: its injection steps from the deck's rules, and its CPU time
from a calibration on finished runs (doc/python.md, "Cost estimate").

Model: the work of a deposition grows with the particles present times the steps, and the
particles grow linearly while they are injected, so CPU ~ c N^2 n_i with n_i the steps between
two injections (the settling after the last one adds a part of the same order, inside c). c is
calibrated on finished runs of this machine (every result.json found under the given folders,
the kept runs of doc/data included), separately for neutral and charged runs; the uncertainty
is the geometric standard deviation of c over those runs (a factor), reported with the estimate.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..params import DepositionParams, ParamError, time_step
from . import population

# when no finished run is found: c of the kept runs of this package (neutral, charged) and a
# factor 3 either way
DEFAULT_C = {False: 2.0e-7, True: 1.5e-6}
DEFAULT_FACTOR = 3.0
KEPT = Path(__file__).resolve().parents[3] / "doc" / "data"


def _x(p: DepositionParams, key: str, default: float) -> float:
    return float(p.extra.get(key, default))


def interval_steps(p: DepositionParams, dt: float | None = None) -> tuple[str, float]:
    """(protocol, steps between two injections) by the deck's rules; sequential counted as the
    plane rain (it waits for each landing: ~3 times the cost, doc/deposition.md)."""
    v = p.deck_vars()
    proto = population.protocol(v)
    if dt is None:
        rmin = p.rp
        if population.is_population(v):
            rmin = min(min(population.bounds(sp["size"])) if sp["size"]["dist"] != "one"
                       else sp["size"]["r"] for sp in population.describe(v)["species"])
        dt = time_step(rmin, p.rho, p.E, p.nu, p.U0, _x(p, "dt_div", 20))
    if not (isinstance(dt, float) and math.isfinite(dt) and dt > 0):
        raise ParamError(f"rp = {p.rp:g}: no time step from these parameters (dt = {dt})")
    charged = population.is_charged(v)
    if proto == "rain":
        gap = _x(p, "gap_rp", 0) or (2.0 if charged else 1.0)
    else:
        L = _x(p, "L_rp", 28)
        gap = _x(p, "seq_gap_rp", 0) or 1568.0 / (L * L)
    n = math.ceil(gap * p.rp / p.U0 / dt)
    return proto, n * (3.0 if proto == "sequential" else 1.0)


def calibration(folders) -> dict:
    """{charged: (c, factor, runs)} from the result.json files under folders."""
    cs = {False: [], True: []}
    seen = set()
    for folder in folders:
        for f in Path(folder).glob("**/result.json"):
            try:
                r = json.loads(f.read_text())
                prm = dict(r["params"])
                extra = prm.pop("extra", {}) or {}
                p = DepositionParams(extra=extra, **prm)
                cpu = float(r.get("cpu_s") or r["wall_s"])
                dt = r.get("lammps", {}).get("dt")
                if r.get("key") in seen or not cpu > 0:
                    continue
                _, n = interval_steps(p, float(dt) if dt else None)
            except (OSError, ValueError, KeyError, TypeError, AttributeError, ArithmeticError):
                continue
            seen.add(r.get("key"))
            cs[population.is_charged(p.deck_vars())].append(cpu / (p.N ** 2 * n))
    out = {}
    for k, v in cs.items():
        if len(v) >= 2:
            logs = [math.log(c) for c in v]
            m = sum(logs) / len(logs)
            sd = math.sqrt(sum((x - m) ** 2 for x in logs) / (len(logs) - 1))
            out[k] = (math.exp(m), math.exp(sd), len(v))
        else:
            out[k] = (DEFAULT_C[k], DEFAULT_FACTOR, 0)
    return out


def estimate(params, folders=()) -> dict:
    """Total injection steps and CPU seconds of the runs, with the factor of uncertainty."""
    cal = calibration([f for f in (*folders, KEPT) if Path(f).is_dir()])
    steps = cpu = 0.0
    factor, runs = 1.0, set()
    protocols = {}
    for p in params:
        proto, n = interval_steps(p)
        protocols.setdefault(proto, 0)
        protocols[proto] += 1
        c, f, k = cal[population.is_charged(p.deck_vars())]
        steps += p.N * n
        cpu += c * p.N ** 2 * n
        factor = max(factor, f)
        runs.add(k)
    return {"steps": steps, "cpu_s": cpu, "factor": factor, "calibration_runs": max(runs or {0}),
            "protocols": protocols}


def cpu_seconds(params, folders=()) -> list[tuple[float, float]]:
    """(CPU seconds, factor of uncertainty) of each run, with one calibration for all."""
    cal = calibration([f for f in (*folders, KEPT) if Path(f).is_dir()])
    out = []
    for p in params:
        _, n = interval_steps(p)
        c, f, _ = cal[population.is_charged(p.deck_vars())]
        out.append((c * p.N ** 2 * n, f))
    return out


def describe(est: dict) -> str:
    def hms(s):
        return f"{s / 3600:.1f} h" if s >= 3600 else f"{s / 60:.1f} min" if s >= 60 else f"{s:.0f} s"
    f = est["factor"]
    src = (f"calibrated on {est['calibration_runs']} finished runs" if est["calibration_runs"]
           else "no finished runs to calibrate on: the package's default")
    return (f"estimated cost: {est['steps']:.3g} injection steps, CPU ~{hms(est['cpu_s'])} "
            f"(x/ {f:.1f}: {hms(est['cpu_s'] / f)} - {hms(est['cpu_s'] * f)}; {src})")
