"""Restart points of in.deposition (`--checkpoint K`, plane and sequential injection): a run
killed after a restart point goes on from it when run again, and ends in the same packing, bit
for bit, as the run that was never interrupted (doc/deposition.md, "Restart points").

Size: N = 25 in L = 6 r_p from H = 60 r_p, one particle at a time at 400 e_0 (charged: fix
coul/fmm's adaptive time stepping and its restart are part of what must continue), ~5 s per run
here. Nothing is statistical: the assertions are identities of files."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import SRC

SEQ = ["--N", 25, "--seed", 1, "--q", 400, "--var", "L_rp", 6, "--var", "H_rp", 60,
       "--var", "inject", "sequential", "--tracer", 20, "--no-render"]
# the plane rain: the next particle after 2 r_p of fall, the earlier ones still in flight
PLANE = SEQ[:-4] + ["plane", "--var", "seq_gap_rp", 2, "--tracer", 20, "--no-render"]


def _run_dir(root: Path) -> Path:
    (wd,) = [d for d in root.iterdir() if d.is_dir()]
    return wd


def _popen(build_dir, args, cwd):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
    env["GC_BUILD_DIR"] = str(build_dir)
    return subprocess.Popen([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=cwd,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def _restart_particle(wd: Path) -> int:
    from granular_charged.run.runner import restart_point
    point = restart_point(wd)
    return point["k"] if point else 0


def _kill_after_a_point(build_dir, deck, out: Path, cwd: Path, at: int = 10):
    """Start the run with restart points every 5 particles and SIGKILL the command and its
    LAMMPS child once a point at particle `at` or later exists."""
    proc = _popen(build_dir, ["-q", "run", "--out", out, "--checkpoint", 5, *deck], cwd)
    try:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 300 and proc.poll() is None:
            dirs = [d for d in out.glob("*") if d.is_dir()] if out.exists() else []
            if dirs and _restart_particle(dirs[0]) >= at:
                break
            time.sleep(0.02)
        assert proc.poll() is None, "the run ended before it could be interrupted"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)


@pytest.mark.parametrize("deck", [SEQ, PLANE], ids=["sequential", "plane"])
def test_a_killed_run_goes_on_from_its_restart_point(cli, build_dir, tmp_path, deck):
    """The reference runs with restart points and is never interrupted; the other is killed
    (SIGKILL to the command and its LAMMPS child) once a restart point at particle 10 or later
    exists, then run again with the same command. Same final.dump, forces.dump and followed
    particle (tracer.dump, cut back to the restart point and continued); result.json counts
    two pieces, the first one interrupted; the restart files are gone afterwards."""
    ref = tmp_path / "ref"
    cli(["-q", "run", "--out", ref, "--checkpoint", 5, *deck], cwd=tmp_path)
    ref_wd = _run_dir(ref)

    cut = tmp_path / "cut"
    _kill_after_a_point(build_dir, deck, cut, tmp_path)
    wd = _run_dir(cut)
    assert not (wd / "result.json").exists()
    stopped_at = _restart_particle(wd)
    assert 10 <= stopped_at < 25

    cli(["-q", "run", "--out", cut, "--checkpoint", 5, *deck], cwd=tmp_path)
    for name in ("final.dump", "forces.dump", "tracer.dump"):
        assert (wd / name).read_bytes() == (ref_wd / name).read_bytes(), name
    res = json.loads((wd / "result.json").read_text())
    pieces = res["pieces"]
    assert [pc["from_particle"] for pc in pieces] == [0, stopped_at]
    assert pieces[0]["interrupted"] and "interrupted" not in pieces[1]
    assert res["cpu_s"] == pytest.approx(sum(pc["cpu_s"] for pc in pieces))
    assert (wd / "log.lammps.1").exists() and "GC RESULT" in (wd / "log.lammps").read_text()
    assert not list(wd.glob("checkpoint*"))


def test_restart_points_leave_the_run_unchanged(cli, tmp_path):
    """Writing restart points must not perturb the run (LAMMPS's write_restart re-initialises
    the system unless noinit; with that, this charged run parted from the one without restart
    points after the third point): with and without --checkpoint, the same packing."""
    cli(["-q", "run", "--out", tmp_path / "a", *SEQ], cwd=tmp_path)
    cli(["-q", "run", "--out", tmp_path / "b", "--checkpoint", 5, *SEQ], cwd=tmp_path)
    a, b = _run_dir(tmp_path / "a"), _run_dir(tmp_path / "b")
    assert a.name == b.name            # the same run: --checkpoint is not a parameter
    assert (a / "final.dump").read_bytes() == (b / "final.dump").read_bytes()


def test_checkpoint_with_the_rain_is_said(cli, tmp_path):
    """The rain from H is one LAMMPS run command: no restart points between particles. A study
    that runs neutral rain beside charged plane or sequential runs gives --checkpoint to all,
    so the deck says it has no effect (log.lammps) instead of stopping, and writes none."""
    cli(["-q", "run", "--out", tmp_path, "--checkpoint", 5, "--N", 5, "--var", "L_rp", 6,
         "--var", "H_rp", 30, "--no-render"], cwd=tmp_path)
    wd = _run_dir(tmp_path)
    assert "GC WARNING: checkpoint 5 has no effect with inject rain" in (wd / "log.lammps").read_text()
    assert json.loads((wd / "result.json").read_text())["natoms"] == 5
    assert not list(wd.glob("checkpoint*"))


def test_checkpoint_must_be_a_count(cli, tmp_path):
    r = cli(["-q", "run", "--out", tmp_path, "--checkpoint", -1, *SEQ], cwd=tmp_path, check=False)
    assert r.returncode != 0 and "checkpoint = -1" in r.stderr
    assert not any(tmp_path.iterdir())


def test_a_kept_restart_point_goes_on_in_another_folder(cli, build_dir, tmp_path):
    """scripts/keep_runs.py --points keeps an unfinished run's restart point (compressed, its
    interrupted piece closed); --unpack-points puts it into another study folder (as on another
    machine after a git checkout), where the same command finishes the run as the uninterrupted
    one did, bit for bit. Keeping it again after the run finished drops the kept point."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("keep_runs", SRC / "scripts" / "keep_runs.py")
    keep_runs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(keep_runs)

    ref = tmp_path / "ref"
    cli(["-q", "run", "--out", ref, "--checkpoint", 5, *SEQ], cwd=tmp_path)
    cut = tmp_path / "cut"
    _kill_after_a_point(build_dir, SEQ, cut, tmp_path)
    stopped_at = _restart_particle(_run_dir(cut))
    kept = tmp_path / "kept"
    assert keep_runs.keep_points(cut, kept) == 1
    assert keep_runs.keep_points(cut, kept) == 0          # the same point: nothing new
    (kept_run,) = [d for d in kept.iterdir() if d.is_dir()]
    assert (kept_run / f"checkpoint-{stopped_at}.restart.gz").exists()
    assert json.loads((kept_run / "pieces.json").read_text())[0]["interrupted"]

    other = tmp_path / "other"
    assert keep_runs.unpack_points(kept, other) == 1
    assert keep_runs.unpack_points(kept, other) == 0      # already there
    cli(["-q", "run", "--out", other, "--checkpoint", 5, *SEQ], cwd=tmp_path)
    wd, ref_wd = _run_dir(other), _run_dir(ref)
    for name in ("final.dump", "forces.dump", "tracer.dump"):
        assert (wd / name).read_bytes() == (ref_wd / name).read_bytes(), name
    pieces = json.loads((wd / "result.json").read_text())["pieces"]
    assert [pc["from_particle"] for pc in pieces] == [0, stopped_at]
    assert pieces[0]["interrupted"] and pieces[0]["wall_s"] > 0

    assert keep_runs.keep_points(other, kept) == 0 and not kept_run.exists()


