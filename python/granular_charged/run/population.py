"""Particle populations of in.deposition: sizes, charges and species, as deck variables.

A population is written as specs, the same on the command line (``--size``, ``--charge``) and in
a study file (doc/populations.md)::

    size:   one | uniform lo=3e-6 hi=7e-6 | lognormal median=5e-6 gsd=1.2 [lo=.. hi=..]
            | discrete radii=2e-6,4e-6 [fractions=0.7,0.3]
    charge: fixed q=400 | area sigma=1e-5 | gauss q=400 sd=50 (or sigma=.. sd=..)
            | bipolar q=400 pos=0.5 (or sigma=.. pos=..)

radii in m, q in e_0, sigma (surface charge density) in C/m^2. A mixture is a list of species,
each with a number fraction, a material (rho, E, nu, gamma, e, mu) and its size and charge specs.
Species 1 uses the deck's plain variable names (rp, q, rho, ...), species s > 1 the names with
the suffix _s (rp_2, rho_2, ...). The deck draws every particle (doc/populations.md); this module
only writes the variables, and gives the distributions' CDFs the tests compare the draws with.
"""
from __future__ import annotations

import math

from ..params import E0, DepositionParams, ParamError, check_deck_values, population_charged

SIZE_KEYS = {"one": ("r",), "uniform": ("lo", "hi"), "lognormal": ("median", "gsd", "lo", "hi"),
             "discrete": ("radii", "fractions")}
CHARGE_KEYS = {"fixed": ("q",), "area": ("sigma",), "gauss": ("q", "sigma", "sd"),
               "bipolar": ("q", "sigma", "pos")}
MATERIAL_KEYS = ("rho", "E", "nu", "gamma", "e", "mu")
# a species' surface for contact charging (in.deposition's tribo_V, tribo_V_2, ...): its contact
# potential [V], given in the material of a study file's species
SURFACE_KEYS = ("tribo_V",)
MAX_SPECIES = 3
MAX_RADII = 6


def parse_spec(text: str | dict, kinds: dict, what: str) -> dict:
    """'uniform lo=3e-6 hi=7e-6' (or a dict with 'dist') as {'dist': 'uniform', 'lo': 3e-6, ...};
    lists (radii, fractions) as lists of floats. ParamError names what is wrong."""
    if isinstance(text, dict):
        spec = dict(text)
    else:
        words = str(text).split()
        if not words:
            raise ParamError(f"{what}: empty")
        spec = {"dist": words[0]}
        for w in words[1:]:
            if "=" not in w:
                raise ParamError(f"{what} {text!r}: {w!r} is not KEY=VALUE")
            k, v = w.split("=", 1)
            spec[k] = v
    dist = spec.get("dist")
    if dist not in kinds:
        raise ParamError(f"{what}: {dist!r} is not one of {', '.join(kinds)}")
    out = {"dist": dist}
    for k, v in spec.items():
        if k == "dist":
            continue
        if k not in kinds[dist]:
            raise ParamError(f"{what} {dist}: no parameter {k!r} (it takes {', '.join(kinds[dist])})")
        try:
            if k in ("radii", "fractions"):
                items = v.replace(",", " ").split() if isinstance(v, str) else list(v)
                out[k] = [float(x) for x in items]
            else:
                out[k] = float(v)
        except (TypeError, ValueError):
            raise ParamError(f"{what} {dist}: {k} = {v!r} is not a number") from None
    _check(out, what)
    return out


# the keys a spec must give (the rest have the deck's defaults); the values' rules are the
# deck's (granular_charged.rules), checked on the deck variables the spec becomes
REQUIRED = {"uniform": ("lo", "hi"), "lognormal": ("median", "gsd"), "discrete": ("radii",),
            "area": ("sigma",), "gauss": ("sd",)}


def _check(s: dict, what: str):
    missing = [k for k in REQUIRED.get(s["dist"], ()) if k not in s]
    if missing:
        raise ParamError(f"{what} {s['dist']} needs {' and '.join(f'{k}=' for k in missing)}")
    if s["dist"] in ("one", "uniform", "lognormal", "discrete"):
        size, charge = (s if s["dist"] != "one" else {**s, "r": s.get("r", DepositionParams.rp)}), None
    else:
        size, charge = {"dist": "one", "r": DepositionParams.rp}, s
    check_vars(species_vars(1, size, charge), what)


def check_vars(v: dict, what: str = ""):
    """ParamError when deck variables v break a rule of the deck (granular_charged.rules; the
    plausibility rules are left to the run's parameters, where exotic yes can pass them)."""
    try:
        check_deck_values(v, plausible=False)
    except ParamError as e:
        raise ParamError(f"{what}: {e}" if what else str(e)) from None


