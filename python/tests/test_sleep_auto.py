"""sleep auto: the deposition deck sleeps as with sleep yes when the bed is expected to be taller
than sleep_auto sleep_depth, else it runs as with sleep no.

The rule has two homes that must agree: the deck's section "sleeping particles: the choice of
sleep auto" (in.deposition, LAMMPS's formulas) and granular_charged/rules.py, sleep_auto
(Python); the clipped lognormal's mean r^3 has one, the derived variable gc_m3 of
granular_charged/rules.py, which both evaluate. test_the_deck_and_python_choose_alike checks the
two homes against each other over random runs; the closed forms are checked against numerical
integration. The deck's set-up alone (up to its first run) answers what the deck chooses and
which fixes it defines, in about a second; the runs that compare whole trajectories are tiny
(N <= 40)."""
import math
import random
import re
import subprocess
from pathlib import Path

import pytest

from granular_charged import rules
from granular_charged.params import DepositionParams, ParamError
from lammps_runs import DECK, lmp_run
from rule_cases import _lmp

PAPER = {"N": "2000", "L_rp": "28"}
TALL = {"N": "20000", "L_rp": "28"}
# a tiny run: 40 particles in a box of 8 r_p, H 30 r_p (expected height 4.1 r_p)
TINY = {"N": "40", "L_rp": "8", "H_rp": "30", "settle_max": "30", "seed": "3"}


def _setup_log(build_dir, cwd, variables, upto="# ---------------- output and stop rule"):
    """The log of the deck's set-up: the deck up to the line `upto` (no run command before it),
    then a line with the choice's numbers at full precision."""
    text = DECK.read_text()
    deck = Path(cwd) / "in.setup"
    deck.write_text(text[:text.index(upto)]
                    + 'print "GC TEST sleep_on ${sleep_on}"\n'
                    + 'if "${sleep} == auto" then "print \'GC TEST h $(v_sleep_h:%.15g) '
                      'threshold $(v_sleep_thr:%.15g)\'"\n')
    return lmp_run(build_dir, deck, cwd, variables, timeout=120)


def _commands(log, pattern=r"^(fix|unfix|run|thermo_style|pair_style|pair_coeff) "):
    """The commands the deck ran, as LAMMPS echoed them with every variable substituted."""
    return [ln.split("#")[0].strip() for ln in log.splitlines()
            if re.match(pattern, ln) and "$" not in ln]


def _sleep_lines(log):
    return [ln for ln in log.splitlines() if ln.startswith("GC SLEEP")]


def _test_values(log):
    m = re.search(r"^GC TEST h (\S+) threshold (\S+)$", log, re.M)
    on = re.search(r"^GC TEST sleep_on (\d)$", log, re.M).group(1)
    return (float(m.group(1)), float(m.group(2))) if m else None, on == "1"


# ---- the choice through lmp ------------------------------------------------------------------

def test_auto_is_off_at_the_papers_size(build_dir, tmp_path):
    """N 2000, L 28 r_p: expected height 16.7 r_p < 3 x 15 r_p; the deck defines the fixes of
    sleep no, no fix sleep/gran, and says why in one line."""
    (tmp_path / "a").mkdir(), (tmp_path / "n").mkdir()
    auto = _setup_log(build_dir, tmp_path / "a", dict(PAPER, sleep="auto"))
    no = _setup_log(build_dir, tmp_path / "n", dict(PAPER, sleep="no"))
    assert _commands(auto) == _commands(no)
    assert not any("sleep/gran" in c for c in _commands(auto))
    assert _sleep_lines(auto) == ["GC SLEEP auto: expected bed height 16.7 r_p <= 45 r_p: "
                                  "sleeping off"], _sleep_lines(auto)
    assert not _sleep_lines(no)


def test_auto_is_on_for_a_tall_bed(build_dir, tmp_path):
    """N 20000, L 28 r_p: expected height 167 r_p > 45 r_p; the fix sleep/gran of sleep yes,
    depth 15 r_p."""
    (tmp_path / "a").mkdir(), (tmp_path / "y").mkdir()
    auto = _setup_log(build_dir, tmp_path / "a", dict(TALL, sleep="auto"))
    yes = _setup_log(build_dir, tmp_path / "y", dict(TALL, sleep="yes"))
    assert _commands(auto) == _commands(yes)
    fix = [c for c in _commands(auto) if "sleep/gran" in c]
    assert len(fix) == 1, fix
    depth = float(re.search(r" depth (\S+)", fix[0]).group(1))
    assert depth == pytest.approx(15 * 2e-6, rel=1e-12, abs=0), fix
    assert _sleep_lines(auto) == ["GC SLEEP auto: expected bed height 167 r_p > 45 r_p: deep "
                                  "sleeping on (depth 15 r_p)"], _sleep_lines(auto)


