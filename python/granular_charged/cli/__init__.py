"""``granular-charged``: the command line of the package (also ``python3 -m granular_charged``).

Subcommands, each a module of this package that registers its own parser and handler: run (one
deposition), sweep (many, resumable), study (a TOML study file of one's own powder:
doc/populations.md), figures (from finished runs), table2 (the Table 2 check), reproduce (the
paper's checks), epd, conventions, one-at-a-time (the studies at paper size), demo (the reduced
Fig. 2 study). ``-v``/``-q`` set the log level; ``--build-dir`` the LAMMPS build.
"""
from __future__ import annotations

import argparse
import errno
import logging
import sys
from pathlib import Path

from .. import __version__
from ..params import ParamError
from ..run.lammps_build import BuildError
from ..run.logs import setup_logging
from ..run.runner import RunError
from ..studies.engine import DryRunDone, EngineError
from . import (conventions, demo, epd, figures, one_at_a_time, options, reproduce, run, study,
               sweep, table2)

log = logging.getLogger("granular_charged")

# the subcommands in the order of --help
COMMANDS = (run, sweep, study, figures, table2, reproduce, epd, conventions, one_at_a_time, demo)


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="granular-charged", parents=[options.common()],
        description="Ballistic deposition of charged adhesive micron spheres with LAMMPS and the "
                    "GRANULAR-CHARGED package (Chen, Li, Liu & Makse, Soft Matter 2016): runs, "
                    "sweeps, tables and the paper's figures.",
        epilog="Run 'granular-charged <command> --help' for a command's options. "
               "Documentation: doc/python.md.")
    ap.formatter_class = options.HelpFormatter
    ap.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    for parser in sub.choices.values():
        parser.formatter_class = options.HelpFormatter
    return ap


def main(argv=None) -> int:
    a = build_parser().parse_args(argv)
    verbose, quiet = getattr(a, "verbose", 0), getattr(a, "quiet", 0)
    setup_logging(verbose, quiet)
    a.progress = quiet == 0 and sys.stderr.isatty()
    try:
        return a.handler(a)
    except DryRunDone:
        return 0
    except EngineError as e:
        # 1: the engine could not start; 3: it stopped on its own error (no case failed)
        log.error("granular-charged %s: %s", a.command, e)
        return e.status
    except ParamError as e:
        # before any run: nothing was started or written
        log.error("granular-charged %s: %s", a.command, e)
        return 2
    except BuildError as e:
        log.error("%s", e)
        return 2
    except RunError as e:
        log.error("%s", e)
        return 1
    except OSError as e:
        # a folder that cannot be made or written (permissions, a full disk, ...)
        if e.errno == errno.ENOSPC:
            where = Path(e.filename).parent if e.filename else Path(getattr(a, "out", "."))
            log.error("granular-charged %s: no space left in %s", a.command, where)
        else:
            log.error("granular-charged %s: %s", a.command, e)
        return 1
    except KeyboardInterrupt:
        log.error("interrupted: finished runs are kept; run the same command again to resume")
        return 130
