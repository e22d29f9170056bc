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

The engine and its jobs end with the command that started them, however it ends (Engine._watch,
guard), so a killed study leaves nothing running; a second command on the folder of a running
one names that command's PID. A failure of Snakemake itself (EngineFailed: its first error line
and what it means) is told apart from a failure of a case (failed.txt in its folder).

Why Snakemake: a case already is a folder with a result file, which is exactly Snakemake's unit
(file targets, rerun when missing); it is in Debian 12 beside the package's other dependencies;
it submits to Slurm natively (7.21: ``--slurm``) and to other schedulers by template, from the
same command that runs on a laptop.
"""
from __future__ import annotations

import ctypes
import json
import logging
import math
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm
from tqdm.contrib.logging import logging_redirect_tqdm

from ..run.after_formation import table2_complete
from ..run.estimate import cpu_seconds
from ..run.child import process_start_time
from ..run.logs import read_new_lines, relay_case_line
from ..run.one_case import FAILED
from ..run.runner import read_result

log = logging.getLogger(__name__)

SNAKEFILE = Path(__file__).resolve().parent / "Snakefile"
# what each job's command runs in (guard): the job ends when the study's command has ended
GUARD = f"{shlex.quote(sys.executable)} -m granular_charged.studies.engine --guard --"
# the plans and Snakemake's log of each study, inside the study's folder
PLAN_DIR = ".gc-workflow"
LOCKED = "cannot be locked"
# the command that started a study's engine, HOST:PID:START (START: the process's start time,
# so that a reused PID is not taken for it); each job of the engine ends when it has ended
OWNER_ENV = "GC_STUDY_OWNER"
# how often a job's guard looks whether that command is still there [s]
GUARD_POLL = 0.25
# the exit status of a command whose engine failed (a failed case: 1)
ENGINE_FAILED_STATUS = 3
# a Slurm time limit: the estimate's upper bound times this, at least this many minutes
TIME_MARGIN = 2.0
MIN_MINUTES = 10


class EngineError(RuntimeError):
    """The workflow engine could not run the study (missing, locked folder, bad cluster options)."""
    status = 1


class EngineFailed(EngineError):
    """The engine itself stopped (Snakemake's own error, not a case's): the cases it did not run
    are not failed, they run when the same command is run again."""
    status = ENGINE_FAILED_STATUS


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
        command = (f"{GUARD} {shlex.quote(sys.executable)} -m granular_charged.run.one_case "
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
        nothing). Raises EngineError when Snakemake cannot start or the folder is locked, and
        EngineFailed when Snakemake itself stopped before running every case."""
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
                    and not live_engines(root):
                # the lock of an engine that is gone (killed with its node): nothing holds it
                log.warning("%s: the lock left by a study that was killed is removed", root)
                self._snakemake(self.command(root, plan) + ["--unlock"], root)
                rc, logfile = self._watch(root, plan, targets, before, describe)
        finally:
            plan.unlink(missing_ok=True)
        text = logfile.read_text(errors="replace") if logfile.exists() else ""
        if rc != 0 and LOCKED in text:
            raise EngineError(locked_message(root, live_engines(root)))
        finished = [t for t in targets if t.exists()]
        # a case failed when its job did (Snakemake's "Error in rule" names its target); one
        # the engine did not get to is not failed, whatever an earlier study left in its folder
        errored = failed_jobs(text)
        failed, not_run = {}, []
        for c in cases:
            if (root / c.target).exists():
                continue
            if c.target in errored:
                msg = root / c.folder / FAILED
                failed[c.folder] = (msg.read_text(errors="replace").strip() if msg.exists()
                                    else f"its job failed (Snakemake's log: {logfile})")
            else:
                not_run.append(c.folder)
        for folder, err in failed.items():
            log.error("case FAILED %s: %s", folder, err)
        if failed:
            log.warning("%d of %d cases failed (run the same command again to retry them)",
                        len(failed), len(cases))
        error = engine_error(text) if rc != 0 else None
        if (rc != 0 and (error or not failed or (not_run and self.keep_going))) \
                or (rc == 0 and not_run):
            # Snakemake's own failure: its cases are not failed, they are still to run
            raise EngineFailed(failure_message(rc, error, not_run, len(cases), logfile))
        if not_run:
            log.warning("%d of %d cases did not run: the study stops at its first failed case",
                        len(not_run), len(cases))
        return {"finished": sorted(map(str, finished)), "failed": failed}

    def _snakemake(self, cmd, root: Path, quiet=False) -> subprocess.CompletedProcess:
        r = subprocess.run(cmd, env=_job_env(), capture_output=True, text=True,
                           preexec_fn=_die_with_parent(signal.SIGKILL))
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
        the finished targets, with elapsed time and ETA; logs each case as it finishes.

        Snakemake ends with this process, however it ends: it stays in this process's group
        (a signal to the group, such as Ctrl-C at a terminal or a kill of the whole command,
        reaches it and its local jobs), and it has a parent-death signal (this process killed
        alone: SIGKILL locally; SIGINT with a batch system, on which Snakemake tries to cancel its
        submitted jobs). Each job runs under a guard (``--guard``) that ends it when this
        process has ended."""
        logfile = root / PLAN_DIR / f"snakemake-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"
        seen = set(before)
        t0 = time.monotonic()
        pos = 0
        death = signal.SIGINT if (self.slurm or self.cluster) else signal.SIGKILL
        with open(logfile, "w") as fh:
            proc = subprocess.Popen(self.command(root, plan), env=_job_env(), stdout=fh,
                                    stderr=subprocess.STDOUT, text=True,
                                    preexec_fn=_die_with_parent(death))
            alive = root / PLAN_DIR / f"engine-{socket.gethostname()}-{proc.pid}"
            alive.write_text(json.dumps({"owner": os.getpid(),
                                         "command": " ".join(map(shlex.quote, sys.argv))}))
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
                # Ctrl-C at a terminal reached Snakemake and its local jobs with this process;
                # anything else (a signal to this process alone, an error) is passed on. Its
                # running jobs stop, their targets stay missing.
                _stop(proc, local=not (self.slurm or self.cluster))
                alive.unlink(missing_ok=True)
                raise


def _stop(proc: subprocess.Popen, local: bool):
    """Stop a Snakemake that this process is leaving. After a Ctrl-C at a terminal it ends by
    itself within a second. Else, locally SIGKILL (its jobs end with this process, by their
    guard; a local Snakemake given SIGINT would wait for them, and a job left running would
    finish a case after the user stopped the study); with a batch system SIGINT, on which it
    tries to cancel the jobs it submitted; SIGKILL when it has not ended after a while."""
    steps = ((None, 1), (signal.SIGKILL, None)) if local else \
        ((None, 10), (signal.SIGINT, 30), (signal.SIGKILL, None))
    for sig, wait in steps:
        if proc.poll() is not None:
            return
        if sig is not None:
            proc.send_signal(sig)
        try:
            proc.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            pass


_LIBC = None


def _die_with_parent(sig):
    """A preexec_fn giving the child the parent-death signal sig (Linux prctl
    PR_SET_PDEATHSIG): it gets sig when this thread ends, even by SIGKILL."""
    global _LIBC
    if _LIBC is None:
        _LIBC = ctypes.CDLL(None, use_errno=True)
    prctl, parent = _LIBC.prctl, os.getpid()

    def preexec():
        prctl(1, int(sig), 0, 0, 0)             # PR_SET_PDEATHSIG
        if os.getppid() != parent:              # the parent died before that
            os.kill(os.getpid(), sig)
    return preexec


def _owner() -> str:
    """This process as the owner of an engine: OWNER_ENV's value."""
    return f"{socket.gethostname()}:{os.getpid()}:{process_start_time(os.getpid())}"


