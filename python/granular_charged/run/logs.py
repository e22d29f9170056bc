"""Logging of the command line (one handler on the package's logger, level from -v/-q) and
what is read from a run's log.lammps: its progress (an ETA with the settling in it) and its
result line (GC RESULT, with whether the run settled and deposited every particle asked).

A module of its own so that the modules the command line drives (sweep, studies, Table 2) never
import the command line back."""
from __future__ import annotations

import logging
import re
import sys
from pathlib import Path

from ..analysis.status import parse_result_line, read_result_line, run_status  # noqa: F401


def read_new_lines(path: Path, pos: int) -> tuple[list[str], int]:
    """The complete lines a growing log (LAMMPS's, Snakemake's) has gained since byte pos, and
    the position after them: a line still being written waits for the next call."""
    try:
        with open(path, "rb") as fh:
            fh.seek(pos)
            chunk = fh.read()
    except OSError:
        return [], pos
    end = chunk.rfind(b"\n") + 1
    return chunk[:end].decode(errors="replace").splitlines(), pos + end


def setup_logging(verbose: int = 0, quiet: int = 0):
    """INFO by default, DEBUG (with times) per -v, WARNING per -q; to stderr."""
    level = logging.INFO - 10 * verbose + 10 * quiet
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"
                                           if verbose else "%(message)s", "%H:%M:%S"))
    root = logging.getLogger("granular_charged")
    root.handlers[:] = [handler]
    root.setLevel(max(logging.DEBUG, level))
    root.propagate = False


# the lines a case run by the workflow engine logs (in Snakemake's log), which the study's
# command relays to its own log: CASE_MARK, the level's name, the message
CASE_MARK = "GC-CASE"


def setup_case_logging():
    """A case run by the engine: its log lines marked for the study's command to relay."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(f"{CASE_MARK} %(levelname)s %(message)s"))
    root = logging.getLogger("granular_charged")
    root.handlers[:] = [handler]
    root.setLevel(logging.DEBUG)
    root.propagate = False


def relay_case_line(line: str, log: logging.Logger) -> bool:
    """Log a marked line of a case at its level (True), or leave it (False)."""
    if not line.startswith(CASE_MARK + " "):
        return False
    level, _, message = line[len(CASE_MARK) + 1:].rstrip("\n").partition(" ")
    log.log(getattr(logging, level, logging.INFO), "%s", message)
    return True


# ---- the run's result line: analysis.status (parse_result_line, read_result_line, run_status;
# the analysis reads them too), here for the modules that read logs

# ---- progress and ETA -------------------------------------------------------------------------

_PROGRESS = re.compile(r"^GC PROGRESS (\d+) / (\d+) particles, step ([^,\s]+), elapsed (\S+) s")


def eta_seconds(line: str, plan: dict | None) -> float | None:
    """Seconds left of a run at its GC PROGRESS line, the settling included: the elapsed time
    per particle-step so far times the particle-steps still to come by the run's plan
    (estimate.run_plan: the particles' injection, the last fall and the settling). None for a
    line that is not a progress line, or without a plan. (The deck's own 'eta' counts the
    particles still to come only, not the settling after them.)"""
    m = _PROGRESS.match(line)
    if m is None or not plan:
        return None
    try:
        k, step, elapsed = int(m.group(1)), float(m.group(3)), float(m.group(4))
    except ValueError:
        return None
    n_i = plan["n_i"]
    n = min(k, plan["N_dep"])
    inject_end = n * n_i
    done = n_i * n * n / 2.0 + n * max(step - inject_end, 0.0)
    if done <= 0 or elapsed <= 0:
        return None
    return max(elapsed * (plan["work"] - done) / done, 0.0)
