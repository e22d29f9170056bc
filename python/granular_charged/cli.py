"""``granular-charged``: the command line of the package (also ``python3 -m granular_charged``).

Subcommands: run (one deposition), sweep (many, resumable), study (a TOML study file of one's
own powder: doc/populations.md), figures (from finished runs),
demo (the reduced Fig. 2 study), reproduce (the paper's checks this package has, and the list of
its claims not yet covered). ``-v``/``-q`` set the log level; ``--build-dir`` the LAMMPS build.
"""
from __future__ import annotations

import argparse
import errno
import logging
import sys
from pathlib import Path

from . import __version__
from .run.logs import setup_logging

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


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Every option's default in --help; descriptions as written (their own line breaks)."""


def _count(text: str) -> int:
    """argparse type: a whole number >= 1 (particles, ranks, jobs)."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, not {v}")
    return v


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
    p.add_argument("--N", type=_count, default=2000, help="particles to inject")
    p.add_argument("--np", type=_count, default=1, help="MPI ranks per run (mpirun)")
    p.add_argument("--var", nargs="+", action="append", default=[], metavar="NAME VALUE",
                   help="any other variable of the deck (its 'variable NAME index' lines), e.g. "
                        "--var L_rp 14 --var farfield average; not those with an option of "
                        "their own (--rp --U0 --gamma --q --N --seed --tracer)"
                        + ("; several values (--var E 1e8 2e8) are an axis of the sweep" if many
                           else ""))
    p.add_argument("--size", default=None, metavar="SPEC",
                   help="size population (doc/populations.md): 'uniform lo=3e-6 hi=7e-6', "
                        "'lognormal median=5e-6 gsd=1.2 [lo= hi=]', 'discrete radii=2e-6,4e-6 "
                        "[fractions=0.7,0.3]' (sets rp to its mean or median)")
    p.add_argument("--charge", default=None, metavar="SPEC",
                   help="charge rule: 'fixed q=400', 'area sigma=1e-5' [C/m^2], 'gauss q=400 "
                        "sd=50', 'bipolar q=400 pos=0.5' (gauss, bipolar: sigma= instead of q= "
                        "for a magnitude proportional to the area)")
    p.add_argument("--inject", choices=["auto", "rain", "plane", "sequential"], default="auto",
                   help="injection protocol (auto: rain when no particle is charged, plane when "
                        "any is; doc/deposition.md)")
    p.add_argument("--tracer", type=int, default=0, help="follow this particle id (Fig. 8)")
    p.add_argument("--checkpoint", type=int, default=0, metavar="K",
                   help="plane and sequential injection: a restart point every K particles; an "
                        "interrupted run goes on from its last one when run again (0: none)")
    p.add_argument("--no-render", action="store_true", help="no rendered packing image")


def engine_options(p: argparse.ArgumentParser):
    """How a study's runs run: locally, or submitted to Slurm or another batch system (the
    workflow engine, Snakemake: doc/python.md, "Many runs and clusters")."""
    g = p.add_argument_group("where the runs run (Snakemake)")
    g.add_argument("--jobs", "--cores", type=_count, default=1,
                   help="runs at a time on this machine; with --slurm or --cluster: jobs "
                        "queued at once")
    g.add_argument("--slurm", action="store_true",
                   help="submit each run as a Slurm job (sbatch) with its --np MPI ranks and a "
                        "time limit from its estimated cost")
    g.add_argument("--account", default=None, help="Slurm account (sbatch -A)")
    g.add_argument("--partition", default=None, help="Slurm partition (sbatch -p)")
    g.add_argument("--mem-mb", type=_count, default=None, metavar="MB",
                   help="memory per job [MB] on a cluster")
    g.add_argument("--cluster", default=None, metavar="TEMPLATE",
                   help="submit each run with this command (Snakemake's --cluster template, e.g. "
                        "'qsub -l walltime={resources.runtime}:00 -pe mpi {resources.tasks}')")
    g.add_argument("--dry-run", action="store_true",
                   help="print the runs that would run or be submitted, run nothing")
    g.add_argument("--unlock", action="store_true",
                   help="first remove the lock a killed study left on the folder")


def build_parser() -> argparse.ArgumentParser:
    common = _common()
    ap = argparse.ArgumentParser(
        prog="granular-charged", parents=[common],
        description="Ballistic deposition of charged adhesive micron spheres with LAMMPS and the "
                    "GRANULAR-CHARGED package (Chen, Li, Liu & Makse, Soft Matter 2016): runs, "
                    "sweeps, tables and the paper's figures.",
        epilog="Run 'granular-charged <command> --help' for a command's options. "
               "Documentation: doc/python.md.")
    ap.formatter_class = HelpFormatter
    ap.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="command", required=True)

    p = sub.add_parser("run", parents=[common], help="one deposition into a folder",
                       description="Run one deposition (the package's in.deposition deck) in "
                                   "OUT/<key>/ and write result.json there; a finished run is "
                                   "not run again unless --force.")
    p.add_argument("--out", default="runs", help="parent folder of the run folder")
    p.add_argument("--seed", type=_count, default=4711)
    p.add_argument("--force", action="store_true", help="run again even if finished")
    _deck_options(p, many=False)

    p = sub.add_parser("sweep", parents=[common], help="many depositions, resumable",
                       description="Every combination of the given values and seeds, one folder "
                                   "each under --out; finished runs are skipped, so an "
                                   "interrupted sweep resumes where it stopped.")
    p.add_argument("--out", required=True, help="results folder (one sub-folder per run)")
    p.add_argument("--preset", choices=["paper"], help="the paper's full set of cases")
    p.add_argument("--seeds", type=_count, nargs="+", default=[4711],
                   help="seeds of the injection positions")
    engine_options(p)
    p.add_argument("--figures", default=None, metavar="DIR", help="then draw the figures here")
    _deck_options(p, many=True)

    p = sub.add_parser("study", parents=[common], help="a study of your own powder from a TOML file",
                       description="Run the study a TOML file describes (material(s), population, "
                                   "protocol, grid, seeds; doc/populations.md), resumably, then its "
                                   "tables and figures (labelled with its name) in its out folder.")
    p.add_argument("file", help="the study file (TOML)")
    engine_options(p)
    p.add_argument("--np", type=_count, default=1, help="MPI ranks per run")
    p.add_argument("--no-render", action="store_true", help="no rendered packing images")
    p.add_argument("--estimate-only", action="store_true",
                   help="print the runs' protocols and estimated cost, run nothing")

    p = sub.add_parser("figures", parents=[common], help="figures and tables of finished runs",
                       description="The paper's figures (PNG + CSV) and the summary table of "
                                   "every finished run under RESULTS (and, with --table2, of a "
                                   "charged-after-formation folder).")
    p.add_argument("results", help="folder of run folders (sweep --out)")
    p.add_argument("--out", required=True, help="folder for the figures")
    p.add_argument("--table2", default=None, metavar="DIR",
                   help="a folder of charged-after-formation runs (demo-output/table2)")
    p.add_argument("--variant", default=None,
                   help="when RESULTS holds runs of several variants (N, non-default material "
                        "or deck variables, e.g. 'N=2000 inject=sequential'): the one to show")

    p = sub.add_parser("table2", parents=[common],
                       help="the Table 2 check on a finished neutral run",
                       description="Charge a formed neutral packing (a finished run folder of "
                                   "'run' or 'sweep') after its formation and relax it (the "
                                   "package's in.charged-after-formation deck), one folder per "
                                   "charge under --out, and write table2.csv beside the paper's "
                                   "Table 2. Resumable.")
    p.add_argument("formed", help="run folder of a finished neutral deposition")
    p.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0],
                   help="charges [e0] given after formation (0: the control)")
    p.add_argument("--out", required=True, help="folder of the Table 2 runs")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help="a variable of in.charged-after-formation for every run (the formed "
                        "run's own settings are taken over), e.g. --var relax_rp 50")
    p.add_argument("--np", type=_count, default=1, help="MPI ranks per run")

    p = sub.add_parser("reproduce", parents=[common],
                       help="the paper's scaling claims at reduced size: q^2 law, Ad* collapse, "
                            "Table 2 (--quick: under 15 min)",
                       description=REPRODUCE_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _study_options(p, "reproduce", "deck variables for every run (e.g. --var theta_crit 0.04)",
                   "the tables, claims and figures of the runs finished in --out so far (a "
                   "study that grows run by run)")
    p.add_argument("--size", choices=["demo", "quick", "paper"], default="demo",
                   help="demo: N = 500 in L = 14 r_p (default); quick: N = 200 in L = 9 r_p, "
                        "charges 0 200 300 400 450, Table 2 at 400 only; paper: N = 2000 in "
                        "L = 28 r_p, the paper's cases (sweep --preset paper and neutral cases "
                        "to Ad = 20) with the deck's default protocols (many CPU hours)")
    p.add_argument("--quick", action="store_const", const="quick", dest="size",
                   help="the same as --size quick")

    p = _fixed_study_parser(sub, common, "epd", "the table of the runs finished in --out so far",
                       help="the electrophoretic deposition study (doc/epd.md), resumable",
                       description="Charged particles (2 um, 1 m/s, 10 mJ/m^2, 400 e0) driven by "
                                   "an applied field onto a grounded floor electrode, E0 = 1e5 and "
                                   "3e5 V/m, eps_p = 0 (not polarisable) and 3.8, N = 500 in "
                                   "L = 14 r_p, three seeds: phi, <Z>, f(Z) and the contact "
                                   "directions against the field, mean +- sd over the seeds "
                                   "(printed and in OUT/epd.csv).")

    p = _fixed_study_parser(sub, common, "conventions",
                       "the tables of the runs finished in --out so far",
                       help="the phi_0 question at paper size: the paper's open conventions "
                            "(doc/reproduction.md), resumable",
                       description="Which convention the paper leaves open gives its Table 2, "
                                   "its neutral phi_0 range and its charge effect together: the "
                                   "rolling limit theta_crit 0.01 (the deck's), 0.02, 0.04 at the "
                                   "three neutral series of Fig. 3 and at 400 e0 (2 um, 1 m/s), "
                                   "N = 2000 in L = 28 r_p, three seeds; phi in the slab or over "
                                   "the whole bed (H_p = mean surface height or highest top), <Z> "
                                   "in the slab or over all particles. Prints the per-case means "
                                   "(OUT/conventions.csv) and the checks per convention "
                                   "(OUT/conventions_checks.csv). The theta_crit 0.01 runs are "
                                   "those of `reproduce --size paper` (the same folders under "
                                   "OUT/runs).")

    p = _fixed_study_parser(sub, common, "one-at-a-time",
                       "the tables of the runs finished in --out so far",
                       help="the one-at-a-time limit at paper size against the default plane "
                            "rain (doc/reproduction.md), resumable",
                       description="inject sequential (each particle once the previous one has "
                                   "landed) at 260 and 400 e0 against the deck's default plane "
                                   "rain at the same charges and the neutral rain, (2 um, 1 m/s, "
                                   "10 mJ/m^2), N = 2000 in L = 28 r_p, three seeds: phi, <Z> "
                                   "and phi_0/phi - 1 per protocol (OUT/one_at_a_time.csv) and "
                                   "their differences in standard errors. The default runs are "
                                   "those of `reproduce --size paper` (the same folders under "
                                   "OUT/runs). A sequential run is hours of CPU: it leaves a "
                                   "restart point every --checkpoint particles and an "
                                   "interrupted one goes on from there.")
    p.add_argument("--checkpoint", type=int, default=50, metavar="K",
                   help="particles between restart points (0: none)")

    p = sub.add_parser("demo", parents=[common],
                       help="the reduced Fig. 2 study: runs, table, Table 2, figures",
                       description=DEMO_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _study_options(p, "demo", "deck variables besides the demo's L_rp 14, inject rain, gap_rp 1")
    p.add_argument("--N", type=_count, default=500, help="particles per run")
    p.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0],
                   help="charges [e0]")
    p.add_argument("--table2-q", type=float, nargs="*", default=[0.0, 260.0, 400.0],
                   help="charges of the Table 2 check (none: skip it)")
    p.add_argument("--tracer", type=int, default=None,
                   help="particle id to follow in the first seed's runs (default: N/2)")
    p.add_argument("--claims", action="store_true",
                   help="then list the paper's claims with what this package checks of each")
    for command in sub.choices.values():
        command.formatter_class = HelpFormatter
    return ap


def _study_options(p: argparse.ArgumentParser, name: str, var_help: str,
                   finished_only: str | None = None):
    """Options that the studies share; finished_only: what --finished-only prints (the study
    has the option when given)."""
    p.add_argument("--out", default=f"{name}-output", help="output folder")
    p.add_argument("--seeds", type=_count, nargs="+", default=[1, 2, 3],
                   help="seeds of the injection positions")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help=var_help)
    engine_options(p)
    p.add_argument("--np", type=_count, default=1, help="MPI ranks per run")
    p.add_argument("--no-render", action="store_true", help="no rendered packing images")
    if finished_only:
        p.add_argument("--finished-only", action="store_true",
                       help=f"run nothing: {finished_only}")


def _fixed_study_parser(sub, common, name: str, finished_only: str, help: str,
                        description: str) -> argparse.ArgumentParser:
    """The parser of a study of fixed runs (epd, conventions, one-at-a-time): resumable, with
    the studies' options and --finished-only printing `finished_only`."""
    p = sub.add_parser(name, parents=[common], help=help,
                       description=description + " Resumable; --finished-only tabulates what "
                                                 "is finished.")
    _study_options(p, name, "deck variables for every run", finished_only)
    return p


