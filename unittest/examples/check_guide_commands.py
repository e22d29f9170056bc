#!/usr/bin/env python3
"""Run every shell command that README.md and the user's guide (doc/guide/*.md) show, reduced.

Usage:
  check_guide_commands.py --build BUILD [--source SRC] [--workdir DIR] [--list] [--page FILE ...]

Every ```sh block of README.md and of doc/guide/*.md is extracted (lines joined at a trailing
backslash; blank lines and comment lines dropped) and run as the user would run it, one bash
shell per block with `set -e -o pipefail`, so that a command that stops working (a removed
option, a renamed file, a deck variable that is gone, a folder that is not there) fails the
test.  Each command is either run, after the reductions below, or skipped for the reason given
in SKIPS; the table of what ran and what was skipped is printed.  Exit status 0 when every
block exits 0 and nothing was written into the source tree, 1 otherwise.

Where a block runs:
  - HOME is a fresh folder per block, so `~/gc-first` and the like are the test's own;
  - a block that names files of the source tree (`examples/...`, `./python`) starts in the
    source tree's root, where the pages source `. build/env.sh`;
  - every other block continues where "First use" leaves the user: in ~/gc-first, holding a
    copy of examples/deposition/in.deposition, with the build's env.sh sourced.
  The commands must write nothing into the source tree (an installed tree is read-only): the
  file names under examples/ and doc/ and the entries of the source root are compared before
  and after (Python's __pycache__ folders apart); what appeared under examples/ and doc/ is
  reported and removed again.

Reductions (REDUCTIONS below: the command keeps its options; only sizes shrink, so every option
and file the page names is still exercised):
  - `. build/env.sh` is the env.sh of the build under test (--build);
  - depositions: N = 30 particles (`-var N`, `--N`; added where the command relies on the
    default of 2000) in a box of 10 r_p where the command takes the default 28 r_p, restart points every 10 particles instead of 50; the charge-after-formation
    relaxation 10 r_p/U_0 instead of 100;
  - a sweep: its first and last charge and one seed, one run at a time (`--jobs 1`).
  With these sizes the whole test took 99 s on a 2-core machine running two other jobs
  (load 4; the slowest blocks: mpi.md 41 s, many-runs.md 19 s, README 10 s).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# (pattern, replacement, why) applied in this order to every command that runs
REDUCTIONS = [
    (r"^\. build/env\.sh\b", '. "$GC_GUIDE_BUILD/env.sh"',
     "the pages' build/env.sh is the env.sh of the build under test"),
    (r"(-var N )\d+", r"\g<1>30", "N = 30 particles"),
    (r"(--N )\d+", r"\g<1>30", "N = 30 particles"),
    (r"(\blmp -in \S*in\.deposition)(?!.*-var N )(.*)$", r"\1\2 -var N 30",
     "N = 30 where the command takes the deck's default of 2000"),
    (r"(granular_charged (run|sweep)\b)(?!.*--N )(.*)$", r"\1\3 --N 30",
     "N = 30 where the command takes the default of 2000"),
    (r"(\blmp -in \S*in\.deposition)(?!.*-var L_rp )(.*)$", r"\1\2 -var L_rp 10",
     "a box of 10 r_p where the command takes the deck's 28 r_p"),
    (r"(granular_charged (run|sweep)\b)(?!.*--var L_rp )(.*)$", r"\1\3 --var L_rp 10",
     "a box of 10 r_p where the command takes the default of 28 r_p"),
    (r"(-var checkpoint )50\b", r"\g<1>10", "a restart point every 10 of the 30 particles"),
    (r"(\blmp -in \S*in\.charged-after-formation)(?!.*-var relax_rp )(.*)$",
     r"\1\2 -var relax_rp 10", "relaxation of 10 r_p/U_0 instead of 100"),
    (r"(--q) 0 200 400\b", r"\1 0 400", "the sweep's first and last charge"),
    (r"(--seeds) 1 2 3\b", r"\1 1", "one seed"),
    (r"(--jobs) \d+", r"\1 1", "one run at a time (a shared machine)"),
]

# (pattern, why it is not run): searched in the command
SKIPS = [
    (r"^make (demo|test)\b", "builds the tree and runs the demo or the whole test suite (tens of "
                             "minutes); this test is one of the suite's"),
    (r"-m venv\b|gc-venv/", "a virtual environment filled by pip: pip fetches the build backend "
                            "and the dependencies from the package index (network), and "
                            "`python3` is whichever interpreter the machine puts first"),
]


def strip_comment(line):
    """The line without a trailing shell comment (a # outside quotes, at a word's start)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].strip()
    return line.strip()


def blocks_of(page):
    """List of (first line number, [commands]) of the ```sh blocks of a Markdown page."""
    out, cur, start, pending = [], None, 0, ""
    with open(page, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            s = line.strip()
            if cur is None:
                if s == "```sh":
                    cur, start, pending = [], n, ""
                continue
            if s.startswith("```"):
                out.append((start, cur))
                cur = None
                continue
            if s.endswith("\\"):
                pending += s[:-1] + " "
                continue
            s = strip_comment(pending + s)
            pending = ""
            if s and not s.startswith("#"):
                cur.append(s)
    return out


def reduce(cmd):
    """The command as run (or None) and what was done to it."""
    for pat, why in SKIPS:
        if re.search(pat, cmd):
            return None, [why]
    done = []
    for pat, rep, why in REDUCTIONS:
        new = re.sub(pat, rep, cmd)
        if new != cmd:
            cmd = new
            if why not in done:
                done.append(why)
    return cmd, done


def in_source_tree(commands):
    """Whether a block names files of the source tree by relative paths (examples/..., ./python)."""
    return any(re.search(r"(^|[\s=/])(\./)?examples(/|\s|$)|(^|\s)\./python\b", c) for c in commands)


def snapshot(src):
    names = set(os.listdir(src))
    for top in ("examples", "doc"):
        for d, dirs, files in os.walk(os.path.join(src, top)):
            dirs[:] = [x for x in dirs if x != "__pycache__"]
            names.update(os.path.relpath(os.path.join(d, x), src) for x in dirs + files)
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True, help="the build folder (its env.sh)")
    ap.add_argument("--source", default=SOURCE)
    ap.add_argument("--workdir", default="guide-commands")
    ap.add_argument("--list", action="store_true", help="print the commands as run; run nothing")
    ap.add_argument("--page", action="append", default=None,
                    help="check these pages instead of README.md and doc/guide/*.md")
    a = ap.parse_args()
    src, build = os.path.abspath(a.source), os.path.abspath(a.build)
    pages = a.page or ([os.path.join(src, "README.md")] + sorted(
        os.path.join(src, "doc", "guide", p) for p in os.listdir(os.path.join(src, "doc", "guide"))
        if p.endswith(".md")))
    if not os.path.isfile(os.path.join(build, "env.sh")):
        print(f"no {build}/env.sh: --build is the build folder")
        return 1
    work = os.path.abspath(a.workdir)
    if not a.list:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
    before = snapshot(src)
    failed, ran, skipped, k = [], 0, 0, 0
    t_all = time.time()
    for page in pages:
        rel = os.path.relpath(page, src)
        for line, commands in blocks_of(page):
            k += 1
            where = "source tree" if in_source_tree(commands) else "~/gc-first"
            print(f"== {rel}, block at line {line} (starts in the {where})", flush=True)
            script = ["set -e -o pipefail"]
            home = os.path.join(work, f"block{k}", "home")
            if where == "source tree":
                script.append(f'cd "{src}"')
            else:
                script += ['. "$GC_GUIDE_BUILD/env.sh"', "mkdir -p ~/gc-first",
                           f'cp "{src}/examples/deposition/in.deposition" ~/gc-first/',
                           "cd ~/gc-first"]
            for i, cmd in enumerate(commands):
                run, notes = reduce(cmd)
                if run is None:
                    skipped += 1
                    print(f"   skipped: {cmd}\n            ({notes[0]})")
                    continue
                ran += 1
                print(f"   run:     {cmd}" + (f"\n       as:  {run}" if run != cmd else ""))
                script.append(f"echo '@@ command {i + 1}: {cmd.replace(chr(39), '')}'")
                script.append(run)
            if a.list or not any(reduce(c)[0] for c in commands):
                continue
            os.makedirs(home, exist_ok=True)
            env = dict(os.environ, HOME=home, GC_GUIDE_BUILD=build,
                       OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
            log = os.path.join(work, f"block{k}", "output.txt")
            t0 = time.time()
            with open(log, "w") as out:
                try:
                    r = subprocess.run(["bash", "-c", "\n".join(script)], cwd=home, env=env,
                                       stdout=out, stderr=subprocess.STDOUT, timeout=300)
                    status = r.returncode
                except subprocess.TimeoutExpired:
                    status = "timeout (300 s)"
            print(f"   exit status {status} ({time.time() - t0:.1f} s; output: {log})", flush=True)
            if status != 0:
                with open(log, encoding="utf-8", errors="replace") as f:
                    text = f.read().splitlines()
                last = [ln for ln in text if ln.startswith("@@ command")]
                failed.append(f"{rel}:{line}: {last[-1][3:] if last else 'the set-up'} "
                              f"-> exit status {status}")
                print("   " + "\n   ".join(text[-15:]))
    after = snapshot(src)
    written = sorted(after - before)
    if written and not a.list:
        failed.append("written into the source tree: " + ", ".join(written[:10]))
        # removed again under examples/ and doc/ (so that the next run sees them again); a new
        # entry of the source root is only reported (another test may be writing there)
        for rel in sorted(written, key=len):
            path = os.path.join(src, rel)
            if rel.split(os.sep)[0] in ("examples", "doc") and os.path.lexists(path):
                shutil.rmtree(path) if os.path.isdir(path) and not os.path.islink(path) \
                    else os.remove(path)
    for f in failed:
        print("FAILED:", f)
    print(f"{k} blocks, {ran} commands run, {skipped} skipped, {len(failed)} failure(s) "
          f"({time.time() - t_all:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
