"""Every study runs its cases through Snakemake (Debian's `snakemake`), locally or on a cluster.

A study is a list of independent cases, each a folder whose target file says it is finished:
``result.json`` for a deposition, ``table2.csv`` for the Table 2 check of a formed packing (which
needs that packing's result.json first). The package writes the list into a plan (JSON) and runs
the package's one Snakefile on it; each Snakemake job runs ``python -m granular_charged.run.one_case``
for one folder, which writes the target atomically at its end. So Snakemake's own rules give the
rest: a target that exists is never run again (an interrupted study resumes with only the
missing cases), at most ``--jobs`` cases (or cores) at a time locally, one Slurm job per case with
``--slurm`` (its MPI ranks, and a time limit from the case's estimated cost), any batch system
through a ``--cluster`` submission template, ``--dry-run``, and a lock on the study's folder that
refuses a second study writing the same cases.

Why Snakemake: a case already is a folder with a result file, which is exactly Snakemake's unit
(file targets, rerun when missing); it is in Debian 12 beside the package's other dependencies;
it submits to Slurm natively (7.21: ``--slurm``) and to other schedulers by template, from the
same command that runs on a laptop.
"""
from __future__ import annotations

import json
import logging
import math
import os
import shlex
import signal
import socket
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm
from tqdm.contrib.logging import logging_redirect_tqdm

from ..run.after_formation import table2_complete
from ..run.estimate import cpu_seconds
from ..run.logs import read_new_lines, relay_case_line
from ..run.one_case import FAILED
from ..run.runner import read_result

log = logging.getLogger(__name__)

SNAKEFILE = Path(__file__).resolve().parent / "Snakefile"
# the plans and Snakemake's log of each study, inside the study's folder
PLAN_DIR = ".gc-workflow"
LOCKED = "cannot be locked"
# a Slurm time limit: the estimate's upper bound times this, at least this many minutes
TIME_MARGIN = 2.0
MIN_MINUTES = 10


class EngineError(RuntimeError):
    """The workflow engine could not run the study (missing, locked folder, bad cluster options)."""


class DryRunDone(Exception):
    """A dry run printed what would run; the command ends there (nothing is analysed)."""


@dataclass
class Case:
    """One case of a study: its folder (relative to the study's root), what it runs, its MPI
    ranks and its time limit [min]; ``spec``: what one_case needs (kind-specific)."""
    folder: str
    kind: str                    # "deposition" or "table2"
    np: int
    minutes: int
    spec: dict = field(default_factory=dict)

    @property
    def target(self) -> str:
        return f"{self.folder}/{'result.json' if self.kind == 'deposition' else 'table2.csv'}"