# --var names that something else sets, per command: {name: what sets it}
_OWN = {"rp": "use --rp", "U0": "use --U0", "gamma": "use --gamma", "q": "use --q",
        "N": "use --N"}


def _refused(command: str) -> dict:
    from .run.runner import RESERVED
    own = dict(_OWN, seed="use --seed" if command == "run" else "use --seeds")
    if command == "reproduce":
        # the study's cases set these; N by its size
        own.update({k: "reproduce sets it per case" for k in ("rp", "U0", "gamma", "q")},
                   N="reproduce sets it (--size)", L_rp="reproduce sets it (--size)")
    if command == "conventions":
        own.update({k: "the conventions study sets it per case" for k in
                    ("rp", "U0", "gamma", "q", "theta_crit")},
                   N="the conventions study runs the paper's N = 2000",
                   L_rp="the conventions study runs the paper's L = 28 r_p",
                   tracer="the conventions study follows none")
    if command == "one-at-a-time":
        own.update({k: "the study sets it per case" for k in ("rp", "U0", "gamma", "q", "inject")},
                   N="the study runs the paper's N = 2000", L_rp="the study runs the paper's L = 28 r_p",
                   tracer="the study follows none")
    if command in ("demo", "reproduce"):
        own["tracer"] = "use --tracer" if command == "demo" else "reproduce follows none"
    return dict(RESERVED, **own)


