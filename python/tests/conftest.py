"""Shared fixtures. The LAMMPS build is found through $GC_BUILD_DIR (set by ctest's
python.pytest), else the lammps module on PYTHONPATH, else <source>/build; a missing build FAILS
the tests that need it (nothing is skipped silently).

Only one LAMMPS run at a time (the runs are sequential): the CI machine has two cores."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(os.environ.get("GC_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SRC / "python"))


@pytest.fixture(scope="session")
def build_dir():
    from granular_charged.run.lammps_build import BuildError, locate_build
    try:
        return locate_build(os.environ.get("GC_BUILD_DIR"))
    except BuildError as e:
        pytest.fail(f"LAMMPS build needed (set GC_BUILD_DIR): {e}")


@pytest.fixture(scope="session")
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
