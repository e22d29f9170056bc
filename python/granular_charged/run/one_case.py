"""Run one case of a study's plan: ``python -m granular_charged.run.one_case PLAN FOLDER`` (the job
of the package's Snakefile, granular_charged.studies.engine). A deposition writes FOLDER/result.json,
a Table 2 check FOLDER/table2.csv, each atomically at its end; a case that fails writes its
error to FOLDER/failed.txt (its target stays missing, so the engine runs it again next time)
and exits 1."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from ..params import DepositionParams, ParamError
from .after_formation import run_table2
from .lammps_build import BuildError, LammpsBuild
from .logs import setup_case_logging
from .runner import RunError, Runner

# a failed case's error, in its folder (the engine reports it)
FAILED = "failed.txt"


def run(plan_path: str, folder: str) -> int:
    setup_case_logging()
    plan = json.loads(Path(plan_path).read_text())
    job = next(j for j in plan["jobs"] if j["folder"] == folder)
    root = Path(plan["root"])
    wd = root / folder
    try:
        runner = Runner(LammpsBuild.find(plan["build_dir"]), np_ranks=job["np"],
                        timeout=plan.get("timeout"), render=plan["render"],
                        checkpoint=plan["checkpoint"])
        if job["kind"] == "deposition":
            p = DepositionParams(**job["params"])
            if wd.name not in (p.key(), p.legacy_key()):
                raise ParamError(f"{wd}: the folder of run {p.key()} must be named after it")
            runner.deposition(p, wd.parent, tracer=job["tracer"], folder=wd)
        else:
            run_table2(runner, root / job["formed"], job["qs"], wd, job["extra"])
    except (RunError, ParamError, BuildError, OSError) as e:
        message = f"{type(e).__name__}: {e}" if isinstance(e, OSError) else str(e)
        try:
            wd.mkdir(parents=True, exist_ok=True)
            (wd / FAILED).write_text(message + "\n")
        except OSError:
            pass
        print(message, file=sys.stderr)
        return 1
    (wd / FAILED).unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python -m granular_charged.run.one_case PLAN FOLDER")
    sys.exit(run(sys.argv[1], sys.argv[2]))
