"""The LAMMPS build for the population depositions (ctest python.powder): the build_dir
fixture of python/tests/lammps_runs.py."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from lammps_runs import build_dir  # noqa: E402,F401 (the fixture, shared)
