"""Keep the finished runs of a study in the repository, compressed, so that a study longer than
one sitting grows over several (doc/data/README.md).

    /usr/bin/python3 scripts/keep_runs.py STUDY_OUT/runs doc/data/paper-size/runs
    /usr/bin/python3 scripts/keep_runs.py --table2 STUDY_OUT/table2 doc/data/paper-size/table2
    /usr/bin/python3 scripts/keep_runs.py --images EPD_OUT/runs doc/data/epd/runs

Copies, for every run folder of SRC with a complete result.json that DST lacks: result.json,
measures.json (computed here when missing), final.dump and forces.dump gzip-compressed (the
package reads path.gz where path is absent), and for the run with a followed particle (the
first seed of a case) its tracer.dump up to 100 samples after the first contact (the dump
follows it every 10 steps to the end of the run) and the rendered packing.png at half size. Logs, restarts
and other dumps stay behind (~120 KB per run, ~0.5 MB with a tracer). With --images every run's
packing.png is kept at half size (~150 KB; the EPD study's pictures). Existing run folders of
DST are left as they are.
"""
from __future__ import annotations

import gzip
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from granular_charged import measures  # noqa: E402
from granular_charged.runner import read_result  # noqa: E402

PLAIN = ("result.json", "measures.json")
COMPRESSED = ("final.dump", "forces.dump")


def tracer_snapshots(text: str, upto: int) -> str:
    """The snapshots of a dump that hold the atom, the first `upto` of them."""
    blocks = text.split("ITEM: TIMESTEP")
    keep = [b for b in blocks[1:] if "ITEM: NUMBER OF ATOMS\n0\n" not in b][:upto]
    return "".join("ITEM: TIMESTEP" + b for b in keep)


def half_size_png(src: Path, dst: Path):
    from PIL import Image
    with Image.open(src) as im:
        im.reduce(2).save(dst, optimize=True)


def keep(src: Path, dst: Path, images: bool = False) -> int:
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
        approach = measures.tracer_approach(run, res)
        if approach is not None:
            # the approach up to its first contact, and 100 samples after it (measures, figures)
            with gzip.open(tmp / "tracer.dump.gz", "wt", 9) as fo:
                fo.write(tracer_snapshots((run / "tracer.dump").read_text(), approach[2] + 101))
        if (approach is not None or images) and (run / "packing.png").exists():
            half_size_png(run / "packing.png", tmp / "packing.png")
        tmp.rename(target)
        kept += 1
    return kept


TABLE2_DUMPS = ("before.dump", "after.dump", "forces_before.dump", "forces_after.dump")


def keep_table2(src: Path, dst: Path) -> int:
    """The Table 2 runs (STUDY_OUT/table2/q*/): result.json and the four dumps, compressed."""
    from granular_charged.after_formation import row_problem
    import json
    kept = 0
    for run in sorted(src.glob("q*")):
        try:
            row = json.loads((run / "result.json").read_text())
        except (OSError, ValueError):
            continue
        if row_problem(row) is not None or (dst / run.name / "result.json").exists():
            continue
        tmp = dst / f".{run.name}.tmp"
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        shutil.copy2(run / "result.json", tmp / "result.json")
        for name in TABLE2_DUMPS:
            if (run / name).exists():
                with open(run / name, "rb") as fi, gzip.open(tmp / f"{name}.gz", "wb", 9) as fo:
                    shutil.copyfileobj(fi, fo)
        tmp.rename(dst / run.name)
        kept += 1
    return kept


if __name__ == "__main__":
    args = sys.argv[1:]
    table2 = args[:1] == ["--table2"]
    images = args[:1] == ["--images"]
    if table2 or images:
        args = args[1:]
    if len(args) != 2:
        sys.exit(__doc__)
    src, dst = Path(args[0]), Path(args[1])
    dst.mkdir(parents=True, exist_ok=True)
    n = keep_table2(src, dst) if table2 else keep(src, dst, images)
    print(f"kept {n} new runs in {dst}")