def _population_vars(a) -> dict:
    """Deck variables of --size, --charge, --inject (none when not given)."""
    from .run.population import CHARGE_KEYS, SIZE_KEYS, parse_spec, species_vars
    v = {}
    if getattr(a, "size", None) or getattr(a, "charge", None):
        rp = a.rp[0] if isinstance(a.rp, list) else a.rp
        size = parse_spec(a.size, SIZE_KEYS, "--size") if a.size else {"dist": "one", "r": rp}
        size.setdefault("r", rp) if size["dist"] == "one" else None
        charge = parse_spec(a.charge, CHARGE_KEYS, "--charge") if a.charge else None
        v = species_vars(1, size, charge)
        if size["dist"] == "one":
            v.pop("rp", None)          # one radius: --rp (a sweep's axis) stays
    if getattr(a, "inject", "auto") != "auto":
        v["inject"] = a.inject
    return v






from .studies.axes import announce, deck_params, sweep_params, var_axes  # noqa: E402


def _vars(a, command: str) -> tuple[dict, dict]:
    """--var pairs checked against the deck that will run: (DepositionParams fields, extra)."""
    from .run.deckfile import deck_variables
    from .params import split_deck_vars
    return split_deck_vars(a.var, deck_variables("in.deposition"), _refused(command))


