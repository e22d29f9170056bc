"""The rules of in.deposition's inputs, stated once: checked by Python before LAMMPS starts, and
generated into the deck's checking block (the deck refuses the same values when run by hand).

Each rule names a deck variable, a test and what the variable must be. Tests are written in
LAMMPS's own formula syntax (equal-style, ``v_NAME`` for a variable's value); a rule's gate, when
it has one, in the syntax of LAMMPS's ``if`` command (``${NAME}`` a number, ``x${NAME} == xword``
a word); ``@`` in a test or a message stands for the rule's own variable. Python evaluates
both by translating them (``_py_formula``, ``_py_gate``); the deck gets them as they are
(``deck_block``). The rules of species s > 1 are those of species 1 with the suffix _s.

A failed rule is one line, ``NAME = VALUE: what it must be``; the deck prints it as
``GC ERROR: NAME = VALUE: ...`` and quits with status 1. A word where a number belongs stops the
deck at the first formula that reads it, with LAMMPS's own one-line error naming the variable
(``ERROR: Variable NAME: Non-numeric variable value in variable formula``): LAMMPS's input
language cannot test whether a word is a number without that error.

Plausibility rules (``plausible=True``) refuse values outside the range any powder has (a
radius above 1 mm, a modulus below 0.1 MPa, ...), naming the likely unit mistake; the deck
variable ``exotic yes`` (``--var exotic yes``, ``exotic = "yes"`` in a study file's [deck])
lets such a value through.

params.check_deck_values raises the first failed rule as a ParamError.

The deck's sleep auto decides from its inputs too: ``sleep_auto`` gives its choice as Python
makes it (the deck makes it in its own section, in LAMMPS's formulas).

``python -m granular_charged.rules --write`` writes the block into the packaged deck;
``--check`` exits 1 when the deck's block differs from the table (python/tests/test_rules.py
checks the same).
"""
from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

SPECIES = (1, 2, 3)
MAX_RADII = 6
MIN_LOGNORMAL_MASS = 1e-3   # a lognormal's probability inside rp_lo .. rp_hi, at least
MAX_REDRAWS = 20000         # the deck's bound on the redraws of one particle's radius
E0 = 1.602176634e-19
MAX_SIGMA = 1e-2            # |surface charge density| [C/m^2]: a surface field of ~1e9 V/m
MIN_STEPS_OF_FLIGHT = 100   # the time step is at most this fraction of the fall from H
MAX_CONTACT_POTENTIAL = 10.0  # |contact potential| [V]: work functions differ by a few V at most
TRIBO_Z0 = (1e-11, 1e-6)    # the cut-off gap z0 [m]: from a tenth of an atom's size to 1 um


def suffix(s: int) -> str:
    return "" if s == 1 else f"_{s}"


@dataclass(frozen=True)
class Rule:
    """name: the deck variable; kind: number | word | list | derived;
    test: a formula that is nonzero when the value is fine (number, derived: the value), the
    allowed words (word), or the test of each item (list: v_ITEM); must: the message after
    'NAME = VALUE: ' (${NAME} and $(FORMULA:%.3g) are filled in); when: an if-boolean gate;
    plausible: skipped with exotic yes; list rules: n (smallest, largest number of items),
    zero_default (the single word 0 means 'not given'), same_len (another list variable)."""
    name: str
    kind: str
    test: object = "1"
    must: str = ""
    when: str = ""
    plausible: bool = False
    n: tuple = (1, MAX_RADII)
    zero_default: bool = False
    same_len: str = ""


def N(name, test, must, raw=False, **kw):
    """A number rule; its message is 'must be ' + must, unless plausible or raw (said as is)."""
    if not (raw or kw.get("plausible")):
        must = "must be " + must
    return Rule(name, "number", test, must, **kw)


def W(name, words, **kw):
    return Rule(name, "word", tuple(words), "must be one of " + ", ".join(words), **kw)


def D(name, formula):
    return Rule(name, "derived", formula)


WHOLE = "floor(v_@) == v_@"
YESNO = ("yes", "no")
LOGN = "x${{r_dist{s}}} == xlognormal"
DISC = "x${{r_dist{s}}} == xdiscrete"
# the contact time of species 1 (the deck's t_c, doc/theory.md eq. (1.10)) and its time step
TC = ("2.87*((0.5*4.0/3.0*PI*v_rp^3*v_rho)^2/(0.5*v_rp*(v_E/(2.0*(1.0-v_nu^2)))^2*v_U0))^0.2")
# the normal CDF Phi(z) = (1 + sign(z) erf(|z|/sqrt 2)) / 2, erf by Abramowitz & Stegun 7.1.26
# (|error| < 1.5e-7; LAMMPS's formulas have no erf)
ERF_T = "1.0/(1.0+0.3275911*abs(v_{z})/sqrt(2.0))"
ERF = ("1.0-v_{t}*(0.254829592+v_{t}*(-0.284496736+v_{t}*(1.421413741+v_{t}*(-1.453152027"
       "+v_{t}*1.061405429))))*exp(0.0-v_{z}*v_{z}/2.0)")
