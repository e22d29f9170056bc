"""Logging of the command line: one handler on the package's logger, level from -v/-q.

A module of its own so that the modules the command line drives (sweep, studies, Table 2) never
import the command line back."""
from __future__ import annotations

import logging
import sys
from pathlib import Path


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