@dataclass
class Engine:
    """How a study's cases run: ``jobs`` at a time locally (cores), or submitted to Slurm
    (``slurm`` with account/partition) or through a ``cluster`` submission template, at most
    ``jobs`` queued at once; ``dry_run``: print what would run or be submitted, run nothing;
    ``unlock``: first remove the lock a killed study left on the folder."""
    jobs: int = 1
    slurm: bool = False
    account: str | None = None
    partition: str | None = None
    mem_mb: int | None = None
    cluster: str | None = None
    dry_run: bool = False
    unlock: bool = False
    progress: bool = True
    keep_going: bool = True

    @classmethod
    def from_args(cls, a) -> "Engine":
        """The engine options of a parsed command line (cli.engine_options)."""
        return cls(jobs=getattr(a, "jobs", 1), slurm=getattr(a, "slurm", False),
                   account=getattr(a, "account", None), partition=getattr(a, "partition", None),
                   mem_mb=getattr(a, "mem_mb", None), cluster=getattr(a, "cluster", None),
                   dry_run=getattr(a, "dry_run", False), unlock=getattr(a, "unlock", False),
                   progress=getattr(a, "progress", False))

    # ---- the plan and the command --------------------------------------------------------
    def _plan(self, root: Path, cases: list[Case], runner) -> Path:
        plan_dir = root / PLAN_DIR
        plan_dir.mkdir(parents=True, exist_ok=True)
        path = plan_dir / f"plan-{os.getpid()}-{time.time_ns()}.json"
        command = (f"{shlex.quote(sys.executable)} -m granular_charged.run.one_case "
                   f"{shlex.quote(str(path))}")
        plan = {"root": str(root), "build_dir": str(runner.build.path), "render": runner.render,
                "checkpoint": runner.checkpoint, "timeout": runner.timeout, "command": command,
                "jobs": [dict(target=c.target, folder=c.folder, kind=c.kind, np=c.np,
                              minutes=c.minutes, **c.spec) for c in cases]}
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(plan, indent=1))
        os.replace(tmp, path)
        return path

    def command(self, root: Path, plan: Path) -> list[str]:
        cmd = [sys.executable, "-m", "snakemake", "--snakefile", str(SNAKEFILE),
               "--directory", str(root), "--config", f"plan={plan}",
               # a target that exists is finished, whatever changed since (code, plan); it is
               # written atomically at the end of its case, so it is never half-written, and one
               # marked incomplete by a killed engine is finished all the same (_drop_unusable
               # removes the unusable ones first)
               "--rerun-triggers", "mtime", "--ignore-incomplete", "--latency-wait", "30",
               "--printshellcmds"]
        if self.keep_going:
            cmd.append("--keep-going")
        if self.slurm and self.cluster:
            raise EngineError("--slurm and --cluster: choose one way to submit")
        if self.slurm or self.cluster:
            cmd += ["--jobs", str(self.jobs), "--max-status-checks-per-second", "1"]
            defaults = []
            if self.mem_mb:
                defaults.append(f"mem_mb={int(self.mem_mb)}")
            if self.slurm:
                cmd.append("--slurm")
                # Snakemake evaluates a resource's value as Python: a quoted string stays a
                # name (an account called `max` is not the builtin)
                if self.account:
                    defaults.append(f"slurm_account={self.account!r}")
                if self.partition:
                    defaults.append(f"slurm_partition={self.partition!r}")
            else:
                cmd += ["--cluster", self.cluster]
            if defaults:
                cmd += ["--default-resources", *defaults]
        else:
            cmd += ["--cores", str(self.jobs)]
        if self.dry_run:
            cmd.append("--dry-run")
        return cmd

    # ---- running ---------------------------------------------------------------------------
    def run(self, root: Path, cases: list[Case], runner, describe=None) -> dict:
        """Run the cases not finished in root; returns {'finished': targets that exist,
        'failed': {folder: error}}. ``describe(path)``: a log line for a finished target (None:
        nothing). Raises EngineError when Snakemake cannot start or the folder is locked."""
        root = Path(root).resolve()
        root.mkdir(parents=True, exist_ok=True)
        for c in cases:
            _drop_unusable(root, c)
        targets = [root / c.target for c in cases]
        before = {t for t in targets if t.exists()}
        todo = [c for c in cases if root / c.target not in before]
        where = ("Slurm" if self.slurm else "the cluster" if self.cluster
                 else f"this machine, {self.jobs} at a time")
        log.info("study in %s: %d cases, %d finished before, %d to run on %s", root, len(cases),
                 len(before), len(todo), where)
        plan = self._plan(root, cases, runner)
        try:
            if self.unlock:
                self._snakemake(self.command(root, plan) + ["--unlock"], root, quiet=True)
            if self.dry_run:
                print(self._dry_run(root, plan, todo))
                raise DryRunDone()
            if not todo:
                return {"finished": sorted(map(str, before)), "failed": {}}
            rc, logfile = self._watch(root, plan, targets, before, describe)
            if rc != 0 and LOCKED in logfile.read_text(errors="replace") \
                    and not _engines_alive(root):
                # the lock of an engine that is gone (killed with its node): nothing holds it
                log.warning("%s: the lock left by a study that was killed is removed", root)
                self._snakemake(self.command(root, plan) + ["--unlock"], root)
                rc, logfile = self._watch(root, plan, targets, before, describe)
        finally:
            plan.unlink(missing_ok=True)
        finished = [t for t in targets if t.exists()]
        failed = {}
        for c in cases:
            if not (root / c.target).exists():
                msg = root / c.folder / FAILED
                failed[c.folder] = (msg.read_text(errors="replace").strip() if msg.exists()
                                    else f"not finished (Snakemake's log: {logfile})")
        text = logfile.read_text(errors="replace") if logfile.exists() else ""
        if rc != 0 and LOCKED in text:
            raise EngineError(
                f"{root}: another study is writing these cases now (Snakemake's lock on the "
                "folder); wait for it to end. If none is running (one was killed), run the "
                "same command again with --unlock")
        if rc != 0 and not failed:
            tail = "\n".join(text.splitlines()[-20:])
            raise EngineError(f"Snakemake failed (exit {rc}, log {logfile}):\n{tail}")
        for folder, err in failed.items():
            log.error("case FAILED %s: %s", folder, err)
        if failed:
            log.warning("%d of %d cases failed (run the same command again to retry them)",
                        len(failed), len(cases))
        return {"finished": sorted(map(str, finished)), "failed": failed}

    def _snakemake(self, cmd, root: Path, quiet=False) -> subprocess.CompletedProcess:
        r = subprocess.run(cmd, env=_job_env(), capture_output=True, text=True)
        if r.returncode != 0 and not quiet:
            raise EngineError(f"Snakemake failed in {root} (exit {r.returncode}):\n"
                              f"{(r.stdout + r.stderr)[-3000:]}")
        return r

    def _dry_run(self, root: Path, plan: Path, todo: list[Case]) -> str:
        """What would run or be submitted: one line per case (folder, ranks, time limit), and
        Snakemake's own dry run (its jobs and their resources)."""
        r = self._snakemake(self.command(root, plan), root)
        how = ("sbatch" + (f" -A {self.account}" if self.account else "")
               + (f" -p {self.partition}" if self.partition else "")) if self.slurm \
            else (self.cluster or "local")
        lines = [f"dry run: {len(todo)} case(s) to run in {root} ({how}):"]
        lines += [f"  {c.folder}: {c.np} MPI rank(s), time limit {c.minutes} min"
                  + (f", --ntasks={c.np} -t {c.minutes}" if self.slurm else "") for c in todo]
        lines += ["", "Snakemake's dry run:", r.stdout.strip()]
        return "\n".join(lines)

    def _watch(self, root: Path, plan: Path, targets, before, describe):
        """Run Snakemake (its output into PLAN_DIR/snakemake-<time>.log) while a bar counts
        the finished targets, with elapsed time and ETA; logs each case as it finishes."""
        logfile = root / PLAN_DIR / f"snakemake-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"
        seen = set(before)
        t0 = time.monotonic()
        pos = 0
        with open(logfile, "w") as fh:
            # a group of its own, so that an interruption reaches Snakemake, its jobs and their
            # LAMMPS children together, as a Ctrl-C at a terminal does
            proc = subprocess.Popen(self.command(root, plan), env=_job_env(), stdout=fh,
                                    stderr=subprocess.STDOUT, text=True, start_new_session=True)
            alive = root / PLAN_DIR / f"engine-{socket.gethostname()}-{proc.pid}"
            alive.touch()
            try:
                with logging_redirect_tqdm(), tqdm(total=len(targets), initial=len(before),
                                                   unit="case", desc="study",
                                                   disable=not self.progress,
                                                   dynamic_ncols=True) as bar:
                    while True:
                        try:
                            rc = proc.wait(timeout=1.0)
                        except subprocess.TimeoutExpired:
                            rc = None
                        pos = _relay(logfile, pos)
                        new = [t for t in targets if t not in seen and t.exists()]
                        for t in new:
                            seen.add(t)
                            bar.update(1)
                            line = describe(t) if describe else None
                            log.info("%s %s", progress(len(seen) - len(before),
                                                       len(targets) - len(before), len(targets),
                                                       time.monotonic() - t0),
                                     line or t.parent.relative_to(root))
                        if rc is not None:
                            alive.unlink(missing_ok=True)
                            return rc, logfile
            except BaseException:
                # Ctrl-C: Snakemake stops its running jobs (their targets stay missing)
                if proc.poll() is None:
                    _signal_group(proc.pid, signal.SIGINT)
                    try:
                        proc.wait(timeout=60)
                    except subprocess.TimeoutExpired:
                        _signal_group(proc.pid, signal.SIGKILL)
                        proc.wait()
                raise


