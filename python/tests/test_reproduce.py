"""`reproduce --size paper`: the study's runs, their order and their folders, and a report of
what is finished without running anything."""
import pytest

from granular_charged import paper
from granular_charged.studies.reproduce import SIZES, Reproduction, paper_size_params
from granular_charged.studies.sweep import PAPER_SETS, expand


def test_paper_size_runs_are_the_sweep_presets_and_the_fig9_neutral_range():
    ps = paper_size_params((1, 2, 3), {}, {})
    keys = [p.key() for p in ps]
    assert len(keys) == len(set(keys))
    # every run of `sweep --preset paper --N 2000` is one of them, in the same folder
    preset = {p.key() for p in expand(PAPER_SETS, 2000, (1, 2, 3), {})}
    assert preset <= set(keys)
    assert all(p.N == 2000 and "L_rp" not in p.extra for p in ps)     # the deck's L = 28 r_p
    # neutral first (cheap, the phi_0 question), then the charged runs
    charged = [p.q > 0 for p in ps]
    assert charged == sorted(charged)
    ad = sorted({round(p.groups()["Ad"], 3) for p in ps if p.q == 0})
    assert ad[0] <= 0.5 and ad[-1] >= 20      # the paper's Fig. 9 range
    # the three series of Fig. 3 have at least four charges each
    for rp, u0 in ((1e-6, 1.0), (1e-6, 2.0), (2e-6, 1.0)):
        qs = {p.q for p in ps if p.rp == rp and p.U0 == u0 and p.gamma == 0.010}
        assert len(qs) >= 5 and 0 in qs
    # the paper's particles per floor area at every size
    for s in SIZES.values():
        assert abs(s["N"] / s["L_rp"] ** 2 / (2000 / 28 ** 2) - 1) < 0.05


def test_paper_size_follows_a_particle_in_the_first_seed_only():
    st = Reproduction(out=".", size_name="paper")
    ps = st.params(True)
    assert {st.tracer(p) for p in ps if p.seed == 1} == {1000}
    assert {st.tracer(p) for p in ps if p.seed != 1} == {0}


def test_finished_only_runs_nothing(cli, tmp_path):
    r = cli(["reproduce", "--size", "paper", "--finished-only", "--out", tmp_path / "o"],
            cwd=tmp_path)
    assert "0 of the study's 84 runs are finished" in r.stderr
    assert "84 of the study's runs are not finished" in r.stdout
    assert not list((tmp_path / "o").glob("runs/*/log.lammps"))
    assert (tmp_path / "o" / "report.txt").exists()
    assert paper.PHI0_RANGE


def test_paper_size_checks_table2_on_every_seeds_packing(tmp_path):
    from granular_charged.studies.demo import Demo
    from granular_charged.studies.study import table2_folder, table2_folders
    assert Reproduction(out=".", size_name="paper").table2_seeds() == (1, 2, 3)
    assert Reproduction(out=".", size_name="demo").table2_seeds() == (1,)
    assert Demo(out=".", seeds=(4, 5)).table2_seeds() == (4,)
    # the first packing's folder is the one a single check always used (kept data stay valid)
    assert table2_folder(tmp_path, None) == tmp_path / "table2"
    for name in ("table2-s3", "table2-s10", "table2", "table2-s2", "table2-sx"):
        (tmp_path / name).mkdir()
    assert [d.name for d in table2_folders(tmp_path)] == ["table2", "table2-s2", "table2-s3",
                                                          "table2-s10"]


def test_table2_frame_names_each_packings_seed():
    from granular_charged.analysis import tables
    rows = [{"q": q, "phi_before": 0.4, "phi_after": 0.4 + dq, "Z_before": 3.9, "Z_after": 3.9,
             "FC_over_FE": 1e4, "params": {"seed": s}}
            for s in (1, 2) for q, dq in ((0.0, 0.0), (400.0, 1e-5))]
    t = tables.table2_frame(rows)
    assert list(t["seed"]) == [1, 1, 2, 2]
    assert list(t["paper_phi"]) == [paper.TABLE2[0][1], paper.TABLE2[2][1]] * 2
    assert t["dphi"].tolist() == [0.0, pytest.approx(1e-5), 0.0, pytest.approx(1e-5)]