def _out_dir(path, option="--out") -> Path:
    """An output folder: may exist as a folder, never as a file (ParamError before any run)."""
    from .params import ParamError
    p = Path(path)
    for q in (p, *p.parents):
        if q.exists():
            if not q.is_dir():
                raise ParamError(f"{option} {path}: {q} is a file, not a folder")
            break
    return p


def _runner(a, render=True):
    from .run.lammps_build import LammpsBuild
    from .run.runner import Runner
    build = LammpsBuild.find(getattr(a, "build_dir", None))
    return Runner(build, np_ranks=getattr(a, "np", 1), render=render,
                  checkpoint=getattr(a, "checkpoint", 0))


def _engine(a):
    from .studies.engine import Engine
    return Engine.from_args(a)


def cmd_run(a) -> int:
    from .run.runner import RunError, Runner
    from .studies.sweep import fmt
    from .run import estimate
    single, _ = var_axes(a.var, "run")
    p = deck_params(single, dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q), _population_vars(a),
                    _refused("run"), a.N, a.seed)
    Runner.check(p, a.tracer)
    from .run.population import protocol
    log.info("injection protocol: %s%s", protocol(p.deck_vars()),
             " (auto: rain when no particle is charged, plane when any is)"
             if a.inject == "auto" else "")
    log.info("%s", estimate.describe(estimate.estimate([p], [a.out])))
    out = _out_dir(a.out)
    runner = _runner(a, not a.no_render)
    runner.show_progress = a.progress
    log.info("run %s in %s (LAMMPS build %s)", p.key(), out.resolve(), runner.build.path)
    try:
        r = runner.deposition(p, out, force=a.force, tracer=a.tracer, lock=True)
    except RunError as e:
        log.error("%s", e)
        return 1
    state = "finished before (not run again)" if r["skipped"] else f"{r['wall_s']:.1f} s"
    log.info("%s: phi = %s, <Z> = %s, %d atoms, lost %d, flying %d (%s)", p.key(),
             fmt(r["phi"], ".4f"), fmt(r["Z"], ".3f"), r["natoms"], r["lost"], r["flying"], state)
    print((Path(r["dir"]) / "result.json").resolve())
    return 0


