"""The one-at-a-time study's tables (granular_charged.studies.one_at_a_time) on made-up results: which
runs it asks for, the protocol of a run, phi_0/phi - 1 against the neutral runs, and the
differences between the protocols in standard errors. No LAMMPS."""
import numpy as np
import pytest

from granular_charged.studies import one_at_a_time as oat


def _result(q, seed, phi, Z, inject=None):
    extra = {"inject": inject} if inject else {}
    return {"params": {"rp": 2e-6, "U0": 1.0, "gamma": 0.01, "q": q, "seed": seed, "N": 2000,
                       "extra": extra}, "phi": phi, "Z": Z, "cpu_s": 100.0}


def test_the_study_asks_for_neutral_default_and_sequential_runs():
    ps = oat.study_params((1, 2, 3))
    keys = [p.key() for p in ps]
    assert len(ps) == 15 and len(set(keys)) == 15
    seq = [p for p in ps if p.extra.get("inject") == "sequential"]
    assert sorted({p.q for p in seq}) == [260.0, 400.0] and len(seq) == 6
    # the default runs are reproduce --size paper's folders: no inject, no L_rp in the key
    assert "rp2um_U1_g10mJ_q400_N2000_s1" in keys
    assert "rp2um_U1_g10mJ_q0_N2000_s1" in keys
    # and the kept runs of doc/data under the long key
    assert "rp2um_U1_g10mJ_q400_N2000_s1_exact_injectsequential" in {p.legacy_key() for p in ps}
    assert all(p.N == 2000 for p in ps)


def test_expansion_and_differences():
    """phi_0 = 0.42 (3 seeds, sd 0.01), 400 e0 default phi = 0.35 and sequential 0.33 (sd 0.01
    each): expansion 0.42/0.35 - 1 = 0.2 and 0.42/0.33 - 1 = 0.2727; the difference of the
    phi means -0.02 has the standard error sqrt(2) 0.01 / sqrt(3) = 0.008165."""
    rs = []
    for s, d in zip((1, 2, 3), (-0.01, 0.0, 0.01)):
        rs += [_result(0.0, s, 0.42 + d, 3.9), _result(400.0, s, 0.35 + d, 3.5 + d),
               _result(400.0, s, 0.33 + d, 3.4 + d, inject="sequential")]
    t = oat.case_table(oat.run_frame(rs))
    seq = t[(t["q"] == 400) & (t["protocol"] == oat.SEQUENTIAL)].iloc[0]
    dflt = t[(t["q"] == 400) & (t["protocol"] == oat.DEFAULT)].iloc[0]
    assert dflt["expansion"] == pytest.approx(0.2)
    assert seq["expansion"] == pytest.approx(0.42 / 0.33 - 1)
    assert seq["runs"] == dflt["runs"] == 3
    d = oat.differences(t).iloc[0]
    assert d["d_phi"] == pytest.approx(-0.02)
    assert d["d_phi_se"] == pytest.approx(np.sqrt(2) * 0.01 / np.sqrt(3))
    assert d["d_phi_in_se"] == pytest.approx(-0.02 / (np.sqrt(2) * 0.01 / np.sqrt(3)))
    assert d["d_Z"] == pytest.approx(-0.1)
    text = oat.format_differences(oat.differences(t))
    assert "400 e0 (3 / 3 runs)" in text


def test_a_charge_with_one_protocol_has_no_difference():
    rs = [_result(0.0, s, 0.42, 3.9) for s in (1, 2)] + \
         [_result(260.0, s, 0.40, 3.8) for s in (1, 2)]
    t = oat.case_table(oat.run_frame(rs))
    assert oat.differences(t).empty
    assert "no charge with runs of both protocols" in oat.format_differences(oat.differences(t))


def test_the_cli_refuses_what_the_study_sets(cli, tmp_path):
    r = cli(["one-at-a-time", "--out", tmp_path / "o", "--var", "inject", "plane",
             "--finished-only"], cwd=tmp_path, check=False)
    assert r.returncode == 2 and "the study sets it per case" in r.stderr
    assert not (tmp_path / "o").exists()