PHI = "0.5*(1.0+((v_{z}>0)-(v_{z}<0))*({erf}))"


def _phi(z: str, t: str) -> str:
    return PHI.format(z=z, erf=ERF.format(z=z, t=t))


def _radius_rules(name: str, gate: str = "") -> list:
    """Plausibility of a radius variable (a number; 0 is left to the other rules)."""
    return [
        N(name, "v_@ <= 1e-3",
          "a radius of ${@} m, above 1 mm; radii are in metres ($(v_@*1e-6:%.3g) for "
          "${@} um)", plausible=True, when=gate),
        N(name, "v_@ == 0 || v_@ >= 1e-8",
          "a radius of ${@} m, below 10 nm; radii are in metres (2e-6 for 2 um)",
          plausible=True, when=gate)]


def _charge_rule(name: str, radius: str, when: str = "") -> list:
    """A charge in e_0 on a sphere of radius `radius`: its surface density at most MAX_SIGMA,
    and not a fraction of e_0 (a charge in coulombs)."""
    return [
        N(name, "v_@ == 0 || abs(v_@) >= 0.5",
          "a charge of ${@} e0, a fraction of an elementary charge; charges are in "
          "elementary charges e0 ($(v_@/1.602176634e-19:%.3g) for ${@} C)",
          plausible=True, when=when),
        N(name, f"abs(v_@)*{E0}/(4.0*PI*v_{radius}^2) <= {MAX_SIGMA}",
          f"a charge of ${{@}} e0 on a radius of ${{{radius}}} m is "
          f"$(abs(v_@)*{E0}/(4.0*PI*v_{radius}^2):%.3g) C/m^2, above {MAX_SIGMA} C/m^2 "
          "(a surface field of 1e9 V/m); charges are in elementary charges e0",
          plausible=True, when=when)]


def _potential_rules(name: str, what: str, gate: str = "") -> list:
    """A contact potential (work function / e) [V]: a number, and at most a few volts (a value
    in mV given as volts is refused, with the volts it probably meant)."""
    return [
        N(name, "v_@ == v_@", f"a number [V] ({what})", when=gate),
        N(name, f"abs(v_@) <= {MAX_CONTACT_POTENTIAL:g}",
          f"a contact potential of ${{@}} V, above {MAX_CONTACT_POTENTIAL:g} V; contact "
          "potentials are volts, a few V at most ($(v_@/1000:%.3g) for ${@} mV)",
          plausible=True, when=gate)]


