"""The input rules of in.deposition (granular_charged/rules.py): one table, checked by Python
before LAMMPS starts and by the deck's generated block when the deck runs by hand (the runs
through lmp: python/tests_powder/test_rules_deck.py).

Every rule of the table gets a case that breaks it and no other rule (found by a search over
candidate values, or given in EXAMPLES); each case is refused through the Python API (a
ParamError naming the variable) and through lmp (status 1, one error line, the same message, no
GC RESULT); a rule without a case fails test_every_rule_has_a_case. The deck's block must be
what the table generates (test_deck_block_is_generated_from_the_table)."""
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from granular_charged import rules
from granular_charged.params import DepositionParams, ParamError
from granular_charged.run import estimate, population
from lammps_runs import DECK, SRC
from rule_cases import CASES, FIELDS, RULES, _problems, rule_id

def test_every_rule_has_a_case():
    missing = [rule_id(r) for r in RULES if rule_id(r) not in CASES]
    assert not missing, f"rules without a case that breaks them (add one to EXAMPLES): {missing}"


@pytest.mark.parametrize("rid", sorted(CASES))
def test_rule_refused_by_python(rid):
    vals = CASES[rid]
    fields = {k: v for k, v in vals.items() if k in FIELDS}
    extra = {k: v for k, v in vals.items() if k not in FIELDS}
    with pytest.raises(ParamError) as e:
        DepositionParams(**fields, extra=extra)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{rid.split('#')[0]} = "), msg


# ---- the generated block ---------------------------------------------------------------------

def test_deck_block_is_generated_from_the_table():
    text = DECK.read_text()
    assert rules.deck_with_block(text) == text, \
        "the deck's input rules differ from rules.py: python -m granular_charged.rules --write"
    example = SRC / "examples" / "deposition" / "in.deposition"
    assert example.read_text() == text


def test_no_rule_message_breaks_the_decks_quoting():
    for r in rules.RULES:
        assert "'" not in r.must and '"' not in r.must, r


def test_a_rule_removed_from_the_deck_is_found(monkeypatch):
    text = DECK.read_text()
    line = next(ln for ln in text.splitlines() if "GC ERROR: q_pos = " in ln)
    assert rules.deck_with_block(text.replace(line + "\n", "")) != text.replace(line + "\n", "")


# ---- what the probes found -----------------------------------------------------------

@pytest.mark.parametrize("vals, words", [
    ({"r_dist": "discrete", "radii": "2e-6 0"}, "radii = 2e-6 0"),
    ({"r_dist": "discrete", "radii": "2e-6 4e-6", "rfrac": "1"}, "rfrac = 1"),
    ({"r_dist": "discrete", "radii": "2e-6 4e-6", "rfrac": "1 2 3"}, "rfrac = 1 2 3"),
    ({"species": "2", "frac_2": "-1"}, "frac_2 = -1"),
    ({"q_dist": "bipolar", "q": "100", "q_pos": "1.5"}, "q_pos = 1.5"),
    ({"q_dist": "gauss", "q": "100", "q_sd": "-5"}, "q_sd = -5"),
    ({"r_dist": "lognormal", "rp_lo": "8e-6", "rp_hi": "9e-6"}, "rp_lo = 8e-6"),
    ({"r_dist": "lognormal", "rp_gsd": "0.9"}, "rp_gsd = 0.9"),
    ({"species": "abc"}, "species = abc: not a number"),
    ({"q_sigma": "abc"}, "q_sigma = abc: not a number"),
    ({"rp": "4"}, "rp = 4: a radius of 4 m, above 1 mm; radii are in metres (4e-06 for 4 um)"),
    ({"E": "70"}, "7e+10 for 70 GPa"),
    ({"q": "1e-15"}, "6.24e+03 for 1e-15 C"),
    ({"rho": "2.5"}, "2.5e+03 for 2.5 g/cm^3"),
    ({"gamma": "10"}, "0.01 for 10 mJ/m^2"),
    ({"U0": "500"}, "5 for 500 cm/s"),
    ({"q_sigma": "5"}, "5e-06 for 5 uC/m^2"),
])
def test_probed_values_are_refused(vals, words):
    found = _problems(vals)
    assert found and words in found[0], found


def test_exotic_lets_the_plausibility_rules_pass():
    assert _problems({"rp": "4"})
    assert not _problems({"rp": "4", "exotic": "yes"})
    # not the other rules
    assert _problems({"rp": "-4", "exotic": "yes"})


def test_lognormal_mass_is_the_cdf():
    from scipy import stats
    for med, gsd, lo, hi in [(2e-6, 1.2, 0, 0), (2e-6, 1.5, 1.9e-6, 2.1e-6), (5e-6, 1.05, 4e-6, 5.1e-6),
                             (3e-6, 2.0, 1e-7, 3.01e-6)]:
        ln = stats.lognorm(s=math.log(gsd), scale=med)
        a = lo or med / gsd ** 3
        b = hi or med * gsd ** 3
        assert abs(rules.lognormal_mass(med, gsd, lo, hi) - (ln.cdf(b) - ln.cdf(a))) < 1e-6


# ---- the property test: random specifications ------------------------------------------------

