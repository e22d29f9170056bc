"""The input rules of in.deposition (granular_charged/rules.py): one table, checked by Python
before LAMMPS starts and by the deck's generated block when the deck runs by hand.

Every rule of the table gets a case that breaks it and no other rule (found by a search over
candidate values, or given in EXAMPLES); each case is refused through the Python API (a
ParamError naming the variable) and through lmp (status 1, one error line, the same message, no
GC RESULT); a rule without a case fails test_every_rule_has_a_case. The deck's block must be
what the table generates (test_deck_block_is_generated_from_the_table)."""
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from granular_charged import rules
from granular_charged.params import DepositionParams, ParamError, param_names
from granular_charged.run import estimate, population
from granular_charged.run.deckfile import deck_variables
from lammps_runs import DECK, SRC

RULES = [r for r in rules.RULES if r.kind != "derived"]
FIELDS = set(param_names())

# values tried for a rule's variable when the search looks for a case that breaks it
CANDIDATES = ["-1", "0", "0.3", "1", "1.5", "2.5", "4", "7", "100", "1e9", "1e-20", "1e-9",
              "-0.1", "0.9", "1e6", "1e13", "30000", "2.5e-7", "bogus", "2e-6 0", "2e-6 4e-6",
              "1e-6 2e-6 3e-6 4e-6 5e-6 6e-6 7e-6", "1 2 3", "10", "0.5", "2e-6 2"]