def cmd_sweep(a) -> int:
    from .run.runner import Runner
    from .studies.sweep import PAPER_SETS, Sweep, load_results
    single, axes = var_axes(a.var, "sweep")
    sets = PAPER_SETS if a.preset == "paper" else [dict(rp=a.rp, U0=a.U0, gamma=a.gamma, q=a.q)]
    popvars = _population_vars(a)
    params = sweep_params(sets, single, axes, popvars, _refused("sweep"), a.N, a.seeds)
    for p in params:
        Runner.check(p, a.tracer)
    announce(params, a.out, a.inject)
    out = _out_dir(a.out)
    figs = _out_dir(a.figures, "--figures") if a.figures else None
    runner = _runner(a, not a.no_render)
    if not runner.build.capabilities["coul/fmm"]:
        from .run.population import is_charged
        skip = [p for p in params if is_charged(p.deck_vars())]
        if skip:
            log.warning("%d charged runs NOT run: fix coul/fmm is absent from %s", len(skip),
                        runner.build.path)
        params = [p for p in params if not is_charged(p.deck_vars())]
    res = Sweep(runner, out, engine=_engine(a)).run(params, a.tracer)
    if figs is not None and params:
        from .analysis.tables import variant
        _figures(load_results(out), figs, None, variant(vars(params[0])))
    return 0 if len(res) == len(params) else 1






def _figures(results, out: Path, t2dir: Path | None, variant: str | None = None):
    from .figures.plan import all_figures
    from .analysis import tables
    from .run.after_formation import load_table2
    results = tables.one_variant(results, variant)
    rows = load_table2(t2dir) if t2dir is not None else []
    out.mkdir(parents=True, exist_ok=True)
    if results:
        s = tables.summary(tables.runs_frame(results))
        s.to_csv(out / "summary.csv", index=False)
        print(tables.format_table(s[["rp_um", "U0", "gamma_mJ", "q", "runs", "phi", "phi_sd", "Z",
                                     "Z_sd", "Adstar", "expansion"]]))
    paths = all_figures(results, out, rows)
    log.info("%d figures in %s", len(paths), out.resolve())
    return paths