def guard(argv: list[str]) -> int:
    """Run a job's command argv (``python -m granular_charged.studies.engine --guard -- ARGV``)
    and end it when the study's command (OWNER_ENV) has ended: a job of a killed study does not
    go on in the background. The job gets SIGKILL if this guard is killed (parent-death
    signal), and SIGINT/SIGTERM sent to the guard; its output is passed on with every line that
    is not a case's log line (run.logs.CASE_MARK) indented, so that the engine's own errors
    stand out in Snakemake's log (engine_error). On another host (a cluster's node) the owner
    cannot be seen and the job is not watched."""
    host, _, rest = os.environ.get(OWNER_ENV, "").partition(":")
    pid, _, born = rest.partition(":")
    watch = host == socket.gethostname() and pid.isdigit()
    if watch and process_start_time(int(pid)) != born:
        print(f"the study's command (PID {pid}) has ended: this job does not run",
              file=sys.stderr)
        return 1
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            preexec_fn=_die_with_parent(signal.SIGKILL))
    def forward(sig, _frame):
        try:
            proc.send_signal(sig)
        except OSError:
            pass
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, forward)

    def copy():
        from ..run.logs import CASE_MARK
        for raw in proc.stdout:
            line = raw.decode(errors="replace")
            sys.stdout.write(line if line.startswith(CASE_MARK) else "    " + line)
            sys.stdout.flush()
    copier = threading.Thread(target=copy, daemon=True)
    copier.start()
    while True:
        try:
            rc = proc.wait(timeout=GUARD_POLL)
            break
        except subprocess.TimeoutExpired:
            pass
        if watch and process_start_time(int(pid)) != born:
            proc.kill()
            proc.wait()
            print(f"    the study's command (PID {pid}) has ended: this job is stopped",
                  flush=True)
            return 1
    copier.join(timeout=10)
    return rc if rc >= 0 else 128 - rc


