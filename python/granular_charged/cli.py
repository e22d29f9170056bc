"""``granular-charged``: the command line of the package (also ``python3 -m granular_charged``).

Subcommands: run (one deposition), sweep (many, resumable), figures (from finished runs),
demo (the reduced Fig. 2 study), reproduce (the paper's checks this package has, and the list of
its claims not yet covered). ``-v``/``-q`` set the log level; ``--build-dir`` the LAMMPS build.
"""
from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

from . import __version__

log = logging.getLogger("granular_charged")

DEMO_DESCRIPTION = """A REDUCED version of the paper's Fig. 2 study, in one folder:
depositions with r_p = 2 um, U_0 = 1 m/s, gamma = 10 mJ/m^2 and q = 0, 260, 400 e0 (the paper's
Fig. 2) for three seeds, with the paper's H = 160 r_p and material (Table 1) but N = 500 in a box
of L = 14 r_p instead of N = 2000 in L = 28 r_p (the same particles per floor area, so the same
bed height and K_eff = 51); then the Table 2 check (charge the first neutral packing, relax),
the tables (summary.csv, runs.csv, table2/table2.csv) and the figures (figures/*.png + CSV).
Finished runs are reused: an interrupted demo resumes."""


REPRODUCE_DESCRIPTION = """The paper's scaling claims tested in this model, resumable:
the charge series q = 0, 100, 200, 260, 300, 400, 450 e0 at the Fig. 2 case (phi_0/phi - 1 vs
q: log-log slope with a bootstrap uncertainty over the seeds; the paper: 2), neutral cases at
U_0 = 0.5, 0.707, 1.414, 2 m/s, gamma = 5, 20 mJ/m^2 and r_p = 1 um (phi and <Z> vs Ad*, the
collapse of the charged cases quantified; the paper's Fig. 9), and the Table 2 check. N = 500
in L = 14 r_p, or with --quick N = 200 in L = 9 r_p and five charges (the paper's particles per floor area),
three seeds, one particle per r_p of fall (doc/deposition.md)."""


def _common() -> argparse.ArgumentParser:
    """Options every subcommand takes (before or after its name)."""
    p = argparse.ArgumentParser(add_help=False)
    g = p.add_argument_group("common options")
    g.add_argument("-v", "--verbose", action="count", default=argparse.SUPPRESS,
                   help="more log output (-v: debug)")
    g.add_argument("-q", "--quiet", action="count", default=argparse.SUPPRESS,
                   help="less log output: warnings and errors only, no progress bar")
    g.add_argument("--build-dir", default=argparse.SUPPRESS, metavar="DIR",
                   help="LAMMPS build folder (default: $GC_BUILD_DIR, the lammps module on "
                        "PYTHONPATH as build/env.sh sets it, or build/ of the checkout)")
    return p


def _deck_options(p: argparse.ArgumentParser, many: bool):
    nargs = "+" if many else None
    p.add_argument("--rp", type=float, nargs=nargs, default=[2e-6] if many else 2e-6,
                   help="particle radius [m]")
    p.add_argument("--U0", type=float, nargs=nargs, default=[1.0] if many else 1.0,
                   help="injection speed [m/s]")
    p.add_argument("--gamma", type=float, nargs=nargs, default=[0.010] if many else 0.010,
                   help="surface energy [J/m^2]")
    p.add_argument("--q", type=float, nargs=nargs, default=[0.0] if many else 0.0,
                   help="charge per particle [e0]")
    p.add_argument("--N", type=int, default=2000, help="particles to inject")
    p.add_argument("--np", type=int, default=1, help="MPI ranks per run (mpirun)")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help="any other deck variable, e.g. --var L_rp 14 --var farfield average")
    p.add_argument("--tracer", type=int, default=0, help="follow this particle id (Fig. 8)")
    p.add_argument("--no-render", action="store_true", help="no rendered packing image")


