"""The child side of a run: drive LAMMPS through its Python module in this process, then read the
results from the LAMMPS instance and write them as JSON (rank 0), and render the packing.

Started by :class:`granular_charged.run.runner.Runner` as
``python -m granular_charged.run.child DECK WORKDIR --kind deposition --var=NAME=VALUE ...``,
optionally under ``mpirun -np K``; not meant to be called by hand. Each variable is one
argument, NAME=VALUE, so that any value (a negative number, an exponent, a word list with
spaces) reaches LAMMPS's ``-var NAME VALUE`` as given.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import threading
import time

from ..paper import Z_COLORS

IMAGE = "packing.png"   # rendered final packing, coloured by Z


def _equal(lmp, name):
    """A variable's value as a float. The type is left to LAMMPS (extract_variable without
    vartype asks lammps_extract_variable_datatype): forcing LMP_VAR_EQUAL on an index or string
    variable makes the module free LAMMPS's own string (heap corruption at exit, seen here)."""
    v = lmp.extract_variable(name)
    if v is None:
        return None
    v = float(v)
    return None if math.isnan(v) else v


def _coord_dist(lmp, cid: str) -> dict:
    """<Z> (global scalar) and f(Z) (global array: Z, count, fraction) of a coord/dist compute."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY, LMP_TYPE_SCALAR
    Zm = lmp.extract_compute(cid, LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR)
    arr = lmp.numpy.extract_compute(cid, LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY)
    return {"Z": float(Zm), "fZ": [float(v) for v in arr[:, 2]],
            "fZ_count": [int(round(v)) for v in arr[:, 1]]}


def extract_deposition(lmp) -> dict:
    """Results of in.deposition from its variables and computes (global, identical on all ranks)."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR
    names = {"steps": "steps", "time_s": "tend", "inserted": "ninj", "atoms": "natoms",
             "lost": "lost", "flying": "nfly", "kerel": "kerel", "zlo": "zlo_n", "zhi": "zhi_n",
             "dt": "dt", "deposited": "ndep", "settled": "settled"}
    out = {k: _equal(lmp, v) for k, v in names.items()}
    for k in ("steps", "inserted", "atoms", "lost", "flying", "deposited"):
        out[k] = int(round(out[k]))
    out["settled"] = bool(out["settled"])    # the stop rule's kinetic-energy criterion met
    out["inject"] = str(lmp.extract_variable("inject"))     # the protocol the run used
    out["sleep"] = "yes" if _equal(lmp, "sleep_on") else "no"   # sleeping, as sleep auto chose
    out["slab"] = bool(_equal(lmp, "slab_ok"))
    out["phi"] = out["Z"] = None
    out["fZ"] = out["fZ_count"] = []
    if out["slab"]:
        out["phi"] = float(lmp.extract_compute("phi", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR))
        out.update(_coord_dist(lmp, "Z"))
    if _equal(lmp, "tribo_on"):
        out["tribo"] = extract_tribo(lmp)
    return out


# fix tribo/charge's global vector, in order (1-based in LAMMPS: f_tribo[1] .. f_tribo[5])
TRIBO_VECTOR = ("moved_C", "wall_C", "pair_events", "wall_events", "unbalanced_quanta")