def failed_jobs(text: str) -> set[str]:
    """The targets of the jobs that failed, from Snakemake's log ("Error in rule R:" blocks
    with their "output: T" line)."""
    out, inside = set(), False
    for line in text.splitlines():
        if line.startswith("Error in rule "):
            inside = True
        elif inside and line.strip().startswith("output:"):
            out.update(line.split(":", 1)[1].replace(",", " ").split())
        elif inside and not line.startswith(" "):
            inside = False
    return out


def engine_error(text: str) -> str | None:
    """The first error of Snakemake itself in its log, one line ("KeyError: 'USER'",
    "WorkflowError: SLURM job submission failed ..."), None if there is none. The jobs' own
    output is indented by their guard and a failed job is reported in an "Error in rule"
    block: neither counts."""
    lines = text.splitlines()
    for k, line in enumerate(lines):
        m = ERROR_LINE.match(line)
        if not m or line.startswith(JOB_ERRORS):
            continue
        if not line[m.end():].strip():
            # "WorkflowError:" with its message on the next line
            rest = [ln.strip() for ln in lines[k + 1:k + 4] if ln.strip()]
            return f"{m.group(1)}: {rest[0]}" if rest else m.group(1)
        return line.strip()
    return None


# an error line of Snakemake (an exception's name, or "Error"), not indented; those of a job
ERROR_LINE = re.compile(r"^((?:[A-Za-z_][\w.]*)?(?:Error|Exception))(?::|$)")
JOB_ERRORS = ("Error in rule ", "Error executing rule ", "MissingOutputException",
              "IncompleteFilesException")


# what an error of Snakemake means and what to do, by a pattern of its first error line
MEANINGS = (
    (r"KeyError: '([A-Z_]+)'",
     "the environment variable {0} is not set and Snakemake needs it (its Slurm submission "
     "asks sacct and sacctmgr for $USER's accounts): set it (export {0}=$(id -un))"),
    (r"SLURM job submission failed",
     "sbatch refused the job: check --account and --partition (sacctmgr show associations "
     "user=$USER lists yours) and the limits of the partition (sinfo)"),
    (r"account .* appears to be invalid",
     "the --account is not one of this user's Slurm accounts: give one that Snakemake lists"),
    (r"Failed to run (\w+)|(\w+): not found",
     "a Slurm command is missing on this machine: run the study on a login node of the "
     "cluster, where sbatch, sacct and sinfo are"),
)


