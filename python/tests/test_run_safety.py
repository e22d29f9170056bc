"""Runs through LAMMPS that the checks of test_cli_checks.py cannot show: a material --var reaches params and the deck together; two commands running one run
into one folder at once; the LAMMPS child after its runner is killed with SIGKILL.

Size: 5 particles in L = 6 r_p from H = 30 r_p (~1-2 s per run here). The runs that must last
long enough to be interfered with set ke_stop 0 (the stop rule never fires) and settle for
settle_max r_p/U_0 (see LONG)."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import SRC
from granular_charged.params import DepositionParams

TINY = ["--N", 5, "--seed", 1, "--var", "L_rp", 6, "--var", "H_rp", 30, "--no-render"]
# ke_stop 0: no stop before the settling time settle_max r_p / U_0 (~330 steps per unit)
LONG = TINY + ["--var", "ke_stop", 0, "--var", "settle_max", 3000]      # ~20 s: outlasts a second
# command's start-up on a loaded machine (300, ~2 s, did not under a parallel ctest)
ENDLESS = TINY + ["--var", "ke_stop", 0, "--var", "settle_max", 100000]  # ~10 min: killed


def _popen(build_dir, args, cwd):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
    env["GC_BUILD_DIR"] = str(build_dir)
    return subprocess.Popen([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=cwd,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _children(workdir: Path) -> list[int]:
    """Pids of LAMMPS children (python -m granular_charged.run.child) running in workdir."""
    pids = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            cmd = (d / "cmdline").read_bytes()
            state = (d / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if b"granular_charged.run.child" in cmd and str(workdir).encode() in cmd and state != "Z":
            pids.append(int(d.name))
    return pids


def _wait_for(cond, timeout, what):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if cond():
            return
        time.sleep(0.05)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


def test_material_var_is_the_run_parameter(cli, tmp_path):
    """--var farfield average --var rho 3000 with q = 100: LAMMPS ran with them (the fix line
    and the particle mass in log.lammps) and result.json's params, groups and key say so
    (before: params.farfield 'exact', params.rho 2500, Ad of rho = 2500)."""
    r = cli(["-q", "run", "--out", tmp_path, "--q", 100, *TINY, "--var", "farfield", "average",
             "--var", "rho", 3000], cwd=tmp_path)
    rf = Path(r.stdout.strip().splitlines()[-1])
    res = json.loads(rf.read_text())
    assert res["params"]["farfield"] == "average" and res["params"]["rho"] == 3000.0
    assert res["params"]["q"] == 100.0 and res["params"]["extra"] == {"L_rp": "6", "H_rp": "30"}
    assert res["groups"]["Ad"] == pytest.approx(0.010 / (3000 * 1.0 * 2e-6), rel=1e-12)
    assert res["key"] == DepositionParams(q=100, N=5, seed=1, farfield="average", rho=3000,
                                          extra={"L_rp": "6", "H_rp": "30"}).key()
    log = (rf.parent / "log.lammps").read_text()
    assert "farfield average" in log                  # fix coul/fmm's line as LAMMPS ran it
    mass = [ln for ln in log.splitlines() if ln.startswith("variable mass")]
    assert mass[-1].rstrip().endswith("*3000.0"), mass     # m = 4/3 pi rp^3 rho, substituted


def test_two_commands_on_one_run_take_turns(build_dir, tmp_path):
    """The same run started twice into one folder, the second while the first runs: before,
    the second emptied the first's folder as an interrupted run ("Cannot open dump file" in the
    first, or a result.json from a mixed folder); with the run's lock the second waits, then
    finds the run finished. Both exit 0 and the folder holds one complete run."""
    args = ["run", "--out", tmp_path / "runs", *LONG]
    first = _popen(build_dir, args, tmp_path)
    wd = tmp_path / "runs" / DepositionParams(N=5, seed=1, extra={
        "H_rp": "30", "L_rp": "6", "ke_stop": "0", "settle_max": "3000"}).key()
    _wait_for(lambda: (wd / "log.lammps").exists() or first.poll() is not None, 60,
              "the first run's log.lammps")
    assert first.poll() is None, "the first run ended before the second started: make LONG longer"
    second = _popen(build_dir, args, tmp_path)
    out1, err1 = first.communicate(timeout=300)
    out2, err2 = second.communicate(timeout=300)
    assert first.returncode == 0, err1[-3000:]
    assert second.returncode == 0, err2[-3000:]
    assert "another process is running it; waiting" in err2
    assert "finished before (not run again)" in err2
    res = json.loads((wd / "result.json").read_text())
    assert res["complete"] and res["natoms"] == 5
    assert out1.strip() == out2.strip() == str((wd / "result.json").resolve())


@pytest.mark.parametrize("ranks", [1, 2])
def test_lammps_child_exits_when_the_runner_is_killed(build_dir, tmp_path, ranks):
    """kill -9 of the command: before, its LAMMPS child ran on to the end (an orphan holding a
    core); now every rank polls the runner every 0.5 s and exits. Allowed: 10 s (the poll, and
    mpirun's shutdown of the other rank)."""
    proc = _popen(build_dir, ["run", "--out", tmp_path / "runs", "--np", ranks, *ENDLESS],
                  tmp_path)
    wd = tmp_path / "runs"
    try:
        _wait_for(lambda: (len(_children(wd)) >= ranks and any(wd.glob("*/log.lammps")))
                  or proc.poll() is not None, 60, "the LAMMPS child")
        assert proc.poll() is None, proc.communicate()[1][-3000:]
        kids = _children(wd)
        t0 = time.monotonic()
        os.kill(proc.pid, signal.SIGKILL)
        proc.communicate()
        _wait_for(lambda: not _children(wd), 10, "the LAMMPS child to exit")
        print(f"{ranks} rank(s): gone {time.monotonic() - t0:.2f} s after the kill")
    finally:
        if proc.poll() is None:
            proc.kill()
        for pid in _children(wd):      # the orphans of a failed check: the test's own
            os.kill(pid, signal.SIGKILL)
    assert kids
    assert not any(wd.glob("*/result.json"))
