"""Run keys (the run folders' names), values on their way to the deck, co-varied grids and the
one-line LAMMPS error, without LAMMPS (test_values_reach_the_deck.py runs them)."""
import json
import random

import pytest

from conftest import SRC
from granular_charged.cli import build_parser
from granular_charged.params import DepositionParams, ParamError, normal_value
from granular_charged.run import child
from granular_charged.run.runner import Runner, lammps_error, read_result, run_folder
from granular_charged.studies import studyfile
from granular_charged.studies.reproduce import paper_size_params

KEPT = SRC / "doc" / "data"

TONER = """
name = "toner"
seeds = [1, 2]
[deck]
U0 = 0.5
N = 40
L_rp = 6
[[species]]
fraction = 0.7
material = {rho = 1100, E = 5e8, nu = 0.4, gamma = 0.04, e = 0.5, mu = 0.4}
size = "lognormal median=4e-6 gsd=1.25"
charge = "area sigma=-2e-7"
[[species]]
fraction = 0.3
material = {rho = 2200, E = 1e9, nu = 0.2, gamma = 0.02, e = 0.7, mu = 0.3}
size = "uniform lo=2e-6 hi=3e-6"
charge = "area sigma=3e-7"
"""


def _study(tmp_path, text, grid=""):
    f = tmp_path / "s.toml"
    f.write_text(text + grid)
    return studyfile.load(f)


# ---- keys ----------------------------------------------------------------------------------

def test_a_mixture_key_is_short_and_readable(tmp_path):
    ps = studyfile.params(_study(tmp_path, TONER))
    assert len(ps) == 2
    for p in ps:
        k = p.key()
        assert len(k) <= 100 and k.startswith("rp4um_U0.5_g40mJ_q0_N40_s")
        assert "_h" in k and len(k.split("_h")[-1]) == 10
        assert len(p.legacy_key()) > 255          # the long form the file system refused


def test_defaults_never_appear_and_values_are_compared_as_numbers():
    d = DepositionParams()
    assert d.key() == "rp2um_U1_g10mJ_q0_N2000_s4711" and d.non_default() == {}
    # a charged run at the default far field names no far field
    assert DepositionParams(q=400).key() == "rp2um_U1_g10mJ_q400_N2000_s4711"
    # a value at its default (as a field, an extra deck variable, a default that is species
    # 1's value) is the default run
    assert DepositionParams(E=200000000).key() == d.key()
    assert DepositionParams(extra={"L_rp": "28.0", "pair_opt": "yes", "q_pos_2": "0.5"}).key() \
        == d.key()
    assert DepositionParams(rho=3000, extra={"species": "2", "rho_2": "3000"}).key() == \
        DepositionParams(rho=3000, extra={"species": "2"}).key()
    # the same value however it is written
    a = DepositionParams(extra={"L_rp": "14", "E0": "1e5", "r_dist": "discrete",
                                "radii": "2e-6 4e-6"})
    b = DepositionParams(extra={"L_rp": "14.0", "E0": "100000", "r_dist": "discrete",
                                "radii": " 2.0e-6  4e-06"})
    assert a.key() == b.key() != d.key()
    assert DepositionParams(rho=1100, extra={"L_rp": 14}).key() == \
        DepositionParams(rho=1100.0, extra={"L_rp": "14"}).key()
    assert normal_value(-0.0) == normal_value("0") == 0.0
    assert normal_value("area") == "area" and normal_value("1.5e-6 3e-6") == [1.5e-6, 3e-6]


def test_main_values_not_written_exactly_get_the_hash():
    a, b = DepositionParams(rp=2.0000001e-6), DepositionParams(rp=2.0000002e-6)
    assert a.key() != b.key() and "_h" in a.key()
    assert DepositionParams(q=-400).key() == "rp2um_U1_g10mJ_q-400_N2000_s4711"