# cases the search cannot find (they need more than one variable)
EXAMPLES = {
    "rp_lo#lognormal-range": {"r_dist": "lognormal", "rp_lo": "3e-6", "rp_hi": "5e-6"},
    "rp_hi#lognormal-range": {"r_dist": "lognormal", "rp_lo": "1e-6", "rp_hi": "1.5e-6"},
    "rp_gsd#lognormal-mass": {"r_dist": "lognormal", "rp_gsd": "1.5", "rp_lo": "1.999e-6",
                              "rp_hi": "2.001e-6"},
    "frac#sum": {"species": "2", "frac": "0", "frac_2": "0"},
    "rp_hi#uniform-order": {"r_dist": "uniform", "rp_lo": "3e-6", "rp_hi": "2e-6"},
    "dt_div#flight": {"dt_div": "0.001"},
    "tracer#range": {"tracer": "11", "N": "10"},
    "resume#population": {"resume": "yes", "q_dist": "area"},
}
for s in (2, 3):
    x = f"_{s}"
    EXAMPLES[f"rp_lo{x}#lognormal-range"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_lo{x}": "3e-6", f"rp_hi{x}": "5e-6"}
    EXAMPLES[f"rp_hi{x}#lognormal-range"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_lo{x}": "1e-6", f"rp_hi{x}": "1.5e-6"}
    EXAMPLES[f"rp_gsd{x}#lognormal-mass"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_gsd{x}": "1.5", f"rp_lo{x}": "1.999e-6",
                                             f"rp_hi{x}": "2.001e-6"}
    EXAMPLES[f"rp_hi{x}#uniform-order"] = {"species": str(s), f"r_dist{x}": "uniform",
                                           f"rp_lo{x}": "3e-6", f"rp_hi{x}": "2e-6"}


def rule_id(rule):
    """name#what: the first words of the message, enough to tell a variable's rules apart."""
    same = [r for r in RULES if r.name == rule.name]
    return f"{rule.name}#{same.index(rule)}"


def _context(rule) -> dict:
    """Variables that open the rule's gate, the rest of the population valid."""
    ctx = {}
    gate = rule.when
    m = re.search(r"\$\{species\} >= (\d)", gate)
    if m:
        ctx["species"] = m.group(1)
    for var, word in re.findall(r"x\$\{(\w+)\} == x([\w/]+)", gate):
        ctx[var] = word
    if "${species} != 1 ||" in gate:
        ctx["q_dist"] = "area"
    for var, word in re.findall(r"x\$\{(\w+)\} != x([\w/]+)", gate):
        if var.startswith("r_dist") and word == "discrete" and "||" not in gate:
            ctx[var] = "one"
    for var, word in list(ctx.items()):
        suf = var[len("r_dist"):] if var.startswith("r_dist") else None
        if word in ("uniform", "lognormal"):
            ctx.setdefault(f"rp_lo{suf}", "1e-6")
            ctx.setdefault(f"rp_hi{suf}", "4e-6")
        if word == "discrete":
            ctx.setdefault(f"radii{suf}", "2e-6 4e-6")
    if rule.plausible:
        ctx["exotic"] = "no"
    return ctx


def _problems(vals):
    return rules.problems(vals, first=False)


def _case(rule):
    """Variables that break this rule (its message first among the problems) and that are fine
    without the rule's variable set to the bad value."""
    base = _context(rule)
    for v in CANDIDATES:
        if rule.kind == "word" and v != "bogus":
            continue
        vals = dict(base, **{rule.name: v})
        found = _problems(vals)
        if found and found[0] == _message_of(rule, vals) and not _problems(base):
            return vals
    return None


def _message_of(rule, vals):
    """The message this rule gives for vals, None if it passes (or is gated off)."""
    one = rules.RULES.index(rule)
    saved = rules.RULES[:]
    try:
        rules.RULES[:] = [r for r in saved if r.kind == "derived"] + [saved[one]]
        got = rules.problems(vals)
    finally:
        rules.RULES[:] = saved
    return got[0] if got else None


def _cases():
    out = {}
    by_id = {rule_id(r): r for r in RULES}
    for key, vals in EXAMPLES.items():
        for rid, r in by_id.items():
            if rid not in out and r.name == key.split("#")[0] and _message_of(r, vals) \
                    and _problems(vals)[:1] == [_message_of(r, vals)]:
                out[rid] = vals
    for rid, r in by_id.items():
        if rid not in out:
            found = _case(r)
            if found:
                out[rid] = found
    return out


CASES = _cases()


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


def _lmp(build_dir, cwd, vals):
    cmd = [str(Path(build_dir) / "lmp"), "-in", str(DECK), "-screen", "none", "-log", "q.log",
           "-nocite"]
    for k, v in vals.items():
        cmd += ["-var", k, v]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    log = Path(cwd) / "q.log"
    assert log.exists(), (r.returncode, r.stdout[-2000:], r.stderr[-2000:])
    return r, log.read_text(errors="replace")


@pytest.mark.parametrize("rid", sorted(CASES))
def test_rule_refused_by_the_deck(build_dir, tmp_path, rid):
    # a small run around the case: a check that let the case through ends in seconds
    vals = dict({"N": "5", "L_rp": "6", "H_rp": "10", "settle_max": "1"}, **CASES[rid])
    r, log = _lmp(build_dir, tmp_path, vals)
    errors = [ln for ln in log.splitlines() if re.match(r"^(GC )?ERROR", ln)]
    name = rid.split("#")[0]
    assert r.returncode != 0, log[-2000:]
    assert len(errors) == 1 and name in errors[0], errors or log[-2000:]
    assert "GC RESULT" not in log and "Traceback" not in r.stderr
    # the deck's message is Python's, word for word
    expect = _problems(vals)[0]
    if "not a number" in expect:
        assert errors[0].startswith("ERROR: Variable "), errors
    else:
        assert errors[0] == "GC ERROR: " + expect


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


@pytest.mark.parametrize("spec", ["uniform lo=1.5e-6 hi=3e-6",
                                  "lognormal median=2e-6 gsd=1.3 lo=1.6e-6 hi=3e-6",
                                  "discrete radii=1.5e-6,3e-6 fractions=0.3,0.7"])
def test_valid_specs_draw_what_they_ask(build_dir, tmp_path, spec):
    """The deck's draws follow the spec: a KS test of 80 radii against the spec's CDF
    (continuous), the fractions of a discrete one within 4 standard deviations."""
    from scipy import stats
    size = population.parse_spec(spec, population.SIZE_KEYS, "--size")
    v = population.species_vars(1, size, None)
    v.update({"N": "80", "L_rp": "12", "H_rp": "12", "settle_max": "5", "computes": "0",
              "seed": "3", "out": "."})
    r, log = _lmp(build_dir, tmp_path, v)
    assert r.returncode == 0, log[-2000:]
    rows = (tmp_path / "final.dump").read_text().split("ITEM: ATOMS")[1].splitlines()[1:]
    radii = [float(ln.split()[5]) / 1 for ln in rows]
    radii = [x / 2 if x > 5e-6 else x for x in radii]
    assert len(radii) == 80
    if size["dist"] == "discrete":
        n_small = sum(abs(x - 1.5e-6) < 1e-9 for x in radii)
        assert abs(n_small - 24) < 4 * math.sqrt(80 * 0.3 * 0.7)
        assert all(min(abs(x - 1.5e-6), abs(x - 3e-6)) < 1e-9 for x in radii)
    else:
        assert stats.kstest(radii, population.radius_cdf(size)).pvalue > 1e-3


# ---- the log of a charged run started by hand ------------------------------------------------

def _q_run_vars(**kw):
    v = {"N": "6", "L_rp": "6", "H_rp": "20", "q": "300", "settle_max": "20", "seed": "2",
         "out": "run1", "computes": "0"}
    v.update({k: str(x) for k, x in kw.items()})
    return v


@pytest.mark.parametrize("split", ["no", "yes"])
def test_the_users_log_keeps_the_summary(build_dir, tmp_path, split):
    """lmp -in in.deposition ... -log q.log: q.log has the protocol, the progress and the
    result, whether the loop's runs stay in it (split_log no) or go to log.inject.lammps."""
    (tmp_path / "run1").mkdir()
    r, log = _lmp(build_dir, tmp_path, _q_run_vars(split_log=split, log_file="q.log"))
    assert r.returncode == 0, log[-3000:]
    for words in ("GC PROTOCOL inject plane", "GC PROGRESS 6 / 6 particles", "GC RESULT"):
        assert words in log, words
    inner = tmp_path / "run1" / "log.inject.lammps"
    assert inner.exists() == (split == "yes")
    if split == "yes":
        assert "GC RESULT" not in inner.read_text() and "Loop time" in inner.read_text()
    assert not (tmp_path / "run1" / "log.lammps").exists()
    res = dict(zip(*[iter(re.search(r"^GC RESULT (.*)$", log, re.M).group(1).split())] * 2))
    assert res["asked"] == "6" and res["settled"] in ("0", "1")
    assert int(res["deposited"]) == int(res["atoms"]) - int(res["flying"])


def test_an_unsettled_short_run_says_so(build_dir, tmp_path):
    (tmp_path / "run1").mkdir()
    r, log = _lmp(build_dir, tmp_path, _q_run_vars(settle_max=0, ke_stop=1e-12))
    assert r.returncode == 0, log[-3000:]
    res = dict(zip(*[iter(re.search(r"^GC RESULT (.*)$", log, re.M).group(1).split())] * 2))
    assert res["settled"] == "0"
    assert "GC WARNING: the run ended unsettled" in log


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


def test_the_decks_redraw_loop_is_bounded(build_dir, tmp_path):
    """A lognormal radius is drawn again outside its clip range at most gc_max_redraws times
    per particle, then the deck stops with an error (the rules keep the clip range's mass at
    least MIN_LOGNORMAL_MASS, so with 20000 this does not happen; here the bound is 1)."""
    deck = tmp_path / "in.deposition"
    text = DECK.read_text()
    line = f"variable gc_max_redraws equal {rules.MAX_REDRAWS}"
    assert line in text
    deck.write_text(text.replace(line, "variable gc_max_redraws equal 1"))
    v = {"N": "20", "L_rp": "8", "H_rp": "12", "r_dist": "lognormal", "rp_gsd": "1.5",
         "rp_lo": "1.9e-6", "rp_hi": "2.1e-6", "settle_max": "5", "computes": "0"}
    cmd = [str(Path(build_dir) / "lmp"), "-in", str(deck), "-screen", "none", "-log", "q.log"]
    for k, x in v.items():
        cmd += ["-var", k, x]
    r = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    log = (tmp_path / "q.log").read_text()
    assert r.returncode == 1 and "GC RESULT" not in log
    assert "no radius inside its clip range after 1 draws" in log


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
