"""Run the package's decks through LAMMPS's Python module, one run per folder.

Each run is a child process (``python -m granular_charged.child``, optionally under
``mpirun -np K``) that drives LAMMPS with ``from lammps import lammps`` and the deck's variables
as ``-var`` arguments, then reads phi, <Z>, f(Z) and the run's counters from the LAMMPS instance
(``extract_variable``, ``extract_compute``) into ``lammps.json`` and renders the packing
(``packing.png``, dump image). The parent adds the Python analysis of the final dump (the
cross-check of the computes) and writes ``result.json`` atomically: a folder with a complete
``result.json`` is never run again (resumable sweeps); a folder without one (an interrupted run)
is emptied and run again.
"""
from __future__ import annotations

import json
import logging
import os
import resource
import shutil
import subprocess
import sys
import time
from importlib import resources
from pathlib import Path

from . import packing
from .lammps_build import LammpsBuild
from .params import DepositionParams, coulomb_to_adhesion

log = logging.getLogger(__name__)

# 3: charged runs without `inject` now use the plane rain (older results of the same name
# came from the rain and are run again)
RESULT_VERSION = 3
DECKS = ("in.deposition", "in.charged-after-formation")


class RunError(RuntimeError):
    """A LAMMPS run failed (the message carries the tail of its log)."""


def deck_path(name: str):
    """A deck shipped as package data (a context manager yielding a real file path)."""
    if name not in DECKS:
        raise ValueError(f"unknown deck {name!r}; the package has {', '.join(DECKS)}")
    return resources.as_file(resources.files("granular_charged") / "decks" / name)