def _table() -> list:
    R = []
    sp = "${{species}} >= {n}"
    # ---- the run -------------------------------------------------------------------------
    R += [N("species", WHOLE + " && v_@ >= 1 && v_@ <= 3", "1, 2 or 3 (species)"),
          N("N", WHOLE + " && v_@ >= 1", "a whole number >= 1 (particles)"),
          N("seed", WHOLE + " && v_@ >= 1 && v_@ <= 900000000",
            "a whole number 1 .. 900000000 (the random seeds of LAMMPS)"),
          W("exotic", YESNO),
          W("inject", ("auto", "rain", "plane", "sequential")),
          W("farfield", ("exact", "average", "none")),
          W("coul_extrapolate", YESNO), W("coul_solver", ("replicated", "distributed")),
          W("electrode", YESNO), W("sleep", ("yes", "no", "auto")), W("sleep_bury", YESNO), W("split_log", YESNO), W("resume", YESNO), W("pair_opt", YESNO),
          W("damping_model", ("marshall", "marshall/printed")),
          W("rolling_model", ("marshall", "marshall/particle")),
          N("U0", "v_@ > 0", "finite and > 0 [m/s] (the time step and the injection interval divide by it)"),
          N("U0", "v_@ <= 100", "a speed of ${U0} m/s, above 100 m/s; speeds are in m/s "
            "($(v_U0/100:%.3g) for ${U0} cm/s)", plausible=True),
          N("U0", "v_@ >= 1e-3", "a speed of ${U0} m/s, below 1 mm/s; speeds are in m/s",
            plausible=True),
          N("theta_crit", "v_@ > 0", "> 0 [rad] (the critical rolling angle)"),
          N("g", "v_@ == v_@", "a number [m/s^2]"),
          N("accuracy", "v_@ > 0 && v_@ < 1", "a relative accuracy between 0 and 1"),
          N("coul_every", WHOLE + " && v_@ >= 1", "a whole number of steps >= 1"),
          N("coul_near", "v_@ >= 0", ">= 0 [r_p]"),
          N("coul_tol", "v_@ >= 0", ">= 0 (0: a fixed interval)"),
          N("coul_check", WHOLE + " && v_@ >= 0", "a whole number of steps >= 0 (0: off)"),
          N("E0", "v_@ == v_@", "a field [V/m]"),
          N("eps_p", "v_@ == 0 || v_@ >= 1",
            "0 (not polarisable) or a relative permittivity >= 1"),
          N("L_rp", "v_@ > 2", "> 2 (the box side in r_p holds the diameter of a particle)"),
          N("H_rp", "v_@ > 0", "> 0 (the injection height in r_p)"),
          N("gap_rp", "v_@ >= 0", ">= 0 (0: the interval of the deck)"),
          N("seq_dz_L", "v_@ >= 0", ">= 0 (0: the start height of the deck)"),
          N("seq_gap_rp", "v_@ >= 0", ">= 0 (0: the interval of the deck)"),
          N("dt_div", "v_@ > 0", "> 0 (the time step is t_c / dt_div)"),
          N("ke_stop", "v_@ >= 0", ">= 0 (0: settle for settle_max)"),
          N("settle_max", "v_@ >= 0", ">= 0 [r_p / U_0]"),
          N("zlo_rp", "v_@ >= 0", ">= 0 [r_p]"),
          N("top_rp", "v_@ == v_@", "a number [r_p]"),
          N("tracer", WHOLE + " && v_@ >= 0 && v_@ <= v_N",
            "a particle id 1 .. N = ${N} (0: none)"),
          N("trace_every", WHOLE + " && v_@ >= 1", "a whole number of steps >= 1"),
          N("dump_every", WHOLE + " && v_@ >= 0", "a whole number of steps >= 0 (0: none)"),
          N("sleep_speed", "v_@ >= 0", ">= 0 [U_0]"),
          N("sleep_force", "v_@ >= 0", ">= 0 [F_C]"),
          N("sleep_wake", "v_@ >= 0", ">= 0 [F_C]"),
          N("sleep_time", "v_@ >= 0", ">= 0 [r_p / U_0] (0: no rest rule)"),
          N("sleep_every", WHOLE + " && v_@ >= 1", "a whole number of steps >= 1"),
          N("sleep_relax", "v_@ >= 0", ">= 0 [r_p / U_0]"),
          N("sleep_depth", "v_@ >= 0", ">= 0 [r_p] (0: off)"),
          N("sleep_depth", "v_@ > 0", "> 0 [r_p] with sleep auto (its threshold is "
            "sleep_auto sleep_depth)", when="x${sleep} == xauto"),
          N("sleep_auto", "v_@ > 0", "> 0 (sleep auto: sleeping when the bed is expected to "
            "be taller than this many sleep_depth)"),
          N("checkpoint", WHOLE + " && v_@ >= 0",
            "a whole number of particles >= 0 (0: no restart points)"),
          N("checkpoint_stop", WHOLE + " && v_@ >= 0", "a whole number of particles >= 0"),
          N("computes", "v_@ == 0 || v_@ == 1", "0 or 1"),
          N("progress", WHOLE + " && v_@ >= 0", "a whole number of particles >= 0 (0: N/50)"),
          W("tribo", YESNO), W("tribo_field", YESNO),
          N("tribo_z0", "v_@ > 0", "> 0 [m] (the cut-off gap of the condenser model)"),
          N("tribo_z0", f"v_@ <= {TRIBO_Z0[1]:g}",
            "a cut-off gap of ${@} m, above 1 um; z0 is in metres ($(v_@*1e-10:%.3g) for "
            "${@} Angstrom, $(v_@*1e-9:%.3g) for ${@} nm)", plausible=True),
          N("tribo_z0", f"v_@ >= {TRIBO_Z0[0]:g}",
            "a cut-off gap of ${@} m, below 0.1 Angstrom (z0 is a gap of a few atoms, "
            "4e-10 m); z0 is in metres", plausible=True)]
    R += _potential_rules("tribo_V_wall", "the contact potential of the floor")
    # ---- each species: fraction, material, size and charge rules --------------------------
    for s in SPECIES:
        x = suffix(s)
        gate = sp.format(n=s) if s > 1 else ""

        def g(extra=""):
            return " && ".join(c for c in (gate, extra) if c)

        R += [N(f"frac{x}", "v_@ >= 0", ">= 0 (a number fraction, normalised over the species)",
                when=gate),
              W(f"r_dist{x}", ("one", "uniform", "lognormal", "discrete"), when=gate),
              W(f"q_dist{x}", ("fixed", "area", "gauss", "bipolar"), when=gate),
              N(f"rho{x}", "v_@ > 0", "> 0 [kg/m^3]", when=gate),
              N(f"rho{x}", "v_@ >= 50",
                f"a density of ${{rho{x}}} kg/m^3, below 50 kg/m^3; densities are in kg/m^3 "
                f"($(v_rho{x}*1000:%.3g) for ${{rho{x}}} g/cm^3)", plausible=True, when=gate),
              N(f"rho{x}", "v_@ <= 25000",
                f"a density of ${{rho{x}}} kg/m^3, above that of any solid (osmium: 22600 kg/m^3)",
                plausible=True, when=gate),
              N(f"E{x}", "v_@ > 0", "> 0 [Pa]", when=gate),
              N(f"E{x}", "v_@ >= 1e5",
                f"a Young modulus of ${{E{x}}} Pa, below 0.1 MPa; moduli are in Pa "
                f"($(v_E{x}*1e9:%.3g) for ${{E{x}}} GPa, $(v_E{x}*1e6:%.3g) for ${{E{x}}} MPa)",
                plausible=True, when=gate),
              N(f"E{x}", "v_@ <= 2e12",
                f"a Young modulus of ${{E{x}}} Pa, stiffer than diamond (1.2e12 Pa); moduli "
                "are in Pa", plausible=True, when=gate),
              N(f"nu{x}", "v_@ > -1 && v_@ < 0.5", "between -1 and 0.5 (a Poisson ratio)",
                when=gate),
              N(f"gamma{x}", "v_@ >= 0", ">= 0 [J/m^2]", when=gate),
              N(f"gamma{x}", "v_@ <= 5",
                f"a surface energy of ${{gamma{x}}} J/m^2, above 5 J/m^2; surface energies are "
                f"in J/m^2 ($(v_gamma{x}/1000:%.3g) for ${{gamma{x}}} mJ/m^2)",
                plausible=True, when=gate),
              N(f"e{x}", "v_@ > 0 && v_@ <= 1", "in (0, 1] (a restitution coefficient)",
                when=gate),
              N(f"mu{x}", "v_@ >= 0", ">= 0 (a friction coefficient)", when=gate),
              N(f"rp{x}", "v_@ > 0", "> 0 [m]", when=gate)]
        R += _radius_rules(f"rp{x}", gate)
        R += [N(f"rp_lo{x}", "v_@ >= 0", ">= 0 [m]", when=gate),
              N(f"rp_hi{x}", "v_@ >= 0", ">= 0 [m]", when=gate)]
        R += _radius_rules(f"rp_lo{x}", gate) + _radius_rules(f"rp_hi{x}", gate)
        uni = g(f"x${{r_dist{x}}} == xuniform")
        logn = g(LOGN.format(s=x))
        disc = g(DISC.format(s=x))
        notdisc = g(f"x${{r_dist{x}}} != xdiscrete")
        R += [N(f"rp_lo{x}", "v_@ > 0",
                "> 0 [m]: r_dist uniform draws between rp_lo and rp_hi".replace(
                    "rp_lo", f"rp_lo{x}").replace("rp_hi", f"rp_hi{x}").replace(
                    "r_dist", f"r_dist{x}"), when=uni),
              N(f"rp_hi{x}", f"v_@ > v_rp_lo{x}",
                f"> rp_lo{x} = ${{rp_lo{x}}} [m] (r_dist{x} uniform draws between them)",
                when=uni),
              N(f"rp_gsd{x}", "v_@ > 1",
                f"> 1 (the geometric standard deviation of r_dist{x} lognormal)", when=logn),
              D(f"gc_lo{x}", f"ternary(v_rp_lo{x} > 0, v_rp_lo{x}, v_rp{x}/v_rp_gsd{x}^3)"),
              D(f"gc_hi{x}", f"ternary(v_rp_hi{x} > 0, v_rp_hi{x}, v_rp{x}*v_rp_gsd{x}^3)"),
              N(f"rp_lo{x}", f"v_gc_lo{x} < v_rp{x}",
                f"the clip range of the lognormal starts at $(v_gc_lo{x}:%.3g) m, not below its "
                f"median rp{x} = ${{rp{x}}} m", raw=True, when=logn),
              N(f"rp_hi{x}", f"v_gc_hi{x} > v_rp{x}",
                f"the clip range of the lognormal ends at $(v_gc_hi{x}:%.3g) m, not above its "
                f"median rp{x} = ${{rp{x}}} m", raw=True, when=logn),
              D(f"gc_za{x}", f"ln(v_gc_lo{x}/v_rp{x})/ln(v_rp_gsd{x})"),
              D(f"gc_zb{x}", f"ln(v_gc_hi{x}/v_rp{x})/ln(v_rp_gsd{x})"),
              D(f"gc_ta{x}", ERF_T.format(z=f"gc_za{x}")),
              D(f"gc_tb{x}", ERF_T.format(z=f"gc_zb{x}")),
              D(f"gc_mass{x}", f"({_phi(f'gc_zb{x}', f'gc_tb{x}')})-"
                               f"({_phi(f'gc_za{x}', f'gc_ta{x}')})"),
              # the clipped lognormal's mean r^3 [m^3] (sleep auto's bed height):
              # rp^3 exp(9 s^2 / 2) (Phi(zb - 3 s) - Phi(za - 3 s)) / mass, s = ln rp_gsd
              D(f"gc_za3{x}", f"v_gc_za{x}-3.0*ln(v_rp_gsd{x})"),
              D(f"gc_zb3{x}", f"v_gc_zb{x}-3.0*ln(v_rp_gsd{x})"),
              D(f"gc_ta3{x}", ERF_T.format(z=f"gc_za3{x}")),
              D(f"gc_tb3{x}", ERF_T.format(z=f"gc_zb3{x}")),
              D(f"gc_m3{x}", f"v_rp{x}^3*exp(4.5*ln(v_rp_gsd{x})^2)*(({_phi(f'gc_zb3{x}', f'gc_tb3{x}')})-"
                             f"({_phi(f'gc_za3{x}', f'gc_ta3{x}')}))/v_gc_mass{x}"),
              N(f"rp_gsd{x}", f"v_gc_mass{x} >= {MIN_LOGNORMAL_MASS}",
                f"the lognormal (median ${{rp{x}}} m) has $(v_gc_mass{x}:%.3g) of its particles "
                f"in rp_lo{x} .. rp_hi{x} = $(v_gc_lo{x}:%.3g) .. $(v_gc_hi{x}:%.3g) m, less "
                f"than {MIN_LOGNORMAL_MASS:g}: a range it cannot reach (move the range to the "
                "median, or widen rp_gsd)", raw=True, when=logn),
              Rule(f"radii{x}", "list", "v_@ > 0",
                   f"r_dist{x} discrete needs 1 to {MAX_RADII} radii > 0 [m] as one word list", when=disc),
              Rule(f"radii{x}", "list", "v_@ <= 1e-3 && v_@ >= 1e-8",
                   "a radius outside 10 nm .. 1 mm; radii are in metres (2e-6 for 2 um)",
                   when=disc, plausible=True),
              Rule(f"rfrac{x}", "list", "v_@ > 0",
                   f"must be 0 (equal fractions) or one number fraction > 0 per radius of radii{x} = "
                   f"${{radii{x}}}", when=disc, zero_default=True, same_len=f"radii{x}"),
              Rule(f"radii{x}", "list", "v_@ == 0",
                   f"must be 0: radii are read with r_dist{x} discrete only (r_dist{x} = "
                   f"${{r_dist{x}}})", when=notdisc, n=(1, 1)),
              Rule(f"rfrac{x}", "list", "v_@ == 0",
                   f"must be 0: number fractions are read with r_dist{x} discrete only (r_dist{x} = "
                   f"${{r_dist{x}}})", when=notdisc, n=(1, 1)),
              N(f"q{x}", "v_@ == v_@", "a number [e0]", when=gate),
              N(f"q_sigma{x}", "v_@ == v_@", "a number [C/m^2]", when=gate),
              N(f"q_sd{x}", "v_@ >= 0", ">= 0 [e0] (a standard deviation)", when=gate),
              N(f"q_pos{x}", "v_@ >= 0 && v_@ <= 1",
                "a fraction in [0, 1] (of the positive particles)", when=gate)]
        R += _charge_rule(f"q{x}", f"rp{x}", when=gate)
        R += _charge_rule(f"q_sd{x}", f"rp{x}", when=gate)
        R += _potential_rules(f"tribo_V{x}", f"the contact potential of species {s}", gate)
        R += [N(f"q_sigma{x}", f"abs(v_@) <= {MAX_SIGMA}",
                f"a surface charge density of ${{q_sigma{x}}} C/m^2, above {MAX_SIGMA} C/m^2 "
                f"(a surface field of 1e9 V/m); densities are in C/m^2 "
                f"($(v_q_sigma{x}*1e-6:%.3g) for ${{q_sigma{x}}} uC/m^2)",
                plausible=True, when=gate)]
    # ---- across variables ----------------------------------------------------------------
    R += [N("frac", "v_frac+(v_species>1)*v_frac_2+(v_species>2)*v_frac_3 > 0",
            "the number fractions of the species (frac, frac_2, frac_3) must sum to > 0",
            raw=True),
          N("checkpoint", "v_@ == 0",
            "must be 0: restart points are not available with a particle population (species, "
            "r_dist, q_dist)", raw=True,
            when="${species} != 1 || x${r_dist} != xone || x${q_dist} != xfixed"),
          N("resume", "0", "must be no: restart points are not available with a particle population "
            "(species, r_dist, q_dist)", raw=True,
            when="x${resume} == xyes && (${species} != 1 || x${r_dist} != xone || "
                 "x${q_dist} != xfixed)"),
          N("dt_div", f"v_H_rp*v_rp/v_U0 >= {MIN_STEPS_OF_FLIGHT}*({TC})/v_dt_div",
            f"the time step t_c/dt_div = $(({TC})/v_dt_div:%.3g) s is not much smaller than "
            "the fall from H, $(v_H_rp*v_rp/v_U0:%.3g) s (fewer than "
            f"{MIN_STEPS_OF_FLIGHT} steps); check the units of rp, rho, E, U0", plausible=True)]
    return R


