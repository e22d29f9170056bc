"""Contact charging in in.deposition (tribo yes: fix tribo/charge; doc/populations.md, "Contact
charging"): its input rules (wrong, extreme and random values, through Python, the command line
and the deck), its options and study-file values reaching the deck, the charge analysis against
closed forms, and the tribo path through LAMMPS.

The runs of the tribo path need fix tribo/charge in the build: they skip, saying so, when the
build has no such style, and run when it has. The others run on any build (the deck's tribo no
path: every deck has it)."""
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import SRC
from granular_charged import rules
from granular_charged.analysis import charges, packing, studytables
from granular_charged.cli import build_parser
from granular_charged.cli import options as cli_options
from granular_charged.params import E0, DepositionParams, ParamError
from granular_charged.run import population
from granular_charged.studies import studyfile
from granular_charged.studies.axes import deck_params
from lammps_runs import DECK, lmp_run, result_line


def _refused(values: dict) -> list[str]:
    return rules.problems(values, first=False)


# ---- the input rules: wrong, extreme and random values ---------------------------------------

@pytest.mark.parametrize("name, value, words", [
    ("tribo", "maybe", "must be one of yes, no"),
    ("tribo", "1", "must be one of yes, no"),
    ("tribo_field", "on", "must be one of yes, no"),
    ("tribo_z0", "0", "must be > 0 [m]"),
    ("tribo_z0", "-4e-10", "must be > 0 [m]"),
    ("tribo_z0", "4", "(4e-10 for 4 Angstrom, 4e-09 for 4 nm)"),
    ("tribo_z0", "1e-13", "below 0.1 Angstrom"),
    ("tribo_z0", "abc", "not a number"),
    ("tribo_V", "500", "(0.5 for 500 mV)"),
    ("tribo_V", "-11", "above 10 V"),
    ("tribo_V", "nan", "not a number"),
    ("tribo_V", "inf", "not a number"),
    ("tribo_V_wall", "250", "(0.25 for 250 mV)"),
    ("tribo_V_wall", "x", "must be a number [V] (the contact potential of the floor)"),
])
def test_wrong_values_are_refused_with_what_they_must_be(name, value, words):
    found = _refused({name: value})
    assert found and found[0].startswith(f"{name} = {value}: ") and words in found[0], found
    with pytest.raises(ParamError) as e:
        DepositionParams(extra={name: value})
    assert str(e.value) == found[0]


def test_a_species_potential_is_checked_with_its_species_only():
    # species 2's potential is read (and checked) only when the run has 2 species
    assert _refused({"tribo_V_2": "50"}) == []
    assert "tribo_V_2 = 50" in _refused({"species": "2", "tribo_V_2": "50"})[0]
    assert "tribo_V_3 = -40" in _refused({"species": "3", "tribo_V_3": "-40"})[0]
    # a species not given has species 1's value (the deck's default ${tribo_V})
    assert _refused({"species": "3", "tribo_V": "0.7"}) == []


def test_exotic_lets_the_plausibility_rules_pass_and_no_other():
    assert _refused({"tribo_V": "50", "exotic": "yes"}) == []
    assert _refused({"tribo_z0": "2e-6", "exotic": "yes"}) == []
    assert "must be > 0" in _refused({"tribo_z0": "-1", "exotic": "yes"})[0]
    assert "not a number" in _refused({"tribo_V": "nan", "exotic": "yes"})[0]


def test_random_values_are_refused_exactly_outside_the_rules():
    """Random potentials (-30 .. 30 V, also written in other forms) and gaps (log-uniform 1e-14 ..
    1e-3 m, both signs): refused exactly when outside |V| <= 10, 1e-11 <= z0 <= 1e-6 (z0 > 0),
    accepted otherwise, with the value named as given."""
    rng = np.random.default_rng(20261206)
    for _ in range(300):
        v = float(rng.uniform(-30, 30))
        text = rng.choice([f"{v:.6g}", f"{v:.3e}", f"{v:+.4f}"])
        s = int(rng.integers(1, 4))
        name = "tribo_V" + ("" if s == 1 else f"_{s}")
        got = _refused({"species": str(s), name: text})
        assert (got != []) == (abs(float(text)) > rules.MAX_CONTACT_POTENTIAL), (text, got)
        if got:
            assert got[0].startswith(f"{name} = {text}: a contact potential of {text} V")
        z = float(10 ** rng.uniform(-14, -3)) * rng.choice([1.0, -1.0])
        got = _refused({"tribo_z0": f"{z:.6g}"})
        z = float(f"{z:.6g}")
        fine = 1e-11 <= z <= 1e-6
        assert (got == []) == fine, (z, got)
        if z <= 0:
            assert "must be > 0" in got[0]
    for word in ("Yes", "YES", "true", "1", "0", "y", "", "yes;", "n0"):
        assert _refused({"tribo": word}) and _refused({"tribo_field": word}), word
    assert _refused({"tribo": "yes", "tribo_field": "no"}) == []


