"""The cost of a run before it starts: its steps by the deck's rules, the settling after the
last particle included, and its CPU time (doc/python.md, "Cost estimate"; doc/benchmarks.md,
"Cost estimate against the actual CPU").

Model: CPU = c * W, W the particle-steps of the run (the particles present, summed over its
time steps):

- injection: N_dep particles, one every n_i steps (the deck's interval: gap_rp r_p / U_0 of the
  rain, seq_gap_rp r_p / U_0 of the plane rain, ~3 times that for the sequential protocol, which
  waits for each landing); the particles present grow linearly: N_dep^2 n_i / 2;
- the fall of the last particle (the rain: from H to the bed top; plane and sequential: the
  start height above the bed top) and the settling until the stop rule (kerel < ke_stop, none
  moving) holds: SETTLE r_p / U_0 of settling (at most settle_max), with N_dep particles.

N_dep is N, or for a charged bed the particles made before the bed's charge turns the next one
back (the deck's barrier of the plane and sequential protocols: particle k cannot reach its
start height h once 2 pi k_e q_k Q_bed / (L^2 m_k) >= g + U_0^2 / (2 (H - h)); E* >= 1 of
params.dimensionless for one kind of particle is the same barrier at the paper's scale); the
estimate then warns. c is per kind (neutral, charged: the Coulomb solver's work; a run with
contact charging, tribo yes, is of the charged kind, fix coul/fmm working on the charges its
contacts make), fitted on this machine (bench/estimate/estimate_vs_actual.py) and refined by the
finished runs found under the given folders (the geometric mean of their c from their actual
steps, when there are two or more of the kind). The factor of uncertainty is that of the fit, or the geometric sd of the
runs' c when larger.

Nothing here raises on odd inputs: a value the model cannot use gives no estimate ('cpu_s'
None, 'note' saying why), never an exception.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..params import E0, DepositionParams, time_step
from . import population

# Fit on this machine (bench/estimate/estimate_vs_actual.py; doc/benchmarks.md, "Cost estimate
# against the actual CPU"): nine runs (the demo's three cases at N = 500, the regolith example's
# three at N = 150, the toner-like binary powder's three at N = 100) give
#   c = 1.64e-7 s (neutral), 3.11e-7 s (charged) per particle-step: the geometric means of
#       CPU / W over the runs of each kind, W from the model below with the runs' own steps;
#   the settling after the last particle, S r_p / U_0 with S = SETTLE_G g r_p / U_0^2 (between
#       SETTLE_MIN and settle_max): measured 15-85 r_p / U_0 for the demo (g r_p / U_0^2 =
#       2e-5), 23-680 for the regolith and the toner (1.6e-4 - 2e-4); an empirical scaling,
#       S = 500 at 2e-4, chosen with c to minimise the largest |log(actual / estimate)|
#       (1.41 over the nine runs; a run the bed's charge stops settles for settle_max: its
#       particles hover above the bed).
DEFAULT_C = {False: 1.64e-7, True: 3.11e-7}
SETTLE_G = 2.5e6
SETTLE_MIN = 10.0
DEFAULT_FACTOR = 2.0
# the bed's packing fraction for its height in the barrier estimate (loose charged beds)
BED_PHI = 0.35
KE = 8.9875517873681764e9       # Coulomb constant [N m^2 / C^2]
KEPT = Path(__file__).resolve().parents[3] / "doc" / "data"


def _num(v, default: float) -> float:
    """v as a finite float, else default (never raises)."""
    try:
        x = float(v)
    except (TypeError, ValueError, OverflowError):
        return default
    return x if math.isfinite(x) else default


def _x(p: DepositionParams, key: str, default: float) -> float:
    return _num((getattr(p, "extra", None) or {}).get(key, default), default)


def _species(v: dict) -> list[dict]:
    """population.describe's species, or one species of the run's own values when it cannot be
    read (never raises)."""
    try:
        sp = population.describe(v)["species"]
        if sp:
            return sp
    except Exception:       # noqa: BLE001 - an estimate never stops a run
        pass
    m = {k: _num(v.get(k), getattr(DepositionParams, k)) for k in population.MATERIAL_KEYS}
    return [{"fraction": 1.0, "size": {"dist": "one", "r": _num(v.get("rp"), DepositionParams.rp)},
             "charge": {"dist": "fixed", "q": _num(v.get("q"), 0.0), "sigma": 0.0, "sd": 0.0,
                        "pos": 0.5}, "material": m}]


def _rmin(size: dict, rp: float) -> float:
    try:
        return min(population.bounds(size)) if size.get("dist") != "one" else float(size["r"])
    except Exception:       # noqa: BLE001
        return rp


def _charge(sp: dict, r: float) -> tuple[float, float]:
    """(mean charge [C], charge of a particle repelled by a bed of that sign [C]) of a particle
    of radius r of species sp."""
    c = sp.get("charge") or {}
    d = c.get("dist", "fixed")
    q = _num(c.get("q"), 0.0) * E0
    sig = _num(c.get("sigma"), 0.0)
    base = sig * 4.0 * math.pi * r * r if (d == "area" or sig != 0.0) else q
    if d == "bipolar":
        pos = min(max(_num(c.get("pos"), 0.5), 0.0), 1.0)
        return (2.0 * pos - 1.0) * base, abs(base)
    return base, base


def barrier(p: DepositionParams, species: list[dict] | None = None) -> dict | None:
    """Where the bed's charge turns the particles back: {'k': the particle that can no longer
    reach its start height (of N), 'Estar': E* of one kind of particle} or None when every
    particle arrives (a neutral bed, or one whose net charge stays below the barrier)."""
    v = p.deck_vars()
    sp = species if species is not None else _species(v)
    rp, U0, g = _num(p.rp, 0.0), _num(p.U0, 0.0), _x(p, "g", 9.81)
    L = _x(p, "L_rp", 28.0) * rp
    H = _x(p, "H_rp", 160.0) * rp
    N = int(_num(p.N, 0))
    if not (rp > 0 and U0 > 0 and L > 0 and H > 0 and N > 0):
        return None
    qmean = vol = 0.0
    rows = []
    for s in sp:
        f = _num(s.get("fraction"), 0.0)
        size = s.get("size") or {}
        try:
            r = population.reference_radius(size)
        except Exception:       # noqa: BLE001
            r = rp
        rho = _num((s.get("material") or {}).get("rho"), p.rho)
        if not (r > 0 and rho > 0 and f > 0):
            continue
        mean, rep = _charge(s, r)
        qmean += f * mean
        vol += f * 4.0 / 3.0 * math.pi * r ** 3
        rows.append((rep, 4.0 / 3.0 * math.pi * r ** 3 * rho))
    if qmean == 0.0 or not rows:
        return None
    # the most strongly repelled kind: largest q/m of the bed's sign
    qm = max((abs(q) / m for q, m in rows if q * qmean > 0), default=0.0)
    if qm <= 0:
        return None
    seq_dz = (_x(p, "seq_dz_L", 0.0) or max(7.0 / (L / rp), 0.25)) * L
    k = N
    for _ in range(20):     # the bed top rises with k: a few fixed-point steps
        h = k * vol / (BED_PHI * L * L) + seq_dz
        if h >= H:
            break
        need = g + U0 * U0 / (2.0 * (H - h))
        kk = need * L * L / (2.0 * math.pi * KE * qm * abs(qmean))
        kk = max(1.0, min(kk, float(N)))
        if abs(kk - k) < 0.5:
            k = kk
            break
        k = kk
    out = {"k": int(k), "N": N}
    if len(sp) == 1 and (sp[0].get("charge") or {}).get("dist", "fixed") == "fixed":
        out["Estar"] = _num(p.groups().get("Estar"), float("nan"))
    return out if k < N else None


def settle_steps_rp(p: DepositionParams) -> float:
    """The settling after the last particle's fall, in r_p / U_0 (the fit above)."""
    g = _x(p, "g", 9.81)
    smax = max(_x(p, "settle_max", 1000.0), 0.0)
    return min(max(SETTLE_G * abs(g) * float(p.rp) / float(p.U0) ** 2, SETTLE_MIN), smax)


