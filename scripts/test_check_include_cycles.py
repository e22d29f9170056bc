"""pytest for scripts/check_include_cycles.py: it names a circle through headers and through a
source, passes a tree whose layers point down and a unit with a private X_impl header.

Run: /usr/bin/python3 -m pytest scripts/test_check_include_cycles.py
The check of the repository itself is scripts/check_include_cycles.py (exit status 1 on a circle).
"""
import importlib.util
import os

_spec = importlib.util.spec_from_file_location(
    "check_include_cycles",
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_include_cycles.py"))
cic = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cic)


def tree(tmp_path, files):
    """A repository of the given files ({path under src/: text}); returns its path."""
    for name, text in files.items():
        f = tmp_path / "src" / name
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text)
    return str(tmp_path)


def check(repo, capsys):
    status = cic.main(["check_include_cycles.py", repo])
    return status, capsys.readouterr().out


# three units of the package over the two libraries, every include pointing down
LAYERED = {
    "GRANULAR-CHARGED/evaluator.h": '#include "backend.h"\n#include "error.h"\n',
    "GRANULAR-CHARGED/evaluator.cpp": '#include "evaluator.h"\n#include "sleepers.h"\n',
    "GRANULAR-CHARGED/sleepers.h": '#include "gcfmm/solver.hpp"\n',
    "GRANULAR-CHARGED/sleepers.cpp": '#include "sleepers.h"\n#include "backend.h"\n',
    "GRANULAR-CHARGED/backend.h": '#include "gcfmm/solver.hpp"\n#include <vector>\n',
    "GRANULAR-CHARGED/backend.cpp": '#include "backend.h"\n',
    "fmm/include/gcfmm/solver.hpp": '#include "gcsimd/simd.hpp"\n',
    "fmm/src/solver.cpp": '#include "solver_impl.hpp"\n',
    # the pimpl pattern: the private Impl header includes its class's header
    "fmm/src/solver_impl.hpp": '#include "gcfmm/solver.hpp"\n',
    "simd/include/gcsimd/simd.hpp": "",
    "simd/src/simd.cpp": '#include "gcsimd/simd.hpp"\n',
}


def test_layers_that_point_down_pass(tmp_path, capsys):
    status, out = check(tree(tmp_path, LAYERED), capsys)
    assert status == 0, out
    # evaluator, sleepers, backend, solver (with its Impl header), simd
    assert "no include circle among 5 units" in out


def test_a_source_that_closes_a_circle_is_named(tmp_path, capsys):
    # the backend's source includes the evaluator, whose header includes the backend's
    files = dict(LAYERED)
    files["GRANULAR-CHARGED/backend.cpp"] += '#include "evaluator.h"\n'
    status, out = check(tree(tmp_path, files), capsys)
    assert status == 1
    assert ("include circle: GRANULAR-CHARGED/backend -> GRANULAR-CHARGED/evaluator -> "
            "GRANULAR-CHARGED/backend") in out
    assert "src/GRANULAR-CHARGED/backend.cpp:2" in out and "src/GRANULAR-CHARGED/evaluator.h:1" in out


def test_a_circle_across_libraries_through_headers_is_named(tmp_path, capsys):
    # the SIMD layer reaching up into the FMM library: simd -> solver -> simd
    files = dict(LAYERED)
    files["simd/include/gcsimd/simd.hpp"] = '#include "gcfmm/solver.hpp"\n'
    status, out = check(tree(tmp_path, files), capsys)
    assert status == 1
    assert "include circle: fmm/solver -> simd/simd -> fmm/solver" in out
    assert "1 include circle among" in out