@pytest.mark.parametrize("epd", [{"E0": "1e5"}, {"eps_p": "3.8"}, {"electrode": "yes"}])
def test_auto_stays_off_with_an_epd_keyword(build_dir, tmp_path, epd):
    """A tall bed with an EPD keyword: fix coul/fmm would need sleepers full with sleepers
    (whose packing has not been measured), so auto runs the commands of sleep no and says why;
    Python chooses the same."""
    (tmp_path / "a").mkdir(), (tmp_path / "n").mkdir()
    v = dict(TALL, **epd)
    auto = _setup_log(build_dir, tmp_path / "a", dict(v, sleep="auto"))
    no = _setup_log(build_dir, tmp_path / "n", dict(v, sleep="no"))
    assert _commands(auto) == _commands(no)
    assert not any("sleep/gran" in c for c in _commands(auto))
    assert _sleep_lines(auto) == ["GC SLEEP auto: expected bed height 167 r_p > 45 r_p, but E0, "
                                  "eps_p or electrode is set: sleeping off"], _sleep_lines(auto)
    py = rules.sleep_auto(dict(v, sleep="auto"))
    assert py["sleep"] == "no" and py["epd"]
    assert not rules.sleep_auto(dict(TALL, sleep="auto"))["epd"]


@pytest.mark.parametrize("asked, same_as, extra", [
    ("auto", "no", {}),                          # 4.1 r_p <= 45 r_p: off
    ("auto", "yes", {"sleep_auto": "0.2"}),      # 4.1 r_p > 3 r_p: on
])
def test_auto_runs_as_what_it_chose_bit_for_bit(build_dir, tmp_path, asked, same_as, extra):
    """A whole tiny run with sleep auto is the run of the setting it chose: the same final
    positions to the last digit, the same result, the same commands (sleeping on: the fix,
    its unfix and the last awake settling)."""
    logs = {}
    for s in (asked, same_as):
        d = tmp_path / s
        d.mkdir()
        logs[s] = lmp_run(build_dir, DECK, d, dict(TINY, sleep=s, out=".", **extra))
    dumps = [(tmp_path / s / "final.dump").read_text() for s in (asked, same_as)]
    assert dumps[0] == dumps[1]
    res = [re.search(r"^GC RESULT .*$", logs[s], re.M).group(0) for s in (asked, same_as)]
    assert res[0] == res[1]
    assert _commands(logs[asked]) == _commands(logs[same_as])
    slept = any("sleep/gran" in c for c in _commands(logs[asked]))
    assert slept == (same_as == "yes")
    assert ("unfix sleep" in _commands(logs[asked])) == slept


# ---- bad values ------------------------------------------------------------------------------

BAD = [({"sleep": "maybe"}, "sleep = maybe: must be one of yes, no, auto"),
       ({"sleep": "auto", "sleep_auto": "0"}, "sleep_auto = 0: must be > 0"),
       ({"sleep_auto": "-1"}, "sleep_auto = -1: must be > 0"),
       ({"sleep": "auto", "sleep_depth": "0"}, "sleep_depth = 0: must be > 0 [r_p] with sleep auto")]


@pytest.mark.parametrize("vals, words", BAD)
def test_bad_values_are_refused_by_python(vals, words):
    with pytest.raises(ParamError) as e:
        DepositionParams(extra=vals)
    assert "\n" not in str(e.value) and str(e.value).startswith(words), str(e.value)


@pytest.mark.parametrize("vals, words", BAD)
def test_bad_values_are_refused_by_the_deck(build_dir, tmp_path, vals, words):
    r, log = _lmp(build_dir, tmp_path, dict({"N": "5", "L_rp": "6", "H_rp": "10",
                                             "settle_max": "1"}, **vals))
    errors = [ln for ln in log.splitlines() if re.match(r"^(GC )?ERROR", ln)]
    assert r.returncode != 0
    assert len(errors) == 1 and errors[0].startswith("GC ERROR: " + words), errors
    assert "GC RESULT" not in log and "GC SLEEP" not in log


def test_sleep_depth_zero_is_fine_without_auto():
    """sleep_depth 0 (no depth rule) is refused only with sleep auto, whose threshold it sets."""
    DepositionParams(extra={"sleep": "yes", "sleep_depth": "0"})


# ---- the rule: Python against closed forms, and against the deck -----------------------------