def bounds(size: dict) -> tuple[float, float]:
    """The radius range of a size spec (a lognormal's default clip: median gsd^-3 .. gsd^3)."""
    d = size["dist"]
    if d == "one":
        return size["r"], size["r"]
    if d == "uniform":
        return size["lo"], size["hi"]
    if d == "lognormal":
        return (size.get("lo") or size["median"] / size["gsd"] ** 3,
                size.get("hi") or size["median"] * size["gsd"] ** 3)
    return min(size["radii"]), max(size["radii"])


def reference_radius(size: dict) -> float:
    """The deck's rp for a species: the radius (one), the median (lognormal), else the
    number-mean radius."""
    d = size["dist"]
    if d == "one":
        return size["r"]
    if d == "lognormal":
        return size["median"]
    if d == "uniform":
        return 0.5 * (size["lo"] + size["hi"])
    radii = size["radii"]
    f = size.get("fractions") or [1.0] * len(radii)
    if not radii:
        return 0.0                  # refused by the rules (no radius)
    if len(f) != len(radii) or sum(f) <= 0:
        f = [1.0] * len(radii)      # fractions the rules refuse: the plain mean meanwhile
    return sum(r * w for r, w in zip(radii, f)) / sum(f)


def _num(v) -> str:
    return f"{v:.10g}"


def species_vars(s: int, size: dict, charge: dict | None, material: dict | None = None,
                 fraction: float | None = None) -> dict:
    """Deck variables {name: value string} of species s (1..3) for its specs."""
    suf = "" if s == 1 else f"_{s}"
    v = {}
    d = size["dist"]
    if d != "one":
        v["r_dist" + suf] = d
    if d == "one":
        v["rp" + suf] = _num(size["r"])
    elif d == "uniform":
        v.update({"rp" + suf: _num(reference_radius(size)), "rp_lo" + suf: _num(size["lo"]),
                  "rp_hi" + suf: _num(size["hi"])})
    elif d == "lognormal":
        lo, hi = bounds(size)
        v.update({"rp" + suf: _num(size["median"]), "rp_gsd" + suf: _num(size["gsd"]),
                  "rp_lo" + suf: _num(lo), "rp_hi" + suf: _num(hi)})
    else:
        v["rp" + suf] = _num(reference_radius(size))
        v["radii" + suf] = " ".join(_num(r) for r in size["radii"])
        if size.get("fractions"):
            v["rfrac" + suf] = " ".join(_num(f) for f in size["fractions"])
    if charge is not None:
        if s > 1:
            # a species' charge rule is its own: none of species 1's charge values carries over
            charge = {"q": 0.0, "sigma": 0.0, "sd": 0.0, "pos": 0.5, **charge}
        if charge["dist"] != "fixed":
            v["q_dist" + suf] = charge["dist"]
        for key, var in (("q", "q"), ("sigma", "q_sigma"), ("sd", "q_sd"), ("pos", "q_pos")):
            if key in charge:
                v[var + suf] = _num(charge[key])
    for k, val in (material or {}).items():
        if k not in MATERIAL_KEYS + SURFACE_KEYS:
            raise ParamError(f"species {s}: material has no {k!r} (it takes "
                             f"{', '.join(MATERIAL_KEYS + SURFACE_KEYS)})")
        try:
            v[k + suf] = _num(float(val))
        except (TypeError, ValueError):
            raise ParamError(f"species {s}: material {k} = {val!r} is not a number") from None
    if fraction is not None and s > 1 or (fraction is not None and fraction != 1.0):
        v["frac" + suf] = _num(fraction)
    return v


def mixture_vars(species: list[dict]) -> dict:
    """Deck variables of a list of species [{'fraction', 'material', 'size', 'charge'}, ...]."""
    if not 1 <= len(species) <= MAX_SPECIES:
        raise ParamError(f"a population has 1-{MAX_SPECIES} species, not {len(species)}")
    v = {}
    if len(species) > 1:
        v["species"] = str(len(species))
    for s, sp in enumerate(species, start=1):
        unknown = set(sp) - {"name", "fraction", "material", "size", "charge"}
        if unknown:
            raise ParamError(f"species {s}: unknown keys {', '.join(sorted(unknown))}")
        size = parse_spec(sp.get("size", "one"), SIZE_KEYS, f"species {s} size")
        if size["dist"] == "one" and "r" not in size:
            raise ParamError(f"species {s} size one needs r=RADIUS")
        charge = parse_spec(sp["charge"], CHARGE_KEYS, f"species {s} charge") if "charge" in sp else None
        try:
            fraction = float(sp.get("fraction", 1.0)) if len(species) > 1 else None
        except (TypeError, ValueError):
            raise ParamError(f"species {s}: fraction = {sp.get('fraction')!r} is not a "
                             "number") from None
        v.update(species_vars(s, size, charge, sp.get("material"), fraction))
    check_vars(v)
    return v