RULES = _table()


# ---- Python: evaluating the rules ---------------------------------------------------------

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\d*\.?\d+)([eE][+-]?\d+)?$")   # LAMMPS's is_double


class _NotNumber(Exception):
    def __init__(self, name):
        self.name = name


def _expand(text: str, rule_name: str) -> str:
    return text.replace("v_@", f"v_{rule_name}").replace("${@}", "${" + rule_name + "}") \
        .replace("@", rule_name)


def _py_formula(f: str) -> str:
    f = re.sub(r"\bv_(\w+)", r"V('\1')", f)
    f = f.replace("&&", " and ").replace("||", " or ")
    f = re.sub(r"!(?!=)", " not ", f)
    f = f.replace("^", "**")
    return re.sub(r"\bPI\b", "pi", f)


def _py_gate(f: str) -> str:
    f = re.sub(r"x\$\{(\w+)\}", r"S('\1')", f)
    f = re.sub(r"\$\{(\w+)\}", r"V('\1')", f)
    f = re.sub(r"(?<![\w'])x([\w/]+)", r"'x\1'", f)
    f = f.replace("&&", " and ").replace("||", " or ")
    return re.sub(r"!(?!=)", " not ", f)


def _ternary(c, a, b):
    return a if c else b


_FUNCS = {"ln": math.log, "exp": math.exp, "sqrt": math.sqrt, "abs": abs, "floor": math.floor,
          "ternary": _ternary, "pi": math.pi}