def _random_params(rng):
    """A parameter set drawn from values that are defaults, default spellings, other values
    and other spellings of the same other values."""
    choices = {
        "rp": [2e-6, 2.0e-6, 3e-6, 4e-6, 2.0000001e-6], "U0": [1.0, 1, 0.5], "q": [0.0, 400, -400.0],
        "gamma": [0.01, 0.04], "N": [2000, 40], "seed": [4711, 1, 2], "E": [2e8, 200000000, 5e8],
        "rho": [2500.0, 1100], "farfield": ["exact", "average"]}
    extras = {"L_rp": ["28", "28.0", "14", "14.0", "1.4e1"], "species": ["1", "2"],
              "q_sigma": ["0", "-2e-7", "-2.0e-07"], "q_sigma_2": ["0", "3e-7", "-2e-7"],
              "q_dist": ["fixed", "area"], "radii": ["0", "2e-6 4e-6", "2e-06  4.0e-6"],
              "inject": ["auto", "plane"], "rho_2": ["2500", "1100", "2200"]}
    while True:
        fields = {k: rng.choice(v) for k, v in choices.items() if rng.random() < 0.5}
        extra = {k: rng.choice(v) for k, v in extras.items() if rng.random() < 0.4}
        if extra.get("radii", "0") != "0":
            extra["r_dist"] = "discrete"
        try:
            return DepositionParams(extra=extra, **fields)
        except ParamError:          # a combination the input rules refuse: draw again
            continue


def test_two_different_parameter_sets_never_share_a_folder():
    """Random parameter sets: the same key exactly when the same non-default values (numbers
    as numbers), and every key short."""
    rng = random.Random(20240611)
    seen = {}
    for _ in range(3000):
        p = _random_params(rng)
        k = p.key()
        assert len(k) <= 100, k
        canon = json.dumps(p.non_default(), sort_keys=True)
        assert seen.setdefault(k, canon) == canon, f"{k}: {seen[k]} and {canon}"
    by_canon = {}
    for k, c in seen.items():
        by_canon.setdefault(c, set()).add(k)
    assert all(len(ks) == 1 for ks in by_canon.values())
    assert len(seen) > 500


# ---- runs under the long key -----------------------------------------------------------------

def test_a_run_under_the_long_key_is_found(tmp_path):
    p = DepositionParams(q=400, N=500, seed=2, extra={"L_rp": "14"})
    old = tmp_path / p.legacy_key()
    assert run_folder(p, tmp_path) == tmp_path / p.key()         # nothing there: the new name
    old.mkdir()
    assert run_folder(p, tmp_path) == tmp_path / p.key()         # an empty old folder: new
    (old / "result.json").write_text("{}")
    assert run_folder(p, tmp_path) == old                        # a result there: found
    (tmp_path / p.key()).mkdir()
    assert run_folder(p, tmp_path) == tmp_path / p.key()         # the new one first
    # a long key the file system cannot hold is never looked up
    big = DepositionParams(rp=4e-6, extra={"species": "2", "q_dist_2": "area", "q_sigma_2": "-2e-7",
                                  "r_dist_2": "uniform", "rp_lo_2": "2e-6", "rp_hi_2": "3e-6",
                                  "rho_2": "2200", "E_2": "1e9", "nu_2": "0.2", "gamma_2": "0.02",
                                  "e_2": "0.5", "mu_2": "0.4", "frac": "0.7", "frac_2": "0.3",
                                  "q_sigma": "-2e-7", "q_dist": "area", "r_dist": "lognormal",
                                  "rp_gsd": "1.25", "rp_lo": "2.048e-06", "rp_hi": "7.8125e-06",
                                  "L_rp": "6", "inject": "plane", "sleep": "yes",
                                  "ke_stop": "1e-3", "settle_max": "500", "progress": "10"})
    assert len(big.legacy_key()) > 255
    assert run_folder(big, tmp_path) == tmp_path / big.key()


def test_the_kept_runs_of_doc_data_are_found():
    """Every run kept in doc/data is found for its parameters under its long key, and
    `reproduce --size paper --finished-only` finds all its runs there."""
    folders = sorted(KEPT.glob("*/runs/*/result.json"))
    assert len(folders) > 100
    for f in folders:
        res = json.loads(f.read_text())
        p = DepositionParams(**res["params"])
        assert run_folder(p, f.parent.parent) == f.parent, f
    runner = Runner(build=None)
    runs = KEPT / "paper-size" / "runs"
    params = paper_size_params((1, 2, 3), {}, {})
    found = [p for p in params if runner.finished(p, runs) is not None]
    assert len(found) == len(params) == 84