def coulomb_works(v: dict) -> bool:
    """Whether fix coul/fmm works in a run (deck variables v): charged particles, or contact
    charging (tribo yes: the charges made by contacts); the kind of its calibration."""
    return population.is_charged(v) or str(v.get("tribo", "no")) == "yes"


def plan(p: DepositionParams, dt: float | None = None) -> dict:
    """The steps of run p by the deck's rules: protocol, dt, injection interval n_i, steps per
    r_p / U_0 of fall, particles deposited (N_dep), the steps of injection, fall and settling,
    the particle-steps W and the barrier (or None). Raises on values the model cannot use (see
    run_plan for the safe one)."""
    v = p.deck_vars()
    proto = population.protocol(v)
    sp = _species(v)
    charged = population.is_charged(v)
    rp, U0 = float(p.rp), float(p.U0)
    if dt is None:
        dts = []
        for s in sp:
            m = s.get("material") or {}
            r = _rmin(s.get("size") or {}, rp)
            dts.append(time_step(r, _num(m.get("rho"), p.rho), _num(m.get("E"), p.E),
                                 _num(m.get("nu"), p.nu), U0, _x(p, "dt_div", 20)))
        dt = min(dts)
    unit = rp / U0 / dt                       # steps per r_p of fall at U_0
    if not (unit > 0 and math.isfinite(unit)):
        raise ValueError(f"no time scale (r_p / U_0 / dt = {unit})")
    L_rp = _x(p, "L_rp", 28.0)
    if proto == "rain":
        gap = _x(p, "gap_rp", 0) or (2.0 if charged else 1.0)
    else:
        gap = _x(p, "seq_gap_rp", 0) or 1568.0 / (L_rp * L_rp)
    n_i = math.ceil(gap * unit) * (3.0 if proto == "sequential" else 1.0)
    N = int(p.N)
    bar = barrier(p, sp) if charged else None
    # the plane and sequential protocols end at the barrier; the rain goes on with particles
    # hovering above the bed, which never settles: the settling runs to settle_max
    n_dep = bar["k"] if bar and proto != "rain" else N
    # bed height in r_p after n_dep particles (the rain's last particle falls from H onto it)
    vol = sum(_num(s.get("fraction"), 0) * (population.reference_radius(s["size"]) / rp) ** 3
              for s in sp if s.get("size")) * 4.0 / 3.0 * math.pi
    bed = n_dep * vol / (BED_PHI * L_rp * L_rp)
    if proto == "rain":
        fall_rp = max(_x(p, "H_rp", 160.0) - bed, 0.0)
    else:
        fall_rp = (_x(p, "seq_dz_L", 0.0) or max(7.0 / L_rp, 0.25)) * L_rp
    settle_rp = settle_steps_rp(p)
    if bar:     # particles hover above the bed: it settles only at settle_max
        settle_rp = max(_x(p, "settle_max", 1000.0), 0.0)
    inject = n_dep * n_i
    post = (fall_rp + settle_rp) * unit
    work = n_i * n_dep * n_dep / 2.0 + n_dep * post
    return {"protocol": proto, "charged": charged, "coulomb": coulomb_works(v), "dt": dt,
            "unit": unit, "n_i": n_i,
            "N": N, "N_dep": n_dep, "inject_steps": inject, "fall_steps": fall_rp * unit,
            "settle_steps": settle_rp * unit, "steps": inject + post, "work": work,
            "barrier": bar}


