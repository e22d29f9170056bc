"""What the command line refuses before it starts LAMMPS, the result
files it will not use, the summary's run count, the folder lock, and the package's import graph.

None of these needs a LAMMPS build: the command line runs with GC_BUILD_DIR naming a folder
that does not exist, so a check that came after looking for the build would fail with "no
LAMMPS build" instead of its own message (and the tests assert it does not)."""
import ast
import json
import logging
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import SRC
from granular_charged.run import deckfile, runner
from granular_charged import params
from granular_charged.studies import sweep
from granular_charged.analysis import tables
from granular_charged.params import DepositionParams, ParamError


def gc(args, cwd):
    env = dict(os.environ, PYTHONPATH=str(SRC / "python"), GC_BUILD_DIR=str(Path(cwd) / "no-build"))
    return subprocess.run([sys.executable, "-m", "granular_charged", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=60)


def refused(r, *words):
    """Exit status 2, a one-line reason with the given words, no traceback, no build looked
    for (the check came first)."""
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr, r.stderr
    assert "no LAMMPS build" not in r.stderr, r.stderr
    for w in words:
        assert w in r.stderr, (w, r.stderr)


# ---- item 3: --var ----------------------------------------------------------------------------
@pytest.mark.parametrize("cmd", ["run", "sweep"])
@pytest.mark.parametrize("name,option", [("q", "--q"), ("N", "--N"), ("rp", "--rp"),
                                         ("U0", "--U0"), ("gamma", "--gamma")])
def test_var_refuses_names_with_their_own_option(tmp_path, cmd, name, option):
    # before: --var q 400 ran charged while result.json said params.q = 0.0
    r = gc([cmd, "--out", tmp_path / "runs", "--var", name, "7"], tmp_path)
    refused(r, f"--var {name} 7", f"use {option}")
    assert not (tmp_path / "runs").exists()


def test_var_refuses_what_the_runner_sets(tmp_path):
    refused(gc(["run", "--var", "out", "x"], tmp_path), "the run's folder")
    refused(gc(["run", "--var", "tracer", "3"], tmp_path), "--tracer")
    refused(gc(["run", "--var", "seed", "3"], tmp_path), "use --seed")
    refused(gc(["sweep", "--out", "r", "--var", "seed", "3"], tmp_path), "use --seeds")
    refused(gc(["reproduce", "--var", "U0", "2"], tmp_path), "reproduce sets it per case")
    refused(gc(["demo", "--var", "q", "2"], tmp_path), "use --q")
    # the conventions study sets the rolling limit per case and runs the paper's size
    refused(gc(["conventions", "--var", "theta_crit", "0.04"], tmp_path),
            "the conventions study sets it per case")
    refused(gc(["conventions", "--var", "L_rp", "14"], tmp_path), "L = 28 r_p")


@pytest.mark.parametrize("value, words", [("-3", "must be >= 0, not -3"),
                                          ("2.5", "not a whole number: '2.5'")])
def test_reproduce_checkpoint_must_be_a_count(tmp_path, value, words):
    refused(gc(["reproduce", "--size", "paper", "--checkpoint", value], tmp_path), words)
    assert not any(tmp_path.iterdir())


def test_reproduce_checkpoint_reaches_the_runner(tmp_path, monkeypatch):
    """--checkpoint K is the runner's restart-point interval (the engine's plan carries it to
    every run); without it, none."""
    from granular_charged.cli import build_parser, options as cli_options
    from granular_charged.run import lammps_build
    monkeypatch.setattr(lammps_build.LammpsBuild, "find", classmethod(lambda cls, d: None))
    for argv, k in ((["reproduce", "--size", "paper", "--checkpoint", "200"], 200),
                    (["reproduce", "--size", "paper"], 0)):
        a = build_parser().parse_args(argv)
        assert cli_options.runner(a).checkpoint == k


@pytest.mark.parametrize("cmd", ["run", "sweep", "demo", "reproduce", "conventions"])
def test_var_unknown_to_the_deck_is_an_error(tmp_path, cmd):
    # before: a misspelled --var L_RP 10 was ignored by the deck but named the folder
    args = [cmd, "--var", "L_RP", "10"] + (["--out", "runs"] if cmd == "sweep" else [])
    r = gc(args, tmp_path)
    refused(r, "in.deposition has no variable 'L_RP'", "did you mean L_rp?")
    assert not any(tmp_path.iterdir())


def test_var_given_twice_and_a_bad_number(tmp_path):
    refused(gc(["run", "--var", "L_rp", "10", "--var", "L_rp", "12"], tmp_path), "given twice")
    refused(gc(["run", "--var", "rho", "heavy"], tmp_path), "--var rho heavy: not a number")


def test_var_material_sets_the_field_and_the_key():
    deck = deckfile.deck_variables("in.deposition")
    f, extra = params.split_deck_vars([("rho", "3000"), ("farfield", "average"),
                                       ("L_rp", "10")], deck, {})
    assert f == {"rho": 3000.0, "farfield": "average"} and extra == {"L_rp": "10"}
    p = DepositionParams(q=400, extra=extra, **f)
    # params (result.json's), the groups (Ad = gamma / (rho U0^2 rp)) and the key see them
    assert p.rho == 3000.0 and p.deck_vars()["rho"] == "3000.0"
    assert p.groups()["Ad"] == pytest.approx(0.010 / (3000 * 1 * 2e-6), rel=1e-12)
    assert p.non_default() == {"L_rp": 10.0, "farfield": "average", "q": 400.0, "rho": 3000.0}
    assert p.key() != DepositionParams(q=400, extra=extra).key() != DepositionParams(q=400).key()


def test_params_refuse_a_field_in_extra():
    # the Python API had the same hole: extra={"q": 400} reached the deck, params.q stayed 0
    with pytest.raises(ParamError, match="q: a parameter of its own"):
        DepositionParams(extra={"q": 400})


def test_deck_variables_come_from_the_deck_file(monkeypatch):
    """The list is the deck's `variable NAME index` lines, read when the command runs: a
    variable added to the deck (e.g. the lead's pair_suffix) is settable with no change here."""
    text = textwrap.dedent("""\
        variable rp         index 2.0e-6     # particle radius
        variable pair_suffix index none      # a new variable
          variable   L_rp index 28
        variable dp    equal 2.0*${rp}
        variable name string abc
        """)
    assert deckfile.parse_index_variables(text) == {"rp": "2.0e-6", "pair_suffix": "none",
                                                   "L_rp": "28"}
    real = deckfile.deck_variables("in.deposition")
    assert {"L_rp", "gap_rp", "inject", "coul_every", "q", "N"} <= set(real)
    assert "dp" not in real and "contact" not in real       # equal/string: not settable
    monkeypatch.setattr(deckfile, "deck_variables",
                        lambda name: dict(real, pair_suffix="none"))
    from granular_charged.cli import options

    class A:
        var = [["pair_suffix", "opt"]]
    assert options.deck_vars(A, "run") == ({}, {"pair_suffix": "opt"})
    with pytest.raises(ParamError):
        runner.Runner.check(DepositionParams(extra={"pair_sufix": "opt"}))


# ---- item 6: bad values, bad folders, bad result files ---------------------------------------
@pytest.mark.parametrize("args,words", [
    (["run", "--N", "0"], ["argument --N: must be >= 1, not 0"]),
    (["run", "--N", "-5"], ["argument --N: must be >= 1, not -5"]),
    (["sweep", "--out", "r", "--N", "0"], ["argument --N: must be >= 1"]),
    (["run", "--np", "0"], ["argument --np: must be >= 1, not 0"]),
    (["sweep", "--out", "r", "--jobs", "0"], ["argument --jobs/--cores: must be >= 1"]),
    (["demo", "--np", "0"], ["argument --np: must be >= 1"]),
    (["run", "--seed", "0"], ["argument --seed: must be >= 1"]),
    (["run", "--N", "5", "--tracer", "9"], ["tracer = 9: must be a particle id 1..N = 5"]),
    (["run", "--U0", "0"], ["U0 = 0: must be finite and > 0"]),
])
def test_bad_values_refused_before_lammps(tmp_path, args, words):
    # before: --N 0 ran LAMMPS, then a traceback and no result.json; --np 0 ran serial
    r = gc(args, tmp_path)
    refused(r, *words)
    assert not any(tmp_path.iterdir())


def test_np_zero_refused_by_the_runner_too():
    with pytest.raises(ParamError, match="np_ranks = 0"):
        runner.Runner(None, np_ranks=0)


@pytest.mark.parametrize("cmd", ["run", "sweep", "demo", "figures"])
def test_out_naming_a_file_is_refused(tmp_path, cmd):
    # before: a NotADirectoryError traceback
    f = tmp_path / "afile"
    f.write_text("x")
    args = {"figures": ["figures", tmp_path, "--out", f / "sub"]}.get(cmd, [cmd, "--out", f / "sub"])
    r = gc(args, tmp_path)
    refused(r, f"{f} is a file, not a folder")


def _result(tmp_path, name, **drop):
    r = {"version": runner.RESULT_VERSION, "complete": True, "key": name,
         "params": {"rp": 2e-6, "U0": 1.0, "gamma": 0.01, "q": 0.0, "N": 5, "seed": 1,
                    "extra": {}},
         "groups": {"Ad": 2.0, "Estar": 0.0, "Adstar": 2.0}, "phi": 0.4, "Z": 4.0,
         "fZ": [0.0] * 21, "inserted": 5, "natoms": 5, "lost": 0, "flying": 0, "wall_s": 1.0}
    for k in drop:
        r.pop(k)
    d = tmp_path / name
    d.mkdir()
    (d / "result.json").write_text(json.dumps(r))
    return d / "result.json"


def test_result_with_missing_keys_is_not_used(tmp_path, caplog):
    good = _result(tmp_path, "good")
    bad = _result(tmp_path, "bad", phi=None, groups=None)
    # before: KeyError in the tables; now named and left out, and run again by the runner
    res = sweep.load_results(tmp_path)
    assert [r["key"] for r in res] == ["good"]
    assert "keys missing: groups, phi, ignored" in caplog.text
    assert runner.read_result(bad) is None and runner.read_result(good) is not None


def test_result_of_an_unchecked_var_is_not_used(tmp_path, caplog):
    f = _result(tmp_path, "old")
    r = json.loads(f.read_text())
    r["params"]["extra"] = {"q": "400"}      # what `--var q 400` wrote before the check
    f.write_text(json.dumps(r))
    assert sweep.load_results(tmp_path) == [] and runner.read_result(f) is None
    assert "params.extra sets q" in caplog.text


def test_figures_of_broken_results_is_an_error_not_a_traceback(tmp_path):
    _result(tmp_path, "bad", params=None)
    (tmp_path / "notjson").mkdir()
    (tmp_path / "notjson" / "result.json").write_text("{")
    r = gc(["figures", tmp_path, "--out", tmp_path / "figs"], tmp_path)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "keys missing: params" in r.stderr and "not valid JSON" in r.stderr
    assert "no finished runs" in r.stderr


def test_table2_rows_with_missing_keys_are_left_out(tmp_path, caplog):
    from granular_charged.run.after_formation import load_table2
    (tmp_path / "q0").mkdir()
    (tmp_path / "q0" / "result.json").write_text(json.dumps({"q": 0.0}))
    assert load_table2(tmp_path) == [] and "keys missing: phi_before" in caplog.text


# ---- item 6: summary.csv counts the runs that contribute -------------------------------------
def test_summary_counts_only_runs_with_a_slab():
    base = {"params": {"rp": 2e-6, "U0": 1.0, "gamma": 0.01, "q": 0.0, "N": 5},
            "groups": {"Ad": 2.0, "Estar": 0.0, "Adstar": 2.0}, "natoms": 5, "lost": 0,
            "flying": 0, "key": "k"}
    res = [dict(base, phi=0.4, Z=4.0, params=dict(base["params"], seed=1)),
           dict(base, phi=None, Z=None, params=dict(base["params"], seed=2))]
    s = tables.summary(tables.runs_frame(res))
    # before: runs = 2 beside phi of one run and a blank sd
    assert s.loc[0, "runs"] == 1 and s.loc[0, "no_slab"] == 1
    assert s.loc[0, "phi"] == 0.4 and np.isnan(s.loc[0, "phi_sd"])
    # and with no slab at all (an all-None column): 0 runs, NaN phi, no TypeError
    s0 = tables.summary(tables.runs_frame(res[1:]))
    assert s0.loc[0, "runs"] == 0 and np.isnan(s0.loc[0, "phi"])


def test_sweep_runs_a_repeated_value_once():
    ps = sweep.expand([dict(rp=2e-6, U0=1.0, gamma=0.01, q=[0, 0, 400])], 5, [1, 1], {})
    assert [p.q for p in ps] == [0, 400]


# ---- item 6: the folder lock -----------------------------------------------------------------
def test_folder_lock_makes_a_second_process_wait(tmp_path, caplog):
    """Two commands writing into one folder at once took turns emptying each other's running
    run folder ("Cannot open dump file"); the run's lock makes the second wait for the first.
    Here the first is a process holding the lock for 1.5 s."""
    caplog.set_level(logging.INFO, logger="granular_charged")
    lock = tmp_path / ".run.lock"
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""\
        import fcntl, sys, time
        fh = open({str(lock)!r}, "a"); fcntl.flock(fh, fcntl.LOCK_EX)
        print("held", flush=True); time.sleep(1.5)""")], stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    t0 = time.monotonic()
    with runner.folder_lock(lock, "run"):
        waited = time.monotonic() - t0
    holder.wait(timeout=10)
    # it waited for the holder (1.5 s minus its start-up), and said so
    assert waited > 0.5, waited
    assert "another process is running it; waiting" in caplog.text


# ---- item 12: no import cycle ----------------------------------------------------------------
PKG = SRC / "python" / "granular_charged"


def _module_name(path: Path) -> str:
    parts = path.relative_to(PKG.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, modules: set) -> set:
    """The package modules a module imports (at any level, also inside functions)."""
    name = _module_name(path)
    here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            base = ".".join(here[:len(here) - node.level + 1] + ([node.module] if node.module else []))
            for a in node.names:
                out.add(f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base)
    return out & modules


def _import_graph() -> dict:
    files = sorted(PKG.rglob("*.py"))
    modules = {_module_name(f) for f in files}
    return {_module_name(f): _imports(f, modules) - {_module_name(f)} for f in files}


def test_package_imports_have_no_cycle():
    graph = _import_graph()
    # only the entry point imports the command line
    cli = "granular_charged.cli"
    assert {k for k, v in graph.items() if not k.startswith(cli)
            and any(m == cli or m.startswith(cli + ".") for m in v)} == {"granular_charged.__main__"}
    state = {}

    def visit(m, path):
        if state.get(m) == 1:
            pytest.fail("import cycle: " + " -> ".join(path + [m]))
        if state.get(m) == 2:
            return
        state[m] = 1
        for n in sorted(graph[m]):
            visit(n, path + [m])
        state[m] = 2
    for m in sorted(graph):
        visit(m, [])


def test_package_roles_import_downwards():
    """The roles of doc/python.md, "Package layout": analysis needs only the parameters and the
    paper's numbers; running one case needs no study, figure or command line; studies and
    figures are two layers side by side over analysis, neither importing the other (the command
    line draws a study's figures); the sub-packages import nothing from the command line."""
    allowed = {"analysis": {"analysis", "params", "paper"},
               "run": {"run", "analysis", "params", "paper"},
               "figures": {"figures", "analysis", "params", "paper"},
               "studies": {"studies", "run", "analysis", "params", "paper"}}
    upward = {}
    for mod, deps in _import_graph().items():
        role = mod.split(".")[1] if mod.count(".") >= 1 else ""
        if role in allowed:
            used = {d.split(".")[1] for d in deps if d.count(".") >= 1}
            if used - allowed[role]:
                upward[mod] = sorted(used - allowed[role])
    assert not upward, f"modules importing a layer their role may not: {upward}"


def test_constants_have_one_home():
    text = {f.relative_to(PKG).as_posix(): f.read_text() for f in PKG.rglob("*.py")}
    for name, home in (("K_EFF", "paper.py"), ("ZMAX", "analysis/packing.py")):
        defs = [f for f, t in text.items()
                for node in ast.walk(ast.parse(t)) if isinstance(node, ast.Assign)
                for tgt in node.targets if isinstance(tgt, ast.Name) and name in tgt.id]
        assert defs == [home], (name, defs)
    legacy = [f for f in text if Path(f).name in ("demo.py", "sweep.py", "reproduce.py",
                                                 "after_formation.py") or f.startswith("cli")]
    assert len(legacy) >= 5, legacy
    for f in legacy:
        assert '__name__ == "__main__"' not in text[f], f