def test_the_engine_cases_of_kept_runs_are_their_folders(tmp_path):
    """A sweep's cases go to the folder a run is kept in (the engine then finds its
    result.json and runs nothing)."""
    from granular_charged.studies.engine import deposition_cases
    from granular_charged.studies.sweep import in_run_folders
    kept = DepositionParams(q=400, seed=1, theta_crit=0.04)
    new = DepositionParams(q=400, seed=2, theta_crit=0.04)
    old = tmp_path / "runs" / kept.legacy_key()
    old.mkdir(parents=True)
    (old / "result.json").write_text("{}")
    cases = in_run_folders(deposition_cases([kept, new], "runs", 1), [kept, new], tmp_path / "runs")
    assert [c.folder for c in cases] == [f"runs/{kept.legacy_key()}", f"runs/{new.key()}"]
    cases = in_run_folders(deposition_cases([kept], "", 1), [kept], tmp_path / "runs")
    assert cases[0].folder == kept.legacy_key()


# ---- values on their way to the deck -------------------------------------------------------

def test_the_child_gets_every_value_as_given():
    values = {"q_sigma": "-2e-07", "q_sigma_2": "-2e-7", "E": "1e+09", "radii_2": "1.5e-6 3e-6",
              "label": "a b=c", "q": "-400"}
    a = child.parser().parse_args(["deck", "wd", *child.var_args(values)])
    assert dict(a.var) == values
    with pytest.raises(SystemExit):
        child.parser().parse_args(["deck", "wd", "--var=novalue"])


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_the_command_line_takes_negative_numbers_as_values(command):
    args = [command, "--var", "q_sigma_2", "-2e-7", "--var", "E0", "-1E+5", "--q", "-4e2",
            "--charge", "area sigma=-2e-7"] + (["--out", "x"] if command == "sweep" else [])
    a = build_parser().parse_args(args)
    assert a.var == [["q_sigma_2", "-2e-7"], ["E0", "-1E+5"]]
    assert a.q in (-400.0, [-400.0]) and a.charge == "area sigma=-2e-7"


def test_study_values_reach_the_deck_as_text(tmp_path):
    d = _study(tmp_path, TONER.replace("L_rp = 6", "L_rp = 6\nsleep = true"),
               "[grid]\nradii_3 = [[2e-6, 4e-6]]\n")
    p = studyfile.params(d)[0]
    v = p.deck_vars()
    assert v["q_sigma"] == "-2e-07" and v["q_sigma_2"] == "3e-07" and v["q_dist_2"] == "area"
    assert v["sleep"] == "yes" and v["radii_3"] == "2e-06 4e-06"


# ---- co-varied grids ---------------------------------------------------------------------------

def test_a_together_axis_varies_its_variables_together(tmp_path):
    grid = "[grid]\ntogether = {q_sigma = [0, -2e-7], q_sigma_2 = [0, 3e-7]}\n"
    d = _study(tmp_path, TONER, grid)
    assert d["grid"] == {"q_sigma": [0, -2e-7], "q_sigma_2": [0, 3e-7]}
    ps = studyfile.params(d)
    assert len(ps) == 2 * 2                       # 2 points x 2 seeds, not 2 x 2 x 2
    pairs = {(p.deck_vars()["q_sigma"], p.deck_vars()["q_sigma_2"]) for p in ps}
    assert pairs == {("0", "0"), ("-2e-07", "3e-07")}
    # with another axis: every combination of the axes' points
    d = _study(tmp_path, TONER, "[grid]\nU0 = [0.5, 1.0]\n[[grid.together]]\n"
                                "q_sigma = [0, -2e-7]\nq_sigma_2 = [0, 3e-7]\n")
    ps = studyfile.params(d)
    assert len(ps) == 2 * 2 * 2 and len({p.key() for p in ps}) == 8
    assert list(d["grid"]) == ["U0", "q_sigma", "q_sigma_2"]