def run_plan(p) -> dict | None:
    """plan(p), or None when its values give none (never raises)."""
    try:
        out = plan(p)
    except Exception:       # noqa: BLE001 - an estimate never stops a run
        return None
    return out if math.isfinite(out["work"]) and out["work"] >= 0 else None


def interval_steps(p: DepositionParams, dt: float | None = None) -> tuple[str, float]:
    """(protocol, steps between two injections) by the deck's rules."""
    pl = plan(p, dt)
    return pl["protocol"], pl["n_i"]


def actual_work(p: DepositionParams, result: dict) -> float | None:
    """The particle-steps of a finished run from its actual steps and particles made."""
    try:
        lmp = result.get("lammps") or {}
        pl = plan(p, lmp.get("dt"))
        steps = float(lmp.get("steps") or result.get("steps"))
        n = float(result.get("inserted") or lmp.get("inserted") or p.N)
        inject = min(n * pl["n_i"], steps)
        return pl["n_i"] * n * n / 2.0 + n * (steps - inject)
    except Exception:       # noqa: BLE001
        return None


def calibration(folders) -> dict:
    """{charged: (c, factor, runs)} from the result.json files under folders: the geometric
    mean of CPU / actual particle-steps over the runs of each kind (two or more), else the
    fit of this machine."""
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
            except (OSError, ValueError, KeyError, TypeError):
                continue
            if r.get("key") in seen or not cpu > 0:
                continue
            seen.add(r.get("key"))
            w = actual_work(p, r)
            if w and w > 0:
                try:
                    cs[coulomb_works(p.deck_vars())].append(cpu / w)
                except Exception:       # noqa: BLE001
                    continue
    out = {}
    for k, v in cs.items():
        if len(v) >= 2:
            logs = [math.log(c) for c in v]
            m = sum(logs) / len(logs)
            sd = math.sqrt(sum((x - m) ** 2 for x in logs) / (len(logs) - 1))
            out[k] = (math.exp(m), max(DEFAULT_FACTOR, math.exp(sd)), len(v))
        else:
            out[k] = (DEFAULT_C[k], DEFAULT_FACTOR, 0)
    return out


