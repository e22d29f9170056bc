"""Values reach the deck as given (a negative area charge of one species of a mixture through
`run`, `sweep` and `study`, the engine's job), and a LAMMPS error is one line: tiny runs."""
import json
import math
import re
from pathlib import Path

import pytest

from granular_charged.params import DepositionParams
from granular_charged.run.lammps_build import LammpsBuild
from granular_charged.run.runner import Runner, RunError

E0 = 1.602176634e-19
SMALL = ["--N", 12, "--var", "L_rp", 5, "--var", "H_rp", 30, "--no-render"]
# species 1 positive, species 2 negative, both by surface area (q = sigma 4 pi r^2)
MIXTURE = ["--charge", "area sigma=3e-7", "--var", "species", 2, "--var", "frac_2", 1,
           "--var", "q_dist_2", "area", "--var", "q_sigma_2", "-2e-7"]


def _charges(folder: Path) -> list[tuple[int, float, float]]:
    """(type, radius, charge) of every particle of final.dump."""
    lines = (folder / "final.dump").read_text().splitlines()
    start = lines.index(next(ln for ln in lines if ln.startswith("ITEM: ATOMS")))
    cols = lines[start].split()[2:]
    t, r, q = cols.index("type"), cols.index("radius"), cols.index("q")
    return [(int(w[t]), float(w[r]), float(w[q])) for w in (ln.split() for ln in lines[start + 1:])]


def _assert_area_charges(folder: Path, sigma: dict):
    rows = _charges(folder)
    assert {t for t, _, _ in rows} == set(sigma), rows
    for t, r, q in rows:
        assert q == pytest.approx(sigma[t] * 4 * math.pi * r * r, rel=1e-9), (t, r, q)


def test_a_negative_area_charge_through_run_and_sweep(cli, tmp_path):
    r = cli(["-q", "run", "--out", tmp_path / "runs", "--seed", 1, *SMALL, *MIXTURE], tmp_path)
    rf = Path(r.stdout.strip().splitlines()[-1])
    assert len(rf.parent.name) <= 100
    _assert_area_charges(rf.parent, {1: 3e-7, 2: -2e-7})
    given = json.loads((rf.parent / "params.json").read_text())
    assert given["deck_vars"]["q_sigma_2"] == "-2e-7" and given["key"] == rf.parent.name
    assert given["non_default"]["q_sigma_2"] == -2e-7
    res = json.loads(rf.read_text())
    assert res["non_default"] == given["non_default"] and res["key"] == rf.parent.name
    # the same run through sweep: the same key, found finished (no second LAMMPS run)
    s = cli(["sweep", "--out", tmp_path / "runs", "--seeds", 1, *SMALL, *MIXTURE], tmp_path)
    assert "0 to run" in s.stderr, s.stderr[-2000:]


TONER = """
name = "toner"
seeds = [1]
protocol = "plane"
[deck]
N = 12
L_rp = 5
H_rp = 30
[[species]]
fraction = 0.7
material = {rho = 1100, E = 5e8, nu = 0.4, gamma = 0.04, e = 0.5, mu = 0.4}
size = "uniform lo=1.8e-6 hi=2.2e-6"
charge = "area sigma=-2e-7"
[[species]]
fraction = 0.3
material = {rho = 2200, E = 1e9, nu = 0.2, gamma = 0.02, e = 0.7, mu = 0.3}
size = "uniform lo=1.5e-6 hi=1.8e-6"
charge = "area sigma=3e-7"
[grid]
together = {q_sigma = [0, -2e-7], q_sigma_2 = [0, 3e-7]}
"""


def test_a_negative_area_charge_through_a_study(cli, tmp_path):
    """A two-species study whose charges vary together: 2 runs (not 4), through the engine's
    job, the charged one with species 1 negative and species 2 positive, as given."""
    f = tmp_path / "toner.toml"
    f.write_text(TONER)
    cli(["-q", "study", f, "--no-render"], tmp_path)
    runs = json.loads("[" + ",".join(p.read_text() for p in
                                     sorted((tmp_path / "toner-output" / "runs").glob("*/result.json"))) + "]")
    assert len(runs) == 2
    by_charge = {r["params"]["extra"]["q_sigma"]: Path(tmp_path / "toner-output" / "runs" / r["key"])
                 for r in runs}
    assert set(by_charge) == {"0", "-2e-07"}
    _assert_area_charges(by_charge["-2e-07"], {1: -2e-7, 2: 3e-7})
    _assert_area_charges(by_charge["0"], {1: 0.0, 2: 0.0})
    table = (tmp_path / "toner-output" / "runs.csv").read_text().splitlines()
    assert table[0].startswith("study,q_sigma,q_sigma_2,") and len(table) == 3


def test_a_lammps_error_is_one_line(cli, tmp_path):
    """A value that passes the deck's rules but that LAMMPS refuses (fix coul/fmm: an accuracy
    finer than its solver reaches): one line with LAMMPS's ERROR, the deck line and the run
    folder; the traceback only with -v."""
    args = ["run", "--out", tmp_path / "runs", "--seed", 1, *SMALL, "--q", 100,
            "--var", "accuracy", "1e-16"]
    r = cli(args, tmp_path, check=False)
    assert r.returncode == 1
    lines = [ln for ln in r.stderr.splitlines() if "ERROR" in ln]
    assert len(lines) == 1, r.stderr
    assert "LAMMPS stopped the run in" in lines[0] and "ERROR: Fix coul/fmm" in lines[0]
    assert "is finer than the solver reaches" in lines[0]
    # LAMMPS checks the accuracy when the fix is initialised, at the deck's first run command
    assert re.search(r"; (in.deposition line \d+|deck line): run 0", lines[0]), lines[0]
    assert str(tmp_path / "runs") in lines[0]
    assert "Traceback" not in r.stderr
    v = cli(["-v"] + args, tmp_path, check=False)
    assert v.returncode == 1 and "Traceback" in v.stderr


def test_the_runner_says_a_lammps_error_in_one_line(build_dir, tmp_path):
    """The same through the runner (the engine's job writes its message into failed.txt)."""
    runner = Runner(LammpsBuild.find(str(build_dir)), render=False)
    variables = DepositionParams(N=12, seed=1, q=100.0,
                                 extra={"L_rp": "5", "H_rp": "30"}).deck_vars()
    variables.update(out=".", accuracy="1e-16")
    with pytest.raises(RunError) as e:
        runner.run_deck("in.deposition", tmp_path / "wd", variables, kind="deposition")
    msg = str(e.value)
    assert "\n" not in msg and "ERROR: Fix coul/fmm" in msg
    assert re.search(r"(in.deposition line \d+|deck line): run 0", msg), msg


def test_an_unsettled_run_says_so(cli, tmp_path):
    """A run whose settling is cut short (settle_max 1 r_p/U_0, far below the settling the stop
    rule needs) ends unsettled: result.json says settled false with a warning, and `run` says
    it; the same run with the default settle_max settles."""
    short = cli(["run", "--out", tmp_path / "runs", "--seed", 1, *SMALL, "--var", "settle_max", 1],
                tmp_path)
    res = json.loads(Path(short.stdout.strip().splitlines()[-1]).read_text())
    assert res["settled"] is False and res["deposited"] == 12
    assert "ended unsettled" in res["warning"] and "ended unsettled" in short.stderr
    full = cli(["run", "--out", tmp_path / "runs", "--seed", 1, *SMALL], tmp_path)
    res = json.loads(Path(full.stdout.strip().splitlines()[-1]).read_text())
    assert res["settled"] is True and "ended unsettled" not in res.get("warning", "")