@pytest.mark.parametrize("median, gsd, lo, hi", [
    (2e-6, 1.2, 0, 0), (2e-6, 1.5, 1.9e-6, 2.1e-6), (3e-6, 2.0, 1e-7, 3.01e-6),
    (2e-6, 3.0, 0, 0), (5e-6, 1.05, 4e-6, 5.1e-6)])
def test_the_lognormal_mean_r3_is_the_integral(median, gsd, lo, hi):
    """gc_m3 against the numerical integral of r^3 over the clipped lognormal. The deck's
    normal CDF (Abramowitz & Stegun 7.1.26, |error| < 1.5e-7) over masses >= 0.1 here: a
    relative error below 1e-5."""
    from scipy import integrate, stats
    ln = stats.lognorm(s=math.log(gsd), scale=median)
    a, b = lo or median / gsd ** 3, hi or median * gsd ** 3
    exact = integrate.quad(lambda r: r ** 3 * ln.pdf(r), a, b, epsabs=0, epsrel=1e-12,
                           limit=200)[0] / (ln.cdf(b) - ln.cdf(a))
    assert rules.lognormal_mean_r3(median, gsd, lo, hi) == pytest.approx(exact, rel=1e-5, abs=0)


def test_mean_r3_of_the_other_size_rules():
    """uniform in r: the integral of r^3 / (hi - lo); discrete: the weighted mean of r^3.
    (Radii in m: every comparison is relative, abs=0.)"""
    from scipy import integrate
    from granular_charged.run.deckfile import deck_variables
    deck = deck_variables("in.deposition")

    def m3(given, s=1):
        return rules.mean_r3(rules.Values(given, deck), s)
    lo, hi = 1.5e-6, 3.5e-6
    exact = integrate.quad(lambda r: r ** 3, lo, hi)[0] / (hi - lo)
    assert m3({"r_dist": "uniform", "rp_lo": lo, "rp_hi": hi}) == \
        pytest.approx(exact, rel=1e-12, abs=0)
    disc = {"species": 2, "r_dist_2": "discrete", "radii_2": "1e-6 3e-6"}
    assert m3(dict(disc, rfrac_2="3 1"), 2) == \
        pytest.approx((3 * 1e-18 + 27e-18) / 4, rel=1e-12, abs=0)
    assert m3(disc, 2) == pytest.approx((1e-18 + 27e-18) / 2, rel=1e-12, abs=0)
    assert m3({"rp": 2e-6}) == pytest.approx(8e-18, rel=1e-12, abs=0)
    # species 2's radius is species 1's when not given (rp_2 = ${rp})
    assert m3({"species": 2, "rp": 3e-6}, 2) == pytest.approx(27e-18, rel=1e-12, abs=0)


def test_python_chooses_by_the_height():
    """The paper's bed: 2000 (4/3 pi) / (0.64 x 784) = 16.7 r_p, off; ten times as many, on;
    sleep yes and no are themselves whatever the height."""
    paper = rules.sleep_auto(dict(PAPER, sleep="auto"))
    assert paper["height_rp"] == pytest.approx(2000 * 4 / 3 * math.pi / (0.64 * 784), rel=1e-12)
    assert paper["threshold_rp"] == 45 and paper["sleep"] == "no"
    assert rules.sleep_auto(dict(TALL, sleep="auto"))["sleep"] == "yes"
    assert rules.sleep_auto(dict(TALL, sleep="no"))["sleep"] == "no"
    assert rules.sleep_auto(dict(PAPER, sleep="yes"))["sleep"] == "yes"


def _random_run(rng):
    """Deck variables of a random run with sleep auto: N, L, the threshold and a population of
    1-3 species, each of one size, uniform, lognormal (clipped or not) or discrete radii."""
    r = lambda: rng.choice([1.0, 1.5, 2.0, 3.0, 5.0]) * 1e-6 * rng.uniform(0.8, 1.2)
    v = {"sleep": "auto", "N": str(rng.choice([10, 300, 2000, 8000, 20000, 100000])),
         "L_rp": f"{rng.uniform(3, 60):.6g}", "sleep_auto": f"{rng.uniform(0.3, 6):.4g}",
         "sleep_depth": f"{rng.choice([6, 15, 30])}"}
    n = rng.choice([1, 1, 2, 3])
    if n > 1:
        v["species"] = str(n)
    for s in range(1, n + 1):
        x = "" if s == 1 else f"_{s}"
        if s > 1 or rng.random() < 0.5:
            v["frac" + x] = f"{rng.uniform(0.05, 2):.4g}"
        d = rng.choice(["one", "uniform", "lognormal", "discrete"])
        v["rp" + x] = f"{r():.6g}"
        if d != "one":
            v["r_dist" + x] = d
        if d == "uniform":
            lo = r()
            v["rp_lo" + x], v["rp_hi" + x] = f"{lo:.6g}", f"{lo * rng.uniform(1.1, 3):.6g}"
        elif d == "lognormal":
            v["rp_gsd" + x] = f"{rng.uniform(1.05, 2.0):.4g}"
            if rng.random() < 0.5:
                med = float(v["rp" + x])
                v["rp_lo" + x] = f"{med * rng.uniform(0.3, 0.95):.6g}"
                v["rp_hi" + x] = f"{med * rng.uniform(1.05, 3):.6g}"
        elif d == "discrete":
            k = rng.choice([1, 2, 3, 6])
            v["radii" + x] = " ".join(f"{r():.6g}" for _ in range(k))
            if rng.random() < 0.5:
                v["rfrac" + x] = " ".join(f"{rng.uniform(0.1, 3):.4g}" for _ in range(k))
    return v