def build_parser() -> argparse.ArgumentParser:
    common = _common()
    ap = argparse.ArgumentParser(
        prog="granular-charged", parents=[common],
        description="Ballistic deposition of charged adhesive micron spheres with LAMMPS and the "
                    "GRANULAR-CHARGED package (Chen, Li, Liu & Makse, Soft Matter 2016): runs, "
                    "sweeps, tables and the paper's figures.",
        epilog="Run 'granular-charged <command> --help' for a command's options. "
               "Documentation: doc/python.md.")
    ap.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="command", required=True)

    p = sub.add_parser("run", parents=[common], help="one deposition into a folder",
                       description="Run one deposition (the package's in.deposition deck) in "
                                   "OUT/<key>/ and write result.json there; a finished run is "
                                   "not run again unless --force.")
    p.add_argument("--out", default="runs", help="parent folder of the run folder (default runs)")
    p.add_argument("--seed", type=int, default=4711)
    p.add_argument("--force", action="store_true", help="run again even if finished")
    _deck_options(p, many=False)

    p = sub.add_parser("sweep", parents=[common], help="many depositions, resumable",
                       description="Every combination of the given values and seeds, one folder "
                                   "each under --out; finished runs are skipped, so an "
                                   "interrupted sweep resumes where it stopped.")
    p.add_argument("--out", required=True, help="results folder (one sub-folder per run)")
    p.add_argument("--preset", choices=["paper"], help="the paper's full set of cases")
    p.add_argument("--seeds", type=int, nargs="+", default=[4711],
                   help="seeds of the injection positions (default 4711)")
    p.add_argument("--jobs", type=int, default=1, help="runs at a time")
    p.add_argument("--figures", default=None, metavar="DIR", help="then draw the figures here")
    _deck_options(p, many=True)

    p = sub.add_parser("figures", parents=[common], help="figures and tables of finished runs",
                       description="The paper's figures (PNG + CSV) and the summary table of "
                                   "every finished run under RESULTS (and, with --table2, of a "
                                   "charged-after-formation folder).")
    p.add_argument("results", help="folder of run folders (sweep --out)")
    p.add_argument("--out", required=True, help="folder for the figures")
    p.add_argument("--table2", default=None, metavar="DIR",
                   help="a folder of charged-after-formation runs (demo-output/table2)")

    p = sub.add_parser("reproduce", parents=[common],
                       help="the paper's scaling claims at reduced size: q^2 law, Ad* collapse, "
                            "Table 2 (--quick: under 15 min)",
                       description=REPRODUCE_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _study_options(p, "reproduce", "deck variables for every run (e.g. --var theta_crit 0.04)")
    p.add_argument("--quick", action="store_true",
                   help="N = 200 in L = 9 r_p instead of N = 500 in L = 14 r_p, charges 0 200 "
                        "300 400 450, Table 2 at 400 only")

    p = sub.add_parser("demo", parents=[common],
                       help="the reduced Fig. 2 study: runs, table, Table 2, figures",
                       description=DEMO_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _study_options(p, "demo", "deck variables besides the demo's L_rp 14, inject rain, gap_rp 1")
    p.add_argument("--N", type=int, default=500, help="particles per run (default 500)")
    p.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0],
                   help="charges [e0] (default 0 260 400)")
    p.add_argument("--table2-q", type=float, nargs="*", default=[0.0, 260.0, 400.0],
                   help="charges of the Table 2 check (none: skip it)")
    p.add_argument("--tracer", type=int, default=None,
                   help="particle id to follow in the first seed's runs (default N/2)")
    p.add_argument("--claims", action="store_true",
                   help="then list the paper's claims with what this package checks of each")
    return ap


def _study_options(p: argparse.ArgumentParser, name: str, var_help: str):
    """Options that demo and reproduce share."""
    p.add_argument("--out", default=f"{name}-output", help=f"output folder (default {name}-output)")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3],
                   help="seeds of the injection positions (default 1 2 3)")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help=var_help)
    p.add_argument("--jobs", type=int, default=1, help="runs at a time")
    p.add_argument("--np", type=int, default=1, help="MPI ranks per run")
    p.add_argument("--no-render", action="store_true", help="no rendered packing images")


def setup_logging(verbose: int, quiet: int):
    level = logging.INFO - 10 * verbose + 10 * quiet
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"
                                           if verbose else "%(message)s", "%H:%M:%S"))
    root = logging.getLogger("granular_charged")
    root.handlers[:] = [handler]
    root.setLevel(max(logging.DEBUG, level))
    root.propagate = False


def _runner(a, render=True):
    from .lammps_build import LammpsBuild
    from .runner import Runner
    build = LammpsBuild.find(getattr(a, "build_dir", None))
    return Runner(build, np_ranks=getattr(a, "np", 1), render=render)