@pytest.mark.parametrize("grid, message", [
    ("together = {q_sigma = [0, -2e-7], q_sigma_2 = [0]}", "q_sigma 2, q_sigma_2 1"),
    ("q_sigma = [0]\ntogether = {q_sigma = [0, -2e-7], q_sigma_2 = [0, 1e-7]}", "given twice"),
    ("together = {q_sigma = 0}", "non-empty list"),
    ("together = 3", "table of lists"),
    ("U0 = 0.5", "non-empty list"),
])
def test_a_bad_grid_is_one_line(tmp_path, grid, message):
    with pytest.raises(ParamError, match=message):
        _study(tmp_path, TONER, "[grid]\n" + grid + "\n")


@pytest.mark.parametrize("change, message", [
    (("seeds = [1, 2]", "seeds = 5"), "seeds = 5"),
    (("U0 = 0.5", 'U0 = "fast"'), "U0 = fast: not a number"),
    (("N = 40", "N = 4.5"), "N = 4.5"),
])
def test_a_word_where_a_number_belongs_is_one_line(tmp_path, change, message):
    with pytest.raises(ParamError, match=message):
        studyfile.params(_study(tmp_path, TONER.replace(*change)))


# ---- LAMMPS's error in one line ------------------------------------------------------------

LOG = """LAMMPS (development)
variable a equal 1
if "${a} == yes" then "print x"
ERROR: If command boolean cannot be evaluated (src/input.cpp:1010)
Last command: if "1 == yes" then "print x"
"""
TRACEBACK = """Traceback (most recent call last):
  File "child.py", line 170, in main
    lmp.file(a.deck)
Exception: ERROR: If command boolean cannot be evaluated (src/input.cpp:1010)
"""


def test_a_lammps_error_is_one_line(tmp_path):
    msg = lammps_error(LOG, TRACEBACK, tmp_path, 1)
    assert "\n" not in msg and "Traceback" not in msg
    assert "ERROR: If command boolean cannot be evaluated" in msg
    assert 'deck line: if "1 == yes" then "print x"' in msg and str(tmp_path) in msg
    # only the child's exception (an error of one rank is not in the log)
    msg = lammps_error("LAMMPS (development)\n", TRACEBACK.replace("ERROR:", "ERROR on proc 0:"),
                       tmp_path, 1)
    assert "ERROR on proc 0: If command boolean" in msg and "\n" not in msg
    # the deck's own check
    msg = lammps_error("print 'GC ERROR: species must be 1, 2 or 3, not 4'\n"
                       "GC ERROR: species must be 1, 2 or 3, not 4\n", "", tmp_path, 1)
    assert msg.startswith("GC ERROR: species must be 1, 2 or 3, not 4") and "\n" not in msg
    assert "failed (exit 9): no error message" in lammps_error("", "", tmp_path, 9)
    said = lammps_error("", "usage: child.py\nchild.py: error: argument --var: bad\n", tmp_path, 2)
    assert "failed (exit 2): child.py: error: argument --var: bad (its log" in said
    # the command echoed before the error, found in the deck with its line number (LAMMPS
    # versions that print the boolean as their "Last input line")
    deck = ('variable a index 1   # a comment\nif "${a} > 0" then &\n'
            '   "print \'# not a comment\'"\n')
    log = ('if "${a} > 0" then    "print \'# not a comment\'"\n'
           "ERROR: If command boolean can only operate on numbers (src/variable.cpp:5720)\n"
           "Last input line: abc > 0\n")
    msg = lammps_error(log, "", tmp_path, 1, deck, "in.x")
    assert msg.endswith("; in.x line 2: if \"${a} > 0\" then \"print '# not a comment'\""), msg
    msg = lammps_error(log.replace("if ", "iff ", 1), "", tmp_path, 1, deck, "in.x")
    assert msg.endswith("; deck line: abc > 0"), msg


def test_read_result_still_reads_kept_results():
    f = next(KEPT.glob("paper-size/runs/*/result.json"))
    assert read_result(f) is not None
