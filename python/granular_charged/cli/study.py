"""``granular-charged study``: a study of one's own powder from a TOML file."""
from __future__ import annotations

from pathlib import Path

from ..studies.axes import announce
from . import options
from .figures import draw_study_file


def register(subparsers):
    p = options.add_command(subparsers, "study", help="a study of your own powder from a TOML file",
                            description="Run the study a TOML file describes (material(s), "
                                        "population, protocol, grid, seeds; doc/populations.md), "
                                        "resumably, then its tables and figures (labelled with "
                                        "its name) in its out folder.")
    p.add_argument("file", help="the study file (TOML)")
    options.engine_options(p)
    p.add_argument("--np", type=options.count, default=1, help="MPI ranks per run")
    p.add_argument("--no-render", action="store_true", help="no rendered packing images")
    p.add_argument("--estimate-only", action="store_true",
                   help="print the runs' protocols and estimated cost, run nothing")
    p.set_defaults(handler=run)


def run(a) -> int:
    # the study file's module loads pandas and matplotlib: imported when the command runs, so that the command line
    # answers --help and argument errors without it
    from ..studies import studyfile
    if a.estimate_only:
        d = studyfile.load(a.file)
        announce(studyfile.params(d), Path(d["out"]) / "runs", d["protocol"])
        return 0
    res = studyfile.run(a.file, options.runner(a, not a.no_render), engine=options.engine(a))
    draw_study_file(res)
    print(res["summary"].to_string(index=False))
    for f in res["figures"]:
        print(f)
    return 0 if res["complete"] else 1
