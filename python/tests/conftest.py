"""Shared fixtures. The LAMMPS build is found through $GC_BUILD_DIR (set by ctest's
python.pytest), else <source>/build; a missing build FAILS the tests that need it (nothing is
skipped silently)."""
import os
import sys
from pathlib import Path

import pytest

SRC = Path(os.environ.get("GC_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SRC / "python"))


@pytest.fixture(scope="session")
def build_dir():
    from granular_charged.runner import RunError, find_build
    try:
        return find_build(os.environ.get("GC_BUILD_DIR"))
    except RunError as e:
        pytest.fail(f"LAMMPS build needed (set GC_BUILD_DIR): {e}")
