"""Run the package's decks through LAMMPS's Python module, one run per folder.

Each run is a child process (``python -m granular_charged.run.child``, optionally under
``mpirun -np K``) that drives LAMMPS with ``from lammps import lammps`` and the deck's variables
as ``-var`` arguments, then reads phi, <Z>, f(Z) and the run's counters from the LAMMPS instance
(``extract_variable``, ``extract_compute``) into ``lammps.json`` and renders the packing
(``packing.png``, dump image). The parent adds the Python analysis of the final dump (the
cross-check of the computes) and writes ``result.json`` atomically: a folder with a complete
``result.json`` is never run again (resumable sweeps); a folder without one (an interrupted run)
is emptied and run again, unless the deck left a restart point there (``checkpoint``, plane and
sequential injection): then the run goes on from it (doc/deposition.md, "Restart points").
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import logging
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..analysis import charges, packing
from ..params import DepositionParams, ParamError, coulomb_to_adhesion
from . import child, estimate, population
from .deckfile import deck_path, deck_variables
from .lammps_build import LammpsBuild
from .logs import eta_seconds, read_new_lines

log = logging.getLogger(__name__)

# 3: charged runs without `inject` now use the plane rain (older results of the same name
# came from the rain and are run again)
RESULT_VERSION = 3
# deck variables the runner sets itself (not extra variables of a run)
RESERVED = {"out": "the run's folder, set by the runner",
            "tracer": "the runner's tracer argument (--tracer)",
            "checkpoint": "the runner's checkpoint argument (--checkpoint)",
            "resume": "set by the runner when a run folder holds a restart point",
            "checkpoint_stop": "a deck variable for tests (it ends a run at a restart point)"}
# a restart point of in.deposition (its checkpoint variable): checkpoint.vars names it (ck_k),
# checkpoint-<ck_k>.restart holds it; and the dumps that follow a run
CHECKPOINT_VARS = "checkpoint.vars"
FOLLOWING_DUMPS = ("tracer.dump", "traj.dump")
# the times of the pieces of a run continued from restart points
PIECES = "pieces.json"
# what every reader of result.json uses (tables, figures, the studies, the resumption)
RESULT_KEYS = ("key", "params", "groups", "phi", "Z", "fZ", "inserted", "natoms", "lost",
               "flying", "wall_s")
PARAM_KEYS = ("rp", "U0", "gamma", "q", "N", "seed")
# the environment variable through which a LAMMPS child learns its parent (child.py watches it)
PARENT_ENV = "GC_PARENT_PID"
# LAMMPS's error lines (Error::all, Error::one), also inside the child's exception
_LAMMPS_ERROR = re.compile(r"ERROR( on proc \d+)?: .*")
# a run's parameters, in its folder beside result.json (write_params)
PARAMS_FILE = "params.json"
# the longest file name (bytes) of the usual file systems
NAME_MAX = 255


class RunError(RuntimeError):
    """A LAMMPS run failed (the message carries the tail of its log)."""


def strict(value):
    """value with every NaN or infinite float as None (strict JSON has no NaN)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict(v) for v in value]
    return value


