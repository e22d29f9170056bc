"""Whether a finished run settled and deposited every particle asked: the deck's result line
(GC RESULT, with its `settled 0|1` field in decks that print it) and result.json's fields, as
one status with a warning line (run.logs re-exports these for the modules that read logs)."""
from __future__ import annotations

import math
from pathlib import Path


RESULT_PREFIX = "GC RESULT "
RESULT_INTS = ("steps", "inserted", "atoms", "lost", "flying", "settled")


def parse_result_line(text: str) -> dict | None:
    """The last 'GC RESULT name value ...' line of a log's text as {name: value} (numbers as
    numbers, 'none' as None; steps, inserted, atoms, lost, flying, settled as ints), None
    without one. A log of a deck without the settled field has no 'settled' key."""
    line = None
    for ln in text.splitlines():
        if ln.startswith(RESULT_PREFIX):
            line = ln
    if line is None:
        return None
    w = line[len(RESULT_PREFIX):].split()
    out = {}
    for k, v in zip(w[0::2], w[1::2]):
        if v == "none":
            out[k] = None
            continue
        try:
            x = float(v)
        except ValueError:
            out[k] = v
            continue
        out[k] = int(round(x)) if k in RESULT_INTS and math.isfinite(x) else x
    return out


def read_result_line(run_dir) -> dict | None:
    """parse_result_line of a run folder's log.lammps (None without the file or the line)."""
    try:
        return parse_result_line((Path(run_dir) / "log.lammps").read_text(errors="replace"))
    except OSError:
        return None


def run_status(result: dict) -> dict:
    """Whether a finished run settled and deposited the particles asked: {'settled': True,
    False or None (not known: a log without the field), 'made': particles made, 'asked': N,
    'short': made < N, 'warning': one line or None}. Read from result.json's fields (settled,
    inserted) when they are there, else from the GC RESULT line of the run's log.lammps."""
    params = result.get("params") or {}
    lmp = result.get("lammps") or {}
    line = None
    settled = result.get("settled", lmp.get("settled"))
    made = result.get("inserted", lmp.get("inserted"))
    if (settled is None or made is None) and result.get("dir"):
        line = read_result_line(result["dir"]) or {}
        settled = line.get("settled") if settled is None else settled
        made = line.get("inserted") if made is None else made
    settled = None if settled is None else bool(int(settled))
    try:
        asked = int(params.get("N"))
    except (TypeError, ValueError):
        asked = None
    made = None if made is None else int(made)
    short = made is not None and asked is not None and made < asked
    problems = []
    if short:
        problems.append(f"only {made} of {asked} particles were deposited (the bed's charge "
                        "turned the next one back, or no free place to start)")
    if settled is False:
        flying = result.get("flying", lmp.get("flying"))
        problems.append("the bed did NOT settle (the kinetic-energy criterion was not met"
                        + (f"; {flying} particles still moving" if flying else "") + ")")
    return {"settled": settled, "made": made, "asked": asked, "short": short,
            "warning": "; ".join(problems) or None}