def test_the_deck_and_python_choose_alike(build_dir, tmp_path):
    """Over random runs (N, L, threshold, populations of 1-3 species of every size rule) the
    deck's expected height equals Python's to 1e-9 (both evaluate the same formulas in double
    precision; the deck passes the per-species mean r^3 on as text of 20 digits) and the
    choice is the same. Heights within 1e-9 of the threshold would be a tie, not a test of the
    rule: none is drawn, and the test says so if one is."""
    rng = random.Random(11)
    cases, on = 0, 0
    while cases < 24:
        v = _random_run(rng)
        if rules.problems(v):
            continue            # a population the rules refuse: not a run
        d = tmp_path / str(cases)
        d.mkdir()
        log = _setup_log(build_dir, d, v, upto="# ---------------- system ---")
        (h, thr), deck_on = _test_values(log)
        py = rules.sleep_auto(v)
        assert h == pytest.approx(py["height_rp"], rel=1e-9), v
        assert thr == pytest.approx(py["threshold_rp"], rel=1e-12), v
        assert abs(h / thr - 1) > 1e-9, ("a tie drawn", v)
        assert deck_on == (py["sleep"] == "yes"), (v, h, thr)
        cases += 1
        on += deck_on
    assert 4 <= on <= cases - 4, on     # both choices are exercised


# ---- the run key and the command line --------------------------------------------------------

def test_the_run_key_names_sleep_auto():
    """A value of sleep other than the deck's default enters the key (its hash), the default
    does not; sleep_auto likewise."""
    from granular_charged.run.deckfile import deck_variables
    default = deck_variables("in.deposition")["sleep"]
    other = "no" if default == "auto" else "auto"
    base = DepositionParams(N=100)
    assert DepositionParams(N=100, extra={"sleep": default}).key() == base.key()
    changed = DepositionParams(N=100, extra={"sleep": other})
    assert changed.key() != base.key() and changed.non_default()["sleep"] == other
    auto = DepositionParams(N=100, extra={"sleep": "auto"})
    assert DepositionParams(N=100, extra={"sleep": "auto", "sleep_auto": "3.0"}).key() == auto.key()
    assert DepositionParams(N=100, extra={"sleep": "auto", "sleep_auto": "4"}).key() != auto.key()


@pytest.mark.parametrize("extra, chosen, line", [
    ([], "no", "expected bed height 4.09 r_p <= 45 r_p: sleeping off"),
    (["--var", "sleep_auto", "0.2"], "yes",
     "expected bed height 4.09 r_p > 3 r_p: deep sleeping on (depth 15 r_p)")])
def test_sleep_auto_through_the_command_line(cli, tmp_path, extra, chosen, line):
    """granular-charged run --var sleep auto: the deck gets it (its GC SLEEP line in the run's
    log), result.json records it and what it chose."""
    import json
    r = cli(["-q", "run", "--out", tmp_path / "runs", "--seed", 3, "--N", TINY["N"],
             "--var", "L_rp", TINY["L_rp"], "--var", "H_rp", TINY["H_rp"],
             "--var", "sleep", "auto", *extra, "--no-render"], tmp_path)
    rf = Path(r.stdout.strip().splitlines()[-1])
    res = json.loads(rf.read_text())
    from granular_charged.run.deckfile import deck_variables
    default = deck_variables("in.deposition")["sleep"]     # a value at its default is not kept
    assert res["params"]["extra"].get("sleep", default) == "auto" and res["sleep"] == chosen
    logs = "".join(p.read_text(errors="replace") for p in rf.parent.glob("log*.lammps"))
    assert "GC SLEEP auto: " + line in logs
