"""Physical parameters, JKR scales and the paper's dimensionless groups.

References: ``doc/theory.md`` sections 1-2 of the project, i.e. Chen, Li, Liu & Makse, Soft Matter
2016 (arXiv:1509.07012; "the paper"), its Table 1, Eqs. 1-2 (JKR), 7-8 (U_eff, Ad*), and
Marshall, J. Comput. Phys. 228 (2009) 1541. SI units throughout.
"""
from __future__ import annotations

import difflib
import hashlib
import json
import math
import re
from dataclasses import asdict, dataclass, field, fields

from .paper import K_EFF

E0 = 1.602176634e-19        # elementary charge [C]
EPS0 = 8.8541878128e-12     # vacuum permittivity [F/m]
QQR2E_LAMMPS_SI = 8.9876e9  # LAMMPS's 'units si' Coulomb constant (doc/theory.md, eq. (3.1))


class ParamError(ValueError):
    """Parameters that cannot make a run; the message names the parameter and its bad value."""


# Fields of DepositionParams without an option of their own on the command line: `--var NAME
# VALUE` sets them as fields (typed), so that result.json's params, the groups and the key see
# them. (As extra deck variables they reached LAMMPS while params kept the default.)
MATERIAL = ("farfield", "rho", "E", "nu", "e", "mu", "theta_crit")


FARFIELDS = ("exact", "average", "none")


def _finite(x) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def check_deck_values(values: dict, plausible: bool = True):
    """ParamError with the first rule of in.deposition that deck variables `values` break (the
    others at the deck's defaults; granular_charged.rules has the rules, the same the deck
    checks itself); plausible False leaves out the plausibility rules."""
    from . import rules
    found = rules.problems(values, plausible=plausible)
    if found:
        raise ParamError(found[0])


def check_deck_value(name: str, value):
    """ParamError when deck variable `name` = value breaks a rule of in.deposition."""
    check_deck_values({name: value})


def same_value(a, b) -> bool:
    """Whether two deck values are the same (as text, or as the same number)."""
    if str(a).strip() == str(b).strip():
        return True
    try:
        return float(a) == float(b)
    except (TypeError, ValueError):
        return False


