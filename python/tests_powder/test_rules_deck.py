"""The input rules through lmp (ctest python.powder): every rule of
granular_charged/rules.py broken once at the deck's start (status 1, one error line naming the
variable, the message Python gives word for word, no GC RESULT), the draws of valid size specs,
the bounded redraws, the log a charged run keeps and the end of an unsettled run. Each rule case
ends at the deck's start (~1 s, most of it LAMMPS's start-up); the runs are small (N <= 80)."""
import math
import re
import subprocess
from pathlib import Path

import pytest

from granular_charged import rules
from granular_charged.run import population
from lammps_runs import DECK
from rule_cases import CASES, _lmp, _problems


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
