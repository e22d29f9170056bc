#!/usr/bin/env python3
"""No diary where a user reads: dates of work, sessions, internal issue numbers.

Scans README.md, doc/ (but not doc/data/, the kept runs and their records), examples/, src/
and python/ for
  - ISO dates of work (2026-12-03), and month-year dates ("Dec 2026", "3 December 2026");
  - the words session, sitting, yesterday, and internal issue numbers or names ("issue 45",
    "issues 14 and 11", "#45", 'issue "Deposition throughput"');
and prints file:line: text for each hit (--summary: the count per file). Exit status 1 when there is any hit, 0 otherwise.

What is not a hit: LAMMPS's release names (4Jul2026, 4Feb2025, the version 20260704) name
the software, not the day of a piece of work; a paper's year ("Soft Matter 2016") is a
citation. Machine-written output is not scanned: LAMMPS's reference logs (log.*, which carry
LAMMPS's own version banner), data files (csv, json, dumps, images).

Usage: check_no_diary.py [--summary] [PATH ...]   (default: the scope above)
"""
import os
import re
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCOPE = ["README.md", "doc", "examples", "src", "python"]
SKIP_DIRS = {os.path.join("doc", "data"), "__pycache__", ".pytest_cache"}
TEXT_SUFFIXES = (".md", ".rst", ".txt", ".py", ".cpp", ".h", ".hpp", ".c", ".cmake", ".sh",
                 ".toml", ".cfg", ".ini", ".mol", ".in")
MONTHS = ("Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Sept|Oct|Nov|Dec|January|February|March|April|"
          "June|July|August|September|October|November|December")
PATTERNS = [
    ("date", re.compile(r"\b20\d\d-\d\d-\d\d\b")),
    ("date", re.compile(r"\b(?:%s)\.? +(?:\d{1,2}, +)?20\d\d\b" % MONTHS)),
    ("word", re.compile(r"\b(?:sessions?|sittings?|yesterday)\b", re.I)),
    ("issue", re.compile(r"\bissues? +\d+|\bissues? +#\d+|\bissues? +[\"\u201c]|(?<![\w&/])#\d{1,3}\b",
                         re.I)),
]


def is_text(path):
    name = os.path.basename(path)
    if name.startswith("log."):
        return False  # LAMMPS's reference logs: machine output with LAMMPS's version banner
    return (name.endswith(TEXT_SUFFIXES) or name.startswith("in.") or name in
            ("README", "CMakeLists.txt", "Makefile"))


def files(paths):
    for top in paths:
        full = os.path.join(REPO, top)
        if os.path.isfile(full):
            yield top
            continue
        for root, dirs, names in os.walk(full):
            rel = os.path.relpath(root, REPO)
            dirs[:] = sorted(d for d in dirs if os.path.join(rel, d) not in SKIP_DIRS and d not in SKIP_DIRS)
            for n in sorted(names):
                p = os.path.join(rel, n)
                if is_text(p):
                    yield p


def scan(path):
    hits = []
    with open(os.path.join(REPO, path), encoding="utf-8", errors="replace") as f:
        for i, line in enumerate(f, 1):
            for kind, rx in PATTERNS:
                m = rx.search(line)
                if m:
                    hits.append((i, kind, m.group(0), line.strip()))
                    break
    return hits


def main(argv):
    summary = "--summary" in argv
    paths = [a for a in argv if a != "--summary"] or SCOPE
    total, per_file = 0, {}
    for p in files(paths):
        hits = scan(p)
        if hits:
            per_file[p] = len(hits)
            total += len(hits)
            if not summary:
                for i, kind, what, line in hits:
                    print(f"{p}:{i}: [{kind} {what!r}] {line[:160]}")
    if summary:
        for p, n in sorted(per_file.items()):
            print(f"{n:5d}  {p}")
    print(f"check_no_diary: {total} hit(s) in {len(per_file)} file(s)")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
