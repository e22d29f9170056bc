#!/usr/bin/env python3
"""Run the short version of an example deck and compare its thermo output with the reference log.

Usage:
  run_example.py --lmp LMP --example NAME [--np K] [--workdir DIR] [--write-reference]

NAME is a folder of examples/ (deposition, charged-after-formation, powder).  The short command
of each example is defined once, in EXAMPLES below; the reference log examples/NAME/
log.<date>.NAME.g++.<K> holds the thermo output of the same command (--write-reference writes
it), except for the powder, whose log is of the full deck and is compared at the steps both
print (see EXAMPLES).

Compared: every thermo block (the rows between a "Step ..." header and "Loop time"), at every
step that both logs print, every column except the timings (CPU, TotWall, CPULeft); and the
numbers of the deck's last result line (GC RESULT, GC AFTER, POWDER).  Exit status 0 when all
agree within the tolerance, 1 otherwise (each difference printed), 2 when a run fails.

Tolerance (RTOL below), argued from what was measured:
  - The same build, the same seed and the same number of ranks repeat the run bit for bit
    (the decks draw every random number from their seed; the reductions of LAMMPS and of
    fix coul/fmm are in a fixed order), so the printed digits are identical: LAMMPS prints
    8 significant digits, and RTOL = 1e-7 lets only the last printed digit's rounding differ.
  - Against the other supported release (4Feb2025 against 4Jul2026) the same short commands
    also print identical thermo rows (measured with tolerance 0: every column of every row of
    the three examples, and of the deposition on 2 ranks), so one tolerance serves both
    releases.  1 and 2 ranks do not agree (13 of the deposition's 17 rows differ, from the
    5th digit on), hence one reference log per rank count.  A granular deposition is
    chaotic: a difference at round-off level (another compiler, other flags, another order of
    a sum) grows with every collision until the rows part in their first digits; such a change
    is what this test is there to show, so the tolerance is not widened to hide it.
  - Columns that are exact integers (Step, atoms, counts) must be equal.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLES_DIR = os.path.join(REPO, "examples")
LOG_DATE = "4Dec26"
RTOL = 1e-7
TIMING_COLUMNS = {"cpu", "totwall", "cpuleft", "s/cpu"}
RESULT_LINE = re.compile(r"^(GC RESULT|GC AFTER|POWDER) ")

# name -> list of (deck, arguments) run in one folder in this order; the log of the last one is
# compared.  "compare" is "all" (the reference is of this command: every row) or "common" (the
# reference is of a longer run of the same system: the rows at the steps both print).
EXAMPLES = {
    # a neutral bed of 250 particles in a 10 r_p box, one particle per r_p of fall: ~5 s
    "deposition": {
        "runs": [("deposition/in.deposition", ["-var", "N", "250", "-var", "L_rp", "10",
                                                "-var", "gap_rp", "1"])],
        "compare": "all"},
    # the same bed, charged to 400 e_0 after its formation and relaxed for 10 r_p/U_0: ~10 s
    "charged-after-formation": {
        "runs": [("deposition/in.deposition", ["-var", "N", "250", "-var", "L_rp", "10",
                                                "-var", "gap_rp", "1"]),
                 ("charged-after-formation/in.charged-after-formation",
                  ["-var", "restart", "final.restart", "-var", "q_after", "400",
                   "-var", "relax_rp", "10"])],
        "compare": "all"},
    # the shipped deck (200 particles, 60000 steps, thermo every 6000) run for its first 6000
    # steps (thermo every 600): rows at steps 0 and 6000 are compared with the full log's
    "powder": {
        "runs": [("powder/in.powder", ["-var", "steps", "6000"])],
        "compare": "common"},
}


def thermo_blocks(path):
    """List of (header, rows) of a LAMMPS log; rows are lists of strings."""
    blocks, header, rows = [], None, []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            words = line.split()
            if words and words[0] == "Step":
                header, rows = words, []
                continue
            if header is not None:
                if line.startswith("Loop time"):
                    blocks.append((header, rows))
                    header = None
                elif len(words) == len(header) and re.match(r"^-?\d+$", words[0]):
                    rows.append(words)
    return blocks


def result_line(path):
    found = None
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if RESULT_LINE.match(line):
                found = line.split()
    return found


def agree(a, b):
    try:
        x, y = float(a), float(b)
    except ValueError:
        return a == b
    if re.match(r"^-?\d+$", a) and re.match(r"^-?\d+$", b):
        return int(a) == int(b)
    return abs(x - y) <= RTOL * max(abs(x), abs(y)) or x == y


def compare(test_log, ref_log, mode):
    problems, compared = [], 0
    test, ref = thermo_blocks(test_log), thermo_blocks(ref_log)
    if mode == "all" and len(test) != len(ref):
        problems.append(f"{len(test)} thermo blocks, the reference has {len(ref)}")
    for k, ((th, trows), (rh, rrows)) in enumerate(zip(test, ref)):
        if th != rh:
            problems.append(f"block {k + 1}: columns {th}, reference {rh}")
            continue
        ref_by_step = {r[0]: r for r in rrows}
        if mode == "all" and [r[0] for r in trows] != [r[0] for r in rrows]:
            problems.append(f"block {k + 1}: steps {[r[0] for r in trows]}, reference "
                            f"{[r[0] for r in rrows]}")
        for row in trows:
            ref_row = ref_by_step.get(row[0])
            if ref_row is None:
                continue
            compared += 1
            for col, a, b in zip(th, row, ref_row):
                if col.lower() not in TIMING_COLUMNS and not agree(a, b):
                    problems.append(f"block {k + 1}, step {row[0]}, {col}: {a}, reference {b}")
    if mode == "all":
        tres, rres = result_line(test_log), result_line(ref_log)
        if (tres is None) != (rres is None) or (tres and (len(tres) != len(rres) or not all(
                agree(a, b) for a, b in zip(tres, rres)))):
            problems.append(f"result line: {' '.join(tres or [])}\n   reference: "
                            f"{' '.join(rres or [])}")
    if compared == 0:
        problems.append("no thermo row at a step the reference prints")
    return problems, compared


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lmp", required=True)
    ap.add_argument("--example", required=True, choices=sorted(EXAMPLES))
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--write-reference", action="store_true")
    a = ap.parse_args()

    spec = EXAMPLES[a.example]
    ref = os.path.join(EXAMPLES_DIR, a.example, f"log.{LOG_DATE}.{a.example}.g++.{a.np}")
    work = os.path.abspath(a.workdir or f"example-{a.example}-{a.np}")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    log = None
    for i, (deck, args) in enumerate(spec["runs"]):
        log = os.path.join(work, f"log.{i}")
        cmd = [a.lmp, "-in", os.path.join(EXAMPLES_DIR, deck), "-log", log, "-screen", "none"]
        if a.np > 1:
            cmd = [a.mpiexec, "-np", str(a.np), "--oversubscribe"] + cmd
        cmd += args
        print("running:", " ".join(cmd), flush=True)
        r = subprocess.run(cmd, cwd=work, env=env)
        if r.returncode != 0:
            print(f"run failed with status {r.returncode}; see {log}")
            return 2
    if a.write_reference:
        shutil.copyfile(log, ref)
        print(f"wrote {ref}")
        return 0
    if not os.path.isfile(ref):
        print(f"no reference log {ref}")
        return 1
    problems, compared = compare(log, ref, spec["compare"])
    for p in problems:
        print("DIFFERS:", p)
    print(f"{a.example}, {a.np} rank(s): {compared} thermo rows compared with "
          f"{os.path.relpath(ref, REPO)}, {len(problems)} difference(s) (rtol {RTOL:g})")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