def cmd_study(a) -> int:
    from .studies import studyfile
    if a.estimate_only:
        d = studyfile.load(a.file)
        announce(studyfile.params(d), Path(d["out"]) / "runs", d["protocol"])
        return 0
    res = studyfile.run(a.file, _runner(a, not a.no_render), engine=_engine(a))
    print(res["summary"].to_string(index=False))
    for f in res["figures"]:
        print(f)
    return 0 if res["complete"] else 1


def cmd_figures(a) -> int:
    from .studies.sweep import load_results
    out = _out_dir(a.out)
    results = load_results(Path(a.results))
    if not results:
        log.error("no finished runs (*/result.json) in %s", a.results)
        return 1
    _figures(results, out, Path(a.table2) if a.table2 else None, a.variant)
    return 0


def cmd_table2(a) -> int:
    from .analysis import tables
    from .run.after_formation import DECK, OWN, run_table2
    from .run.deckfile import deck_variables
    from .params import split_deck_vars
    _, extra = split_deck_vars(a.var, deck_variables(DECK), OWN, DECK)
    out = _out_dir(a.out)
    rows = run_table2(_runner(a), Path(a.formed), a.q, out, extra)
    print(tables.format_table(tables.table2_frame(rows), "{:.5g}"))
    return 0


def cmd_reproduce(a) -> int:
    from .studies.reproduce import Reproduction, report
    from .run.runner import Runner
    fields, extra = _vars(a, "reproduce")
    study = Reproduction(out=_out_dir(a.out), size_name=a.size, seeds=tuple(a.seeds),
                         extra=extra, fields=fields, jobs=a.jobs, progress=a.progress,
                         finished_only=a.finished_only, engine=_engine(a))
    for p in study.params(True):
        Runner.check(p, study.tracer(p))
    res = study.run(_runner(a, not a.no_render))
    text = report(res, study)
    (Path(res["out"]) / "report.txt").write_text(text + "\n")
    print(text)
    return 0 if res["complete"] or a.finished_only else 1


def cmd_demo(a) -> int:
    from .studies.demo import DEMO_VARS, Demo, claims_report, report
    from .run.runner import Runner
    fields, extra = _vars(a, "demo")
    study = Demo(out=_out_dir(a.out), N=a.N, qs=tuple(a.q), seeds=tuple(a.seeds),
                 table2_qs=tuple(a.table2_q), extra={**DEMO_VARS, **extra}, fields=fields,
                 jobs=a.jobs, progress=a.progress, follow=a.tracer, engine=_engine(a))
    for p in study.params(True):
        Runner.check(p, study.tracer(p))
    res = study.run(_runner(a, not a.no_render))
    print(report(res, study))
    if a.claims:
        print()
        print(claims_report(res))
    return 0 if res["complete"] else 1


def _study_runs(a, params) -> tuple[Path, list[dict]]:
    """A study of fixed runs (epd, conventions): run what is not finished in OUT/runs (nothing
    with --finished-only), then the finished runs of the study there (logged when none)."""
    from .studies.sweep import Sweep, load_results
    out = _out_dir(a.out)
    runs = out / "runs"
    if not a.finished_only:
        Sweep(_runner(a, not a.no_render), runs, engine=_engine(a)).run(params)
    keys = {p.key() for p in params}
    results = [r for r in load_results(runs) if r["key"] in keys] if runs.exists() else []
    if not results:
        log.error("no finished runs of the study in %s", runs)
    return out, results


def cmd_epd(a) -> int:
    from .studies import epd
    from .run.runner import Runner
    _, extra = _vars(a, "epd")
    params = epd.study_params(tuple(a.seeds))
    for p in params:
        p.extra.update(extra)
        Runner.check(p, 0)
    out, results = _study_runs(a, params)
    if not results:
        return 1
    t = epd.table(results)
    t.to_csv(out / "epd.csv", index=False)
    print(epd.format_table(t))
    from .figures.epd import epd_figures
    for path in epd_figures(results, out / "figures"):
        print(f"figure: {path}")
    return 0 if a.finished_only or len(results) == len(params) else 1


