"""``granular-charged table2``: the Table 2 check on a finished neutral run."""
from __future__ import annotations

from pathlib import Path

from ..params import split_deck_vars
from ..run import deckfile
from ..run.after_formation import DECK, OWN, run_table2
from . import options


def register(subparsers):
    p = options.add_command(subparsers, "table2",
                            help="the Table 2 check on a finished neutral run",
                            description="Charge a formed neutral packing (a finished run folder "
                                        "of 'run' or 'sweep') after its formation and relax it "
                                        "(the package's in.charged-after-formation deck), one "
                                        "folder per charge under --out, and write table2.csv "
                                        "beside the paper's Table 2. Resumable.")
    p.add_argument("formed", help="run folder of a finished neutral deposition")
    p.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0],
                   help="charges [e0] given after formation (0: the control)")
    p.add_argument("--out", required=True, help="folder of the Table 2 runs")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help="a variable of in.charged-after-formation for every run (the formed "
                        "run's own settings are taken over), e.g. --var relax_rp 50")
    p.add_argument("--np", type=options.count, default=1, help="MPI ranks per run")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the table loads pandas: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..analysis import tables
    _, extra = split_deck_vars(a.var, deckfile.deck_variables(DECK), OWN, DECK)
    out = options.out_dir(a.out)
    rows = run_table2(options.runner(a), Path(a.formed), a.q, out, extra)
    print(tables.format_table(tables.table2_frame(rows), "{:.5g}"))
    return 0
