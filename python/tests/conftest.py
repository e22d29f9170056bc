"""Shared fixtures: build_dir (lammps_runs.py, shared with tests_powder) and cli, the command
line run in a folder.

Only one LAMMPS run at a time (the runs are sequential): the CI machine has two cores."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from lammps_runs import SRC, build_dir  # noqa: F401 (build_dir: the fixture, shared)


@pytest.fixture(scope="package")
def cli(build_dir):
    """Run `python -m granular_charged ARGS` (the command line) in a folder; returns the
    CompletedProcess. The package comes from this checkout, LAMMPS from build_dir."""
    def run(args, cwd, check=True, timeout=600):
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
        env["GC_BUILD_DIR"] = str(build_dir)
        r = subprocess.run([sys.executable, "-m", "granular_charged"] + [str(a) for a in args],
                           cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
        if check and r.returncode != 0:
            pytest.fail(f"granular-charged {' '.join(map(str, args))} failed ({r.returncode}):\n"
                        f"{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        return r
    return run