class Values:
    """The deck's variables as it resolves them: the given ones over the deck's defaults
    (${NAME} in a default is the value of NAME), derived ones computed on demand."""

    def __init__(self, given: dict, defaults: dict):
        self.text = {k: str(v).strip() for k, v in defaults.items()}
        self.text.update({k: str(v).strip() for k, v in given.items()})
        for k, v in list(self.text.items()):
            for _ in range(5):
                m = re.fullmatch(r"\$\{(\w+)\}", v)
                if not m:
                    break
                v = self.text.get(m.group(1), v)
            self.text[k] = v
        self.derived = {r.name: r.test for r in RULES if r.kind == "derived"}
        self.cache = {}

    def word(self, name):
        return "x" + self.text.get(name, "")

    def number(self, name):
        if name in self.cache:
            return self.cache[name]
        if name in self.derived:
            v = evaluate(self.derived[name], self)
        else:
            t = self.text.get(name)
            if t is None or not _NUMBER.match(t):
                raise _NotNumber(name)
            v = float(t)
            if not math.isfinite(v):
                raise _NotNumber(name)
        self.cache[name] = v
        return v


@lru_cache(maxsize=None)
def _compiled(text: str, gate: bool):
    return compile(_py_gate(text) if gate else _py_formula(text), "<rule>", "eval")