@dataclass
class DepositionParams:
    """Inputs of examples/deposition/in.deposition; defaults = the paper's Table 1 / Fig. 2."""
    rp: float = 2.0e-6        # particle radius [m]
    U0: float = 1.0           # injection speed [m/s]
    gamma: float = 0.010      # surface energy per surface [J/m^2]
    q: float = 0.0            # charge per particle [e_0]
    N: int = 2000             # particles injected
    seed: int = 4711
    farfield: str = "exact"   # fix coul/fmm far field
    rho: float = 2500.0
    E: float = 2.0e8
    nu: float = 0.33
    e: float = 0.7
    mu: float = 0.3
    theta_crit: float = 0.01
    extra: dict = field(default_factory=dict)   # any other deck variable (gap_rp, dt_div, ...)

    def __post_init__(self):
        own = sorted(set(self.extra) & set(param_names()))
        if own:
            raise ParamError(f"{', '.join(own)}: a parameter of its own "
                             f"(DepositionParams({own[0]}=...)), not an extra deck variable")
        # every deck variable, the given ones over the deck's defaults, against the deck's
        # rules (granular_charged.rules: the same rules the deck checks itself)
        def text(v):                # a float as short as it is exact: 0 and 2e-06, not 0.0
            if isinstance(v, float):
                g = f"{v:g}"
                return g if float(g) == v else repr(v)
            return v
        check_deck_values({k: text(v) for k, v in asdict(self).items() if k != "extra"}
                          | dict(self.extra))
        for f in fields(self):
            if f.name == "extra":
                continue
            kind = type(f.default)
            value = getattr(self, f.name)
            setattr(self, f.name, int(float(value)) if kind is int else kind(value))

    def deck_vars(self) -> dict:
        d = asdict(self)
        extra = d.pop("extra")
        d.update(extra)
        return {k: str(v) for k, v in d.items()}

    def key(self) -> str:
        """The name of the run's folder: the series (r_p, U_0, gamma), q, N and the seed, then
        ``_h`` and a hash of every non-default value (:meth:`non_default`) when anything else
        differs from its default or one of those values is not written out exactly: about
        40-60 characters (at most ~100), the same for the same run however its values are written (``E 2e8`` is
        ``E 200000000``, a value at its default is the default), different for different runs.
        The run's params.json and result.json list every value."""
        canon = self.non_default()
        head = f"{series_name(self.rp, self.U0, self.gamma)}_q{self.q:g}_N{int(self.N)}_s{int(self.seed)}"
        exact = (float(f"{self.rp * 1e6:g}e-6") == self.rp and float(f"{self.U0:g}") == self.U0
                 and float(f"{self.gamma * 1e3:g}e-3") == self.gamma
                 and float(f"{self.q:g}") == self.q)
        if set(canon) - set(KEY_MAIN) or not exact:
            head += "_h" + key_hash(canon)
        return head

    def non_default(self) -> dict:
        """Every deck variable of the run whose value differs from its default, {name: value}
        sorted by name, each value in one form (:func:`normal_value`): the parameter set that
        the key's hash stands for. A default is the field's (DepositionParams) or the deck's
        ``variable NAME index DEFAULT``; a default ``${other}`` (species 2's rho_2 is species
        1's rho) is the run's value of other."""
        from .run.deckfile import deck_variables
        deck = deck_variables("in.deposition")
        given = {k: getattr(self, k) for k in param_names()}
        given.update(self.extra)

        def default(name, depth=0):
            if name in _FIELD_DEFAULTS:
                return _FIELD_DEFAULTS[name]
            d = deck.get(name)
            m = _REFERENCE.fullmatch(d or "")
            if m and depth < 8:
                ref = m.group(1) or m.group(2)
                return given[ref] if ref in given else default(ref, depth + 1)
            return d
        out = {}
        for name in sorted(given):
            value = normal_value(given[name])
            d = default(name)
            if d is None or normal_value(d) != value:
                out[name] = value
        return out

    def legacy_key(self) -> str:
        """The folder name of runs made before keys were hashed (every non-default value
        written out, up to hundreds of characters): such a folder is still found and resumed
        (runner.run_folder)."""
        base = f"{series_name(self.rp, self.U0, self.gamma)}_q{self.q:g}_N{self.N}_s{self.seed}"
        if self.q or (self.extra and self._population_charged()):
            base += f"_{self.farfield}"
        tags = {k: getattr(self, k) for k in MATERIAL
                if k != "farfield" and getattr(self, k) != getattr(DepositionParams, k)}
        tags.update(self.extra)
        for k in sorted(tags):
            v = tags[k]
            base += f"_{k}{v:g}" if isinstance(v, float) else f"_{k}{v}"
        return base.replace("/", "-").replace(" ", ",")

    def _population_charged(self) -> bool:
        return population_charged(self.deck_vars())

    # derived -------------------------------------------------------------------------------
    @property
    def mass(self) -> float:
        return 4.0 / 3.0 * math.pi * self.rp ** 3 * self.rho

    @property
    def L(self) -> float:
        return float(self.extra.get("L_rp", 28)) * self.rp

    def groups(self) -> dict:
        """Ad, E*, Ad* with the paper's K_eff = 20 N (L/r_p)^-2 for this N and L (51.0 for
        N = 2000, L = 28 r_p, and for the demo's N = 500, L = 14 r_p)."""
        K = 20.0 * self.N / float(self.extra.get("L_rp", 28)) ** 2
        d = dimensionless(self.gamma, self.rho, self.U0, self.rp, self.q, K_eff=K)
        d["K_eff"] = K
        return d