def extract_tribo(lmp) -> dict:
    """Contact charging of in.deposition (its fix tribo): the charge moved between particles
    and the net charge the floor gave (cumulative, C), the pair and wall charging events, the
    charge quanta the particles gained less those the floor gave (0: charge conserved), and the
    net charge of the particles at the end (C)."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR
    out = {k: float(lmp.extract_fix("tribo", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, i))
           for i, k in enumerate(TRIBO_VECTOR)}
    for k in ("pair_events", "wall_events", "unbalanced_quanta"):
        out[k] = int(round(out[k]))
    out["Q_C"] = _equal(lmp, "Qnet")
    return out


def extract_after(lmp) -> dict:
    """Results of in.charged-after-formation (its immediate-valued equal-style variables)."""
    names = {"phi_before": "phi0", "Z_before": "Z0", "phi_after": "phi1", "Z_after": "Z1",
             "zlo": "zlo_n", "zhi": "zhi_n", "steps": "nrelax"}
    return {k: _equal(lmp, v) for k, v in names.items()}


def render(lmp, path: str, rp: float):
    """The final packing as LAMMPS renders it (dump image): spheres at their true diameter,
    coloured by per-atom Z of compute coord/dist (all contacts, no slab), one colour per Z
    (paper.Z_COLORS, the same as the figures' colour bar), viewed from the side and a little
    above, centred on the bed."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR
    lmp.command("compute gc_zall all coord/dist contact geometric")
    # top of the bed: the highest particle touching another one (a particle still bouncing
    # high above the bed, "flying", would otherwise shrink the bed to a dot)
    lmp.command("variable gc_zbed atom z*(c_gc_zall>0)")
    lmp.command("compute gc_ztop all reduce max v_gc_zbed")
    lmp.command("run 0 post no")          # computes must be initialised by a run before a dump
    ztop = lmp.extract_compute("gc_ztop", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR) + rp
    if ztop <= rp:                        # no contact at all: frame everything
        lmp.command("compute gc_zmax all reduce max z")
        ztop = lmp.extract_compute("gc_zmax", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR) + rp
    lo, hi = lmp.extract_box()[:2]
    lx, boxz = hi[0] - lo[0], hi[2] - lo[2]
    cz = 0.5 * ztop / boxz
    # dump image fits the whole box (tall: the injection height) into the frame; zoom so that
    # the bed (height ztop, ~1.5 lx wide seen obliquely) fills most of it (factor 1.6: with
    # zoom boxz / ztop the bed took 42 % of the frame height, with 1.8 its top was cut off)
    zoom = max(1.0, 1.6 * boxz / max(ztop, 1.5 * lx))
    colors = " ".join(f"color gcz{k} {r:.3f} {g:.3f} {b:.3f}" for k, (r, g, b) in enumerate(Z_COLORS))
    names = " ".join(f"gcz{k}" for k in range(len(Z_COLORS)))
    nz = len(Z_COLORS)
    lmp.command(
        f"write_dump all image {path} c_gc_zall diameter size 800 900 view 70 -35 "
        f"center s 0.5 0.5 {cz:.4f} zoom {zoom:.3f} box no 0.0 axes no 0.0 0.0 shiny 0.3 "
        f"ssao yes 4711 0.5 modify backcolor white {colors} "
        f"amap -0.5 {nz - 0.5} sa 1 {nz} {names}")


def process_start_time(pid: int) -> str | None:
    """The start time of process pid (field 22 of /proc/PID/stat), None if it is gone or a
    zombie: with the pid it names one process, even if the pid is reused later."""
    try:
        stat = open(f"/proc/{pid}/stat").read()
    except OSError:
        return None
    fields = stat[stat.rindex(")") + 2:].split()   # after "pid (comm) "
    return None if fields[0] in "ZX" else fields[19]


def watch_parent(pid: int, interval: float = 0.5):
    """Exit this process when the runner process pid has died (e.g. kill -9, which it cannot
    pass on): a watcher thread polls it, since LAMMPS holds the main thread in C. The pid comes
    from the runner (runner.PARENT_ENV) and not from getppid(): under mpirun the ranks' parent
    is mpirun, which outlives the runner. os._exit: no clean-up that could wait on LAMMPS; the
    run's folder has no result.json and is run again next time. mpirun ends when its ranks
    have."""
    born = process_start_time(pid)
    if born is None:
        os._exit(3)

    def poll():
        while process_start_time(pid) == born:
            time.sleep(interval)
        os._exit(3)

    threading.Thread(target=poll, name="gc-parent-watch", daemon=True).start()


def var_arg(text: str) -> tuple[str, str]:
    """--var=NAME=VALUE as (NAME, VALUE): split at the first '=' (a name has none)."""
    name, eq, value = text.partition("=")
    if not eq or not name:
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=VALUE")
    return name, value


def var_args(variables: dict) -> list[str]:
    """The child's arguments for deck variables: one --var=NAME=VALUE each."""
    return [f"--var={k}={v}" for k, v in variables.items()]


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("deck")
    ap.add_argument("workdir")
    ap.add_argument("--kind", choices=["deposition", "after", "none"], default="none")
    ap.add_argument("--var", type=var_arg, action="append", default=[], metavar="NAME=VALUE",
                    help="a deck variable, one argument: --var=NAME=VALUE")
    ap.add_argument("--render", action="store_true", help="write packing.png (dump image)")
    return ap


def main(argv=None) -> int:
    if os.environ.get("GC_PARENT_PID"):
        watch_parent(int(os.environ["GC_PARENT_PID"]))
    a = parser().parse_args(argv)
    from lammps import lammps
    os.chdir(a.workdir)
    args = ["-log", "log.lammps", "-screen", "none", "-nocite"]
    for k, v in a.var:
        args += ["-var", k, v]
    lmp = lammps(cmdargs=args)
    try:
        lmp.file(a.deck)
        res = {}
        if a.kind == "deposition":
            res = extract_deposition(lmp)
        elif a.kind == "after":
            res = extract_after(lmp)
        res["lammps_version"] = lmp.version()
        res["nprocs"] = lmp.extract_setting("world_size")
        if a.render:
            rp = dict(a.var).get("rp", "2e-6")
            render(lmp, IMAGE, float(rp))
            res["image"] = IMAGE
        if lmp.extract_setting("world_rank") == 0:
            with open("lammps.json.tmp", "w") as fh:
                json.dump(res, fh, indent=1)
            os.replace("lammps.json.tmp", "lammps.json")
    finally:
        lmp.close()
        lmp.finalize()   # MPI_Finalize: without it mpirun reports a failure at exit
    return 0


if __name__ == "__main__":
    sys.exit(main())
