"""Values the deck or a style would take without a word are refused before LAMMPS starts (one
line, no traceback); a deck variable given at its default is the default run; result.json is
strict JSON with a truthful source; a wrong-typed result.json is redone like a garbage one; a
full disk is said as such and leaves nothing that looks finished."""
import json
import math
import os
import subprocess
from pathlib import Path

import pytest

from granular_charged.run.deckfile import deck_variables
from granular_charged.params import DepositionParams, split_deck_vars
from granular_charged.run.runner import read_result, write_json

TINY = ["--N", 10, "--var", "L_rp", 6, "--var", "H_rp", 60, "--no-render"]


@pytest.mark.parametrize("args, name", [
    (["--var", "eps_p", "-2"], "eps_p = -2"),
    (["--gamma", "-0.01"], "gamma = -0.01"),
    (["--gamma", "nan"], "gamma = nan"),
    (["--U0", "inf"], "U0 = inf"),
    (["--rp", "inf"], "rp = inf"),
    (["--var", "farfield", "bogus"], "farfield = bogus"),
    (["--var", "theta_crit", "nan"], "theta_crit = nan"),
    (["--var", "pair_opt", "maybe"], "pair_opt = maybe"),
])
def test_values_the_deck_would_ignore_are_refused(cli, tmp_path, args, name):
    r = cli(["run", "--out", tmp_path / "o", *TINY, *args], tmp_path, check=False)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and "must be" in lines[0], r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists(), "a folder was made for a refused run"


@pytest.mark.parametrize("value", ["nan", "inf", "-6", "0"])
def test_box_side_must_be_a_positive_number(cli, tmp_path, value):
    r = cli(["run", "--out", tmp_path / "o", "--N", 10, "--var", "L_rp", value], tmp_path,
            check=False)
    assert r.returncode == 2 and f"L_rp = {value}" in r.stderr and "Traceback" not in r.stderr


def test_a_deck_variable_at_its_default_is_the_default_run():
    deck = deck_variables("in.deposition")
    fields, extra = split_deck_vars([("pair_opt", "yes"), ("L_rp", "28.0"), ("eps_p", "0")],
                                    deck, {})
    assert extra == {}
    assert DepositionParams(extra=extra, **fields).key() == DepositionParams().key()
    _, other = split_deck_vars([("pair_opt", "no")], deck, {})
    assert DepositionParams(extra=other).key() != DepositionParams().key()


def test_result_json_is_strict(tmp_path):
    path = tmp_path / "r.json"
    write_json(path, {"phi": float("nan"), "fZ": [0.5, float("inf")], "Z": 4.0})

    def refuse(word):
        raise ValueError(f"not strict JSON: {word}")
    data = json.loads(path.read_text(), parse_constant=refuse)
    assert data == {"phi": None, "fZ": [0.5, None], "Z": 4.0}


def test_a_thin_bed_with_the_computes_says_so(cli, tmp_path):
    r = cli(["-q", "run", "--out", tmp_path, *TINY], tmp_path)
    path = Path(r.stdout.strip().splitlines()[-1])
    res = json.loads(path.read_text(), parse_constant=lambda w: pytest.fail(f"bare {w}"))
    assert res["phi"] is None                        # ten particles: no slab
    assert res["source"] == "python (the bed was too thin for the computes' slab)"


def _kept_result() -> Path:
    from conftest import SRC
    return next((SRC / "doc" / "data" / "paper-size" / "runs").glob("*/result.json"))


@pytest.mark.parametrize("field, value", [("phi", "abc"), ("natoms", "many"),
                                           ("fZ", {"a": 1}), ("wall_s", None)])
def test_a_wrong_typed_result_is_not_finished(cli, tmp_path, field, value):
    res = json.loads(_kept_result().read_text())
    assert read_result(_kept_result()) is not None or res.get("version") != 3
    res[field] = value
    wd = tmp_path / "runs" / res["key"]
    wd.mkdir(parents=True)
    (wd / "result.json").write_text(json.dumps(res))
    assert read_result(wd / "result.json") is None
    # the figures leave it out with a warning, no traceback
    r = cli(["figures", tmp_path / "runs", "--out", tmp_path / "figs"], tmp_path, check=False)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert "values of the wrong type" in r.stderr and field in r.stderr


def test_a_wrong_typed_result_is_run_again_by_a_study(cli, tmp_path):
    r = cli(["-q", "run", "--out", tmp_path / "runs", *TINY], tmp_path)
    path = Path(r.stdout.strip().splitlines()[-1])
    res = json.loads(path.read_text())
    res["phi"] = "abc"
    path.write_text(json.dumps(res))
    cli(["sweep", "--out", tmp_path / "runs", *TINY], tmp_path)
    again = json.loads(path.read_text())
    assert again["phi"] is None and again["complete"]


@pytest.fixture
def small_disk(tmp_path):
    """A 40 kB file system (tmpfs): too small for a run's files."""
    where = tmp_path / "disk"
    where.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=40k", "tmpfs", str(where)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here (needs root): {r.stderr.strip()}")
    yield where
    subprocess.run(["umount", str(where)], check=True)


def test_a_full_disk_is_said_and_nothing_looks_finished(cli, tmp_path, small_disk):
    r = cli(["-q", "run", "--out", small_disk / "o", *TINY], tmp_path, check=False)
    assert r.returncode == 1
    assert "no space left in " + str(small_disk / "o") in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and "molecule file" not in r.stderr, r.stderr
    assert not [f for f in small_disk.rglob("result.json*")]
