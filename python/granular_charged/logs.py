"""Logging of the command line: one handler on the package's logger, level from -v/-q.

A module of its own so that the modules the command line drives (sweep, studies, Table 2) never
import the command line back."""
from __future__ import annotations

import logging
import sys


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
