"""What the studies of fixed runs (epd, conventions, one-at-a-time) share on the command line:
their parser, running what is not finished, and their report."""
from __future__ import annotations

import argparse
import logging
from pathlib import Path

from ..run.runner import Runner
from ..studies.sweep import Sweep, finished_results
from . import options

log = logging.getLogger("granular_charged")


def add_parser(subparsers, name: str, finished_only: str, help: str,
               description: str) -> argparse.ArgumentParser:
    """The parser of a study of fixed runs: resumable, with the studies' options and
    --finished-only printing `finished_only`."""
    p = options.add_command(subparsers, name, help=help,
                            description=description + " Resumable; --finished-only tabulates "
                                                      "what is finished.")
    options.study_options(p, name, "deck variables for every run", finished_only)
    return p


def study_runs(a, params) -> tuple[Path, list[dict]]:
    """Run what is not finished in OUT/runs (nothing with --finished-only), then the finished
    runs of the study there (logged when none)."""
    out = options.out_dir(a.out)
    runs = out / "runs"
    if not a.finished_only:
        Sweep(options.runner(a, not a.no_render), runs, engine=options.engine(a)).run(params)
    results = finished_results(params, runs) if runs.exists() else []
    if not results:
        log.error("no finished runs of the study in %s", runs)
    return out, results


def checked_study(a, command: str, study_params):
    """The runs of a study: its parameters (study_params(seeds, extra=, fields=) with the --var
    pairs checked for the command), each checked, then study_runs; returns
    (out, params, results)."""
    fields, extra = options.deck_vars(a, command)
    params = study_params(tuple(a.seeds), extra=extra, fields=fields)
    for p in params:
        Runner.check(p, 0)
    out, results = study_runs(a, params)
    return out, params, results


def report(a, out: Path, name: str, params, results, *parts: str) -> int:
    """Print a study's report (how many runs are finished, then its parts), write it to
    OUT/<name>.txt; the exit status: 0 when every run is finished or with --finished-only."""
    text = "\n\n".join([f"{len(results)} of {len(params)} runs finished", *parts])
    (out / f"{name}.txt").write_text(text + "\n")
    print(text)
    return 0 if a.finished_only or len(results) == len(params) else 1