# ---- the command line and study files --------------------------------------------------------

def _gc(args, cwd):
    env = dict(os.environ, PYTHONPATH=str(SRC / "python"),
               GC_BUILD_DIR=str(Path(cwd) / "no-build"))
    return subprocess.run([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("args, words", [
    (["--tribo-V", "0.5"], "--tribo-V: contact charging's values are read with --tribo only"),
    (["--tribo-V-wall", "0.2"], "--tribo-V-wall: contact charging's values are read with"),
    (["--tribo", "--tribo-V", "500"], "tribo_V = 500: a contact potential of 500 V"),
    (["--tribo", "--tribo-V", "0", "0.5"], "tribo_V_2 = 0.5: the run has 1 species"),
    (["--tribo", "--tribo-V", "0", "1", "2", "3"], "one contact potential per species, at most 3"),
    (["--tribo", "--tribo-z0", "0.4"], "tribo_z0 = 0.4: a cut-off gap of 0.4 m"),
    (["--tribo", "--tribo-z0", "-1e-10"], "tribo_z0 = -1e-10: must be > 0 [m]"),
    (["--tribo", "--tribo-V", "abc"], "tribo_V = abc: not a number"),
    (["--tribo", "--tribo-V", "0.3", "--var", "tribo_V", "0.3"], "--var tribo_V: set by"),
    (["--var", "tribo", "perhaps"], "tribo = perhaps: must be one of yes, no"),
    (["--var", "tribo_V_wall", "1e3"], "tribo_V_wall = 1e3: a contact potential of 1e3 V"),
])
@pytest.mark.parametrize("command", ["run", "sweep"])
def test_the_command_line_refuses_before_it_starts(tmp_path, command, args, words):
    r = _gc([command, "--out", tmp_path / "runs", "--N", 10, *args], tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], r.stderr
    assert "Traceback" not in r.stderr and "no LAMMPS build" not in r.stderr
    assert not (tmp_path / "runs").exists()


def _run_params(args, command="run"):
    from granular_charged.studies.axes import var_axes
    a = build_parser().parse_args([command, *args] + (["--out", "x"] if command == "sweep" else []))
    single, _ = var_axes(a.var, command)
    rp = a.rp[0] if isinstance(a.rp, list) else a.rp
    p = deck_params(single, dict(rp=rp, U0=1.0, gamma=0.01, q=0.0),
                    cli_options.population_vars(a), cli_options.refused(command), a.N, 1)
    cli_options.check_species_values(p)
    return p


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_the_options_reach_the_deck_as_given(command):
    p = _run_params(["--tribo", "--tribo-V", "-0.25", "5e-1", "--tribo-V-wall", "-2e-1",
                     "--tribo-z0", "8e-10", "--tribo-field", "no", "--var", "species", "2"],
                    command)
    v = p.deck_vars()
    assert (v["tribo"], v["tribo_V"], v["tribo_V_2"], v["tribo_V_wall"], v["tribo_z0"],
            v["tribo_field"]) == ("yes", "-0.25", "5e-1", "-2e-1", "8e-10", "no")
    # every value is part of the run's key; the default run is not touched
    assert p.key() != _run_params(["--tribo", "--tribo-V", "-0.25", "0.4", "--var", "species",
                                   "2"], command).key()
    plain = _run_params([], command)
    assert "tribo" not in plain.deck_vars() and plain.key() == DepositionParams(seed=1).key()
    # tribo with the deck's defaults is another run than tribo no
    assert _run_params(["--tribo"], command).key() != plain.key()


STUDY = """
name = "bipolar"
seeds = [1, 2]
[deck]
N = 12
tribo = true
tribo_V_wall = 0.2
[[species]]
fraction = 0.5
size = "uniform lo=1.8e-6 hi=2.2e-6"
material = {rho = 2500, tribo_V = 0}
[[species]]
fraction = 0.5
size = "uniform lo=1.8e-6 hi=2.2e-6"
material = {rho = 2500, tribo_V = 0.5}
[grid]
tribo_z0 = [4e-10, 8e-10]
"""


def test_study_file_potentials_per_species_reach_the_deck(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(STUDY)
    ps = studyfile.params(studyfile.load(f))
    assert len(ps) == 4 and len({p.key() for p in ps}) == 4
    for p in ps:
        v = p.deck_vars()
        assert (v["tribo"], v["tribo_V"], v["tribo_V_2"], v["tribo_V_wall"]) == \
            ("yes", "0", "0.5", "0.2")
    assert {p.deck_vars().get("tribo_z0", "4e-10") for p in ps} == {"4e-10", "8e-10"}
    # result.json's population names each species' contact potential
    sp = population.describe(ps[0].deck_vars())["species"]
    assert [s["material"]["tribo_V"] for s in sp] == [0.0, 0.5]
    for bad, words in [("tribo_V = 0.5}", "tribo_V = 50}"), ("tribo_V = 0}", "work = 4.5}")]:
        f.write_text(STUDY.replace(bad, words))
        with pytest.raises(ParamError) as e:
            studyfile.params(studyfile.load(f))
        assert ("tribo_V_2 = 50" in str(e.value) if "50" in words
                else "material has no 'work'" in str(e.value)), str(e.value)


# ---- the analysis against closed forms --------------------------------------------------------

def _snapshot(types, z, q_e0, r=1e-6, L=1e-5):
    n = len(z)
    cols = {"id": np.arange(1, n + 1), "type": np.asarray(types), "x": np.zeros(n),
            "y": np.zeros(n), "z": np.asarray(z, float), "radius": np.full(n, r),
            "q": np.asarray(q_e0, float) * E0}
    return packing.Snapshot(0, np.array([[0, L], [0, L], [0, 1e-3]]), cols)


def test_the_statistics_per_species_are_those_of_the_charges():
    rng = np.random.default_rng(7)
    n = 500
    types = rng.integers(1, 3, n)
    q = np.where(types == 1, rng.normal(40, 10, n), rng.normal(-30, 20, n)).round()
    z = rng.uniform(0, 4e-5, n)
    a = charges.analyse(_snapshot(types, z, q), 2e-6)
    st = {r["species"]: r for r in a["stats"]}
    for t in (1, 2):
        qt = q[types == t]
        # the dump's charges are e0 multiples written with 12 digits: 1e-9 relative
        assert st[t]["n"] == len(qt)
        assert st[t]["q_mean_e0"] == pytest.approx(qt.mean(), rel=1e-9)
        assert st[t]["q_sd_e0"] == pytest.approx(qt.std(ddof=1), rel=1e-9)
        assert st[t]["frac_negative"] == pytest.approx((qt < 0).mean(), abs=0)
        assert st[t]["q_total_e0"] == pytest.approx(qt.sum(), rel=1e-9)
    assert st["all"]["n"] == n and st["all"]["q_total_e0"] == pytest.approx(q.sum(), rel=1e-9)
    # the histogram: common bins over all charges, each species' counts add up to its number
    h = a["histogram"]
    for t in (1, 2):
        assert sum(r["count"] for r in h if r["species"] == t) == (types == t).sum()
    assert min(r["q_lo_e0"] for r in h) == q.min() and max(r["q_hi_e0"] for r in h) == q.max()


def test_the_depth_profile_of_a_linear_charge_is_the_line():
    """q = a (h - z) / r_p + b per species (h = 2 <z>): each depth bin's mean charge is the line at
    the bin's mean depth, exactly; bins are depth_rp wide from multiples of depth_rp."""
    rp = 2e-6
    z = np.linspace(0.5e-6, 40e-6, 400)
    types = np.where(np.arange(400) % 3 == 0, 2, 1)
    h = 2.0 * z.mean()
    d = (h - z) / rp
    q = np.where(types == 1, 3.0 * d - 5.0, -7.0 * d + 1.0)
    snap = _snapshot(types, z, q)
    for width in (1.0, 2.0, 3.5):
        prof = charges.depth_profile(charges.particles(snap, rp), width)
        for row in prof:
            t = row["species"]
            sel = (np.floor(d / width) * width == row["depth_lo_rp"]) & (
                True if t == "all" else types == t)
            assert row["n"] == sel.sum() > 0
            assert row["depth_hi_rp"] - row["depth_lo_rp"] == pytest.approx(width)
            assert np.all((d[sel] >= row["depth_lo_rp"] - 1e-9) & (d[sel] < row["depth_hi_rp"] + 1e-9))
            if t != "all":
                line = (3.0 * d[sel].mean() - 5.0) if t == 1 else (-7.0 * d[sel].mean() + 1.0)
                assert row["q_mean_e0"] == pytest.approx(line, rel=1e-9, abs=1e-9)
        assert sum(r["n"] for r in prof if r["species"] == "all") == 400
    with pytest.raises(ValueError):
        charges.depth_profile(charges.particles(snap, rp), 0.0)


def test_a_dump_without_charges_says_so():
    snap = _snapshot([1], [1e-6], [0.0])
    del snap.cols["q"]
    with pytest.raises(ValueError, match="no column q"):
        charges.analyse(snap, 2e-6)


def test_study_tables_of_the_charges(tmp_path):
    """charges_summary.csv: per grid point and species, the mean of the runs' means and their
    sd over the seeds; charge_depth_summary.csv: the particles' mean, pooled over the seeds."""
    import pandas as pd
    d = {"name": "t", "grid": {"tribo_V_2": [0.5]}, "species": [{"name": "a"}, {"name": "b"}]}
    results = []
    for seed, (m1, m2) in enumerate([(10.0, -20.0), (14.0, -26.0)], start=1):
        q = np.array([m1 - 1, m1 + 1, m2, m2])
        snap = _snapshot([1, 1, 2, 2], [1e-6, 3e-6, 5e-6, 7e-6], q)
        results.append({"key": f"k{seed}", "params": {"seed": seed, "N": 4, "extra":
                                                      {"tribo_V_2": "0.5"}},
                        "phi": None, "Z": None, "fZ": [], "charges": charges.analyse(snap, 1e-6),
                        "lost": 0, "natoms": 4, "inserted": 4, "flying": 0, "settled": True})
    studytables.study_tables(d, results, tmp_path)
    s = pd.read_csv(tmp_path / "charges_summary.csv")
    a = s[s.species_name == "a"].iloc[0]
    b = s[s.species_name == "b"].iloc[0]
    assert a.q_mean_e0 == pytest.approx(12.0) and a.q_mean_sd_e0 == pytest.approx(math.sqrt(8))
    assert b.q_mean_e0 == pytest.approx(-23.0) and b.frac_negative == 1.0 and a.runs == 2
    dep = pd.read_csv(tmp_path / "charge_depth_summary.csv")
    total = dep[dep.species == "all"]
    assert total.n.sum() == 8
    assert (total.q_mean_e0 * total.n).sum() == pytest.approx(2 * 12.0 * 2 - 2 * 23.0 * 2)


# ---- the deck ----------------------------------------------------------------------------------

SMALL = {"N": 12, "L_rp": 5, "H_rp": 30, "seed": 1}


def test_tribo_no_leaves_the_deck_as_it_was(build_dir, tmp_path):
    """The default run defines neither fix tribo/charge nor, neutral, fix coul/fmm, writes no
    GC TRIBO line and no charge column of its own in final.dump."""
    text = lmp_run(build_dir, DECK, tmp_path, SMALL)
    assert not re.search(r"^fix\s+(tribo|coul)\s", text, re.M), "a fix that tribo no must not make"
    assert "GC TRIBO" not in re.sub(r"^(if|print).*$", "", text, flags=re.M)
    head = next(ln for ln in (tmp_path / "final.dump").read_text().splitlines()
                if ln.startswith("ITEM: ATOMS"))
    assert head.split()[2:] == ["id", "type", "x", "y", "z", "radius", "q"]
    assert result_line(text)["deposited"] == "12"


# ---- the tribo path (fix tribo/charge in the build) ------------------------------------------

@pytest.fixture(scope="module")
def tribo_build(build_dir):
    from granular_charged.run.lammps_build import LammpsBuild
    if not LammpsBuild(Path(build_dir)).capabilities.get("tribo/charge"):
        pytest.skip(f"fix tribo/charge is not in the build {build_dir}: the tribo path runs "
                    "once it is")
    return build_dir


def _tribo_line(text: str) -> dict:
    m = re.search(r"^GC TRIBO RESULT (.*)$", text, re.M)
    assert m, "no GC TRIBO RESULT line"
    w = m.group(1).split()
    return {k: float(v) for k, v in zip(w[0::2], w[1::2])}


def _dump(folder: Path) -> dict:
    snap = packing.read_dump(Path(folder) / "final.dump", last_only=True)
    return snap.cols


# a bipolar binary powder injected neutral: species 1 (0 V) and 2 (0.5 V) on a 0.2 V floor;
# species 2, of the higher potential, is charged negatively by species 1 and by the floor,
# species 1 positively by both
BIPOLAR = dict(SMALL, N=16, species=2, frac_2=1, q=0, tribo="yes", tribo_V=0, tribo_V_2=0.5,
               tribo_V_wall=0.2)


def _conserved(text: str, cols: dict):
    """The identities of contact charging from a neutral start: each particle's charge is the
    charge it gained by contacts (the dump's q and f_tribo, 12 digits: 1e-9 relative), the
    particles' total is what the floor gave (GC TRIBO RESULT's wall and Q), and charge moved."""
    t = _tribo_line(text)
    q, gained = cols["q"], cols["f_tribo"]
    scale = max(np.abs(q).sum(), 1e-30)
    np.testing.assert_allclose(q, gained, rtol=1e-9, atol=1e-12 * scale)
    assert q.sum() == pytest.approx(t["wall"], abs=1e-9 * scale)
    assert t["Q"] == pytest.approx(t["wall"], abs=1e-9 * scale)
    assert t["moved"] >= 0 and t["pair_events"] >= 0 and t["wall_events"] > 0
    assert t["unbalanced"] == 0
    return t


@pytest.mark.parametrize("inject", ["rain", "plane", "sequential"])
def test_a_bipolar_binary_charges_by_its_potentials(tribo_build, tmp_path, inject):
    """The population's protocols (rain: one by one; plane; sequential): fix coul/fmm is
    defined although every particle starts neutral; charge is conserved; species 2 (higher
    potential) ends negative on average and species 1 positive."""
    # plane, sequential: H = 60 r_p (the start plane, 7 r_p above the bed top, stays in the box
    # longer when a pair of opposite charges rests high above the 16 particles' bed; above the
    # box the deck ends the deposition, with a warning, and the identities hold all the same)
    text = lmp_run(tribo_build, DECK, tmp_path,
                   dict(BIPOLAR, inject=inject, H_rp=30 if inject == "rain" else 60))
    assert re.search(r"^fix coul all coul/fmm", text, re.M)
    assert re.search(r"^fix tribo all tribo/charge z0 4e-10 potential 0 0.5 wall floor 0.2 "
                     r"wall floor2 0.2 field yes", text, re.M), "the fix as the deck makes it"
    cols = _dump(tmp_path)
    t = _conserved(text, cols)
    assert t["moved"] > 0 and t["pair_events"] > 0
    q, types = cols["q"], cols["type"].astype(int)
    assert q[types == 1].mean() > 0 > q[types == 2].mean(), (q, types)


@pytest.mark.parametrize("inject", ["rain", "plane"])
def test_one_kind_without_field_charges_from_the_floor_only(tribo_build, tmp_path, inject):
    """One kind (rain: fix deposit; plane), 0.5 V on a 0 V floor, field no: like particles
    exchange nothing (V_i - V_j = 0 and no field term), so no charge moves between particles and
    every particle's charge is the floor's, of the sign of V_floor - V: <= 0."""
    v = dict(SMALL, q=0, tribo="yes", tribo_V=0.5, tribo_V_wall=0, tribo_field="no",
             inject=inject)
    text = lmp_run(tribo_build, DECK, tmp_path, v)
    cols = _dump(tmp_path)
    t = _conserved(text, cols)
    assert t["moved"] == 0.0
    assert np.all(cols["q"] <= 0.0) and cols["q"].min() < 0.0
    assert t["wall"] < 0.0


def test_a_run_records_and_analyses_its_charges(tribo_build, tmp_path):
    """granular-charged run --tribo: result.json's tribo (the fix's counters) and charges (per
    species, against depth) agree with final.dump; the tables and the figure in the folder."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC / "python"),
                                                       str(Path(tribo_build) / "python")]),
               GC_BUILD_DIR=str(tribo_build))
    args = ["-q", "run", "--out", tmp_path / "runs", "--seed", 1, "--N", 16, "--var", "L_rp", 5,
            "--var", "H_rp", 30, "--var", "species", 2, "--var", "frac_2", 1, "--no-render",
            "--tribo", "--tribo-V", 0, 0.5, "--tribo-V-wall", 0.2]
    r = subprocess.run([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    res_file = Path(r.stdout.strip().splitlines()[-1])
    res = json.loads(res_file.read_text())
    wd = res_file.parent
    cols = _dump(wd)
    t = res["tribo"]
    assert set(t) == {"moved_C", "wall_C", "pair_events", "wall_events", "unbalanced_quanta",
                      "Q_C"}
    assert t["unbalanced_quanta"] == 0
    assert cols["q"].sum() == pytest.approx(t["wall_C"], abs=1e-9 * np.abs(cols["q"]).sum())
    st = {s["species"]: s for s in res["charges"]["stats"]}
    types = cols["type"].astype(int)
    for s in (1, 2):
        qs = cols["q"][types == s] / E0
        assert st[s]["n"] == len(qs) and st[s]["q_mean_e0"] == pytest.approx(qs.mean(), rel=1e-9)
        assert st[s]["frac_negative"] == (qs < 0).mean()
    assert [m["material"]["tribo_V"] for m in res["population"]["species"]] == [0.0, 0.5]
    # the depth profile of the run's particles with r_p = 2 um, bins of 2 r_p
    df = charges.particles(packing.read_dump(wd / "final.dump", last_only=True), 2e-6)
    assert res["charges"]["depth"] == json.loads(json.dumps(charges.depth_profile(df)))
    assert sum(r["n"] for r in res["charges"]["depth"] if r["species"] == "all") == 16
    for name in ("charges.csv", "charge_depth.csv", "charge_hist.csv",
                 "charge_distribution.png", "charge_distribution.csv"):
        assert (wd / name).exists(), name
    header = (wd / "charges.csv").read_text().splitlines()[0]
    assert header.startswith("species,n,q_mean_e0,q_sd_e0"), header


def test_restart_points_carry_the_contact_charging(tribo_build, tmp_path):
    """One kind, one at a time (sequential), 0.5 V on a 0 V floor with the field: a run stopped
    at its restart point after particle 5 and resumed ends in the same bed and the same charges,
    digit for digit, as the run that was not stopped (the fix's contact records and counters
    are in the restart file: a contact present at the restart point does not charge again)."""
    v = dict(SMALL, N=10, q=0, tribo="yes", tribo_V=0.5, inject="sequential", checkpoint=5)
    whole, split = tmp_path / "whole", tmp_path / "split"
    whole.mkdir()
    split.mkdir()
    t_whole = _tribo_line(lmp_run(tribo_build, DECK, whole, dict(v, out=".")))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = [str(Path(tribo_build) / "lmp"), "-in", str(DECK), "-screen", "none", "-log", "a.log"]
    for k, x in dict(v, out=".", checkpoint_stop=5).items():
        cmd += ["-var", k, str(x)]
    subprocess.run(cmd, cwd=split, env=env, check=True, timeout=600, capture_output=True)
    assert "GC CHECKPOINT STOP" in (split / "a.log").read_text()
    t_split = _tribo_line(lmp_run(tribo_build, DECK, split, dict(v, out=".", resume="yes")))
    assert t_split == t_whole
    assert (split / "final.dump").read_text() == (whole / "final.dump").read_text()


def test_a_run_charged_by_contacts_is_labelled_so():
    r = {"params": {"q": 0.0, "extra": {"tribo": "yes"}}}
    assert studytables.charge_label(r) == "injected uncharged, charged by contacts"
    r = {"params": {"q": 100.0, "extra": {}}}
    assert studytables.charge_label(r) == "q 100 e0"


def test_a_start_plane_above_the_box_ends_the_deposition(build_dir, tmp_path):
    """The plane rain in a box 8 + 4 r_p high: once the bed top plus the start height (7 r_p in a
    box 4 r_p wide) is above the box, the deck ends the deposition with a warning and its result
    line (LAMMPS's create_atoms would stop the run with an error: the case of a cluster of
    opposite charges resting near the lid, made here by the bed itself)."""
    text = lmp_run(build_dir, DECK, tmp_path, {"N": 40, "L_rp": 4, "H_rp": 8, "seed": 1,
                                               "inject": "plane"})
    m = re.search(r"^GC WARNING: particle (\d+): the start height z = (\S+) is above the box "
                  r".*deposition ends with (\d+) particles$", text, re.M)
    assert m, text[-2000:]
    k, z, made = int(m.group(1)), float(m.group(2)), int(m.group(3))
    assert made == k - 1 < 40 and z + 0.01 * 2e-6 >= (8 + 4) * 2e-6
    assert result_line(text)["inserted"] == str(made)