def write_json(path: Path, data: dict):
    """Write JSON atomically (a temporary file renamed over the target): an interrupted write
    never leaves a truncated file that looks complete."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1))
    os.replace(tmp, path)


def read_result(path: Path) -> dict | None:
    """A complete result.json of the current version, else None."""
    try:
        res = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    if res.get("version") == RESULT_VERSION and res.get("complete"):
        return res
    return None


class Runner:
    """Runs decks in folders with one LAMMPS build, ``np_ranks`` MPI ranks per run."""

    def __init__(self, build: LammpsBuild, np_ranks: int = 1, timeout: float | None = None,
                 render: bool = True):
        self.build = build
        self.np_ranks = np_ranks
        self.timeout = timeout
        self.render = render

    # ---- one deck -------------------------------------------------------------------------
    def run_deck(self, deck: str, workdir: Path, variables: dict, kind: str = "none",
                 render: bool = False) -> dict:
        """Run a packaged deck in workdir (created); return lammps.json plus wall/CPU times.
        Raises RunError with the tail of the log on failure."""
        workdir = Path(workdir)
        workdir.mkdir(parents=True, exist_ok=True)
        (workdir / "lammps.json").unlink(missing_ok=True)
        with deck_path(deck) as deck_file:
            cmd = [sys.executable, "-m", "granular_charged.child", str(deck_file), str(workdir),
                   "--kind", kind] + (["--render"] if render else [])
            for k, v in variables.items():
                cmd += ["--var", str(k), str(v)]
            if self.np_ranks > 1:
                mpirun = shutil.which("mpirun") or shutil.which("mpiexec")
                if not mpirun:
                    raise RunError("mpirun not found (needed for --np > 1)")
                cmd = [mpirun, "-np", str(self.np_ranks), "--oversubscribe"] + cmd
            log.debug("run: %s", " ".join(cmd))
            t0 = time.monotonic()
            ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            r = subprocess.run(cmd, env=self.build.child_env(), capture_output=True, text=True,
                               timeout=self.timeout)
            wall = time.monotonic() - t0
            ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        res_file = workdir / "lammps.json"
        if r.returncode != 0 or not res_file.exists():
            logf = workdir / "log.lammps"
            tail = "\n".join(logf.read_text(errors="replace").splitlines()[-15:]) if logf.exists() else ""
            raise RunError(f"LAMMPS run in {workdir} failed (exit {r.returncode}):\n{tail}\n"
                           f"{r.stderr[-1500:]}")
        out = json.loads(res_file.read_text())
        out["wall_s"] = wall
        # CPU of all ranks; approximate when runs overlap (jobs > 1)
        out["cpu_s"] = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
        return out

    # ---- one deposition -------------------------------------------------------------------
    def workdir(self, p: DepositionParams, root: Path) -> Path:
        return Path(root) / p.key()

    def finished(self, p: DepositionParams, root: Path) -> dict | None:
        return read_result(self.workdir(p, root) / "result.json")

    def deposition(self, p: DepositionParams, root: Path, force: bool = False,
                   tracer: int = 0) -> dict:
        """Run in.deposition for p in root/<p.key()>, analyse, write result.json, return it.
        A complete result.json is returned unchanged (with 'skipped': True) unless force."""
        wd = self.workdir(p, root)
        done = None if force else self.finished(p, root)
        if done is not None:
            done["skipped"] = True
            done["dir"] = str(wd)
            log.debug("%s: finished before, skipped", p.key())
            return done
        if wd.exists():
            log.info("%s: incomplete run folder (interrupted?), running it again", p.key())
            shutil.rmtree(wd)
        if p.q and not self.build.capabilities["coul/fmm"]:
            raise RunError(f"{p.key()}: charged runs need fix coul/fmm, absent from {self.build.path}")
        variables = p.deck_vars()
        variables["out"] = "."
        variables.setdefault("computes", "1" if self.build.capabilities["packing computes"] else "0")
        if tracer:
            variables["tracer"] = str(tracer)
        lmp = self.run_deck("in.deposition", wd, variables, kind="deposition",
                            render=self.render and self.build.can_render)
        res = self.analyse(wd, p, lmp)
        res["tracer"] = tracer
        res["np"] = self.np_ranks
        write_json(wd / "result.json", res)
        res["skipped"] = False
        res["dir"] = str(wd)
        return res

    @staticmethod
    def analyse(workdir: Path, p: DepositionParams, lmp: dict) -> dict:
        """result.json: LAMMPS's own numbers (lmp, read from the instance) as phi, Z, fZ, and
        the Python analysis of final.dump beside them (python.*)."""
        snap = packing.read_dump(Path(workdir) / "final.dump", last_only=True)
        zlo_rp = float(p.extra.get("zlo_rp", 4.0))
        top_rp = float(p.extra.get("top_rp", 6.0))
        ana = packing.analyse(snap, p.rp, zlo_rp, top_rp)
        py = {k: ana.get(k) for k in ("phi", "Z", "fZ", "n_slab", "zlo", "zhi", "slab_thickness_rp")}
        from_lammps = lmp.get("phi") is not None
        res = {
            "version": RESULT_VERSION, "complete": True, "key": p.key(),
            "params": {k: v for k, v in vars(p).items()},
            "groups": p.groups(), "FC_over_FE": coulomb_to_adhesion(p.gamma, p.rp, p.q),
            "lammps": lmp, "python": py,
            "source": "lammps computes" if from_lammps else "python (no computes in the build)",
            "phi": lmp["phi"] if from_lammps else py["phi"],
            "Z": lmp["Z"] if from_lammps else py["Z"],
            "fZ": lmp["fZ"] if from_lammps else py["fZ"],
            "zlo": lmp.get("zlo", py["zlo"]), "zhi": lmp.get("zhi", py["zhi"]),
            "slab_thickness_rp": py["slab_thickness_rp"],
            "inserted": lmp["inserted"], "natoms": lmp["atoms"], "lost": lmp["lost"],
            "flying": lmp["flying"], "wall_s": lmp["wall_s"], "cpu_s": lmp["cpu_s"],
            "image": lmp.get("image"),
        }
        warnings = [ana["warning"]] if "warning" in ana else []
        if lmp["inserted"] < p.N:
            # inject sequential stops when the bed's charge turns the next particle back
            warnings.append(f"only {lmp['inserted']} of {p.N} particles were deposited (log.lammps)")
        if warnings:
            res["warning"] = "; ".join(warnings)
            log.warning("%s: %s", workdir, res["warning"])
        return res
