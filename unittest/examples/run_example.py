#!/usr/bin/env python3
"""Run the short version of an example deck and compare its thermo output with the reference log.

Usage:
  run_example.py --lmp LMP --example NAME [--np K] [--simd PATH] [--workdir DIR] [--write-reference]

NAME is a folder of examples/ (deposition, charged-after-formation, powder), or powder-full (the
powder deck as shipped).  The short command
of each example is defined once, in EXAMPLES below; the reference log examples/NAME/
log.<date>.NAME.g++.<K> holds the thermo output of the same command (--write-reference writes
it), except for the powder, whose log is of the full deck and is compared at the steps both
print (see EXAMPLES).  --simd PATH runs with GCSIMD_MAX_PATH=PATH (exit status 77 when the CPU has
no such path).

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
  - The short deposition and charged-after-formation runs print the same digits on the three
    SIMD paths of the package (--simd generic|avx2|avx512, measured: 0 differences at RTOL), so
    they keep RTOL on every path; ctest runs them on each path the CPU has.

The powder across machines (powder, powder-full; --simd PATH runs on one SIMD path):
  fix coul/fmm's kernels differ between the package's SIMD paths (the P2P kernels take 1/sqrt
  from a hardware estimate refined by Newton steps on AVX2 and AVX-512, exactly on the generic
  path, and sum in another order), so a machine without AVX-512 does not repeat the reference
  log, which is of the AVX-512 path, bit for bit.  Measured on one machine, the full deck on
  each path (GCSIMD_MAX_PATH=avx512|avx2|generic, thermo every 600 steps at 17 digits, positions
  dumped every 600 steps; relative differences to the AVX-512 run):
    - without fix coul/fmm the three paths give identical positions and velocities at every
      dump of the 60000 steps: pair_style granular with the package's sub-models and the wall
      are the same on every path; the Coulomb solver is the only source of difference;
    - with it, every printed digit agrees up to step ~2400; the first difference is one ulp of
      the Coulomb energy (step 3000, 1e-16), and it grows with the collisions, with jumps when
      contacts form or break (steps 22200, 45000, 54600):
        step        6000     12000    18000    24000    30000    36000    42000    48000    54000    60000
        c_ke  avx2  0        3.0e-15  2.3e-14  2.5e-10  1.1e-10  3.3e-09  1.0e-08  4.2e-07  4.8e-05  5.4e-05
        c_ke  gen.  0        3.6e-15  1.4e-11  3.6e-10  4.6e-10  4.7e-09  1.4e-08  6.3e-08  1.9e-05  6.5e-05
        rms |dx| / mean diameter, avx2 and generic: 3e-16 (6000), 1e-13 (12000), 2e-9 (24000),
        2e-8 (30000), 2e-7 (42000), 6e-7 (48000), 2e-6 (54000), 4e-6 (60000);
      the largest c_ke difference in any 600-step row up to 60000 is 4.6e-4 (step 58200), and
      the AVX2 path's c_ke at step 54000 (7.9022942e-15) is that of a machine without AVX-512
      (7.9026737e-15 in the reference).  The bed at the end agrees much better than its residual
      kinetic energy: c_phi 0.39317305 against 0.39317306 (2.5e-8), c_Z equal, zhi of the
      POWDER line 2.5e-8.
  Tolerances (powder_rtol): another compiler or CPU perturbs the run at round-off level as the
  paths do, but possibly from the first step instead of step ~3000; at the growth measured in
  the fall (x ~3 per 1000 steps) that makes its differences up to ~20x larger, so each row's
  tolerance is 100x the largest difference measured between the paths up to its step, rounded
  up, and never below RTOL (POWDER_KE_RTOL: up to step 30000 the printed digits must agree).
  phi and zhi: 1e-5 (400x the measured 2.5e-8).  <Z>: 4e-3, one contact more or less among the
  ~170 particles of the analysis slab (2/170 of 3.44), since a contact at the margin may flip
  on another machine (none did between the paths).  Every other column (Step, Time, Atoms,
  c_qtot: the charge sum's order follows LAMMPS's atom sorting, 6e-16 apart) keeps RTOL.
  ctest runs the deck's first 6000 steps on every path the CPU has (examples.powder.<path>:
  rows 0 and 6000 of the reference, where all paths agree to 3.5e-16, so RTOL) and the whole
  deck on the CPU's default path (examples.powder.full: every row and the POWDER line, 64 s).
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
# the powder (see the docstring): c_ke's tolerance up to each step; phi, zhi; <Z>
POWDER_KE_RTOL = [(30000, RTOL), (42000, 3e-6), (48000, 8e-4), (54000, 6e-3),
                  (float("inf"), 5e-2)]
POWDER_PHI_RTOL = 1e-5
POWDER_Z_RTOL = 4e-3
TIMING_COLUMNS = {"cpu", "totwall", "cpuleft", "s/cpu"}
SIMD_PATHS = ("generic", "avx2", "avx512")
SKIPPED = 77       # ctest's SKIP_RETURN_CODE
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
        "compare": "common", "rtol": "powder"},
    # the shipped deck as it is (~75 s on one core): every row of the full log and its last line
    "powder-full": {
        "folder": "powder",
        "runs": [("powder/in.powder", [])],
        "compare": "all", "rtol": "powder"},
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


def powder_rtol(column, step):
    """The powder's tolerance of a thermo column at a step, or of a word of its POWDER line
    (step None): see "The powder across machines" above."""
    column = column.lower()
    if column == "c_ke":
        return max(RTOL, next(r for upto, r in POWDER_KE_RTOL if step <= upto))
    if column in ("c_phi", "phi", "zhi"):
        return POWDER_PHI_RTOL
    if column in ("c_z", "z"):
        return POWDER_Z_RTOL
    return RTOL


RTOLS = {"powder": powder_rtol}


def agree(a, b, rtol=RTOL):
    try:
        x, y = float(a), float(b)
    except ValueError:
        return a == b
    if re.match(r"^-?\d+$", a) and re.match(r"^-?\d+$", b):
        return int(a) == int(b)
    return abs(x - y) <= rtol * max(abs(x), abs(y)) or x == y


def compare(test_log, ref_log, mode, rtol=lambda column, step: RTOL):
    """Differences of a log from its reference beyond rtol(column, step) (step None: the
    words of the result line, column the word before each), and the number of rows compared."""
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
                tol = rtol(col, int(row[0]))
                if col.lower() not in TIMING_COLUMNS and not agree(a, b, tol):
                    problems.append(f"block {k + 1}, step {row[0]}, {col}: {a}, reference {b} "
                                    f"(rtol {tol:g})")
    if mode == "all":
        tres, rres = result_line(test_log), result_line(ref_log)
        if (tres is None) != (rres is None) or (tres and (len(tres) != len(rres) or not all(
                agree(a, b, rtol(label, None))
                for label, a, b in zip([""] + tres[:-1], tres, rres)))):
            problems.append(f"result line: {' '.join(tres or [])}\n   reference: "
                            f"{' '.join(rres or [])}")
    if compared == 0:
        problems.append("no thermo row at a step the reference prints")
    return problems, compared


def cpu_has(path):
    """Whether this CPU runs a SIMD path of the package (the test of src/simd/src/simd.cpp)."""
    if path == "generic":
        return True
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            flags = set(next((ln.split(":", 1)[1].split() for ln in f
                              if ln.startswith("flags")), []))
    except OSError:
        return False
    need = {"avx2": {"avx2", "fma"}, "avx512": {"avx2", "fma", "avx512f", "avx512dq"}}[path]
    return need <= flags


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lmp", required=True)
    ap.add_argument("--example", required=True, choices=sorted(EXAMPLES))
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--simd", choices=SIMD_PATHS, default=None,
                    help="run on this SIMD path of the package (GCSIMD_MAX_PATH); exit status 77 "
                         "(skipped) when the CPU does not have it")
    ap.add_argument("--write-reference", action="store_true")
    a = ap.parse_args()

    spec = EXAMPLES[a.example]
    folder = spec.get("folder", a.example)
    rtol = RTOLS.get(spec.get("rtol"), lambda column, step: RTOL)
    ref = os.path.join(EXAMPLES_DIR, folder, f"log.{LOG_DATE}.{folder}.g++.{a.np}")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if a.simd:
        if not cpu_has(a.simd):
            print(f"skipped: this CPU has no {a.simd} path")
            return SKIPPED
        env["GCSIMD_MAX_PATH"] = a.simd
    work = os.path.abspath(a.workdir or f"example-{a.example}-{a.np}" +
                           (f"-{a.simd}" if a.simd else ""))
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    log = None
    for i, (deck, args) in enumerate(spec["runs"]):
        log = os.path.join(work, f"log.{i}")
        cmd = [a.lmp, "-in", os.path.join(EXAMPLES_DIR, deck), "-log", log, "-screen", "none"]
        if a.np > 1:
            cmd = [a.mpiexec, "-np", str(a.np), "--oversubscribe"] + cmd
        cmd += args
        print("running:", (f"GCSIMD_MAX_PATH={a.simd} " if a.simd else "") + " ".join(cmd), flush=True)
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
    problems, compared = compare(log, ref, spec["compare"], rtol)
    for p in problems:
        print("DIFFERS:", p)
    print(f"{a.example}, {a.np} rank(s){', ' + a.simd if a.simd else ''}: {compared} thermo rows "
          f"compared with {os.path.relpath(ref, REPO)}, {len(problems)} difference(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