# the values a run's key always names (the hash stands for every other one)
KEY_MAIN = ("rp", "U0", "gamma", "q", "N", "seed")
_FIELD_DEFAULTS = {f.name: f.default for f in fields(DepositionParams) if f.name != "extra"}
# a deck default that is another variable's value: ${name} or $n
_REFERENCE = re.compile(r"\$\{(\w+)\}|\$(\w)")
_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def normal_value(value):
    """A deck value in one form, for comparing and hashing: a number (given as a number or as
    text: 14, "14", "14.0", "1.4e1") as a float, a word list of numbers ("2e-6 4e-6") as a list
    of floats, other text with its white space collapsed."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value) + 0.0          # -0.0 is 0.0
    text = " ".join(str(value).split())
    words = text.split(" ")
    if text and all(_NUMBER.fullmatch(w) for w in words):
        numbers = [float(w) + 0.0 for w in words]
        return numbers[0] if len(numbers) == 1 else numbers
    return text


def key_hash(values: dict) -> str:
    """10 hex digits of the SHA-1 of a parameter set (canonical JSON: sorted names, compact)."""
    text = json.dumps(values, sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(text.encode()).hexdigest()[:10]


def population_charged(v: dict) -> bool:
    """in.deposition's rule (its variables pop, chg<s>): a particle population (more than one
    species, a size or a charge rule) any species of which is charged: q != 0 (but with
    q_dist area), q_sigma != 0 (but with q_dist fixed), q_sd != 0 with q_dist gauss; a species
    s > 1 reads name_s, else species 1's value."""
    n = int(float(v.get("species", 1)))
    if n == 1 and v.get("r_dist", "one") == "one" and v.get("q_dist", "fixed") == "fixed":
        return False
    for s in range(1, n + 1):
        def g(name, default):
            key = f"{name}_{s}"
            return v[key] if s > 1 and key in v else v.get(name, default)
        qd = g("q_dist", "fixed")
        q, sig, sd = (float(g(k, 0.0)) for k in ("q", "q_sigma", "q_sd"))
        if (qd != "area" and q != 0) or (qd != "fixed" and sig != 0) or (qd == "gauss" and sd != 0):
            return True
    return False


def series_name(rp: float, U0: float, gamma: float) -> str:
    """A series (r_p, U_0, gamma) as file names write it: rp2um_U1_g10mJ."""
    return f"rp{rp * 1e6:g}um_U{U0:g}_g{gamma * 1e3:g}mJ"


def param_names() -> tuple:
    """The fields of DepositionParams that are deck variables (all but `extra`)."""
    return tuple(f.name for f in fields(DepositionParams) if f.name != "extra")


def split_deck_vars(pairs, deck: dict, refused: dict, deck_name: str = "in.deposition"):
    """``--var NAME VALUE`` pairs as (fields of DepositionParams, typed; other deck variables).

    ``deck``: the variables of the deck that will run ({name: default}, see
    deckfile.deck_variables); ``refused``: {name: what sets it instead} for names that have
    their own option or are set by the runner. ParamError for a refused name, a name the deck
    does not have (with the names it may have meant), a name given twice, and a field's value
    that is not of the field's type."""
    fields_, extra = {}, {}
    seen = set()
    for name, value in pairs:
        if name in seen:
            raise ParamError(f"--var {name}: given twice")
        seen.add(name)
        if name in refused:
            raise ParamError(f"--var {name} {value}: {name} is not set with --var: "
                             f"{refused[name]}")
        if name not in deck:
            near = difflib.get_close_matches(name, deck, n=3, cutoff=0.6)
            near += [k for k in deck if k.lower() == name.lower() and k not in near]
            hint = f" (did you mean {' or '.join(near)}?)" if near else ""
            raise ParamError(f"--var {name} {value}: {deck_name} has no variable {name!r}{hint}; "
                             f"--var sets: {', '.join(sorted(set(deck) - set(refused), key=str.lower))}")
        if name in MATERIAL:
            kind = type(getattr(DepositionParams, name))
            try:
                fields_[name] = kind(value)
            except ValueError:
                raise ParamError(f"--var {name} {value}: not a number") from None
        elif not same_value(value, deck[name]):
            # a variable given at the deck's default is the default run (its key and folder)
            extra[name] = value
    return fields_, extra


def pair_modulus(E: float, nu: float) -> float:
    """E* of two like spheres: 1/E* = 2 (1 - nu^2)/E (doc/theory.md, eq. (1.1))."""
    return E / (2.0 * (1.0 - nu * nu))


def contact_time(rp: float, rho: float, E: float, nu: float, U0: float) -> float:
    """Hertz collision time of two like spheres at relative speed U0 (doc/theory.md, eq. (1.10)):
    t_c = 2.87 (m*^2 / (R E*^2 v))^(1/5), R = r_p/2, m* = m/2."""
    m = 4.0 / 3.0 * math.pi * rp ** 3 * rho
    return 2.87 * ((0.5 * m) ** 2 / (0.5 * rp * pair_modulus(E, nu) ** 2 * U0)) ** 0.2


