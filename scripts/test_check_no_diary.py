"""pytest for scripts/check_no_diary.py: it finds what it must, lets pass what it must.

Run: /usr/bin/python3 -m pytest scripts/test_check_no_diary.py
The scan of the repository itself is scripts/check_no_diary.py (exit status 1 on any hit).
"""
import importlib.util
import os

_spec = importlib.util.spec_from_file_location(
    "check_no_diary", os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_no_diary.py"))
cnd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cnd)


def hits(text, tmp_path):
    f = tmp_path / "page.md"
    f.write_text(text)
    cnd.REPO = str(tmp_path)
    return [h[1] for h in cnd.scan("page.md")]


def test_finds_diary(tmp_path):
    assert hits("measured 2026-12-03 on the build machine\n", tmp_path) == ["date"]
    assert hits("as of Dec 2026 the order is 9\n", tmp_path) == ["date"]
    assert hits("on 3 December 2026 we\n", tmp_path) == ["date"]
    assert hits("in the fifth session, the\n", tmp_path) == ["word"]
    assert hits('@pytest.fixture(scope="session")\n', tmp_path) == ["word"]
    assert hits("a later sitting gave\n", tmp_path) == ["word"]
    assert hits("yesterday's run\n", tmp_path) == ["word"]
    assert hits("fixed in issue 45\n", tmp_path) == ["issue"]
    assert hits("(issues 14 and 11)\n", tmp_path) == ["issue"]
    assert hits('### Protocol checks (issue "Deposition throughput")\n', tmp_path) == ["issue"]


def test_lets_pass(tmp_path):
    assert hits("LAMMPS 4Jul2026 and 4Feb2025 (20260704)\n", tmp_path) == []
    assert hits("Chen et al., Soft Matter 2016\n", tmp_path) == []
    assert hits("the order is 9 and the leaf size 80\n", tmp_path) == []


def test_skips_machine_output():
    assert not cnd.is_text("examples/deposition/log.4Jul26.deposition.g++.1")
    assert cnd.is_text("examples/deposition/in.deposition")
    assert cnd.is_text("doc/theory.md")