def evaluate(formula: str, vals: Values, item: tuple = ()) -> float:
    """A formula's value; item (NAME, value): NAME reads value (a list's item)."""
    def V(name):
        return item[1] if item and name == item[0] else vals.number(name)
    return eval(_compiled(formula, False), {"__builtins__": {}, "V": V, **_FUNCS})


def gate_open(gate: str, vals: Values) -> bool:
    return bool(eval(_compiled(gate, True), {"__builtins__": {}, "V": vals.number, "S": vals.word}))


def _message(rule_name: str, template: str, vals: Values, item=None) -> str:
    def fill(m):
        if m.group(1) is not None:
            return vals.text.get(m.group(1), "")
        try:
            v = evaluate(m.group(2), vals)
        except (_NotNumber, ArithmeticError, ValueError, TypeError):
            return "?"
        return m.group(3) % v if isinstance(v, (int, float)) else "?"
    text = re.sub(r"\$\{(\w+)\}|\$\((.+?):(%[.\w]+)\)", fill, _expand(template, rule_name))
    return f"{rule_name} = {vals.text.get(rule_name, '')}: {text}"


def _not_number(name: str, vals: Values) -> str:
    what = next((r.must for r in _rules_of(name) if r.kind == "number"
                 and r.must.startswith("must be ")), "must be a number")
    return f"{name} = {vals.text.get(name, '')}: not a number; {_expand(what, name)}"


def _rules_of(name):
    return (r for r in RULES if r.name == name)


def _list(text: str):
    return str(text).split()


def _check_list(rule: Rule, vals: Values):
    words = _list(vals.text.get(rule.name, "0"))
    bad = [w for w in words if not _NUMBER.match(w) or not math.isfinite(float(w))]
    if bad:
        return (f"{rule.name} = {vals.text.get(rule.name, '')}: {bad[0]} is not a number; "
                + _message(rule.name, rule.must, vals).split(": ", 1)[1])
    nums = [float(w) for w in words]
    if rule.zero_default and nums == [0.0]:
        return None
    n_ok = rule.n[0] <= len(nums) <= rule.n[1]
    if rule.same_len:
        n_ok = len(nums) == len(_list(vals.text.get(rule.same_len, "0")))
    test = _expand(rule.test, rule.name)
    if n_ok and all(evaluate(test, vals, (rule.name, x)) for x in nums):
        return None
    return _message(rule.name, rule.must, vals)