def write_json(path: Path, data: dict):
    """Write strict JSON (NaN and inf as null) atomically (a temporary file renamed over the
    target): an interrupted write never leaves a truncated file that looks complete; a write
    that fails (a full disk) leaves no temporary file."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(json.dumps(strict(data), indent=1, allow_nan=False))
        os.replace(tmp, path)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        raise no_space(e, path.parent) from e


def no_space(error: OSError, folder: Path) -> OSError:
    """A full disk said as such (with the folder); other errors unchanged."""
    if getattr(error, "errno", None) == errno.ENOSPC:
        return RunError(f"no space left in {folder}")
    return error


def disk_full(folder: Path, need: int = 1 << 20) -> bool:
    """Whether the file system of folder has less than `need` bytes free."""
    try:
        return shutil.disk_usage(folder).free < need
    except OSError:
        return False


def result_problem(res) -> str | None:
    """Why a result.json's content cannot be used (None: it can): not an object, or keys
    missing that the tables, figures and studies read."""
    if not isinstance(res, dict):
        return "not a JSON object"
    missing = [k for k in RESULT_KEYS if k not in res]
    if not isinstance(res.get("params"), dict):
        missing.append("params")
    else:
        missing += [f"params.{k}" for k in PARAM_KEYS if k not in res["params"]]
    if missing:
        return f"keys missing: {', '.join(dict.fromkeys(missing))}"
    wrong = [k for k, ok in (("phi", _number_or_none(res["phi"])), ("Z", _number_or_none(res["Z"])),
                             ("fZ", isinstance(res["fZ"], list)
                              and all(_number_or_none(x) for x in res["fZ"])),
                             ("wall_s", _number(res["wall_s"])))
             if not ok]
    wrong += [k for k in ("inserted", "natoms", "lost", "flying")
              if not (isinstance(res[k], int) and not isinstance(res[k], bool))]
    wrong += [f"params.{k}" for k in PARAM_KEYS if not _number(res["params"][k])]
    if wrong:
        return f"values of the wrong type: {', '.join(wrong)}"
    # written before --var was checked: `--var q 400` ran charged with params.q = 0
    shadow = sorted(set(res["params"].get("extra") or {}) & set(res["params"]))
    if shadow:
        return (f"params.extra sets {', '.join(shadow)} beside params' own value (an older "
                "version's unchecked --var): its parameters do not describe the run")
    return None


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _number_or_none(x) -> bool:
    return x is None or _number(x)


def load_result_files(files, problem=result_problem) -> list[dict]:
    """The usable results among the JSON files ``files`` (sorted), each with 'dir' (its folder):
    a file that is not valid JSON, or whose content has a problem (``problem(r)`` returns a
    message instead of None), is named in a warning and left out."""
    rows = []
    for f in sorted(files):
        try:
            r = json.loads(Path(f).read_text())
        except (OSError, ValueError) as e:
            log.warning("%s: not valid JSON (%s), ignored", f, e)
            continue
        why = problem(r)
        if why:
            log.warning("%s: %s, ignored", f, why)
            continue
        r["dir"] = str(Path(f).parent)
        rows.append(r)
    return rows


def read_result(path: Path) -> dict | None:
    """A complete, usable result.json of the current version, else None."""
    try:
        res = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    if result_problem(res) is None and res.get("version") == RESULT_VERSION and res.get("complete"):
        return res
    return None


@contextlib.contextmanager
def folder_lock(lockfile: Path, what: str):
    """Hold an exclusive lock (fcntl.flock) on lockfile while a run uses its folder: two
    commands writing into one folder at once take turns instead of emptying each other's
    running folder. Waits (with a log line) while another process holds it; the kernel
    releases it when the holder exits, however it exits."""
    lockfile = Path(lockfile)
    lockfile.parent.mkdir(parents=True, exist_ok=True)
    with open(lockfile, "a") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            log.info("%s: another process is running it; waiting for it to finish", what)
            fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def restart_point(workdir: Path, suffix: str = "") -> dict | None:
    """The restart point in.deposition left in a run folder: {'k': particles made, 'step':
    its time step} from checkpoint.vars, or None when the folder has none (or its restart file
    is missing; suffix ".gz": a point kept compressed, scripts/keep_runs.py)."""
    workdir = Path(workdir)
    if not (workdir / CHECKPOINT_VARS).exists():
        return None
    values = {}
    for line in (workdir / CHECKPOINT_VARS).read_text().splitlines():
        words = line.split()
        if len(words) == 4 and words[0] == "variable" and words[2] == "equal":
            values[words[1]] = words[3]
    try:
        point = {"k": int(values["ck_k"]), "step": int(values["ck_step"])}
    except (KeyError, ValueError):
        return None
    return point if (workdir / f"checkpoint-{point['k']}.restart{suffix}").exists() else None


def close_interrupted_pieces(pieces: list[dict], kept_until: float):
    """A piece without times was interrupted: it counts up to its last restart point (written
    at kept_until, a time.time()), as wall and CPU time alike (its later work is done again)."""
    for pc in pieces:
        if "wall_s" not in pc:
            pc["interrupted"] = True
            pc["wall_s"] = pc["cpu_s"] = max(0.0, kept_until - pc["start"])


def trim_dump(path: Path, before_step: int):
    """Keep the snapshots of a LAMMPS text dump from before a step: a run continued from a
    restart point at that step writes the later ones again."""
    path = Path(path)
    if not path.exists():
        return
    blocks = path.read_text().split("ITEM: TIMESTEP\n")
    keep = [b for b in blocks[1:] if int(b.split("\n", 1)[0]) < before_step]
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("".join("ITEM: TIMESTEP\n" + b for b in keep))
    os.replace(tmp, path)


def deck_commands(text: str) -> dict[str, int]:
    """{command: its first line number} of a deck: lines continued with & joined, comments
    (# outside quotes) dropped, white space collapsed, as LAMMPS echoes them in its log."""
    out, buf, first = {}, "", 0
    for n, line in enumerate(text.splitlines(), start=1):
        first = first or n
        line = _strip_comment(line).rstrip()
        if line.endswith("&"):
            buf += line[:-1] + " "
            continue
        command = " ".join((buf + line).split())
        if command:
            out.setdefault(command, first)
        buf, first = "", 0
    return out


def _strip_comment(line: str) -> str:
    quote = None
    for k, c in enumerate(line):
        if quote:
            quote = None if c == quote else quote
        elif c in "\"'":
            quote = c
        elif c == "#":
            return line[:k]
    return line


def lammps_error(log_text: str, stderr: str, workdir: Path, returncode: int,
                 deck: str = "", deck_name: str = "the deck") -> str:
    """One line for a LAMMPS run that failed: the error (the deck's first GC ERROR line, else
    LAMMPS's last ERROR line, from its log, else from the child's exception), the deck line it
    refers to (the command LAMMPS echoed before it, found in the deck's text with its line
    number, else LAMMPS's "Last command" / "Last input line") and the run folder. The child's
    traceback and the log's tail are for -v (the caller logs them at debug level)."""
    commands = deck_commands(deck) if deck else {}
    for lines in (log_text.splitlines(), stderr.splitlines()):
        gc = next((ln.strip() for ln in lines if ln.startswith("GC ERROR")), None)
        if gc:
            return f"{gc} (the run in {workdir})"
        for k in range(len(lines) - 1, -1, -1):
            m = _LAMMPS_ERROR.search(lines[k])
            if not m:
                continue
            before = " ".join(_strip_comment(lines[k - 1]).split()) if k else ""
            last = next((ln.split(":", 1)[1].strip() for ln in lines[k + 1:k + 4]
                         if ln.startswith(("Last command:", "Last input line:"))), None)
            if before in commands:
                where = f"; {deck_name} line {commands[before]}: {before}"
            else:
                where = f"; deck line: {last}" if last else ""
            return f"LAMMPS stopped the run in {workdir}: {m.group(0).strip()}{where}"
    said = next((ln.strip() for ln in reversed(stderr.splitlines()) if ln.strip()), None)
    return (f"LAMMPS run in {workdir} failed (exit {returncode}): "
            + (said if said else "no error message")
            + f" (its log: {workdir / 'log.lammps'}; -v shows the child's output)")


def run_folder(p: DepositionParams, root: Path) -> Path:
    """The folder of run p under root: root/<p.key()>, or the folder named by the key of
    earlier versions (p.legacy_key(), every non-default value written out) when only that one
    exists and holds the run's result.json or a restart point: a run made then is found,
    reused and resumed. Every command finds a run's folder here."""
    root = Path(root)
    new = root / p.key()
    legacy = p.legacy_key()
    if legacy == new.name or len(os.fsencode(legacy)) > NAME_MAX or new.exists():
        return new
    old = root / legacy
    if (old / "result.json").exists() or (old / CHECKPOINT_VARS).exists():
        return old
    return new


def write_params(wd: Path, p: DepositionParams):
    """params.json in a run's folder: its key, every value that differs from its default (the
    key's hash stands for them), every deck variable as the deck receives it."""
    write_json(Path(wd) / PARAMS_FILE, {"key": p.key(), "non_default": p.non_default(),
                                        "deck_vars": p.deck_vars()})


def tribo_on(deck_vars: dict) -> bool:
    """Whether a run's deck variables switch contact charging on (in.deposition's tribo)."""
    return str(deck_vars.get("tribo", "no")) == "yes"


def parse_progress(line: str) -> dict | None:
    """{'k', 'N', 'step', 'elapsed', 'eta'} of a GC PROGRESS line of in.deposition:
    'GC PROGRESS k / N particles, step S, elapsed T s, eta T s'."""
    w = line.replace(",", " ").split()
    try:
        out = {"k": int(float(w[2])), "N": int(w[4]), "step": int(w[7]),
               "elapsed": float(w[9]), "eta": float(w[12])}
    except (IndexError, ValueError):
        return None
    # the rain's line goes on during the settling with the stop rule's kinetic energy
    out["kerel"] = float(w[15]) if len(w) > 15 and w[14] == "kerel" else None
    return out


class Runner:
    """Runs decks in folders with one LAMMPS build, ``np_ranks`` MPI ranks per run;
    ``checkpoint`` > 0: plane and sequential depositions leave a restart point every that many
    particles, from which an interrupted run goes on."""

    def __init__(self, build: LammpsBuild, np_ranks: int = 1, timeout: float | None = None,
                 render: bool = True, checkpoint: int = 0):
        if not (isinstance(np_ranks, int) and np_ranks >= 1):
            raise ParamError(f"np_ranks = {np_ranks}: MPI ranks per run must be a whole number >= 1")
        if not (isinstance(checkpoint, int) and checkpoint >= 0):
            raise ParamError(f"checkpoint = {checkpoint}: particles between restart points must "
                             "be a whole number >= 0 (0: none)")
        self.build = build
        self.np_ranks = np_ranks
        self.timeout = timeout
        self.render = render
        self.checkpoint = checkpoint
        self.show_progress = False     # a tqdm bar per deposition (run; a sweep of one job)

    # ---- one deck -------------------------------------------------------------------------
    def run_deck(self, deck: str, workdir: Path, variables: dict, kind: str = "none",
                 render: bool = False, plan: dict | None = None) -> dict:
        """Run a packaged deck in workdir (created); return lammps.json plus wall/CPU times.
        plan: a deposition's estimate.run_plan, for the time left its progress bar shows.
        Raises RunError with the tail of the log on failure."""
        workdir = Path(workdir)
        workdir.mkdir(parents=True, exist_ok=True)
        (workdir / "lammps.json").unlink(missing_ok=True)
        with deck_path(deck) as deck_file:
            deck_text = deck_file.read_text(errors="replace")
            cmd = [sys.executable, "-m", "granular_charged.run.child", str(deck_file), str(workdir),
                   "--kind", kind] + (["--render"] if render else [])
            cmd += child.var_args(variables)
            if self.np_ranks > 1:
                mpirun = shutil.which("mpirun") or shutil.which("mpiexec")
                if not mpirun:
                    raise RunError("mpirun not found (needed for --np > 1)")
                cmd = [mpirun, "-np", str(self.np_ranks), "--oversubscribe"] + cmd
            log.debug("run: %s", " ".join(cmd))
            env = self.build.child_env()
            env[PARENT_ENV] = str(os.getpid())    # the child exits when this process dies
            t0 = time.monotonic()
            ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            if self.show_progress and kind == "deposition":
                r = self._watch(cmd, env, workdir, kind, plan)
            else:
                r = subprocess.run(cmd, env=env, capture_output=True, text=True,
                                   timeout=self.timeout)
            wall = time.monotonic() - t0
            ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        res_file = workdir / "lammps.json"
        if (r.returncode != 0 or not res_file.exists()) and disk_full(workdir):
            # LAMMPS's own message would be about the file it could not finish (an empty
            # particle.mol: "Unexpected end of molecule file")
            raise RunError(f"no space left in {workdir}")
        if r.returncode != 0 or not res_file.exists():
            logf = workdir / "log.lammps"
            text = logf.read_text(errors="replace") if logf.exists() else ""
            stop = [ln for ln in text.splitlines() if ln.startswith("GC CHECKPOINT STOP")]
            if r.returncode == 0 and stop:
                raise RunError(f"{workdir}: {stop[-1][3:]}; run it again to go on from there")
            inner = workdir / "log.inject.lammps"     # the one-by-one loops' runs
            if inner.exists() and "GC RESULT" not in text:
                text += "\n" + inner.read_text(errors="replace")
            tail = "\n".join(text.splitlines()[-15:])
            log.debug("LAMMPS run in %s failed (exit %d); its log ends:\n%s\n%s", workdir,
                      r.returncode, tail, r.stderr[-3000:])
            raise RunError(lammps_error(text, r.stderr, workdir, r.returncode,
                                        deck_text, deck))
        out = json.loads(res_file.read_text())
        out["wall_s"] = wall
        # CPU of all ranks; approximate when runs overlap (jobs > 1)
        out["cpu_s"] = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
        return out

    def _watch(self, cmd, env, workdir: Path, kind: str,
               plan: dict | None = None) -> subprocess.CompletedProcess:
        """Run the child, following the GC PROGRESS lines of its log.lammps (particles made / N)
        with a tqdm bar when self.show_progress (a deposition); the timeout kills it."""
        with tempfile.TemporaryFile("w+") as fo, tempfile.TemporaryFile("w+") as fe:
            proc = subprocess.Popen(cmd, env=env, stdout=fo, stderr=fe, text=True)
            bar = None
            if self.show_progress and kind == "deposition":
                from tqdm import tqdm
                # the time left is the plan's (the settling included), not tqdm's own rate
                bar = tqdm(total=None, unit="particle", desc=Path(workdir).name[:40],
                           leave=False, dynamic_ncols=True,
                           bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} "
                                      "[{elapsed}{postfix}]")
            logf, pos, t0 = Path(workdir) / "log.lammps", 0, time.monotonic()
            try:
                while True:
                    try:
                        rc = proc.wait(timeout=1.0)
                        break
                    except subprocess.TimeoutExpired:
                        pass
                    if self.timeout and time.monotonic() - t0 > self.timeout:
                        proc.kill()
                        proc.wait()
                        raise subprocess.TimeoutExpired(cmd, self.timeout)
                    if bar is not None:
                        pos = self._progress(logf, pos, bar, plan)
            except BaseException:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
                raise
            finally:
                if bar is not None:
                    bar.close()
            fo.seek(0)
            fe.seek(0)
            return subprocess.CompletedProcess(cmd, rc, fo.read(), fe.read())

    @staticmethod
    def _progress(logf: Path, pos: int, bar, plan: dict | None = None) -> int:
        """Read log.lammps from byte pos; move the bar to the last GC PROGRESS line's count,
        with the time left by the run's plan (eta_seconds: the settling included)."""
        lines, pos = read_new_lines(logf, pos)
        last = settle = None
        left = None
        for line in lines:
            if line.startswith("GC PROGRESS "):
                last = parse_progress(line)
                left = eta_seconds(line, plan)
            elif line.startswith("GC SETTLE "):
                settle = line.replace(",", " ").split()
        if last is not None:
            bar.total = last["N"]
            bar.n = last["k"]
            post = {"step": last["step"]}
            if left is not None:
                post["left"] = f"~{left:.0f} s"
            if last.get("kerel") is not None and last["k"] >= last["N"]:
                post["settling: kerel"] = f"{last['kerel']:.2g}"
            bar.set_postfix(post, refresh=False)
        if settle is not None:
            # the last settling: the stop rule's kinetic energy against its threshold
            bar.set_postfix({"step": settle[3], "settling: kerel": f"{settle[5]} -> {settle[8].rstrip(')')}",
                             "moving": settle[-1]}, refresh=False)
        if last is not None or settle is not None:
            bar.refresh()
        return pos

    # ---- one deposition -------------------------------------------------------------------
    def workdir(self, p: DepositionParams, root: Path) -> Path:
        return run_folder(p, root)

    def finished(self, p: DepositionParams, root: Path) -> dict | None:
        return read_result(self.workdir(p, root) / "result.json")

    @staticmethod
    def check(p: DepositionParams, tracer: int = 0):
        """ParamError unless p can run: its extra variables are variables of in.deposition that
        the runner does not set itself, and the tracer is one of its particles."""
        deck = deck_variables("in.deposition")
        for k in p.extra:
            if k in RESERVED:
                raise ParamError(f"deck variable {k!r}: {RESERVED[k]}")
            if k not in deck:
                raise ParamError(f"in.deposition has no variable {k!r}")
        if not (0 <= tracer <= p.N):
            raise ParamError(f"tracer = {tracer}: must be a particle id 1..N = {p.N} (0: none)")

    def deposition(self, p: DepositionParams, root: Path, force: bool = False,
                   tracer: int = 0, lock: bool = False, folder: Path | None = None) -> dict:
        """Run in.deposition for p in its folder under root (run_folder; ``folder``: this one,
        the case's folder of the engine), analyse, write result.json, return it.
        A complete result.json is returned unchanged (with 'skipped': True) unless force.
        lock: hold root/.<key>.lock meanwhile (folder_lock; the `run` command, which runs
        outside the workflow engine and its lock)."""
        self.check(p, tracer)
        wd = Path(folder) if folder is not None else self.workdir(p, root)
        if not lock:
            return self._deposition(p, wd, force, tracer)
        with folder_lock(Path(root) / f".{p.key()}.lock", p.key()):
            return self._deposition(p, wd, force, tracer)

    def _deposition(self, p: DepositionParams, wd: Path, force: bool, tracer: int) -> dict:
        done = None if force else read_result(wd / "result.json")
        if done is not None:
            done["skipped"] = True
            done["dir"] = str(wd)
            log.debug("%s: finished before, skipped", p.key())
            return done
        point = None if force else restart_point(wd)
        if wd.exists() and point is None:
            # the engine makes a case's folder before it starts the case: empty, it is new
            if any(wd.iterdir()):
                log.info("%s: incomplete run folder (interrupted?), running it again", p.key())
            shutil.rmtree(wd)
        if population.is_charged(p.deck_vars()) and not self.build.capabilities["coul/fmm"]:
            raise RunError(f"{p.key()}: charged runs need fix coul/fmm, absent from {self.build.path}")
        if tribo_on(p.deck_vars()) and not (self.build.capabilities["coul/fmm"]
                                            and self.build.capabilities.get("tribo/charge")):
            raise RunError(f"{p.key()}: tribo yes (contact charging) needs fix tribo/charge and "
                           f"fix coul/fmm, absent from {self.build.path}")
        variables = p.deck_vars()
        variables["out"] = "."
        # the one-by-one protocols' short runs in log.inject.lammps, the run's own log small
        # (the child's LAMMPS writes log.lammps: doc/deposition.md, "Logs")
        variables.setdefault("split_log", "yes")
        variables.setdefault("computes", "1" if self.build.capabilities["packing computes"] else "0")
        if tracer:
            variables["tracer"] = str(tracer)
        restart_note = None
        wd.mkdir(parents=True, exist_ok=True)
        write_params(wd, p)
        try:
            pieces = self._begin_piece(wd, point, variables)
            lmp = self.run_deck("in.deposition", wd, variables, kind="deposition",
                                render=self.render and self.build.can_render,
                                plan=estimate.run_plan(p))
        except RunError as e:
            if point is None or str(e).startswith("no space left"):
                raise
            # a restart point LAMMPS cannot read (truncated, emptied): the deck keeps only the
            # last one, so the run starts afresh, and says so
            restart_note = (f"its restart point after particle {point['k']} could not be read; "
                            "the run started afresh")
            log.warning("%s: %s", p.key(), restart_note)
            shutil.rmtree(wd)
            wd.mkdir(parents=True)
            write_params(wd, p)
            variables.pop("resume", None)
            point = None
            pieces = self._begin_piece(wd, None, variables)
            lmp = self.run_deck("in.deposition", wd, variables, kind="deposition",
                                render=self.render and self.build.can_render,
                                plan=estimate.run_plan(p))
        pieces[-1].update(wall_s=lmp["wall_s"], cpu_s=lmp["cpu_s"])
        if len(pieces) > 1:
            write_json(wd / PIECES, pieces)
            lmp["wall_s"] = sum(pc["wall_s"] for pc in pieces)
            lmp["cpu_s"] = sum(pc["cpu_s"] for pc in pieces)
        try:
            res = self.analyse(wd, p, lmp, computes=variables["computes"] == "1")
        except (OSError, ValueError, KeyError, IndexError, TypeError) as e:
            # a run LAMMPS finished but whose output cannot be analysed: an error of this run
            # (no result.json: the folder is run again next time), not a traceback
            raise RunError(f"{p.key()}: the analysis of {wd} failed: {type(e).__name__}: {e}") from e
        res["tracer"] = tracer
        res["np"] = self.np_ranks
        notes = [n for n in (restart_note, *(pc.get("note") for pc in pieces)) if n]
        if notes:
            res["restart_note"] = "; ".join(notes)
            res["warning"] = "; ".join(filter(None, [res.get("warning"), *notes]))
        log.info("%s: injection protocol %s%s", p.key(), res["protocol"],
                 " (auto)" if p.extra.get("inject", "auto") == "auto" else "")
        if len(pieces) > 1:
            res["pieces"] = pieces
        write_json(wd / "result.json", res)
        for path in wd.glob("checkpoint*"):
            path.unlink(missing_ok=True)
        res["skipped"] = False
        res["dir"] = str(wd)
        return res

    def _begin_piece(self, wd: Path, point: dict | None, variables: dict) -> list[dict]:
        """Set up a run's next piece: from its restart point when it has one (resume yes, the
        dumps cut back to it, the earlier log kept as log.lammps.<n>), the restart interval
        (this runner's, else the interrupted piece's); returns the pieces so far, the new one
        last. An interrupted piece counts up to its last restart point (mtime of checkpoint.vars;
        its later work is done again), as wall and CPU time alike."""
        pieces = []
        if point is not None:
            pieces = self._earlier_pieces(wd)
            close_interrupted_pieces(pieces, (wd / CHECKPOINT_VARS).stat().st_mtime)
            variables["resume"] = "yes"
            for name in FOLLOWING_DUMPS:
                trim_dump(wd / name, point["step"])
            if (wd / "log.lammps").exists():
                os.replace(wd / "log.lammps", wd / f"log.lammps.{len(pieces)}")
            log.info("%s: going on from its restart point after particle %d (step %d)",
                     wd.name, point["k"], point["step"])
        every = self.checkpoint or next((pc["checkpoint"] for pc in reversed(pieces)
                                         if pc.get("checkpoint")), 0)
        if every:
            variables["checkpoint"] = str(every)
        pieces.append({"from_particle": point["k"] if point else 0, "start": time.time(),
                       "checkpoint": every})
        if every:
            wd.mkdir(parents=True, exist_ok=True)
            write_json(wd / PIECES, pieces)
        return pieces

    @staticmethod
    def _earlier_pieces(wd: Path) -> list[dict]:
        """The pieces of pieces.json; when it is unreadable or not a list of pieces, one
        interrupted piece from the folder's first file (its CPU time is not dropped)."""
        try:
            pieces = json.loads((wd / PIECES).read_text())
            if isinstance(pieces, list) and all(isinstance(pc, dict) and _number(pc.get("start"))
                                                for pc in pieces) and pieces:
                return pieces
        except (OSError, ValueError):
            pass
        first = min((f.stat().st_mtime for f in wd.iterdir()
                     if f.is_file() and not f.name.startswith(("checkpoint", PIECES))),
                    default=(wd / CHECKPOINT_VARS).stat().st_mtime)
        note = (f"{PIECES} was unreadable: the earlier pieces are counted as one, from the "
                "folder's first file to the restart point")
        log.warning("%s: %s", wd.name, note)
        return [{"from_particle": 0, "start": first, "note": note}]

    @staticmethod
    def analyse(workdir: Path, p: DepositionParams, lmp: dict, computes: bool = False) -> dict:
        """result.json: LAMMPS's own numbers (lmp, read from the instance) as phi, Z, fZ, and
        the Python analysis of final.dump beside them (python.*)."""
        snap = packing.read_dump(Path(workdir) / "final.dump", last_only=True)
        zlo_rp = float(p.extra.get("zlo_rp", 4.0))
        top_rp = float(p.extra.get("top_rp", 6.0))
        # f(Z) with LAMMPS's bins (compute coord/dist's zmax) when the computes ran
        zmax = len(lmp["fZ"]) - 1 if lmp.get("fZ") else packing.ZMAX_DEFAULT
        ana = packing.analyse(snap, p.rp, zlo_rp, top_rp, zmax=zmax)
        py = {k: ana.get(k) for k in ("phi", "Z", "fZ", "n_slab", "zlo", "zhi", "slab_thickness_rp")}
        from_lammps = lmp.get("phi") is not None
        res = {
            "version": RESULT_VERSION, "complete": True, "key": p.key(),
            "params": {k: v for k, v in vars(p).items()}, "non_default": p.non_default(),
            "groups": p.groups(), "FC_over_FE": coulomb_to_adhesion(p.gamma, p.rp, p.q),
            "lammps": lmp, "python": py,
            "source": ("lammps computes" if from_lammps
                       else "python (no computes in the build)" if not computes
                       else "python (the bed was too thin for the computes' slab)"),
            "phi": lmp["phi"] if from_lammps else py["phi"],
            "Z": lmp["Z"] if from_lammps else py["Z"],
            "fZ": lmp["fZ"] if from_lammps else py["fZ"],
            "zlo": lmp.get("zlo", py["zlo"]), "zhi": lmp.get("zhi", py["zhi"]),
            "slab_thickness_rp": py["slab_thickness_rp"],
            "inserted": lmp["inserted"], "natoms": lmp["atoms"], "lost": lmp["lost"],
            "flying": lmp["flying"], "deposited": lmp.get("deposited"),
            "settled": lmp.get("settled"), "wall_s": lmp["wall_s"], "cpu_s": lmp["cpu_s"],
            "image": lmp.get("image"),
            # the protocol the deck used (its GC PROTOCOL line), and the population it drew
            "protocol": lmp.get("inject") or population.protocol(p.deck_vars()),
            # whether particles slept (fix sleep/gran; the choice of sleep auto)
            "sleep": lmp.get("sleep"),
            "population": population.describe(p.deck_vars()),
        }
        if population.is_population(p.deck_vars()):
            res["python"].update(packing.by_class(snap, res["population"], py["zlo"], py["zhi"]))
        if tribo_on(p.deck_vars()):
            # contact charging: the fix's counters, the final charges per species and against
            # the depth below the bed top (tables in the run's folder)
            res["tribo"] = lmp.get("tribo")
            res["charges"] = charges.analyse(snap, p.rp)
            charges.write_tables(res["charges"], workdir)
        warnings = [ana["warning"]] if "warning" in ana else []
        if lmp["inserted"] < p.N:
            # inject sequential stops when the bed's charge turns the next particle back
            warnings.append(f"only {lmp['inserted']} of {p.N} particles were deposited (log.lammps)")
        elif lmp.get("deposited") is not None and lmp["deposited"] < p.N:
            warnings.append(f"{lmp['deposited']} of {p.N} particles deposited ({lmp['lost']} lost, "
                            f"{lmp['flying']} still flying)")
        if lmp.get("settled") is False:
            warnings.append(f"the run ended unsettled: relative kinetic energy "
                            f"{lmp['kerel']:.3g}, above ke_stop "
                            f"{p.extra.get('ke_stop', 1e-4)}, after settle_max (raise settle_max)")
        if warnings:
            res["warning"] = "; ".join(warnings)
            log.warning("%s: %s", workdir, res["warning"])
        return res
