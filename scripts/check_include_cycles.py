#!/usr/bin/env python3
"""No include circle among the package's C++ files: layers that point down.

Reads the #include "..." lines of src/GRANULAR-CHARGED, src/fmm and src/simd and builds the
graph of their units: X.h (or X.hpp) and X.cpp of one library are one unit, as a reader takes
them (the header says what the unit offers, the source how), so a unit depends on another when
either of its files includes a file of the other. An include that names no file of these
libraries (LAMMPS, Eigen, the standard library) is not an edge. A quoted name is looked up as
the compiler does: beside the including file, then in the libraries' include/ folders. A
private X_impl header (pimpl) is part of the unit whose header it includes first.

Prints each circle as the chain of units with the include that makes each step
(file:line) and exits with status 1; prints "no include circle among N units" and exits with
0 otherwise.

Usage: check_include_cycles.py [REPO]   (default: the repository this script is in)
"""
import os
import re
import sys

LIBRARIES = ("GRANULAR-CHARGED", "fmm", "simd")    # under REPO/src
SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".c")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def source_files(repo):
    """Every C and C++ file of the libraries, as (library, path)."""
    for lib in LIBRARIES:
        top = os.path.join(repo, "src", lib)
        for folder, dirs, files in os.walk(top):
            dirs.sort()
            for name in sorted(files):
                if name.endswith(SUFFIXES):
                    yield lib, os.path.join(folder, name)


def unit_of(lib, path):
    """A file's unit: its library and its name without the suffix (X.h and X.cpp are one)."""
    return f"{lib}/{os.path.splitext(os.path.basename(path))[0]}"


def resolved_includes(repo, files):
    """{file: [(included file of the libraries, line)]}, a quoted name looked up beside the
    including file, then in the libraries' include/ folders (as the compiler does)."""
    include_dirs = sorted({os.path.join(repo, "src", lib, "include") for lib in LIBRARIES
                           if os.path.isdir(os.path.join(repo, "src", lib, "include"))})
    known = {os.path.realpath(p) for _, p in files}
    out = {}
    for _, path in files:
        found = out.setdefault(os.path.realpath(path), [])
        with open(path, encoding="utf-8", errors="replace") as fh:
            for number, text in enumerate(fh, 1):
                m = INCLUDE.match(text)
                if not m:
                    continue
                for folder in [os.path.dirname(path)] + include_dirs:
                    target = os.path.realpath(os.path.join(folder, m.group(1)))
                    if os.path.isfile(target):
                        if target in known:
                            found.append((target, number))
                        break
    return out


def include_graph(repo):
    """{unit: {included unit: (file, line) of the first include that makes the edge}}.

    A private X_impl header (the pimpl pattern: Solver::Impl in src/fmm/src/solver_impl.hpp)
    holds the internals of the class whose header it includes first, and a reader takes it as
    part of that class's unit."""
    files = list(source_files(repo))
    includes = resolved_includes(repo, files)
    unit = {os.path.realpath(p): unit_of(lib, p) for lib, p in files}
    for path in unit:
        stem = os.path.splitext(os.path.basename(path))[0]
        if stem.endswith("_impl") and not path.endswith((".cpp", ".cc", ".c")) and includes[path]:
            unit[path] = unit[includes[path][0][0]]
    graph = {u: {} for u in unit.values()}
    for path, found in includes.items():
        here = unit[path]
        for target, number in found:
            if unit[target] != here:
                graph[here].setdefault(unit[target], (os.path.relpath(path, repo), number))
    return graph


def circles(graph):
    """One circle through each strongly connected group of two or more units (Tarjan's
    algorithm, iterative), each as the list of its units, the first repeated at the end."""
    index, low, on_stack, stack, groups = {}, {}, set(), [], []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.append(member)
                    if member == node:
                        break
                if len(group) > 1:
                    groups.append(sorted(group))
    return [shortest_circle(graph, g) for g in sorted(groups)]


def shortest_circle(graph, group):
    """The shortest circle through the group's first unit, within the group (breadth first)."""
    start, members = group[0], set(group)
    previous = {start: None}
    queue = [start]
    for node in queue:
        for child in sorted(graph[node]):
            if child == start:
                chain = [node]
                while previous[chain[-1]] is not None:
                    chain.append(previous[chain[-1]])
                return chain[::-1] + [start]
            if child in members and child not in previous:
                previous[child] = node
                queue.append(child)
    raise AssertionError(f"no circle in the strongly connected group {group}")


def describe(graph, circle):
    steps = [f"  {a} -> {b}   ({graph[a][b][0]}:{graph[a][b][1]})" for a, b in zip(circle, circle[1:])]
    return "include circle: " + " -> ".join(circle) + "\n" + "\n".join(steps)


def main(argv):
    repo = argv[1] if len(argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    graph = include_graph(repo)
    found = circles(graph)
    for circle in found:
        print(describe(graph, circle))
    if found:
        print(f"{len(found)} include circle{'s' if len(found) > 1 else ''} among {len(graph)} units "
              "of src/" + ", src/".join(LIBRARIES))
        return 1
    print(f"no include circle among {len(graph)} units of src/" + ", src/".join(LIBRARIES))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
