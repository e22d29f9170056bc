"""Particle populations of in.deposition (sizes, charges, species), the protocol record, the
progress lines, --var axes, study files, the polydisperse analysis and the powder example.

The LAMMPS runs are small (N <= 120 in L = 9-10 r_p) and short (settle_max 100): they test the
draws and the bookkeeping, not the packing's statistics."""
import re
import sys

import numpy as np
import pytest

from granular_charged.analysis import packing
from granular_charged.figures.studyfile import study_label
from granular_charged.params import DepositionParams, ParamError
from granular_charged.run import population
from lammps_runs import SRC, lmp_run


# ---- without LAMMPS ---------------------------------------------------------------------------

def test_default_run_keys_do_not_change():
    # the kept runs of doc/data are found by these names (the long key of the second)
    assert DepositionParams().key() == "rp2um_U1_g10mJ_q0_N2000_s4711"
    assert DepositionParams(q=400, N=500, seed=2, extra={"L_rp": "14"}).legacy_key() == \
        "rp2um_U1_g10mJ_q400_N500_s2_exact_L_rp14"


def test_population_specs_become_deck_variables():
    v = population.mixture_vars([
        {"fraction": 0.25, "material": {"rho": 3000, "gamma": 0.02},
         "size": "uniform lo=3e-6 hi=7e-6", "charge": "area sigma=1e-6"},
        {"fraction": 0.75, "size": "discrete radii=2e-6,4e-6 fractions=0.5,0.5",
         "charge": "bipolar q=300 pos=0.3", "material": {"E": 1e9}}])
    assert v["species"] == "2" and v["r_dist"] == "uniform" and v["rp"] == "5e-06"
    assert v["radii_2"] == "2e-06 4e-06" and v["q_dist_2"] == "bipolar" and float(v["E_2"]) == 1e9
    assert v["frac"] == "0.25" and v["frac_2"] == "0.75" and v["q_pos_2"] == "0.3"
    with pytest.raises(ParamError):
        population.parse_spec("uniform lo=7e-6 hi=3e-6", population.SIZE_KEYS, "--size")
    with pytest.raises(ParamError):
        population.parse_spec("lognormal median=5e-6", population.SIZE_KEYS, "--size")


def test_protocol_rule_follows_the_population():
    assert population.protocol({"q": "0"}) == "rain"
    assert population.protocol({"q": "400"}) == "plane"
    # charge only through the area rule: charged, so auto is the plane rain
    assert population.protocol({"q": "0", "q_dist": "area", "q_sigma": "1e-6"}) == "plane"
    assert population.protocol({"q": "0", "q_dist": "area", "q_sigma": "0"}) == "rain"
    assert population.protocol({"q": "0", "inject": "sequential"}) == "sequential"


def test_var_axes_are_a_product_with_the_other_axes():
    from granular_charged.cli.options import refused
    from granular_charged.studies.axes import sweep_params, var_axes
    single, axes = var_axes([["E", "1e8", "2e8"], ["L_rp", "14"], ["gap_rp", "1", "2"]], "sweep")
    ps = sweep_params([dict(rp=[2e-6], U0=[1.0], gamma=[0.01], q=[0.0, 100.0])], single, axes,
                      {}, refused("sweep"), 50, [1, 2])
    assert len(ps) == 2 * 2 * 2 * 2 and len({p.key() for p in ps}) == 16
    assert {p.E for p in ps} == {1e8, 2e8} and {p.extra["gap_rp"] for p in ps} == {"1", "2"}
    with pytest.raises(ParamError):
        var_axes([["E", "1e8", "2e8"]], "run")


def test_study_file_grid_seeds_and_protocol_warning(tmp_path, caplog):
    from granular_charged.studies import studyfile
    from granular_charged.studies.axes import announce
    f = tmp_path / "s.toml"
    f.write_text('name = "my dust"\nseeds = [1, 2, 3]\n[deck]\nU0 = 0.5\nN = 40\n'
                 '[material]\nrho = 3000\nE = 1e8\ngamma = 0.02\n'
                 '[population]\nsize = "uniform lo=3e-6 hi=7e-6"\ncharge = "area sigma=5e-7"\n'
                 '[grid]\nq_sigma = [0, 5e-7]\n')
    d = studyfile.load(f)
    ps = studyfile.params(d)
    assert len(ps) == 6 and {p.rho for p in ps} == {3000.0} and {p.U0 for p in ps} == {0.5}
    assert {p.extra["q_sigma"] for p in ps} == {"0", "5e-07"}
    # auto: q_sigma 0 is neutral (rain), 5e-7 charged (plane): said before the runs start
    with caplog.at_level("INFO"):
        announce(ps, tmp_path)
    assert "DIFFERENT injection protocols" in caplog.text
    caplog.clear()
    f.write_text(f.read_text().replace('name = "my dust"', 'name = "my dust"\nprotocol = "plane"'))
    with caplog.at_level("INFO"):
        announce(studyfile.params(studyfile.load(f)), tmp_path)
    assert "DIFFERENT" not in caplog.text and "every run: plane" in caplog.text
    assert "estimated cost" in caplog.text
    # the figures' title names the study and its material
    fake = [{"params": dict(vars(p), extra=dict(p.extra)), "protocol": "plane"} for p in ps]
    label = study_label(d, fake)
    # (the charges differ between the points: each point's figure says its own)
    assert label.startswith("my dust (rho 3000, E 1e+08, uniform radii, gamma 0.02 J/m^2")
    assert "paper" not in label and "area" not in label


