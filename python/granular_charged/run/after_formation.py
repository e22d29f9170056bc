"""The paper's Table 2 check: charge a formed neutral packing, relax, compare phi and <Z>.

Every charge starts from the same restart file (final.restart of a q = 0 deposition run); q = 0
is the control (restart + relaxation without charge). The deck is the package's
in.charged-after-formation; its numbers are read from the LAMMPS instance (lammps.json).
"""
from __future__ import annotations

import json
import logging
from pathlib import Path

from ..params import ParamError, coulomb_to_adhesion
from .deckfile import deck_variables
from .runner import RunError, Runner, load_result_files, read_result, write_json

DECK = "in.charged-after-formation"
# the variables of a Table 2 run that are not the formed packing's: where it starts from, the
# charge it is given, and its folder
OWN = {"restart": "the formed packing's final.restart", "q_after": "the Table 2 charges",
       "out": "the Table 2 run's folder"}
# what table2_frame and the figures read of a Table 2 run's result.json
ROW_KEYS = ("q", "phi_before", "phi_after", "Z_before", "Z_after", "FC_over_FE", "wall_s")

log = logging.getLogger(__name__)


def run_table2(runner: Runner, formed: Path, qs, out: Path, extra: dict | None = None) -> list[dict]:
    """One charged-after-formation run per charge in out/q<q>/, one after the other (a finished
    one is kept); writes out/table2.csv (atomically, when every charge is done) (ours beside the paper's Table 2) and returns the rows in the
    order of qs. Each run takes the formed run's parameters and every deck variable of it that
    in.charged-after-formation also has (the contact models, the Coulomb solver's settings, the
    slab), then `extra` (variables of that deck)."""
    deck = deck_variables(DECK)
    for k in extra or {}:
        if k in OWN or k not in deck:
            raise ParamError(f"{DECK}: {k!r} is not a variable a Table 2 run takes"
                             + (f" ({OWN[k]} sets it)" if k in OWN else ""))
    formed = Path(formed).resolve()
    res_formed = read_result(formed / "result.json")
    if res_formed is None:
        raise RunError(f"{formed}: no complete result.json of a deposition run")
    p = res_formed["params"]
    if p["q"] != 0:
        raise RunError("the formed packing must be neutral (q = 0)")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)

    def run_one(q) -> dict:
        wd = out / f"q{q:g}"
        rf = wd / "result.json"
        try:
            r = json.loads(rf.read_text())
            if row_problem(r) is None:
                r["dir"] = str(wd)
                log.debug("table 2, q = %g: finished before", q)
                return r
            log.info("table 2, q = %g: %s is incomplete, running it again", q, rf)
        except (OSError, ValueError):
            pass
        formed_vars = {k: v for k, v in p.items() if k != "extra"} | p.get("extra", {})
        v = {k: x for k, x in formed_vars.items() if k in deck and k not in OWN}
        v.update({"restart": str(formed / "final.restart"), "q_after": q, "out": "."})
        v.update(extra or {})
        lmp = runner.run_deck("in.charged-after-formation", wd, {k: str(x) for k, x in v.items()},
                              kind="after")
        r = dict(lmp)
        r.update({"q": q, "formed": str(formed), "params": p,
                  "FC_over_FE": coulomb_to_adhesion(p["gamma"], p["rp"], q)})
        write_json(rf, r)
        r["dir"] = str(wd)
        log.info("table 2, q = %g e0: phi %.5f -> %.5f, <Z> %.4f -> %.4f (%.0f s)", q,
                 r["phi_before"], r["phi_after"], r["Z_before"], r["Z_after"], r["wall_s"])
        return r

    rows = [run_one(q) for q in qs]
    tmp = out / "table2.csv.tmp"
    # pandas only when a check's table is written: the command line starts without it
    from ..analysis import tables
    tables.table2_frame(rows).to_csv(tmp, index=False)
    tmp.replace(out / "table2.csv")
    return rows


def table2_complete(folder: Path, qs) -> bool:
    """Whether folder holds a usable Table 2 run for each charge of qs."""
    have = {float(r["q"]) for r in load_table2(folder)
            if isinstance(r.get("q"), (int, float))}
    return all(float(q) in have for q in qs)



def load_table2(folder: Path) -> list[dict]:
    """The finished Table 2 runs under folder/q*/ (with 'dir'); unreadable or incomplete ones
    are named in a warning and left out."""
    return load_result_files(Path(folder).glob("q*/result.json"), row_problem)


def row_problem(r) -> str | None:
    """Why a Table 2 result.json cannot be used (None: it can): keys of a row missing."""
    missing = [k for k in ROW_KEYS if not isinstance(r, dict) or k not in r]
    return f"keys missing: {', '.join(missing)}" if missing else None
