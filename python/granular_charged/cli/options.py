"""Options that several subcommands share, and turning options into the objects that run: the
common options, a deposition's deck options, where the runs run (the workflow engine), the
studies' options; --var pairs checked against the deck, output folders, the runner and engine."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

from ..params import ParamError, split_deck_vars
from ..run import deckfile
from ..run.lammps_build import LammpsBuild
from ..run.population import CHARGE_KEYS, SIZE_KEYS, parse_spec, species_vars
from ..run.runner import RESERVED, Runner
from ..studies.engine import Engine


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Every option's default in --help; descriptions as written (their own line breaks)."""


def _whole_at_least(text: str, least: int) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if v < least:
        raise argparse.ArgumentTypeError(f"must be >= {least}, not {v}")
    return v


def count(text: str) -> int:
    """argparse type: a whole number >= 1 (particles, ranks, jobs)."""
    return _whole_at_least(text, 1)


def count_or_zero(text: str) -> int:
    """argparse type: a whole number >= 0 (0: none; particles between restart points)."""
    return _whole_at_least(text, 0)


def common() -> argparse.ArgumentParser:
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


# a number written with a minus sign (-2, -.5, -2e-7, -1E+3): an option's value, never an
# option (argparse's own rule takes -2e-7 for an option name: `--var q_sigma -2e-7` failed)
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def add_command(subparsers, name: str, **kwargs) -> argparse.ArgumentParser:
    """A subcommand's parser, with the common options; a negative number (-2e-7) after an
    option is its value."""
    p = subparsers.add_parser(name, parents=[common()], **kwargs)
    p._negative_number_matcher = NEGATIVE_NUMBER
    return p


def deck_options(p: argparse.ArgumentParser, many: bool):
    """The deposition's options (run: one value each; sweep: several, an axis each)."""
    nargs = "+" if many else None
    p.add_argument("--rp", type=float, nargs=nargs, default=[2e-6] if many else 2e-6,
                   help="particle radius [m]")
    p.add_argument("--U0", type=float, nargs=nargs, default=[1.0] if many else 1.0,
                   help="injection speed [m/s]")
    p.add_argument("--gamma", type=float, nargs=nargs, default=[0.010] if many else 0.010,
                   help="surface energy [J/m^2]")
    p.add_argument("--q", type=float, nargs=nargs, default=[0.0] if many else 0.0,
                   help="charge per particle [e0]")
    p.add_argument("--N", type=count, default=2000, help="particles to inject")
    p.add_argument("--np", type=count, default=1, help="MPI ranks per run (mpirun)")
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
    g = p.add_argument_group("contact charging (fix tribo/charge)",
                             "doc/populations.md, section Contact charging")
    g.add_argument("--tribo", action="store_true",
                   help="contacts charge the particles (in.deposition's tribo yes); the "
                        "injected particles keep their charge rule (--q 0: neutral)")
    g.add_argument("--tribo-V", nargs="+", default=None, metavar="V",
                   help="contact potential (work function / e) [V] of species 1, 2, 3 in "
                        "order (tribo_V, tribo_V_2, tribo_V_3; a species not given has species "
                        "1's); only differences matter (default 0)")
    g.add_argument("--tribo-V-wall", default=None, metavar="V",
                   help="the floor's contact potential [V] (tribo_V_wall, default 0)")
    g.add_argument("--tribo-z0", default=None, metavar="M",
                   help="cut-off gap z0 of the condenser model [m] (tribo_z0, default 4e-10)")
    g.add_argument("--tribo-field", choices=["yes", "no"], default=None,
                   help="yes: the normal field at a contact reduces the transfer (tribo_field, "
                        "default yes)")
    p.add_argument("--tracer", type=int, default=0, help="follow this particle id (Fig. 8)")
    p.add_argument("--checkpoint", type=int, default=0, metavar="K",
                   help="plane and sequential injection: a restart point every K particles; an "
                        "interrupted run goes on from its last one when run again (0: none)")
    p.add_argument("--no-render", action="store_true", help="no rendered packing image")


