"""The command line: subcommands and their help, errors, the decks as package data, and the
package installed with pip into a fresh virtual environment (offline) running outside the
checkout."""
import os
import shutil
import subprocess
from importlib import resources
from pathlib import Path

import pytest

from conftest import SRC

SUBCOMMANDS = ("run", "sweep", "figures", "table2", "demo", "reproduce")


def test_help_lists_the_subcommands(cli, tmp_path):
    out = cli(["--help"], cwd=tmp_path).stdout
    for c in SUBCOMMANDS:
        assert f"\n    {c} " in out, c
    for opt in ("-v", "-q", "--build-dir"):
        assert opt in out


@pytest.mark.parametrize("cmd,opt", [("run", "--seed"), ("sweep", "--seeds"), ("figures", "--table2"),
                                     ("table2", "--q"), ("demo", "--table2-q"),
                                     ("reproduce", "--quick")])
def test_each_subcommand_has_help(cli, tmp_path, cmd, opt):
    r = cli([cmd, "--help"], cwd=tmp_path)
    assert f"usage: granular-charged {cmd}" in r.stdout and opt in r.stdout
    assert "--build-dir" in r.stdout and "--quiet" in r.stdout


def test_missing_build_is_a_clear_error(cli, tmp_path):
    r = cli(["--build-dir", tmp_path / "nowhere", "run", "--N", "10"], cwd=tmp_path, check=False)
    assert r.returncode == 2
    assert "no LAMMPS build (liblammps.so)" in r.stderr and "--build-dir" in r.stderr


def test_figures_without_runs_fails(cli, tmp_path):
    r = cli(["figures", tmp_path, "--out", tmp_path / "f"], cwd=tmp_path, check=False)
    assert r.returncode == 1 and "no finished runs" in r.stderr


def test_decks_have_one_home():
    # the decks are package data; examples/ links to them instead of holding copies
    decks = resources.files("granular_charged") / "decks"
    for name, ex in (("in.deposition", "deposition"),
                     ("in.charged-after-formation", "charged-after-formation")):
        with resources.as_file(decks / name) as f:
            assert "GRANULAR-CHARGED" in f.read_text()
            link = SRC / "examples" / ex / name
            assert link.is_symlink() and link.resolve() == Path(f).resolve()


def test_pip_install_offline_into_fresh_venv_and_run_outside_checkout(build_dir, tmp_path):
    """`pip install ./python` with pip's default build isolation and no package index (none
    exists here): the in-tree backend takes setuptools and wheel from the system. Then the
    console script runs a tiny deposition from a folder outside the checkout, with the decks
    from the installed package."""
    # a copy of python/, so that the build (build/, *.egg-info) does not write into the checkout
    src = tmp_path / "src"
    shutil.copytree(SRC / "python", src, ignore=shutil.ignore_patterns(
        "build", "*.egg-info", "__pycache__", "tests"))
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)],
                   check=True)
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "GC_BUILD_DIR", "GC_SOURCE_DIR")}
    env["PIP_NO_INDEX"] = "1"                 # no index, as on the CI machine
    r = subprocess.run([str(venv / "bin" / "pip"), "install", str(src)], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    exe = venv / "bin" / "granular-charged"
    out = subprocess.run([str(exe), "--help"], env=env, capture_output=True, text=True,
                         cwd=tmp_path)
    assert out.returncode == 0 and all(c in out.stdout for c in SUBCOMMANDS)
    work = tmp_path / "elsewhere"
    work.mkdir()
    r = subprocess.run([str(exe), "-v", "--build-dir", str(build_dir), "run", "--N", "20",
                        "--var", "L_rp", "6", "--var", "H_rp", "30", "--no-render",
                        "--out", "runs"], env=env, cwd=work, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "site-packages/granular_charged/decks/in.deposition" in r.stderr
    res = Path(r.stdout.strip().splitlines()[-1])
    assert res.exists() and res.is_relative_to(work)