def failure_message(rc: int, error: str | None, not_run: list[str], total: int,
                    logfile: Path) -> str:
    """One line: Snakemake's own failure, what it means, what to do."""
    if error is None:
        error = (f"killed by signal {-rc}" if rc < 0
                 else f"exit {rc} without an error message")
    meaning = "Snakemake stopped on an error of its own, not of a case (its log has the details)"
    for pattern, text in MEANINGS:
        m = re.search(pattern, error)
        if m:
            meaning = text.format(*(g for g in m.groups() if g))
            break
    cases = (f"{len(not_run)} of {total} cases did not run (they did not fail)" if not_run
             else "every case ran")
    return (f"the engine (Snakemake) failed: {error}; {cases}. What it means: {meaning}; then "
            f"run the same command again (Snakemake's log: {logfile})")


def live_engines(root: Path) -> list[dict]:
    """The engines started by studies on this folder that may still be running, each
    {host, pid, owner (the PID of the command that started it, None if unknown or gone)}:
    one on another host, or one on this host whose Snakemake process exists (from the
    engine-<host>-<pid> files; those of engines that are gone are removed)."""
    host = socket.gethostname()
    found = []
    for f in sorted((root / PLAN_DIR).glob("engine-*")):
        h, _, pid = f.name[len("engine-"):].rpartition("-")
        try:
            info = json.loads(f.read_text() or "{}")
        except (OSError, ValueError):
            info = {}
        owner = info.get("owner")
        if h != host or not pid.isdigit():
            found.append({"host": h, "pid": pid, "owner": owner})
            continue
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
        except OSError:
            f.unlink(missing_ok=True)
            continue
        if b"snakemake" not in cmdline:
            f.unlink(missing_ok=True)
            continue
        if owner is not None and process_start_time(int(owner)) is None:
            owner = None
        found.append({"host": h, "pid": pid, "owner": owner})
    return found


def locked_message(root: Path, engines: list[dict]) -> str:
    """Why the folder is locked and how to go on: the running engine (its PID, how to stop
    it), or a lock nobody holds here."""
    host = socket.gethostname()
    for e in engines:
        if e["host"] != host:
            return (f"{root}: a study started on host {e['host']} is running on this folder "
                    f"(its engine, Snakemake, is PID {e['pid']} there); wait for it to end, or "
                    f"stop it on {e['host']} with `kill {e['owner'] or e['pid']}`. If that "
                    "host is gone, run the same command again with --unlock")
    for e in engines:
        if e["owner"]:
            return (f"{root}: a study is running on this folder (granular-charged, PID "
                    f"{e['owner']}; its engine, Snakemake, PID {e['pid']}); wait for it to "
                    f"end, or stop it and its runs with `kill {e['owner']}`")
        return (f"{root}: the engine of a study that ended is still running on this folder "
                f"(Snakemake, PID {e['pid']}); stop it and its runs with `kill {e['pid']}` "
                f"(if it was started in a process group of its own: `kill -- -{e['pid']}`)")
    return (f"{root}: Snakemake's lock is on this folder, but no study's engine runs on this "
            "machine; if none runs on another one either, run the same command again with "
            "--unlock")


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


def _job_env() -> dict:
    """The environment of Snakemake and its jobs: this package first on PYTHONPATH, this
    process as their owner (OWNER_ENV)."""
    env = dict(os.environ)
    env[OWNER_ENV] = _owner()
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


if __name__ == "__main__":
    if sys.argv[1:2] != ["--guard"] or "--" not in sys.argv[2:3]:
        sys.exit("usage: python -m granular_charged.studies.engine --guard -- COMMAND ...")
    sys.exit(guard(sys.argv[3:]))