def engine_options(p: argparse.ArgumentParser):
    """How a study's runs run: locally, or submitted to Slurm or another batch system (the
    workflow engine, Snakemake: doc/python.md, "Many runs and clusters")."""
    g = p.add_argument_group("where the runs run (Snakemake)")
    g.add_argument("--jobs", "--cores", type=count, default=1,
                   help="runs at a time on this machine; with --slurm or --cluster: jobs "
                        "queued at once")
    g.add_argument("--slurm", action="store_true",
                   help="submit each run as a Slurm job (sbatch) with its --np MPI ranks and a "
                        "time limit from its estimated cost")
    g.add_argument("--account", default=None, help="Slurm account (sbatch -A)")
    g.add_argument("--partition", default=None, help="Slurm partition (sbatch -p)")
    g.add_argument("--mem-mb", type=count, default=None, metavar="MB",
                   help="memory per job [MB] on a cluster")
    g.add_argument("--cluster", default=None, metavar="TEMPLATE",
                   help="submit each run with this command (Snakemake's --cluster template, e.g. "
                        "'qsub -l walltime={resources.runtime}:00 -pe mpi {resources.tasks}')")
    g.add_argument("--dry-run", action="store_true",
                   help="print the runs that would run or be submitted, run nothing")
    g.add_argument("--unlock", action="store_true",
                   help="first remove the lock a killed study left on the folder")


def study_options(p: argparse.ArgumentParser, name: str, var_help: str,
                  finished_only: str | None = None):
    """Options that the studies share; finished_only: what --finished-only prints (the study
    has the option when given)."""
    p.add_argument("--out", default=f"{name}-output", help="output folder")
    p.add_argument("--seeds", type=count, nargs="+", default=[1, 2, 3],
                   help="seeds of the injection positions")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help=var_help)
    engine_options(p)
    p.add_argument("--np", type=count, default=1, help="MPI ranks per run")
    p.add_argument("--no-render", action="store_true", help="no rendered packing images")
    if finished_only:
        p.add_argument("--finished-only", action="store_true",
                       help=f"run nothing: {finished_only}")


# --var names that something else sets, per command: {name: what sets it}
_OWN = {"rp": "use --rp", "U0": "use --U0", "gamma": "use --gamma", "q": "use --q",
        "N": "use --N"}


def refused(command: str) -> dict:
    """The --var names the command does not take: {name: what sets it instead}."""
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


# the contact-charging options and their deck variables (--tribo-V: one per species)
TRIBO_OPTIONS = {"tribo_V_wall": "tribo_V_wall", "tribo_z0": "tribo_z0",
                 "tribo_field": "tribo_field"}


def tribo_vars(a) -> dict:
    """Deck variables of --tribo and its values (none when not given); ParamError for values
    without --tribo (the deck would not read them) and for more potentials than species."""
    v = {}
    potentials = getattr(a, "tribo_V", None) or []
    given = [f"--{k.replace('_', '-')}" for k in ("tribo_V", *TRIBO_OPTIONS)
             if getattr(a, k, None) is not None]
    if not getattr(a, "tribo", False):
        if given:
            raise ParamError(f"{given[0]}: contact charging's values are read with --tribo only")
        return v
    v["tribo"] = "yes"
    if len(potentials) > 3:
        raise ParamError(f"--tribo-V {' '.join(potentials)}: one contact potential per species, "
                         "at most 3")
    for s, value in enumerate(potentials, start=1):
        v["tribo_V" + ("" if s == 1 else f"_{s}")] = value
    for opt, name in TRIBO_OPTIONS.items():
        if getattr(a, opt, None) is not None:
            v[name] = getattr(a, opt)
    return v


def check_species_values(p):
    """ParamError for a contact potential of a species the run does not have (--tribo-V with
    more values than species: the deck would not read them)."""
    n = int(float(p.extra.get("species", 1)))
    extra = [k for k in ("tribo_V_2", "tribo_V_3") if k in p.extra and int(k[-1]) > n]
    if extra:
        raise ParamError(f"{extra[0]} = {p.extra[extra[0]]}: the run has {n} species "
                         f"(--var species {int(extra[0][-1])} for more)")


def population_vars(a) -> dict:
    """Deck variables of --size, --charge, --inject and the contact-charging options (none when
    not given)."""
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
    v.update(tribo_vars(a))
    return v


def deck_vars(a, command: str) -> tuple[dict, dict]:
    """--var pairs checked against the deck that will run: (DepositionParams fields, extra)."""
    return split_deck_vars(a.var, deckfile.deck_variables("in.deposition"), refused(command))


def out_dir(path, option="--out") -> Path:
    """An output folder: may exist as a folder, never as a file (ParamError before any run)."""
    p = Path(path)
    for q in (p, *p.parents):
        if q.exists():
            if not q.is_dir():
                raise ParamError(f"{option} {path}: {q} is a file, not a folder")
            break
    return p


def runner(a, render=True) -> Runner:
    """The runner of one case with the LAMMPS build, ranks and checkpoints of the options."""
    build = LammpsBuild.find(getattr(a, "build_dir", None))
    return Runner(build, np_ranks=getattr(a, "np", 1), render=render,
                  checkpoint=getattr(a, "checkpoint", 0))


def engine(a) -> Engine:
    """The workflow engine with the options' place to run (locally, Slurm, a cluster)."""
    return Engine.from_args(a)
