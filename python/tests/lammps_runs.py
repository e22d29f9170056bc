"""What the tests that run LAMMPS share (python/tests and python/tests_powder): the checkout, the
deposition deck, the build_dir fixture (the build found through $GC_BUILD_DIR, else the lammps
module on PYTHONPATH, else <source>/build; a missing build FAILS the tests that need it, nothing
is skipped silently), a run of lmp on a deck and the deck's result line."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(os.environ.get("GC_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SRC / "python"))
DECK = SRC / "python" / "granular_charged" / "decks" / "in.deposition"


@pytest.fixture(scope="package")
def build_dir():
    from granular_charged.run.lammps_build import BuildError, locate_build
    try:
        return locate_build(os.environ.get("GC_BUILD_DIR"))
    except BuildError as e:
        pytest.fail(f"LAMMPS build needed (set GC_BUILD_DIR): {e}")


def lmp_run(build_dir, deck, cwd, variables, timeout=900):
    """lmp -in deck with -var NAME VALUE per variable in cwd; its log.lammps text (the test fails
    with the log's tail when lmp does)."""
    cmd = [str(Path(build_dir) / "lmp"), "-in", str(deck), "-screen", "none", "-log", "log.lammps"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    text = (Path(cwd) / "log.lammps").read_text()
    assert r.returncode == 0, text[-3000:] + r.stderr[-2000:]
    return text


def result_line(text):
    """The deck's 'GC RESULT name value ...' line of a log as {name: value}."""
    m = re.search(r"^GC RESULT (.*)$", text, re.M)
    w = m.group(1).split()
    return dict(zip(w[0::2], w[1::2]))