def time_step(rp, rho, E, nu, U0, dt_div=20.0) -> float:
    """The decks' rule: dt = t_c / dt_div (default 20)."""
    return contact_time(rp, rho, E, nu, U0) / dt_div


def jkr_scales(R: float, Estar: float, gamma: float) -> dict:
    """F_C = 3 pi gamma R, a_0 = (9 pi gamma R^2 / E*)^(1/3), delta_C = a_0^2 / (2 6^(1/3) R)."""
    FC = 3.0 * math.pi * gamma * R
    a0 = (9.0 * math.pi * gamma * R * R / Estar) ** (1.0 / 3.0)
    dC = a0 * a0 / (2.0 * 6.0 ** (1.0 / 3.0) * R)
    return {"FC": FC, "a0": a0, "deltaC": dC}


def jkr_force_of_overlap(delta, R, Estar, gamma):
    """Elastic-adhesive normal force F_ne(delta) (> 0 repulsive) on the attached JKR branch,
    from F/F_C = 4 (a^3 - a^1.5) and delta/delta_C = 6^(1/3) (2 a^2 - 4/3 a^0.5) (doc/theory.md, eq. (1.4)
    sec. 1; the squared form, not the paper's typo). Valid for -delta_C <= delta; vectorised."""
    import numpy as np
    s = jkr_scales(R, Estar, gamma)
    d = np.atleast_1d(np.asarray(delta, dtype=float)) / s["deltaC"]
    a_min = 6.0 ** (-2.0 / 3.0)   # separation point: delta = -delta_C
    out = np.empty_like(d)
    for k, dk in enumerate(d):
        # delta(a) is increasing for a >= a_min: bisection on the attached branch
        lo, hi = a_min, max(2.0, (abs(dk) + 2.0) ** 0.5)
        f = lambda a: 6.0 ** (1.0 / 3.0) * (2.0 * a * a - 4.0 / 3.0 * math.sqrt(a)) - dk
        if f(lo) > 1e-9:
            out[k] = math.nan
            continue
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if f(mid) > 0:
                hi = mid
            else:
                lo = mid
        a = 0.5 * (lo + hi)
        out[k] = 4.0 * (a ** 3 - a ** 1.5)
    return out * s["FC"]


def dimensionless(gamma, rho, U0, rp, q_e0, K_eff=K_EFF) -> dict:
    """The paper's Sec. 4.2 groups.

    Ad = gamma / (rho U0^2 r_p)                              (dimensionless: J/m^2 / (kg/m^3 m^2/s^2 m))
    E* = K_eff q^2 / (eps0 U0^2 r_p^4 rho)                   (C^2 / (F/m m^2/s^2 m^4 kg/m^3) = 1)
    U_eff^2 = U0^2 (1 - E*),  Ad* = gamma / (rho U_eff^2 r_p)  (Eqs. 7-8)

    Units check: q = 400 e_0, r_p = 2 um, U0 = 1 m/s, rho = 2500 gives E* = 0.59 < 1 and
    E* = 1 at q ~ 520 e_0, as doc/theory.md, eq. (2.2) implies. Ad* is infinite (returned as inf) when
    E* >= 1 (injected particles cannot reach the bed).
    """
    q = q_e0 * E0
    Ad = gamma / (rho * U0 ** 2 * rp)
    Estar = K_eff * q * q / (EPS0 * U0 ** 2 * rp ** 4 * rho)
    Ueff2 = U0 ** 2 * (1.0 - Estar)
    Adstar = gamma / (rho * Ueff2 * rp) if Ueff2 > 0 else math.inf
    return {"Ad": Ad, "Estar": Estar, "Adstar": Adstar, "Ueff": math.sqrt(max(Ueff2, 0.0))}


def coulomb_to_adhesion(gamma, rp, q_e0) -> float:
    """F_C / F_E with F_C = 3 pi gamma R (R = r_p/2) and F_E = q^2 / (4 pi eps0 (2 r_p)^2)
    (two touching charged spheres). The paper quotes ~1e4 for its Table 2."""
    q = q_e0 * E0
    FC = 3.0 * math.pi * gamma * rp / 2.0
    FE = q * q / (4.0 * math.pi * EPS0 * (2.0 * rp) ** 2)
    return FC / FE if FE > 0 else math.inf
