"""The paper's Table 2 check: charge a formed neutral packing, relax, compare phi and <Z>.

Every charge starts from the same restart file (final.restart of a q = 0 deposition run); q = 0
is the control (restart + relaxation without charge). The deck is the package's
in.charged-after-formation; its numbers are read from the LAMMPS instance (lammps.json).
"""
from __future__ import annotations

import json
import logging
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from . import tables
from .params import coulomb_to_adhesion
from .runner import RunError, Runner, read_result, write_json

log = logging.getLogger(__name__)


def run_table2(runner: Runner, formed: Path, qs, out: Path, extra: dict | None = None,
               jobs: int = 1) -> list[dict]:
    """One charged-after-formation run per charge in out/q<q>/ (resumable; up to `jobs` at a
    time); writes out/table2.csv (ours beside the paper's Table 2) and returns the rows in the
    order of qs."""
    formed = Path(formed).resolve()
    res_formed = read_result(formed / "result.json")
    if res_formed is None:
        raise RunError(f"{formed}: no complete result.json of a deposition run")
    p = res_formed["params"]
    if p["q"] != 0:
        raise RunError("the formed packing must be neutral (q = 0)")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)

    def one(q) -> dict:
        wd = out / f"q{q:g}"
        rf = wd / "result.json"
        if rf.exists():
            try:
                r = json.loads(rf.read_text())
                r["dir"] = str(wd)
                log.debug("table 2, q = %g: finished before", q)
                return r
            except ValueError:
                pass
        v = {k: p[k] for k in ("rp", "U0", "gamma", "rho", "E", "nu", "e", "mu", "theta_crit")}
        v.update({"restart": str(formed / "final.restart"), "q_after": q, "out": "."})
        for k in ("zlo_rp", "top_rp"):
            if k in p.get("extra", {}):
                v[k] = p["extra"][k]
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

    if jobs > 1 and len(qs) > 1:
        with ThreadPoolExecutor(min(jobs, len(qs))) as ex:
            rows = list(ex.map(one, qs))    # each run is a LAMMPS subprocess
    else:
        rows = [one(q) for q in qs]
    tables.table2_frame(rows).to_csv(out / "table2.csv", index=False)
    return rows


def main(argv=None) -> int:
    """python3 -m granular_charged.after_formation --formed RUN_DIR --q ... --out DIR"""
    import argparse

    from .cli import setup_logging
    from .lammps_build import LammpsBuild
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--formed", required=True, help="run folder of a neutral deposition")
    ap.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--build-dir", default=None)
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1, help="runs at a time")
    ap.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    a = ap.parse_args(argv)
    setup_logging(0, 0)
    runner = Runner(LammpsBuild.find(a.build_dir), np_ranks=a.np)
    rows = run_table2(runner, Path(a.formed), a.q, Path(a.out), dict(a.var), jobs=a.jobs)
    print(tables.format_table(tables.table2_frame(rows), "{:.5g}"))
    return 0


if __name__ == "__main__":
    import sys
    sys.exit(main())