def _random_size(rng):
    d = rng.choice(["uniform", "lognormal", "discrete"])
    r = lambda: f"{rng.choice([-1, 0, 1, 2, 3, 5, 8]) * 1e-6 * rng.choice([1, 1, 1.3])}"
    if d == "uniform":
        return f"uniform lo={r()} hi={r()}"
    if d == "lognormal":
        extra = f" lo={r()} hi={r()}" if rng.random() < 0.5 else ""
        return f"lognormal median={r()} gsd={rng.choice([0.5, 1, 1.01, 1.2, 2])}{extra}"
    n = rng.choice([0, 1, 2, 3, 7])
    radii = ",".join(r() for _ in range(n)) or "0"
    fr = ""
    if rng.random() < 0.5:
        fr = " fractions=" + ",".join(str(rng.choice([-1, 0, 1, 2])) for _ in range(rng.choice([1, 2, 3])))
    return f"discrete radii={radii}{fr}"


def test_random_population_specs_are_refused_or_reach_the_deck_whole():
    """Every random specification is refused with a one-line message or becomes deck variables
    that break no rule; a lognormal accepted needs on average at most 1 / MIN_LOGNORMAL_MASS
    draws per particle, and exceeding the deck's MAX_REDRAWS is practically impossible."""
    import random
    rng = random.Random(7)
    accepted = refused = 0
    for _ in range(400):
        spec = _random_size(rng)
        try:
            size = population.parse_spec(spec, population.SIZE_KEYS, "--size")
        except ParamError as e:
            assert "\n" not in str(e) and str(e).startswith("--size"), (spec, e)
            refused += 1
            continue
        accepted += 1
        v = population.species_vars(1, size, None)
        assert not _problems(v), (spec, _problems(v))
        if size["dist"] == "lognormal":
            lo, hi = population.bounds(size)
            mass = rules.lognormal_mass(size["median"], size["gsd"], lo, hi)
            assert mass >= rules.MIN_LOGNORMAL_MASS
            assert (1 - mass) ** rules.MAX_REDRAWS < 1e-8
        p = DepositionParams(N=10, rp=float(v.pop("rp")), extra=v)
        assert estimate.estimate([p])["cpu_s"] > 0
    assert accepted > 20 and refused > 20


# ---- the command line and the study file -----------------------------------------------------

def _gc(args, cwd):
    """The command line with no LAMMPS build to find: a check that came after looking for the
    build would fail with "no LAMMPS build" instead of its own message."""
    env = dict(os.environ, PYTHONPATH=str(SRC / "python"), GC_BUILD_DIR=str(Path(cwd) / "no-build"))
    return subprocess.run([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("args, words", [
    (["--var", "species", "abc"], "species = abc: not a number"),
    (["--var", "q_sigma", "abc"], "q_sigma = abc: not a number"),
    (["--rp", "4"], "rp = 4: a radius of 4 m"),
    (["--size", "lognormal median=2e-6 gsd=1.5 lo=1.999e-6 hi=2.001e-6"], "rp_gsd = 1.5"),
    (["--size", "discrete radii=2e-6,0"], "radii = 2e-06 0"),
    (["--charge", "bipolar q=300 pos=2"], "q_pos = 2"),
])
def test_the_command_line_refuses_before_lammps(tmp_path, args, words):
    r = _gc(["run", "--out", tmp_path / "o", "--N", 10, "--no-render", *args], tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "no LAMMPS build" not in r.stderr, r.stderr
    assert not list(tmp_path.glob("o/**/result.json"))


def test_an_exotic_value_passes_with_the_override():
    with pytest.raises(ParamError, match="rp = 4: a radius of 4 m"):
        DepositionParams(rp=4)
    assert DepositionParams(rp=4, extra={"exotic": "yes"}).rp == 4.0


@pytest.mark.parametrize("line, words", [('U0 = "fast"', "U0 = fast: not a number"),
                                          ("rp = 4", "rp = 4: a radius of 4 m"),
                                          ('N = "many"', "N = many: not a number"),
                                          ("seeds = 5", "seeds = 5: must be a list")])
def test_a_study_file_word_or_unit_mistake_is_one_line(tmp_path, line, words):
    f = tmp_path / "s.toml"
    seeds = "" if line.startswith("seeds") else "seeds = [1]\n"
    top, deck = (line + "\n", "") if line.startswith("seeds") else ("", line + "\n")
    f.write_text(f'name = "x"\n{seeds}{top}[deck]\n{deck}[population]\n'
                 'charge = "area sigma=1e-7"\n[grid]\nq_sigma = [0]\n')
    r = _gc(["study", f, "--estimate-only"], tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_the_estimate_skips_a_finished_run_it_cannot_use(tmp_path):
    """A result.json whose time step is 0 (or missing numbers) is left out of the calibration,
    not a ZeroDivisionError."""
    d = tmp_path / "run"
    d.mkdir()
    (d / "result.json").write_text(json.dumps({
        "key": "k", "params": {"rp": 2e-6, "U0": 1.0, "gamma": 0.01, "q": 0.0, "N": 5,
                               "seed": 1, "extra": {}},
        "cpu_s": 10.0, "lammps": {"dt": 0}}))
    cal = estimate.calibration([tmp_path])
    assert cal[False][2] == 0


def test_every_deck_input_has_a_rule():
    """Each `variable NAME index` input of the deck is checked by a rule (out and log_file,
    file names, take any word)."""
    from granular_charged.run.deckfile import deck_variables
    ruled = {r.name for r in RULES}
    missing = sorted(set(deck_variables("in.deposition")) - ruled - {"out", "log_file"})
    assert not missing, f"deck inputs without a rule in granular_charged/rules.py: {missing}"