def cmd_run(a) -> int:
    from .params import DepositionParams
    from .runner import RunError
    from .sweep import fmt
    runner = _runner(a, not a.no_render)
    p = DepositionParams(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q, N=a.N, seed=a.seed,
                         extra={k: v for k, v in a.var})
    log.info("run %s in %s (LAMMPS build %s)", p.key(), Path(a.out).resolve(), runner.build.path)
    try:
        r = runner.deposition(p, Path(a.out), force=a.force, tracer=a.tracer)
    except RunError as e:
        log.error("%s", e)
        return 1
    state = "finished before (not run again)" if r["skipped"] else f"{r['wall_s']:.1f} s"
    log.info("%s: phi = %s, <Z> = %s, %d atoms, lost %d, flying %d (%s)", p.key(),
             fmt(r["phi"], ".4f"), fmt(r["Z"], ".3f"), r["natoms"], r["lost"], r["flying"], state)
    print((Path(r["dir"]) / "result.json").resolve())
    return 0


def cmd_sweep(a) -> int:
    from .sweep import PAPER_SETS, Sweep, expand, load_results
    runner = _runner(a, not a.no_render)
    extra = {k: v for k, v in a.var}
    sets = PAPER_SETS if a.preset == "paper" else [dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q)]
    params = expand(sets, a.N, a.seeds, extra)
    if not runner.build.capabilities["coul/fmm"]:
        skip = [p for p in params if p.q]
        if skip:
            log.warning("%d charged runs NOT run: fix coul/fmm is absent from %s", len(skip),
                        runner.build.path)
        params = [p for p in params if not p.q]
    res = Sweep(runner, Path(a.out), jobs=a.jobs, progress=a.progress).run(params, a.tracer)
    if a.figures:
        _figures(load_results(Path(a.out)), Path(a.figures), None)
    return 0 if len(res) == len(params) else 1


def _figures(results, out: Path, t2dir: Path | None):
    from . import figures, tables
    rows = []
    if t2dir is not None:
        for f in sorted(Path(t2dir).glob("q*/result.json")):
            r = json.loads(f.read_text())
            r["dir"] = str(f.parent)
            rows.append(r)
    out.mkdir(parents=True, exist_ok=True)
    if results:
        s = tables.summary(tables.runs_frame(results))
        s.to_csv(out / "summary.csv", index=False)
        print(tables.format_table(s[["rp_um", "U0", "gamma_mJ", "q", "runs", "phi", "phi_sd", "Z",
                                     "Z_sd", "Adstar", "expansion"]]))
    paths = figures.all_figures(results, out, rows)
    log.info("%d figures in %s", len(paths), out.resolve())
    return paths


def cmd_figures(a) -> int:
    from .sweep import load_results
    results = load_results(Path(a.results))
    if not results:
        log.error("no finished runs (*/result.json) in %s", a.results)
        return 1
    _figures(results, Path(a.out), Path(a.table2) if a.table2 else None)
    return 0


def cmd_reproduce(a) -> int:
    from .reproduce import Reproduction, report
    runner = _runner(a, not a.no_render)
    study = Reproduction(out=Path(a.out), quick=a.quick, seeds=tuple(a.seeds),
                         extra={k: v for k, v in a.var}, jobs=a.jobs, progress=a.progress)
    res = study.run(runner)
    print(report(res, study))
    return 0 if res["complete"] else 1


def cmd_demo(a, reproduce=False) -> int:
    from .demo import DEMO_VARS, Study, claims_report, report
    runner = _runner(a, not a.no_render)
    extra = dict(DEMO_VARS)
    extra.update({k: v for k, v in a.var})
    study = Study(out=Path(a.out), N=a.N, qs=tuple(a.q), seeds=tuple(a.seeds),
                  table2_qs=tuple(a.table2_q), extra=extra, jobs=a.jobs, progress=a.progress,
                  tracer=a.tracer)
    res = study.run(runner)
    print(report(res, study))
    if reproduce:
        print()
        print(claims_report(res))
    return 0 if res["complete"] else 1


def main(argv=None) -> int:
    a = build_parser().parse_args(argv)
    verbose, quiet = getattr(a, "verbose", 0), getattr(a, "quiet", 0)
    setup_logging(verbose, quiet)
    a.progress = quiet == 0 and sys.stderr.isatty()
    from .lammps_build import BuildError
    try:
        if a.command == "run":
            return cmd_run(a)
        if a.command == "sweep":
            return cmd_sweep(a)
        if a.command == "figures":
            return cmd_figures(a)
        if a.command == "reproduce":
            return cmd_reproduce(a)
        return cmd_demo(a, reproduce=a.claims)
    except BuildError as e:
        log.error("%s", e)
        return 2
    except KeyboardInterrupt:
        log.error("interrupted: finished runs are kept; run the same command again to resume")
        return 130


if __name__ == "__main__":
    sys.exit(main())