def _folders(folders) -> list:
    return [f for f in folders if Path(f).is_dir()]


def estimate(params, folders=()) -> dict:
    """Total steps (the settling included) and CPU seconds of the runs, with the factor of
    uncertainty, the runs the bed's charge stops early ('turned_back': [(key, k, N, E*)]) and
    the runs without an estimate ('no_estimate': their keys)."""
    cal = calibration(_folders(folders))
    steps = cpu = settle = 0.0
    factor, runs = 1.0, set()
    protocols, turned, none = {}, [], []
    for p in params:
        pl = run_plan(p)
        if pl is None:
            try:
                none.append(p.key())
            except Exception:       # noqa: BLE001
                none.append(str(p))
            continue
        protocols[pl["protocol"]] = protocols.get(pl["protocol"], 0) + 1
        c, f, k = cal[pl["coulomb"]]
        steps += pl["steps"]
        settle += pl["fall_steps"] + pl["settle_steps"]
        cpu += c * pl["work"]
        factor = max(factor, f)
        runs.add(k)
        if pl["barrier"]:
            b = pl["barrier"]
            turned.append((p.key(), b["k"], b["N"], b.get("Estar")))
    return {"steps": steps, "settle_steps": settle, "cpu_s": cpu if not none else None,
            "cpu_s_known": cpu, "factor": factor, "calibration_runs": max(runs or {0}),
            "protocols": protocols, "turned_back": turned, "no_estimate": none}


def cpu_seconds(params, folders=()) -> list[tuple[float, float]]:
    """(CPU seconds, factor of uncertainty) of each run, with one calibration for all (a run
    without an estimate: that of the fit's c times a million particle-steps, factor 10)."""
    cal = calibration(_folders(folders))
    out = []
    for p in params:
        pl = run_plan(p)
        if pl is None:
            out.append((DEFAULT_C[True] * 1e6, 10.0))
            continue
        c, f, _ = cal[pl["coulomb"]]
        out.append((c * pl["work"], f))
    return out


def hms(s: float) -> str:
    return f"{s / 3600:.1f} h" if s >= 3600 else f"{s / 60:.1f} min" if s >= 60 else f"{s:.0f} s"


def describe(est: dict) -> str:
    """The estimate as one line, then a warning line per kind of problem (runs the bed's charge
    stops early, runs without an estimate)."""
    f = est["factor"]
    src = (f"calibrated on {est['calibration_runs']} finished runs" if est["calibration_runs"]
           else "this machine's fit")
    cpu = est.get("cpu_s_known", est.get("cpu_s")) or 0.0
    line = (f"estimated cost: {est['steps']:.3g} steps ({est.get('settle_steps', 0):.3g} of "
            f"them the last fall and the settling), CPU ~{hms(cpu)} (x/ {f:.1f}: "
            f"{hms(cpu / f)} - {hms(cpu * f)}; {src})")
    turned = est.get("turned_back") or []
    if turned:
        key, k, n, es = turned[0]
        more = f" (and {len(turned) - 1} more runs)" if len(turned) > 1 else ""
        estar = f", E* = {es:.2g}" if es is not None and math.isfinite(es) else ""
        line += (f"\nWARNING: the bed's charge will turn the particles back: {key} deposits "
                 f"~{k} of {n} particles before the barrier{estar}{more}; such runs end early "
                 "with fewer particles than asked (the estimate counts the ones that arrive)")
    none = est.get("no_estimate") or []
    if none:
        line += (f"\nWARNING: no cost estimate for {len(none)} run(s) ({none[0]}"
                 f"{', ...' if len(none) > 1 else ''}): their values give no time scale")
    return line