def _checked_study(a, command: str, study_params):
    """The runs of a study of fixed runs: its parameters (study_params(seeds, extra=, fields=)
    with the --var pairs checked for the command), each checked, then _study_runs; returns
    (out, params, results)."""
    from .run.runner import Runner
    fields, extra = _vars(a, command)
    params = study_params(tuple(a.seeds), extra=extra, fields=fields)
    for p in params:
        Runner.check(p, 0)
    out, results = _study_runs(a, params)
    return out, params, results


def _study_report(a, out: Path, name: str, params, results, *parts: str) -> int:
    """Print a study's report (how many runs are finished, then its parts), write it to
    OUT/<name>.txt; the exit status: 0 when every run is finished or with --finished-only."""
    text = "\n\n".join([f"{len(results)} of {len(params)} runs finished", *parts])
    (out / f"{name}.txt").write_text(text + "\n")
    print(text)
    return 0 if a.finished_only or len(results) == len(params) else 1


def cmd_conventions(a) -> int:
    from .studies import conventions
    out, params, results = _checked_study(a, "conventions", conventions.study_params)
    if not results:
        return 1
    t = conventions.case_table(conventions.run_frame(results))
    c = conventions.checks(t)
    t.to_csv(out / "conventions.csv", index=False)
    c.to_csv(out / "conventions_checks.csv", index=False)
    status = _study_report(a, out, "conventions", params, results, conventions.format_cases(t),
                           conventions.format_checks(c), conventions.verdict(c))
    from .figures.conventions import phi0_question
    path = phi0_question(t, out / "figures")
    if path:
        print(f"figure: {path}")
    return status


def cmd_one_at_a_time(a) -> int:
    from .studies import one_at_a_time as study
    out, params, results = _checked_study(a, "one-at-a-time", study.study_params)
    if not results:
        return 1
    t = study.case_table(study.run_frame(results))
    d = study.differences(t)
    t.to_csv(out / "one_at_a_time.csv", index=False)
    d.to_csv(out / "one_at_a_time_differences.csv", index=False)
    return _study_report(a, out, "one_at_a_time", params, results, study.format_table(t),
                         study.format_differences(d))


COMMANDS = {"run": cmd_run, "sweep": cmd_sweep, "study": cmd_study, "figures": cmd_figures, "table2": cmd_table2,
            "reproduce": cmd_reproduce, "demo": cmd_demo, "epd": cmd_epd,
            "conventions": cmd_conventions, "one-at-a-time": cmd_one_at_a_time}


def main(argv=None) -> int:
    a = build_parser().parse_args(argv)
    verbose, quiet = getattr(a, "verbose", 0), getattr(a, "quiet", 0)
    setup_logging(verbose, quiet)
    a.progress = quiet == 0 and sys.stderr.isatty()
    from .studies.engine import DryRunDone, EngineError
    from .run.lammps_build import BuildError
    from .params import ParamError
    from .run.runner import RunError
    try:
        return COMMANDS[a.command](a)
    except DryRunDone:
        return 0
    except EngineError as e:
        log.error("granular-charged %s: %s", a.command, e)
        return 1
    except ParamError as e:
        # before any run: nothing was started or written
        log.error("granular-charged %s: %s", a.command, e)
        return 2
    except BuildError as e:
        log.error("%s", e)
        return 2
    except RunError as e:
        log.error("%s", e)
        return 1
    except OSError as e:
        # a folder that cannot be made or written (permissions, a full disk, ...)
        if e.errno == errno.ENOSPC:
            where = Path(e.filename).parent if e.filename else Path(getattr(a, "out", "."))
            log.error("granular-charged %s: no space left in %s", a.command, where)
        else:
            log.error("granular-charged %s: %s", a.command, e)
        return 1
    except KeyboardInterrupt:
        log.error("interrupted: finished runs are kept; run the same command again to resume")
        return 130
