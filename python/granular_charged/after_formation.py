"""The paper's Table 2 check: charge a formed neutral packing, relax, compare phi and <Z>.

  /usr/bin/python3 -m granular_charged.after_formation --formed demo-output/runs/<neutral run> \
      --q 0 260 400 --out table2

Every charge starts from the same restart file (final.restart of a q = 0 deposition run); q = 0
is the control (restart + relaxation without charge).
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

from .params import coulomb_to_adhesion
from .runner import SOURCE_DIR, RunError, find_build, run_deck

DECK = SOURCE_DIR / "examples" / "charged-after-formation" / "in.charged-after-formation"


def parse_after(log: Path) -> dict:
    line = [ln for ln in log.read_text(errors="replace").splitlines() if ln.startswith("GC AFTER")]
    if not line:
        raise RunError(f"no 'GC AFTER' line in {log}")
    tok = line[-1].split()[2:]
    return {k: float(v) for k, v in zip(tok[0::2], tok[1::2])}


def run_table2(formed: Path, qs, out: Path, build=None, np_ranks=1, extra=None) -> list[dict]:
    build = find_build(build)
    formed = Path(formed).resolve()
    res_formed = json.loads((formed / "result.json").read_text())
    p = res_formed["params"]
    if p["q"] != 0:
        raise RunError("the formed packing must be neutral (q = 0)")
    rows = []
    for q in qs:
        wd = Path(out) / f"q{q:g}"
        rf = wd / "result.json"
        if rf.exists():
            rows.append(json.loads(rf.read_text()))
            continue
        v = {k: p[k] for k in ("rp", "U0", "gamma", "rho", "E", "nu", "e", "mu", "theta_crit")}
        v.update({"restart": str(formed / "final.restart"), "q_after": q, "out": "."})
        for k in ("zlo_rp", "top_rp"):
            if k in p.get("extra", {}):
                v[k] = p["extra"][k]
        v.update(extra or {})
        wall = run_deck(wd, {k: str(x) for k, x in v.items()}, build, np_ranks, DECK)
        r = parse_after(wd / "log.lammps")
        r.update({"q": q, "wall_s": wall, "formed": str(formed),
                  "FC_over_FE": coulomb_to_adhesion(p["gamma"], p["rp"], q)})
        rf.write_text(json.dumps(r, indent=1))
        rows.append(r)
    with open(Path(out) / "table2.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["q_e0", "phi_before", "phi_after", "Z_before", "Z_after", "FC_over_FE"])
        for r in rows:
            w.writerow([r["q"], r["phi_before"], r["phi_after"], r["Z_before"], r["Z_after"],
                        r["FC_over_FE"]])
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--formed", required=True, help="run folder of a neutral deposition")
    ap.add_argument("--q", type=float, nargs="+", default=[0.0, 260.0, 400.0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--build-dir", default=None)
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    a = ap.parse_args(argv)
    Path(a.out).mkdir(parents=True, exist_ok=True)
    rows = run_table2(Path(a.formed), a.q, Path(a.out), a.build_dir, a.np, dict(a.var))
    print(f"{'q/e0':>6} {'phi before':>11} {'phi after':>10} {'<Z> before':>11} {'<Z> after':>10}"
          f" {'F_C/F_E':>9}")
    for r in rows:
        print(f"{r['q']:6g} {r['phi_before']:11.5f} {r['phi_after']:10.5f} {r['Z_before']:11.4f} "
              f"{r['Z_after']:10.4f} {r['FC_over_FE']:9.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
