"""In-tree PEP 517 build backend: setuptools' own backend, taken from the system.

Why: ``pip install ./python`` builds in an isolated environment and would download the
``[build-system] requires`` (setuptools, wheel) from an index. This machine, and the CI, have no
index; Debian ships setuptools and wheel as python3-setuptools / python3-wheel. So the
pyproject names no requirement and points ``build-backend`` here (``backend-path``); this module
finds the setuptools and wheel of the interpreter the environment was made from (for a venv:
its base interpreter, asked in a child started with ``-I`` so that pip's isolation variables do
not apply), appends their folder to ``sys.path`` when the isolated environment lacks them, and
re-exports ``setuptools.build_meta``. If setuptools is importable already (``pip install
--no-build-isolation``, or an index that provided it) nothing is added.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys


def _system_dirs() -> list[str]:
    code = ("import json, os, setuptools, wheel; print(json.dumps(sorted({"
            "os.path.dirname(os.path.dirname(m.__file__)) for m in (setuptools, wheel)})))")
    cands = [getattr(sys, "_base_executable", None), "/usr/bin/python3"]
    for exe in cands:
        if not exe or not os.path.exists(exe):
            continue
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
        r = subprocess.run([exe, "-I", "-c", code], capture_output=True, text=True, env=env)
        if r.returncode == 0:
            return json.loads(r.stdout.strip().splitlines()[-1])
    raise ImportError("granular-charged build backend: no setuptools/wheel in the isolated build "
                      "environment nor in the base interpreter; install python3-setuptools and "
                      "python3-wheel (Debian) or use an index")


try:
    import setuptools  # noqa: F401
    import wheel  # noqa: F401
except ImportError:
    for _d in _system_dirs():
        if _d not in sys.path:
            sys.path.append(_d)

from setuptools import build_meta as _bm  # noqa: E402
from setuptools.build_meta import *  # noqa: E402,F401,F403


def _none(config_settings=None):
    # setuptools < 70 asks for "wheel" here, which pip would try to download; it is importable
    # (checked above), so nothing needs to be installed
    return []


get_requires_for_build_wheel = _none
get_requires_for_build_sdist = _none
if hasattr(_bm, "get_requires_for_build_editable"):
    get_requires_for_build_editable = _none