def progress(new_done: int, todo: int, total: int, elapsed: float) -> str:
    """'[done/total cases, elapsed T, ETA T]', the ETA from the mean time of the cases this
    study finished so far (those finished before do not make it look faster)."""
    left = todo - new_done
    eta = tqdm.format_interval(elapsed / new_done * left) if new_done else "?"
    return (f"[{total - left}/{total} cases, elapsed {tqdm.format_interval(elapsed)}, "
            f"ETA {eta}]")


def _relay(logfile: Path, pos: int) -> int:
    """Relay the cases' marked log lines written to Snakemake's log since byte pos."""
    lines, pos = read_new_lines(logfile, pos)
    for line in lines:
        relay_case_line(line, log)
    return pos


def _signal_group(pid: int, sig):
    try:
        os.killpg(pid, sig)
    except ProcessLookupError:
        pass


def _engines_alive(root: Path) -> bool:
    """Whether a Snakemake process started by a study on this folder may still be running: one
    on another host, or one on this host whose process exists (engine-<host>-<pid> files)."""
    host = socket.gethostname()
    for f in (root / PLAN_DIR).glob("engine-*"):
        h, _, pid = f.name[len("engine-"):].rpartition("-")
        if h != host or not pid.isdigit():
            return True
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
        except OSError:
            f.unlink(missing_ok=True)
            continue
        if b"snakemake" in cmdline:
            return True
        f.unlink(missing_ok=True)
    return False


