"""Keep the finished runs of a study in the repository, compressed, so that a study longer than
one sitting grows over several (doc/data/README.md).

    /usr/bin/python3 scripts/keep_runs.py STUDY_OUT/runs doc/data/paper-size/runs
    /usr/bin/python3 scripts/keep_runs.py --table2 STUDY_OUT/table2 doc/data/paper-size/table2
    /usr/bin/python3 scripts/keep_runs.py --images EPD_OUT/runs doc/data/epd/runs
    /usr/bin/python3 scripts/keep_runs.py --points STUDY_OUT/runs doc/data/paper-size/points
    /usr/bin/python3 scripts/keep_runs.py --unpack-points doc/data/paper-size/points STUDY_OUT/runs

Copies, for every run folder of SRC with a complete result.json that DST lacks: result.json,
measures.json (computed here when missing), final.dump and forces.dump gzip-compressed (the
package reads path.gz where path is absent), and for the run with a followed particle (the
first seed of a case) its tracer.dump up to 100 samples after the first contact (the dump
follows it every 10 steps to the end of the run) and the rendered packing.png at half size. Logs, restarts
and other dumps stay behind (~120 KB per run, ~0.5 MB with a tracer). With --images every run's
packing.png is kept at half size (~150 KB; the EPD study's pictures). Existing run folders of
DST are left as they are.

--points keeps the latest restart point of every unfinished run of SRC (a run that has one and
no result.json; doc/deposition.md "Restart points"): checkpoint.vars, the restart file
gzip-compressed, pieces.json and the followed particle's tracer.dump, replacing an older point of
the same run in DST and dropping the kept point of a run that has finished since. A machine lost
between sittings then costs the work since that point, not the whole run. The interrupted piece
is closed in the kept pieces.json at the point's time (the runner would take it from
checkpoint.vars's modification time, which a git checkout does not keep). --unpack-points puts
them back into a working copy's runs folder, decompressed, where the same run command goes on
from them; a run folder there that already has a result or a later point is left alone.
"""
from __future__ import annotations

import gzip
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from granular_charged.analysis import measures  # noqa: E402
from granular_charged.run.runner import read_result  # noqa: E402

PLAIN = ("result.json", "measures.json")
COMPRESSED = ("final.dump", "forces.dump")


def gzip_copy(src: Path, dst: Path):
    """src compressed into dst (level 9)."""
    with open(src, "rb") as fi, gzip.open(dst, "wb", 9) as fo:
        shutil.copyfileobj(fi, fo)


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
                gzip_copy(run / name, tmp / f"{name}.gz")
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


POINT_FILES = ("checkpoint.vars", "pieces.json", "tracer.dump")


def keep_points(src: Path, dst: Path) -> int:
    """The latest restart point of each unfinished run of src into dst/<run>/ (see --points)."""
    import json
    from granular_charged.run.runner import CHECKPOINT_VARS, close_interrupted_pieces, restart_point
    kept = 0
    for run in sorted(p for p in src.iterdir() if p.is_dir()):
        target = dst / run.name
        if read_result(run / "result.json") is not None:
            shutil.rmtree(target, ignore_errors=True)      # finished: keep_runs keeps it
            continue
        point = restart_point(run)
        if point is None:
            continue
        kept_point = restart_point(target, ".gz") if target.is_dir() else None
        if kept_point is not None and kept_point["k"] >= point["k"]:
            continue
        tmp = dst / f".{run.name}.tmp"
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        try:
            # a running deposition replaces its point as it goes: checkpoint.vars names the
            # restart file, and the previous file is removed only after the next one is named
            vars_text = (run / CHECKPOINT_VARS).read_text()
            mtime = (run / CHECKPOINT_VARS).stat().st_mtime
            restart = run / f"checkpoint-{point['k']}.restart"
            gzip_copy(restart, tmp / f"{restart.name}.gz")
        except FileNotFoundError:
            shutil.rmtree(tmp)
            continue
        if f"ck_k equal {point['k']}" not in vars_text:
            shutil.rmtree(tmp)                             # a newer point came meanwhile
            continue
        (tmp / CHECKPOINT_VARS).write_text(vars_text)
        for name in POINT_FILES[2:]:
            if (run / name).exists():
                gzip_copy(run / name, tmp / f"{name}.gz")
        if (run / "pieces.json").exists():
            pieces = json.loads((run / "pieces.json").read_text())
            close_interrupted_pieces(pieces, mtime)
            (tmp / "pieces.json").write_text(json.dumps(pieces, indent=1) + "\n")
        shutil.rmtree(target, ignore_errors=True)
        tmp.rename(target)
        kept += 1
    return kept


def unpack_points(src: Path, dst: Path) -> int:
    """Kept restart points of src back into the run folders of dst, decompressed."""
    from granular_charged.run.runner import restart_point
    unpacked = 0
    for kept in sorted(p for p in src.iterdir() if p.is_dir() and not p.name.startswith(".")):
        point = restart_point(kept, ".gz")
        run = dst / kept.name
        if point is None or read_result(run / "result.json") is not None:
            continue
        there = restart_point(run) if run.is_dir() else None
        if there is not None and there["k"] >= point["k"]:
            continue
        shutil.rmtree(run, ignore_errors=True)
        run.mkdir(parents=True)
        for path in kept.iterdir():
            if path.name.endswith(".gz"):
                with gzip.open(path, "rb") as fi, open(run / path.name[:-3], "wb") as fo:
                    shutil.copyfileobj(fi, fo)
            else:
                shutil.copy2(path, run / path.name)
        unpacked += 1
    return unpacked


TABLE2_DUMPS = ("before.dump", "after.dump", "forces_before.dump", "forces_after.dump")


def keep_table2(src: Path, dst: Path) -> int:
    """The Table 2 runs (STUDY_OUT/table2/q*/): result.json and the four dumps, compressed."""
    from granular_charged.run.after_formation import row_problem
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
                gzip_copy(run / name, tmp / f"{name}.gz")
        tmp.rename(dst / run.name)
        kept += 1
    return kept


if __name__ == "__main__":
    args = sys.argv[1:]
    mode = args[0] if args[:1] and args[0].startswith("--") else ""
    if mode:
        args = args[1:]
    if len(args) != 2 or mode not in ("", "--table2", "--images", "--points", "--unpack-points"):
        sys.exit(__doc__)
    src, dst = Path(args[0]), Path(args[1])
    dst.mkdir(parents=True, exist_ok=True)
    if mode == "--points":
        print(f"kept {keep_points(src, dst)} new restart points in {dst}")
    elif mode == "--unpack-points":
        print(f"put {unpack_points(src, dst)} restart points into {dst}")
    else:
        n = keep_table2(src, dst) if mode == "--table2" else keep(src, dst, mode == "--images")
        print(f"kept {n} new runs in {dst}")
