"""Where the LAMMPS build is, what it can do, and the environment of a child process using it.

A build folder holds ``liblammps.so`` and ``python/lammps`` (the module loads the library beside
it). It is found, in this order, from the ``--build-dir`` argument, ``$GC_BUILD_DIR``, the
``lammps`` module already on ``sys.path`` (``build/env.sh`` puts it there), and ``build/`` of
a source checkout holding this package.
"""
from __future__ import annotations

import importlib.util
import json
import logging
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

log = logging.getLogger(__name__)


class BuildError(RuntimeError):
    """No usable LAMMPS build."""


def _is_build(p: Path) -> bool:
    return (p / "liblammps.so").exists() or any(p.glob("liblammps.so*"))


def _package_parent() -> Path:
    """The folder that holds the granular_charged package (a checkout's python/, or site-packages)."""
    return Path(__file__).resolve().parents[2]


def locate_build(build_dir: str | os.PathLike | None = None) -> Path:
    """The build folder (see the module docstring); BuildError if none is usable."""
    tried = []
    cands = []
    if build_dir:
        cands.append(("--build-dir", Path(build_dir)))
    elif os.environ.get("GC_BUILD_DIR"):
        cands.append(("$GC_BUILD_DIR", Path(os.environ["GC_BUILD_DIR"])))
    else:
        spec = importlib.util.find_spec("lammps")
        if spec is not None and spec.origin:
            cands.append(("the lammps module on sys.path", Path(spec.origin).resolve().parents[2]))
        cands.append(("the checkout's build/", _package_parent().parent / "build"))
    for how, p in cands:
        p = p.resolve()
        if _is_build(p):
            log.debug("LAMMPS build %s (from %s)", p, how)
            return p
        tried.append(f"{p} ({how})")
    raise BuildError("no LAMMPS build (liblammps.so) in " + "; ".join(tried) +
                     ": pass --build-dir, set GC_BUILD_DIR, or source build/env.sh")


@dataclass
class LammpsBuild:
    """A LAMMPS build folder and the styles it has (probed once, in a child process, on demand)."""
    path: Path
    _caps: dict | None = field(default=None, repr=False)

    @classmethod
    def find(cls, build_dir=None) -> "LammpsBuild":
        return cls(locate_build(build_dir))

    def child_env(self) -> dict:
        """Environment for a child process: the build's lammps module and this package first on
        PYTHONPATH, the build on LD_LIBRARY_PATH, Open MPI allowed to run as root."""
        env = dict(os.environ)
        pp = [str(self.path / "python"), str(_package_parent())]
        if env.get("PYTHONPATH"):
            pp.append(env["PYTHONPATH"])
        env["PYTHONPATH"] = os.pathsep.join(pp)
        env["LD_LIBRARY_PATH"] = os.pathsep.join(
            [str(self.path)] + ([env["LD_LIBRARY_PATH"]] if env.get("LD_LIBRARY_PATH") else []))
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
        return env

    @property
    def capabilities(self) -> dict:
        """{'version', 'coul/fmm', 'tribo/charge', 'packing computes', 'dump image', 'png'} of this
        build."""
        if self._caps is None:
            code = (
                "import json; from lammps import lammps\n"
                "l = lammps(cmdargs=['-log', 'none', '-screen', 'none', '-nocite'])\n"
                "print(json.dumps({'version': l.version(),\n"
                "  'coul/fmm': bool(l.has_style('fix', 'coul/fmm')),\n"
                "  'tribo/charge': bool(l.has_style('fix', 'tribo/charge')),\n"
                "  'packing computes': all(l.has_style('compute', c) for c in\n"
                "                          ('packing/slab', 'coord/dist')),\n"
                "  'dump image': bool(l.has_style('dump', 'image')),\n"
                "  'png': bool(l.has_png_support)}))\n"
                "l.close()\n")
            r = subprocess.run([sys.executable, "-c", code], env=self.child_env(),
                               capture_output=True, text=True, timeout=120)
            if r.returncode != 0:
                raise BuildError(f"cannot load LAMMPS from {self.path}: {r.stderr.strip()[-600:]}")
            self._caps = json.loads(r.stdout.strip().splitlines()[-1])
            log.debug("LAMMPS %s capabilities: %s", self.path, self._caps)
        return self._caps

    @property
    def can_render(self) -> bool:
        return self.capabilities["dump image"] and self.capabilities["png"]