# ---- the population of a run, from its deck variables ---------------------------------------

def _get(vars_: dict, name: str, s: int, default):
    """The value of a species' variable as the deck resolves it: name_s, else species 1's."""
    if s > 1 and f"{name}_{s}" in vars_:
        return vars_[f"{name}_{s}"]
    return vars_.get(name, default)


def describe(vars_: dict) -> dict:
    """The population of a run from its deck variables (DepositionParams.deck_vars()):
    {'species': [{'fraction', 'size', 'charge', 'material'}...]}; the record of result.json."""
    n = int(float(vars_.get("species", 1)))
    fr = [float(vars_.get("frac" if s == 1 else f"frac_{s}", 1.0)) for s in range(1, n + 1)]
    out = []
    for s in range(1, n + 1):
        g = lambda name, default: _get(vars_, name, s, default)
        rd = g("r_dist", "one")
        rp = float(g("rp", DepositionParams.rp))
        size = {"dist": rd}
        if rd == "one":
            size["r"] = rp
        elif rd == "uniform":
            size.update(lo=float(g("rp_lo", 0)), hi=float(g("rp_hi", 0)))
        elif rd == "lognormal":
            gsd = float(g("rp_gsd", 1.2))
            lo, hi = float(g("rp_lo", 0)), float(g("rp_hi", 0))
            size.update(median=rp, gsd=gsd, lo=lo or rp / gsd ** 3, hi=hi or rp * gsd ** 3)
        else:
            radii = [float(x) for x in str(g("radii", "0")).split()]
            fw = str(g("rfrac", "0")).split()
            size.update(radii=radii, fractions=[float(x) for x in fw] if fw != ["0"]
                        else [1.0] * len(radii))
        qd = g("q_dist", "fixed")
        charge = {"dist": qd, "q": float(g("q", 0.0)), "sigma": float(g("q_sigma", 0.0)),
                  "sd": float(g("q_sd", 0.0)), "pos": float(g("q_pos", 0.5))}
        material = {k: float(g(k, getattr(DepositionParams, k))) for k in MATERIAL_KEYS}
        if str(vars_.get("tribo", "no")) == "yes":
            material["tribo_V"] = float(g("tribo_V", 0.0))
        out.append({"fraction": fr[s - 1] / sum(fr), "size": size, "charge": charge,
                    "material": material})
    return {"species": out}


def is_population(vars_: dict) -> bool:
    """The deck's rule (its variable pop): anything but one species of one radius and charge."""
    return (int(float(vars_.get("species", 1))) != 1 or vars_.get("r_dist", "one") != "one"
            or vars_.get("q_dist", "fixed") != "fixed")


def is_charged(vars_: dict) -> bool:
    if not is_population(vars_):
        return float(vars_.get("q", 0)) != 0
    return population_charged(vars_)


def protocol(vars_: dict) -> str:
    """The injection protocol a run uses: inject, or for auto the deck's rule (rain when no
    particle is charged, plane when any is)."""
    inj = vars_.get("inject", "auto")
    if inj != "auto":
        return inj
    return "plane" if is_charged(vars_) else "rain"


# ---- the distributions, for tests and the analysis ------------------------------------------

def radius_cdf(size: dict):
    """F(r) of a size spec as the deck draws it (the lognormal truncated to lo..hi)."""
    from scipy import stats
    d = size["dist"]
    if d == "uniform":
        return stats.uniform(loc=size["lo"], scale=size["hi"] - size["lo"]).cdf
    if d == "lognormal":
        ln = stats.lognorm(s=math.log(size["gsd"]), scale=size["median"])
        lo, hi = bounds(size)
        a, b = ln.cdf(lo), ln.cdf(hi)
        import numpy as np
        return lambda r: (np.clip(ln.cdf(r), a, b) - a) / (b - a)
    raise ValueError(f"{d}: a discrete distribution, not a continuous one")


def area_charge(r, sigma: float):
    """Charge [e_0] of a sphere of radius r with surface charge density sigma [C/m^2]."""
    return sigma * 4.0 * math.pi * r * r / E0
