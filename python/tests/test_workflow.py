"""Studies run through the workflow engine (Snakemake, granular_charged.studies.engine): a killed
study leaves no process running (its engine, jobs and LAMMPS end with its command) and resumes
with only its missing runs, ending as a clean one; the Slurm path through stand-in sbatch/sacct
commands carries each run's ranks, time and resources; a second study on the folder of a running
one is refused with the running one's PID, and stopping that as told leaves nothing running;
a failure of the engine itself is said as such (its error and meaning, exit status 3), no case
marked failed, while a failed case stays a failed case."""
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
# three of them
STUDY3 = ["sweep", "--N", 20, "--q", 0, "--U0", 1, "--seeds", 1, 2, 3, "--no-render",
          "--var", "L_rp", 6, "--var", "H_rp", 60, "--var", "gap_rp", 1]
# how long the processes of a killed study may outlive it [s]
GONE_WITHIN = 2.0
# what a run computes; its times and folder differ from one execution to the next
SAME = ("key", "params", "phi", "Z", "fZ", "inserted", "natoms", "lost", "flying", "python")


def env_for(build_dir, unset=(), **extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
    env["GC_BUILD_DIR"] = str(build_dir)
    env.update(extra)
    for name in unset:
        env.pop(name, None)
    return env


def start(build_dir, args, cwd, unset=(), **extra):
    """The command line in a process group of its own (so that the test can kill all of it)."""
    return subprocess.Popen([sys.executable, "-m", "granular_charged"] + [str(a) for a in args],
                            cwd=cwd, env=env_for(build_dir, unset, **extra),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)


def finish(proc, timeout=600) -> str:
    out, _ = proc.communicate(timeout=timeout)
    return out


def results(folder: Path) -> dict:
    return {f.parent.name: json.loads(f.read_text()) for f in folder.glob("*/result.json")}


def study_processes(folder: Path) -> list[str]:
    """The live processes of the study in folder (its command, Snakemake, the jobs, their LAMMPS
    children): those whose command line names the folder or that run in it (/proc)."""
    found = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit() or int(d.name) == os.getpid():
            continue
        try:
            cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            state = (d / "stat").read_text().rsplit(")", 1)[1].split()[0]
            cwd = os.readlink(d / "cwd")
        except OSError:
            continue
        if state in "ZX":          # ended, not yet reaped
            continue
        if str(folder) in cmd or cwd == str(folder) or cwd.startswith(f"{folder}/"):
            found.append(f"{d.name}: {cmd.strip()}")
    return found


def wait_gone(folder: Path, seconds: float) -> list[str]:
    """Poll until no process of the study in folder is left, at most seconds; what is left."""
    t0 = time.monotonic()
    while (left := study_processes(folder)) and time.monotonic() - t0 < seconds:
        time.sleep(0.05)
    return left


def wait_for(condition, proc, seconds, what):
    t0 = time.monotonic()
    while not condition():
        assert proc.poll() is None, finish(proc)
        assert time.monotonic() - t0 < seconds, f"{what}: not after {seconds} s"
        time.sleep(0.1)


@pytest.mark.parametrize("kill", ["group", "command"])
def test_killed_study_leaves_nothing_running_and_resumes_with_only_its_missing_runs(
        build_dir, tmp_path, kill):
    """SIGKILL to the command's process group (a lost terminal, a batch system's kill) or to
    the command alone (nothing it can pass on): its engine, jobs and LAMMPS end with it."""
    out = tmp_path / "study"
    proc = start(build_dir, STUDY3 + ["--out", out, "--jobs", 1], tmp_path)
    wait_for(lambda: len(results(out)) >= 1, proc, 300, "the first run")
    # while the second one runs in LAMMPS
    wait_for(lambda: any("granular_charged.run.child" in p for p in study_processes(out)),
             proc, 300, "the second run")
    running = study_processes(out)
    assert any("snakemake" in p for p in running), running
    t0 = time.monotonic()
    if kill == "group":
        os.killpg(proc.pid, signal.SIGKILL)
    else:
        os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    left = wait_gone(out, GONE_WITHIN - (time.monotonic() - t0))
    assert not left, f"alive {GONE_WITHIN} s after the kill:\n" + "\n".join(left)
    done = results(out)
    assert 1 <= len(done) < 3, "the study was not interrupted mid-way"
    stamps = {k: (out / k / "result.json").stat().st_mtime_ns for k in done}

    resumed = start(build_dir, STUDY3 + ["--out", out, "--jobs", 1], tmp_path)
    log = finish(resumed)
    assert resumed.returncode == 0, log
    assert f"{len(done)} finished before, {3 - len(done)} to run" in log, log
    assert "the lock left by a study that was killed is removed" in log, log
    after = results(out)
    assert len(after) == 3 and all(r["complete"] for r in after.values())
    # the runs finished before the kill were not run again
    assert {k: (out / k / "result.json").stat().st_mtime_ns for k in done} == stamps
    if kill == "command":
        return
    clean_dir = tmp_path / "clean"
    clean = start(build_dir, STUDY3 + ["--out", clean_dir, "--jobs", 1], tmp_path)
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


def test_a_second_study_on_the_folder_of_a_running_one_names_it_and_how_to_stop_it(
        build_dir, tmp_path):
    out = tmp_path / "study"
    first = start(build_dir, STUDY + ["--out", out, "--jobs", 1], tmp_path)
    # the first study's engine holds the folder once its lock files are there
    wait_for(lambda: list((out / ".snakemake" / "locks").glob("*.lock")), first, 120,
             "the first study's lock")
    second = start(build_dir, STUDY + ["--out", out, "--jobs", 1], tmp_path)
    text = finish(second)
    assert second.returncode == 1, text
    assert first.poll() is None, "the first study ended before the second one met it"
    assert f"a study is running on this folder (granular-charged, PID {first.pid};" in text, text
    assert f"stop it and its runs with `kill {first.pid}`" in text, text
    # as told: its engine and runs end with it
    subprocess.run(["kill", str(first.pid)], check=True)
    first.wait(timeout=60)
    left = wait_gone(out, GONE_WITHIN)
    assert not left, "\n".join(left)
    done = results(out)
    assert len(done) < RUNS
    assert all(r["complete"] and r["natoms"] == 20 for r in done.values())


SLURM = ["sweep", "--N", 20, "--q", 0, "--seeds", 1, 2, "--no-render", "--var", "L_rp", 6,
         "--var", "H_rp", 60, "--var", "gap_rp", 1, "--slurm", "--account", "standin-account",
         "--partition", "standin-part", "--jobs", 2]


@pytest.mark.parametrize("setting, error, meaning", [
    ({"unset": ["USER"]}, "KeyError: 'USER'", "the environment variable USER is not set"),
    ({"SLURM_STANDIN_REFUSE": "Invalid account or account/partition combination specified"},
     "WorkflowError: SLURM job submission failed. The error message was sbatch: error: Batch "
     "job submission failed: Invalid account", "sbatch refused the job"),
], ids=["USER-unset", "sbatch-refuses"])
def test_a_failure_of_the_engine_is_not_a_failure_of_the_cases(build_dir, tmp_path, setting,
                                                               error, meaning):
    setting = dict(setting)
    unset = setting.pop("unset", [])
    out = tmp_path / "study"
    env = dict(SLURM_STANDIN=str(tmp_path / "slurm"),
               PATH=f"{STANDINS}{os.pathsep}{os.environ.get('PATH', '')}", **setting)
    if "USER" not in unset:
        env["USER"] = os.environ.get("USER", "root")
    proc = start(build_dir, SLURM + ["--out", out], tmp_path, unset=unset, **env)
    text = finish(proc, timeout=300)
    assert proc.returncode == 3, text
    assert f"the engine (Snakemake) failed: {error}" in text, text
    assert "2 of 2 cases did not run (they did not fail)" in text, text
    assert f"What it means: {meaning}" in text, text
    assert "case FAILED" not in text and "cases failed" not in text, text
    assert not list(out.glob("*/failed.txt")) and not results(out)
    # one line
    assert len([ln for ln in text.splitlines() if "the engine (Snakemake) failed" in ln]) == 1


def test_a_failed_case_is_a_failed_case_and_not_the_engine(tmp_path, monkeypatch):
    """The engine's report of a case whose job fails (here a stand-in job, no LAMMPS): that case
    FAILED with its message, the others finished, no engine failure."""
    from granular_charged.studies import engine

    def plan(self, root, cases, runner):
        (root / engine.PLAN_DIR).mkdir(parents=True, exist_ok=True)
        path = root / engine.PLAN_DIR / "plan.json"
        job = ("sh -c 'mkdir -p $0; if [ $0 = bad ]; then echo broken > $0/failed.txt; exit 1; "
               "fi; echo done > $0/result.json'")
        path.write_text(json.dumps({"root": str(root), "command": f"{engine.GUARD} {job}",
                                    "jobs": [dict(target=c.target, folder=c.folder, kind=c.kind,
                                                  np=1, minutes=10) for c in cases]}))
        return path

    monkeypatch.setattr(engine.Engine, "_plan", plan)
    monkeypatch.setenv("PYTHONPATH", str(SRC / "python"))
    cases = [engine.Case(folder=f, kind="deposition", np=1, minutes=10) for f in ("good", "bad")]
    res = engine.Engine(jobs=1, progress=False).run(tmp_path, cases, runner=None)
    assert res["failed"] == {"bad": "broken"}, res
    assert [Path(t).parent.name for t in res["finished"]] == ["good"]