def problems(given: dict, defaults: dict | None = None, plausible: bool = True,
             first: bool = True) -> list[str]:
    """The failed rules (one line each; the first only, if first) of a run's deck variables
    `given` over the deck's `defaults` (deckfile.deck_variables when None); plausible False
    skips the plausibility rules (exotic yes does too)."""
    if defaults is None:
        from .run.deckfile import deck_variables
        defaults = deck_variables("in.deposition")
    vals = Values(given, defaults)
    out = []
    exotic = vals.text.get("exotic") == "yes"
    for rule in RULES:
        if rule.kind == "derived" or (rule.plausible and (exotic or not plausible)):
            continue
        try:
            if rule.when and not gate_open(rule.when, vals):
                continue
            if rule.kind == "word":
                if vals.text.get(rule.name) not in rule.test:
                    msg = f"{rule.name} = {vals.text.get(rule.name, '')}: {rule.must}"
                else:
                    continue
            elif rule.kind == "list":
                msg = _check_list(rule, vals)
                if msg is None:
                    continue
            else:
                try:
                    fine = evaluate(_expand(rule.test, rule.name), vals)
                except (ArithmeticError, ValueError, TypeError):
                    fine = False    # NaN in LAMMPS: every comparison with it is false
                if fine:
                    continue
                msg = _message(rule.name, rule.must, vals)
        except _NotNumber as e:
            msg = _not_number(e.name, vals)
        if msg not in out:
            out.append(msg)
        if first:
            break
    return out


def lognormal_mass(median: float, gsd: float, lo: float, hi: float) -> float:
    """The probability of a lognormal (median, gsd) inside lo .. hi, as the rules compute it."""
    vals = Values({"rp": median, "rp_gsd": gsd, "rp_lo": lo, "rp_hi": hi}, {})
    return vals.number("gc_mass")


def lognormal_mean_r3(median: float, gsd: float, lo: float, hi: float) -> float:
    """The mean r^3 [m^3] of a lognormal (median, gsd) clipped to lo .. hi (0: the deck's
    default clip), as the deck computes it for sleep auto (the derived variable gc_m3)."""
    vals = Values({"rp": median, "rp_gsd": gsd, "rp_lo": lo, "rp_hi": hi}, {})
    return vals.number("gc_m3")


# ---- sleep auto: the deck's choice of sleeping ---------------------------------------------
# The deck's section "sleeping particles: the choice of sleep auto" states the same rule in
# LAMMPS's formulas; python/tests/test_sleep_auto.py checks the two against each other.

# the packing fraction of the expected bed height: random close packing of equal spheres, denser
# than any bed the deck deposits (measured 0.20-0.50: doc/reproduction.md, doc/deposition.md), so
# the height is at most the bed's real one and sleep auto errs toward sleeping off
SLEEP_AUTO_PHI = 0.64


def mean_r3(vals: Values, s: int) -> float:
    """The mean r^3 [m^3] of species s's radii as the deck draws them: r_dist one rp^3; uniform
    (in r) (hi^4 - lo^4) / (4 (hi - lo)); lognormal clipped to its range (gc_m3, the deck's
    formula); discrete the mean of the radii's cubes weighted by rfrac (0: equal)."""
    x = suffix(s)
    d = vals.text.get(f"r_dist{x}", "one")
    if d == "uniform":
        lo, hi = vals.number(f"rp_lo{x}"), vals.number(f"rp_hi{x}")
        return (hi ** 4 - lo ** 4) / (4.0 * (hi - lo))
    if d == "lognormal":
        return vals.number(f"gc_m3{x}")
    if d == "discrete":
        radii = [float(w) for w in _list(vals.text.get(f"radii{x}", "0"))]
        w = [float(f) for f in _list(vals.text.get(f"rfrac{x}", "0"))]
        if w == [0.0]:
            w = [1.0] * len(radii)
        return sum(r ** 3 * f for r, f in zip(radii, w)) / sum(w)
    return vals.number(f"rp{x}") ** 3


def sleep_auto(given: dict, defaults: dict | None = None) -> dict:
    """The deck's sleep rule for a run's deck variables `given` (over the deck's `defaults`,
    deckfile.deck_variables when None): {'sleep': yes or no, the setting the run uses;
    'height_rp': the bed's expected height N <4/3 pi r^3> / (SLEEP_AUTO_PHI L^2) in r_p, <r^3>
    over the species weighted by their number fractions; 'threshold_rp': sleep_auto
    sleep_depth; 'epd': whether E0, eps_p or electrode is set}. sleep yes and no are
    themselves; auto is yes when the height exceeds the threshold and no EPD keyword is set
    (fix coul/fmm would need sleepers full with them, whose packing has not been measured).
    The values must pass the input rules (problems)."""
    if defaults is None:
        from .run.deckfile import deck_variables
        defaults = deck_variables("in.deposition")
    vals = Values(given, defaults)
    n = int(vals.number("species"))
    frac = [vals.number(f"frac{suffix(s)}") if s <= n else 0.0 for s in SPECIES]
    m3 = sum(f * mean_r3(vals, s) for f, s in zip(frac, SPECIES) if f > 0) / sum(frac)
    rp, L = vals.number("rp"), vals.number("L_rp") * vals.number("rp")
    height = vals.number("N") * 4.0 / 3.0 * math.pi * m3 / (SLEEP_AUTO_PHI * L * L) / rp
    threshold = vals.number("sleep_auto") * vals.number("sleep_depth")
    epd = (vals.number("E0") != 0 or vals.number("eps_p") > 0
           or vals.text["electrode"] == "yes")
    sleep = vals.text["sleep"]
    if sleep == "auto":
        sleep = "yes" if height > threshold and not epd else "no"
    return {"sleep": sleep, "height_rp": height, "threshold_rp": threshold, "epd": epd}