def _job_env() -> dict:
    """The environment of Snakemake and its jobs: this package first on PYTHONPATH."""
    env = dict(os.environ)
    here = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join([here] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p and p != here])
    return env


def _drop_unusable(root: Path, case: Case):
    """A target that exists but cannot be used (garbage, an older version, wrong types) is
    removed, so that the engine runs its case again."""
    path = root / case.target
    if not path.exists():
        return
    if case.kind == "deposition":
        ok = read_result(path) is not None
    else:
        ok = table2_complete(path.parent, case.spec["qs"])
    if not ok:
        log.info("%s: unusable or of an older version, run again", path)
        path.unlink()


def minutes_for(cpu_s: float, factor: float, np_ranks: int) -> int:
    """A time limit [min] for a case of estimated CPU time cpu_s (x/ factor): the estimate's
    upper bound times TIME_MARGIN, at least MIN_MINUTES. Not divided by the np_ranks: a bed of
    a few thousand particles gains far less than the ranks from them, and a limit too short
    loses the run while one too long only waits longer in the queue."""
    return max(MIN_MINUTES, math.ceil(cpu_s * factor * TIME_MARGIN / 60))


def deposition_cases(params, runs_folder: str, np_ranks: int, tracer=0, calibrate=()) -> list[Case]:
    """The cases of depositions (runs_folder/<key>, relative to the study's root), each with
    its time limit from the cost estimate (estimate.cpu_seconds)."""
    costs = cpu_seconds(params, calibrate)
    cases = []
    for p, (cpu, factor) in zip(params, costs):
        tr = tracer(p) if callable(tracer) else tracer
        cases.append(Case(folder=f"{runs_folder}/{p.key()}" if runs_folder else p.key(),
                          kind="deposition", np=np_ranks,
                          minutes=minutes_for(cpu, factor, np_ranks),
                          spec={"params": _params_dict(p), "tracer": tr}))
    return cases


def table2_case(folder: str, formed: str, qs, extra: dict, np_ranks: int, minutes: int) -> Case:
    return Case(folder=folder, kind="table2", np=np_ranks, minutes=minutes,
                spec={"formed": formed, "qs": [float(q) for q in qs], "extra": dict(extra)})


def _params_dict(p) -> dict:
    from dataclasses import asdict
    return asdict(p)