@pytest.mark.parametrize("damage", ["truncated", "empty"])
def test_an_unreadable_restart_point_starts_the_run_afresh(cli, build_dir, tmp_path, damage):
    """A restart file cut short or emptied (a full disk, a copy that stopped): the deck keeps
    only the last point, so the run starts afresh, says so in its log and in result.json, and
    ends as a run without restart points does."""
    ref = tmp_path / "ref"
    cli(["-q", "run", "--out", ref, *PLANE], cwd=tmp_path)
    cut = tmp_path / "cut"
    _kill_after_a_point(build_dir, PLANE, cut, tmp_path)
    wd = _run_dir(cut)
    restart = wd / f"checkpoint-{_restart_particle(wd)}.restart"
    data = restart.read_bytes()
    restart.write_bytes(data[: len(data) // 2] if damage == "truncated" else b"")

    r = cli(["run", "--out", cut, "--checkpoint", 5, *PLANE], cwd=tmp_path)
    assert "could not be read; the run started afresh" in r.stderr
    assert "Traceback" not in r.stderr
    res = json.loads((wd / "result.json").read_text())
    assert "could not be read; the run started afresh" in res["restart_note"]
    assert "could not be read" in res["warning"]
    assert (wd / "final.dump").read_bytes() == (_run_dir(ref) / "final.dump").read_bytes()


def test_an_unreadable_pieces_file_keeps_the_earlier_cpu_time(cli, build_dir, tmp_path):
    """pieces.json spoilt while a run was interrupted: the earlier work still counts (one
    interrupted piece from the folder's first file to the restart point), and result.json
    says why."""
    cut = tmp_path / "cut"
    _kill_after_a_point(build_dir, PLANE, cut, tmp_path)
    wd = _run_dir(cut)
    (wd / "pieces.json").write_text('[{"from_particle": 0, "sta')
    cli(["-q", "run", "--out", cut, "--checkpoint", 5, *PLANE], cwd=tmp_path)
    res = json.loads((wd / "result.json").read_text())
    first, last = res["pieces"]
    assert first["interrupted"] and "pieces.json was unreadable" in first["note"]
    assert first["cpu_s"] > 0
    assert res["cpu_s"] == pytest.approx(first["cpu_s"] + last["cpu_s"])
    assert "pieces.json was unreadable" in res["warning"]
