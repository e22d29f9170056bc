#!/usr/bin/env python3
"""The cost estimate (granular_charged.run.estimate) against the actual CPU of small runs of
in.deposition on this machine: the demo's cases, the regolith example and a toner-like binary
powder, N reduced. Runs lmp one case at a time (one process), then prints per case the
estimate, the actual CPU (the child's user + system time, from the resource usage: on a shared
machine CPU time, not wall time, is what the model predicts), their ratio, and the steps and
settling predicted and measured. doc/benchmarks.md, "Cost estimate against the actual CPU",
keeps the table.

    . build/env.sh
    python3 bench/estimate/estimate_vs_actual.py [--lmp build/lmp] [--only demo-q0,...]
        [--scale 1.0] [--json out.json] [--fit] [--measured out.json]

--fit prints the per-particle-step costs and the settling (in r_p / U_0) that reproduce the
measurements (per kind: the c of DEFAULT_C in estimate.py, and the settling measured); --measured prints the
table again from the measurements of an earlier --json (no run: the estimate of today's model
against them). Exit status 1 when a ratio lies outside [1/2, 2].
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(SRC / "python"))

from granular_charged.params import DepositionParams  # noqa: E402
from granular_charged.run import estimate, logs, population  # noqa: E402

DECK = SRC / "python" / "granular_charged" / "decks" / "in.deposition"

DEMO = {"L_rp": "14", "inject": "rain", "gap_rp": "1"}
REGOLITH = [{"size": "uniform lo=3e-6 hi=7e-6", "charge": "area sigma=5e-7",
             "material": {"rho": 3000, "E": 1e8, "gamma": 0.020}}]
TONER = [{"fraction": 0.7, "size": "lognormal median=4e-6 gsd=1.25",
          "charge": "area sigma=-1e-6",
          "material": {"rho": 1100, "E": 5e8, "nu": 0.4, "gamma": 0.04, "e": 0.5, "mu": 0.4}},
         {"fraction": 0.3, "size": "uniform lo=2e-6 hi=3e-6", "charge": "area sigma=1e-6",
          "material": {"rho": 2200, "E": 1e9, "nu": 0.2, "gamma": 0.02, "e": 0.7, "mu": 0.3}}]


def population_params(species, N, U0, extra, sigma_scale=1.0):
    """DepositionParams of a population (study-file style: species 1's material as the fields)."""
    v = population.mixture_vars(species)
    for k in ("q_sigma", "q_sigma_2", "q_sigma_3"):
        if k in v:
            v[k] = f"{float(v[k]) * sigma_scale:.6g}"
    fields = {"rp": float(v.pop("rp")), "U0": U0}
    for k in ("rho", "E", "nu", "gamma", "e", "mu"):
        if k in v:
            fields[k] = float(v.pop(k))
    v.update(extra)
    return DepositionParams(N=N, seed=1, extra=v, **fields)


def cases(scale: float = 1.0) -> dict:
    n = lambda k: max(10, int(round(k * scale)))      # noqa: E731
    return {
        "demo-q0": DepositionParams(q=0.0, N=n(500), seed=1, extra=dict(DEMO)),
        "demo-q260": DepositionParams(q=260.0, N=n(500), seed=1, extra=dict(DEMO)),
        "demo-q400": DepositionParams(q=400.0, N=n(500), seed=1, extra=dict(DEMO)),
        "regolith-s0": population_params(REGOLITH, n(150), 0.5, {"L_rp": "14", "inject": "plane"}, 0.0),
        "regolith-s5e-7": population_params(REGOLITH, n(150), 0.5, {"L_rp": "14", "inject": "plane"}),
        "regolith-s1e-6": population_params(REGOLITH, n(150), 0.5, {"L_rp": "14", "inject": "plane"}, 2.0),
        "toner-s0": population_params(TONER, n(100), 0.5, {"L_rp": "14"}, 0.0),
        "toner-s1e-6": population_params(TONER, n(100), 0.5, {"L_rp": "14"}),
        # the bed's charge turns the particles back (the estimate's barrier: ~10 particles)
        "toner-s4e-6": population_params(TONER, n(100), 0.5, {"L_rp": "14"}, 4.0),
    }


def run_case(lmp: str, p: DepositionParams, work: Path) -> dict:
    """lmp on in.deposition for p in work; CPU seconds of the child and the log's numbers."""
    cmd = [lmp, "-in", str(DECK), "-screen", "none", "-log", str(work / "log.lammps")]
    v = p.deck_vars()
    v.update(out=str(work), computes="1")
    for k, val in v.items():
        cmd += ["-var", k, str(val)]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True)
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
    text = (work / "log.lammps").read_text(errors="replace") if (work / "log.lammps").exists() else ""
    res = logs.parse_result_line(text) or {}
    if r.returncode != 0 or not res:
        raise RuntimeError(f"lmp failed ({r.returncode}):\n{text[-2000:]}\n{r.stderr[-1000:]}")
    # the step of the last injection: the last GC PROGRESS line with k = inserted (the loops),
    # else the rain's interval times the particles
    last = None
    for m in re.finditer(r"^GC PROGRESS (\d+) / (\d+) particles, step (\d+)", text, re.M):
        if int(m.group(1)) >= res.get("inserted", 0):
            last = int(m.group(3))
            break
    return {"cpu_s": cpu, "result": res, "last_injection_step": last}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lmp", default=shutil.which("lmp") or str(SRC / "build" / "lmp"))
    ap.add_argument("--only", default="", help="comma-separated case names")
    ap.add_argument("--scale", type=float, default=1.0, help="N of every case times this")
    ap.add_argument("--json", default="", help="write the measurements here")
    ap.add_argument("--fit", action="store_true", help="print the constants the runs give")
    ap.add_argument("--keep", default="", help="keep the run folders under this folder")
    ap.add_argument("--measured", default="", help="no runs: the measurements of an earlier --json")
    a = ap.parse_args()
    todo = cases(a.scale)
    if a.only:
        todo = {k: v for k, v in todo.items() if k in a.only.split(",")}
    rows = []
    before = {r["case"]: r for r in json.loads(Path(a.measured).read_text())} if a.measured else {}
    head = (f"{'case':16s} {'N':>4s} {'made':>4s} {'settled':>7s} {'steps est':>9s} "
            f"{'steps':>9s} {'post est':>8s} {'post':>8s} {'CPU est':>8s} {'CPU':>8s} {'ratio':>6s}  note")
    print(head, flush=True)
    for name, p in todo.items():
        pl = estimate.plan(p)
        est = estimate.estimate([p])
        if a.measured:
            if name not in before:
                continue
            b = before[name]
            m = {"cpu_s": b["cpu"], "result": {"inserted": b["made"], "steps": b["steps"],
                                               "settled": b["settled"]},
                 "last_injection_step": b.get("last_injection_step")}
            work = None
        else:
            work = Path(tempfile.mkdtemp(prefix=f"gc-est-{name}-", dir=a.keep or None))
            m = run_case(a.lmp, p, work)
        res = m["result"]
        made = int(res.get("inserted", 0))
        steps = float(res.get("steps", 0))
        inj = m["last_injection_step"] if m["last_injection_step"] is not None else made * pl["n_i"]
        post_rp = (steps - inj) / pl["unit"]
        pred_post_rp = (pl["fall_steps"] + pl["settle_steps"]) / pl["unit"]
        w = estimate.actual_work(p, {"lammps": {"steps": steps, "dt": pl["dt"]}, "inserted": made})
        row = {"case": name, "N": p.N, "made": made, "settled": res.get("settled"),
               "charged": pl["charged"], "protocol": pl["protocol"],
               "steps_est": pl["steps"], "steps": steps, "post_rp_est": pred_post_rp,
               "post_rp": post_rp, "fall_rp": pl["fall_steps"] / pl["unit"],
               "cpu_est": est["cpu_s"], "cpu": m["cpu_s"], "work": w,
               "N_dep_est": pl["N_dep"], "last_injection_step": inj}
        row["ratio"] = row["cpu"] / row["cpu_est"] if row["cpu_est"] else float("nan")
        rows.append(row)
        note = f"est. stops at {pl['N_dep']}" if pl["barrier"] else ""
        st = "-" if row["settled"] is None else str(row["settled"])
        print(f"{name:16s} {p.N:4d} {made:4d} {st:>7s} {row['steps_est']:9.3g} {steps:9.3g} "
              f"{pred_post_rp:8.0f} {post_rp:8.0f} {row['cpu_est']:8.1f} {row['cpu']:8.1f} "
              f"{row['ratio']:6.2f}  {note}", flush=True)
        if work is not None and not a.keep:
            shutil.rmtree(work, ignore_errors=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    if a.fit:
        for kind in (False, True):
            sel = [r for r in rows if r["charged"] == kind and r["work"]]
            if not sel:
                continue
            gm = lambda xs: math.exp(sum(math.log(x) for x in xs) / len(xs))   # noqa: E731
            c = gm([r["cpu"] / r["work"] for r in sel])
            settle = gm([max(r["post_rp"] - r["fall_rp"], 1.0) for r in sel])
            print(f"fit {'charged' if kind else 'neutral'}: c = {c:.3g} s per particle-step, "
                  f"settling {settle:.0f} r_p / U_0 ({len(sel)} runs)")
    bad = [r for r in rows if not (0.5 <= r["ratio"] <= 2.0)]
    print(f"total CPU {sum(r['cpu'] for r in rows) / 60:.1f} min; "
          f"{len(rows) - len(bad)} of {len(rows)} within a factor 2")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