def test_rdf_contact_is_rdf_slab_for_one_size():
    # a monodisperse random packing: g(x) with x = r / (r_i + r_j) must be rdf_slab at r = 2 r_p x
    rng = np.random.default_rng(3)
    n, L = 600, 20.0
    cols = {"id": np.arange(1, n + 1), "x": rng.uniform(0, L, n), "y": rng.uniform(0, L, n),
            "z": rng.uniform(0, 10, n), "radius": np.full(n, 0.5)}
    snap = packing.Snapshot(0, np.array([[0, L], [0, L], [0, 10]]), cols)
    rc, g = packing.rdf_slab(snap, 2.0, 8.0, 3.0, 60)
    xc, gx = packing.rdf_contact(snap, 2.0, 8.0, 3.0, 60)
    # same pairs and the same ideal count (every partner has the same radius): equal to round-off
    assert np.allclose(xc, rc) and np.allclose(g, gx, rtol=1e-9, atol=1e-12)


# ---- the example (the deck's population runs: python/tests_powder) ------------------------------

def test_powder_example_short_version(build_dir, tmp_path):
    """examples/powder/in.powder, short: it runs, and every particle's charge is sigma 4 pi r^2
    (the dump against the closed form), the total charge their sum."""
    text = lmp_run(build_dir, SRC / "examples" / "powder" / "in.powder", tmp_path,
                   {"N": 60, "steps": 2000})
    m = re.search(r"^POWDER phi (\S+) Z (\S+) zlo \S+ zhi \S+ Q (\S+) C", text, re.M)
    assert m, text[-2000:]
    snap = packing.read_dump(tmp_path / "final.dump", last_only=True)
    assert snap.n == 60 and 3e-6 <= snap["radius"].min() and snap["radius"].max() <= 7e-6
    np.testing.assert_allclose(snap["q"], 5e-7 * 4 * np.pi * snap["radius"] ** 2, rtol=1e-5)
    assert float(m.group(3)) == pytest.approx(snap["q"].sum(), rel=1e-5)


def _figure_texts(monkeypatch, fn, results, out):
    """Every text (titles, labels, legend entries) of the figures fn draws from results."""
    texts = []

    def capture(fig, path, data=None, tight=True):
        for t in fig.findobj(lambda a: hasattr(a, "get_text")):
            texts.append(t.get_text())
        import matplotlib.pyplot as plt
        plt.close(fig)
        return path

    monkeypatch.setattr(sys.modules[fn.__module__], "save", capture)
    fn(results, out)
    return " ".join(texts)


def test_figures_carry_the_users_material_not_the_paper(monkeypatch, tmp_path):
    """The paper's annotations only on the paper's material; a user's runs are labelled with
    theirs (all_figures decides; rdf and fZ are drawn here from two kept paper-size runs)."""
    import copy
    from granular_charged.figures import base, expansion, structure
    from granular_charged.run.runner import load_result_files
    kept = SRC / "doc" / "data" / "paper-size" / "runs"
    res = load_result_files([kept / "rp2um_U1_g10mJ_q0_N2000_s1" / "result.json",
                             kept / "rp2um_U1_g10mJ_q400_N2000_s1_exact" / "result.json"])
    assert len(res) == 2
    base.PAPER.update(on=not base.material_label(res), material=base.material_label(res))
    assert "paper" in _figure_texts(monkeypatch, structure.rdf, res, tmp_path)
    mine = copy.deepcopy(res)
    for r in mine:
        r["params"]["rho"] = 3000.0
        r["params"]["extra"] = dict(r["params"].get("extra") or {}, r_dist="uniform")
    lab = base.material_label(mine)
    assert lab == "rho 3000, uniform radii"
    base.PAPER.update(on=False, material=lab)
    for fn in (structure.rdf, structure.fZ, expansion.phi_vs_q):
        t = _figure_texts(monkeypatch, fn, mine, tmp_path)
        assert "paper" not in t.lower() and "rho 3000" in t, fn.__name__
    base.PAPER.update(on=True, material="")


def test_progress_bar_follows_the_log(tmp_path):
    """The run's bar reads the deck's GC PROGRESS lines as log.lammps grows (a partial last line
    is left for the next read)."""
    from granular_charged.run.runner import Runner

    class Bar:
        total = n = None
        post = {}

        def set_postfix(self, ordered_dict=None, refresh=True, **kw):   # tqdm's signature
            self.post = dict(ordered_dict or {}, **kw)

        def refresh(self):
            pass

    log = tmp_path / "log.lammps"
    log.write_text("units si\nGC PROGRESS 40 / 300 particles, step 1234, elapsed 3 s, eta 20 s\n"
                   "GC PROGRESS 80 / 300 particles, step 2468, elapsed 6 s, eta 17 s\nGC PRO")
    bar = Bar()
    pos = Runner._progress(log, 0, bar)
    assert (bar.n, bar.total, bar.post["step"]) == (80, 300, 2468)
    with open(log, "a") as fh:
        fh.write("GRESS 120 / 300 particles, step 3702, elapsed 9 s, eta 14 s\n")
    pos = Runner._progress(log, pos, bar)
    assert bar.n == 120
    # the last settling: the stop rule's kinetic energy and the particles still moving
    with open(log, "a") as fh:
        fh.write("GC SETTLE step 9000, kerel 0.0031 (stop below 1e-4), moving 2\n")
    Runner._progress(log, pos, bar)
    assert bar.post["settling: kerel"] == "0.0031 -> 1e-4" and bar.post["moving"] == "2"