# ---- the deck: the generated checking block -----------------------------------------------

BEGIN = "# ---------------- input rules (generated by python -m granular_charged.rules --write: edit"
END = "# ---------------- end of the generated input rules"


def _deck_message(rule: Rule, name: str) -> str:
    text = _expand(rule.must, name)
    return f"GC ERROR: {name} = ${{{name}}}: {text}"


def _deck_gate(rule: Rule) -> str:
    parts = []
    if rule.plausible:
        parts.append("x${exotic} != xyes")
    if rule.when:
        parts.append(f"({rule.when})")
    return " && ".join(parts)


def deck_block() -> str:
    """The deck's checking block, from RULES."""
    out = [BEGIN + " the table there, not here) --------",
           "# Every input is checked here before anything is set up: a value a rule refuses",
           "# stops the deck with 'GC ERROR: NAME = VALUE: what it must be' (doc/populations.md,",
           "# \"Input rules\"); exotic yes lets the plausibility rules' values through. A word",
           "# where a number belongs stops it at the first formula that reads it (LAMMPS's",
           "# error 'Variable NAME: Non-numeric variable value').",
           "# (the block is not echoed to the log)",
           "echo none",
           f"variable gc_max_redraws equal {MAX_REDRAWS}   # the bound on a lognormal's redraws"]
    for r in RULES:
        if r.kind == "derived":
            out.append(f"variable {r.name} equal {r.test}")
    k = 0
    for r in RULES:
        if r.kind == "derived":
            continue
        k += 1
        gate = _deck_gate(r)
        skip = f"gc_rule_{k}"
        fail = f"then \"print '{_deck_message(r, r.name)}'\" \"quit 1\""
        lines = []
        if r.kind == "word":
            cond = " && ".join(f"x${{{r.name}}} != x{w}" for w in r.test)
            lines.append(f"if \"{cond}\" {fail}")
        elif r.kind == "number":
            lines.append(f"if \"$({_expand(r.test, r.name)}) == 0\" {fail}")
        else:
            item = f"{r.name}_item"
            test = r.test.replace("v_@", f"v_{item}")
            lines += ["variable gc_n equal 0",
                      "variable gc_bad equal 0",
                      "variable gc_zero equal 0",
                      f"variable _gcw index ${{{r.name}}}",
                      f"label {skip}_loop",
                      f"  variable {item} string ${{_gcw}}",
                      "  variable gc_n equal $(v_gc_n+1)",
                      f"  variable gc_bad equal $(v_gc_bad+(({test})==0))",
                      f"  variable gc_zero equal $(v_{item}==0)",
                      "  next _gcw",
                      f"jump SELF {skip}_loop"]
            n_ok = f"${{gc_n}} >= {r.n[0]} && ${{gc_n}} <= {r.n[1]}"
            if r.same_len:
                lines += ["variable gc_m equal 0",
                          f"variable _gcw index ${{{r.same_len}}}",
                          f"label {skip}_count",
                          "  variable gc_m equal $(v_gc_m+1)",
                          "  next _gcw",
                          f"jump SELF {skip}_count"]
                n_ok = "${gc_n} == ${gc_m}"
            ok = f"(${{gc_bad}} == 0 && {n_ok})"
            if r.zero_default:
                ok = f"(${{gc_n}} == 1 && ${{gc_zero}} == 1) || {ok}"
            lines.append(f"if \"!({ok})\" {fail}")
        if gate:
            out.append(f"if \"!({gate})\" then \"jump SELF {skip}\"")
            out += lines
            out.append(f"label {skip}")
        else:
            out += lines
    out.append("echo log")
    out.append(END + " ------------------------------------------------")
    return "\n".join(out) + "\n"


def deck_files() -> list[Path]:
    here = Path(__file__).resolve().parent
    return [here / "decks" / "in.deposition"]


def deck_with_block(text: str) -> str:
    """The deck's text with its generated block replaced by deck_block()."""
    i = text.index(BEGIN)
    j = text.index(END)
    j = text.index("\n", j) + 1
    return text[:i] + deck_block() + text[j:]


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--write"]:
        for f in deck_files():
            f.write_text(deck_with_block(f.read_text()))
            print(f"wrote the input rules into {f}")
        return 0
    if argv[:1] == ["--check"]:
        bad = [f for f in deck_files() if deck_with_block(f.read_text()) != f.read_text()]
        for f in bad:
            print(f"{f}: the generated input rules differ from granular_charged/rules.py "
                  "(python -m granular_charged.rules --write)")
        return 1 if bad else 0
    print(deck_block(), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
