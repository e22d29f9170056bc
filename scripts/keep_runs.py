"""Keep the finished runs of a study in the repository, compressed, so that a study longer than
one sitting grows over several (doc/data/README.md).

    /usr/bin/python3 scripts/keep_runs.py STUDY_OUT/runs doc/data/paper-size/runs

Copies, for every run folder of SRC with a complete result.json that DST lacks: result.json,
measures.json (computed here when missing), the rendered packing.png, and final.dump,
forces.dump and tracer.dump gzip-compressed (the package reads path.gz where path is absent).
Logs, restarts and other dumps stay behind. Existing run folders of DST are left as they are.
"""
from __future__ import annotations

import gzip
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from granular_charged import measures  # noqa: E402
from granular_charged.runner import read_result  # noqa: E402

PLAIN = ("result.json", "measures.json", "packing.png")
COMPRESSED = ("final.dump", "forces.dump", "tracer.dump")


def keep(src: Path, dst: Path) -> int:
    kept = 0
    for run in sorted(p for p in src.iterdir() if p.is_dir()):
        res = read_result(run / "result.json")
        target = dst / run.name
        if res is None or (target / "result.json").exists():
            continue
        measures.load(run, dict(res, dir=str(run)))
        tmp = dst / f".{run.name}.tmp"
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        for name in PLAIN:
            if (run / name).exists():
                shutil.copy2(run / name, tmp / name)
        for name in COMPRESSED:
            if (run / name).exists():
                with open(run / name, "rb") as fi, gzip.open(tmp / f"{name}.gz", "wb", 9) as fo:
                    shutil.copyfileobj(fi, fo)
        tmp.rename(target)
        kept += 1
    return kept


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, dst = Path(sys.argv[1]), Path(sys.argv[2])
    dst.mkdir(parents=True, exist_ok=True)
    print(f"kept {keep(src, dst)} new runs in {dst}")
