"""Studies run through the workflow engine (Snakemake, granular_charged.studies.engine): an interrupted
study resumes with only its missing runs and ends as a clean one; the Slurm path through
stand-in sbatch/sacct commands carries each run's ranks, time and resources; a second study on
the folder of a running one is refused and nothing is corrupted."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import SRC

STANDINS = Path(__file__).resolve().parent / "slurm_standins"
# five tiny neutral runs (two speeds, seeds): seconds each
STUDY = ["sweep", "--N", 20, "--q", 0, "--U0", 1, 2, "--seeds", 1, 2, 3, "--no-render",
         "--var", "L_rp", 6, "--var", "H_rp", 60, "--var", "gap_rp", 1]
RUNS = 6
# what a run computes; its times and folder differ from one execution to the next
SAME = ("key", "params", "phi", "Z", "fZ", "inserted", "natoms", "lost", "flying", "python")


def env_for(build_dir, **extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
    env["GC_BUILD_DIR"] = str(build_dir)
    env.update(extra)
    return env


def start(build_dir, args, cwd, **extra):
    """The command line in a process group of its own (so that the test can kill all of it)."""
    return subprocess.Popen([sys.executable, "-m", "granular_charged"] + [str(a) for a in args],
                            cwd=cwd, env=env_for(build_dir, **extra), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)


def finish(proc, timeout=600) -> str:
    out, _ = proc.communicate(timeout=timeout)
    return out


def results(folder: Path) -> dict:
    return {f.parent.name: json.loads(f.read_text()) for f in folder.glob("*/result.json")}


def test_killed_study_resumes_with_only_its_missing_runs(build_dir, tmp_path):
    out = tmp_path / "study"
    proc = start(build_dir, STUDY + ["--out", out, "--jobs", 2], tmp_path)
    t0 = time.monotonic()
    while len(results(out)) < 2:
        assert proc.poll() is None, finish(proc)
        assert time.monotonic() - t0 < 300, "no run finished in 300 s"
        time.sleep(0.2)
    # the whole study at once, as a lost node: the command, and the engine with its jobs and
    # their LAMMPS children (a process group of its own, named by its engine-<host>-<pid> file)
    engines = list((out / ".gc-workflow").glob("engine-*"))
    os.killpg(proc.pid, signal.SIGKILL)
    for f in engines:
        os.killpg(int(f.name.rsplit("-", 1)[1]), signal.SIGKILL)
    proc.wait()
    done = results(out)
    assert 2 <= len(done) < RUNS, "the study was not interrupted mid-way"
    stamps = {k: (out / k / "result.json").stat().st_mtime_ns for k in done}

    resumed = start(build_dir, STUDY + ["--out", out, "--jobs", 2], tmp_path)
    log = finish(resumed)
    assert resumed.returncode == 0, log
    assert f"{len(done)} finished before, {RUNS - len(done)} to run" in log, log
    assert "the lock left by a study that was killed is removed" in log, log
    after = results(out)
    assert len(after) == RUNS
    # the runs finished before the kill were not run again
    assert {k: (out / k / "result.json").stat().st_mtime_ns for k in done} == stamps

    clean_dir = tmp_path / "clean"
    clean = start(build_dir, STUDY + ["--out", clean_dir, "--jobs", 2], tmp_path)
    assert (log := finish(clean)) and clean.returncode == 0, log
    clean_runs = results(clean_dir)
    assert sorted(clean_runs) == sorted(after)
    for k in after:
        assert {f: after[k][f] for f in SAME} == {f: clean_runs[k][f] for f in SAME}, k


def test_study_through_slurm_carries_ranks_time_and_resources(build_dir, tmp_path):
    standin = tmp_path / "slurm"
    path = f"{STANDINS}{os.pathsep}{os.environ.get('PATH', '')}"
    out = tmp_path / "study"
    args = ["sweep", "--N", 20, "--q", 0, "--seeds", 1, 2, "--no-render", "--np", 2,
            "--var", "L_rp", 6, "--var", "H_rp", 60, "--var", "gap_rp", 1, "--out", out,
            "--slurm", "--account", "standin-account", "--partition", "standin-part",
            "--mem-mb", 500, "--jobs", 2]
    env = dict(SLURM_STANDIN=str(standin), PATH=path, USER=os.environ.get("USER", "root"),
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    dry = start(build_dir, args + ["--dry-run"], tmp_path, **env)
    text = finish(dry)
    assert dry.returncode == 0, text
    assert "2 case(s) to run" in text and "--ntasks=2 -t 10" in text, text
    assert not (standin / "calls.jsonl").exists(), "a dry run submitted jobs"
    assert not list(out.glob("*/result.json"))

    proc = start(build_dir, args, tmp_path, **env)
    log = finish(proc)
    assert proc.returncode == 0, log
    calls = [json.loads(ln) for ln in (standin / "calls.jsonl").read_text().splitlines()]
    assert len(calls) == 2, calls
    for call in calls:
        words = " ".join(call)
        for want in ("-A standin-account", "-p standin-part", "-t 10", "--ntasks=2",
                     "--cpus-per-task=1", "--mem 500"):
            assert want in words, (want, words)
        assert "granular_charged.run.one_case" not in words or "--slurm-jobstep" in words
    done = results(out)
    assert len(done) == 2
    # each job ran its case with the requested ranks
    assert all(r["np"] == 2 for r in done.values())


def test_a_second_study_on_the_folder_of_a_running_one_is_refused(build_dir, tmp_path):
    out = tmp_path / "study"
    first = start(build_dir, STUDY + ["--out", out, "--jobs", 1], tmp_path)
    t0 = time.monotonic()
    # the first study's engine holds the folder once its lock files are there
    while not list((out / ".snakemake" / "locks").glob("*.lock")):
        assert first.poll() is None, finish(first)
        assert time.monotonic() - t0 < 120
        time.sleep(0.1)
    second = start(build_dir, STUDY + ["--out", out, "--jobs", 1], tmp_path)
    text = finish(second)
    assert second.returncode == 1, text
    assert "another study is writing these cases now" in text, text
    log = finish(first)
    assert first.returncode == 0, log
    done = results(out)
    assert len(done) == RUNS
    assert all(r["complete"] and r["natoms"] == 20 for r in done.values())
