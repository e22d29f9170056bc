"""Particle populations of in.deposition (sizes, charges, species), the protocol record, the
progress lines, --var axes, study files, the polydisperse analysis and the powder example.

The LAMMPS runs are small (N <= 120 in L = 9-10 r_p) and short (settle_max 100): they test the
draws and the bookkeeping, not the packing's statistics."""
import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from granular_charged import packing, population
from granular_charged.params import E0, DepositionParams, ParamError

SRC = Path(__file__).resolve().parents[2]
DECK = SRC / "python" / "granular_charged" / "decks" / "in.deposition"


def lmp_run(build_dir, deck, cwd, variables, timeout=600):
    cmd = [str(Path(build_dir) / "lmp"), "-in", str(deck), "-screen", "none", "-log", "log.lammps"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    text = (Path(cwd) / "log.lammps").read_text()
    assert r.returncode == 0, text[-3000:] + r.stderr[-2000:]
    return text


def result_line(text):
    m = re.search(r"^GC RESULT (.*)$", text, re.M)
    w = m.group(1).split()
    return dict(zip(w[0::2], w[1::2]))


# ---- without LAMMPS ---------------------------------------------------------------------------

def test_default_run_keys_do_not_change():
    # the kept runs of doc/data are found by these names
    assert DepositionParams().key() == "rp2um_U1_g10mJ_q0_N2000_s4711"
    assert DepositionParams(q=400, N=500, seed=2, extra={"L_rp": "14"}).key() == \
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
    from granular_charged.cli import _refused, sweep_params, var_axes
    single, axes = var_axes([["E", "1e8", "2e8"], ["L_rp", "14"], ["gap_rp", "1", "2"]], "sweep")
    ps = sweep_params([dict(rp=[2e-6], U0=[1.0], gamma=[0.01], q=[0.0, 100.0])], single, axes,
                      {}, _refused("sweep"), 50, [1, 2])
    assert len(ps) == 2 * 2 * 2 * 2 and len({p.key() for p in ps}) == 16
    assert {p.E for p in ps} == {1e8, 2e8} and {p.extra["gap_rp"] for p in ps} == {"1", "2"}
    with pytest.raises(ParamError):
        var_axes([["E", "1e8", "2e8"]], "run")


def test_study_file_grid_seeds_and_protocol_warning(tmp_path, caplog):
    from granular_charged import studyfile
    from granular_charged.axes import announce
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


# ---- the deck ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def lognormal_gauss_run(build_dir, tmp_path_factory):
    """120 particles, lognormal radii (median 2 um, gsd 1.25, clipped to 1-4 um), Gaussian
    charges (mean 100, sd 30 e_0), plane rain."""
    d = tmp_path_factory.mktemp("lognormal")
    text = lmp_run(build_dir, DECK, d, {
        "N": 120, "L_rp": 10, "r_dist": "lognormal", "rp_gsd": 1.25, "rp_lo": 1.0e-6,
        "rp_hi": 4.0e-6, "q_dist": "gauss", "q": 100, "q_sd": 30, "inject": "plane",
        "settle_max": 100, "zlo_rp": 2, "top_rp": 3})
    return d, text


def test_deck_draws_follow_the_requested_distributions(lognormal_gauss_run):
    d, text = lognormal_gauss_run
    snap = packing.read_dump(d / "final.dump", last_only=True)
    r, q = snap["radius"], snap["q"] / E0
    assert len(r) == 120
    size = {"dist": "lognormal", "median": 2e-6, "gsd": 1.25, "lo": 1.0e-6, "hi": 4.0e-6}
    # KS tests at the 1 % level: a correct deck fails one of them 2 % of the time at most, but
    # the draws are fixed by the seed, so the test is deterministic; a wrong law (gsd or median
    # off by 10 %, the clip missing) gives p < 1e-3 at n = 120
    assert stats.kstest(r, population.radius_cdf(size)).pvalue > 0.01
    assert r.min() >= 1.0e-6 and r.max() <= 4.0e-6
    assert stats.kstest(q, stats.norm(100, 30).cdf).pvalue > 0.01
    # the KS test has little power against a wrong width at n = 120; the moments of ln r (the
    # truncated normal of the clipped lognormal) and of q within 4 standard errors (SE of a
    # mean sd/sqrt(n), of an sd sd/sqrt(2 n)) catch a width off by 20 % (> 5 SE)
    s = math.log(1.25)
    tn = stats.truncnorm(math.log(1.0e-6 / 2e-6) / s, math.log(4.0e-6 / 2e-6) / s,
                         loc=math.log(2e-6), scale=s)
    n = len(r)
    assert abs(np.log(r).mean() - tn.mean()) < 4 * tn.std() / math.sqrt(n)
    assert abs(np.log(r).std(ddof=1) - tn.std()) < 4 * tn.std() / math.sqrt(2 * n)
    assert abs(q.mean() - 100) < 4 * 30 / math.sqrt(n)
    assert abs(q.std(ddof=1) - 30) < 4 * 30 / math.sqrt(2 * n)
    # the run says and records its protocol, keeps log.lammps small and reports progress
    assert "GC PROTOCOL inject plane" in text
    assert text.count("Loop time") <= 4, "log.lammps holds the one-by-one loop's runs"
    prog = [ln for ln in text.splitlines() if ln.startswith("GC PROGRESS")]
    assert len(prog) >= 10 and prog[-1].startswith("GC PROGRESS 120 / 120")
    from granular_charged.runner import parse_progress
    assert parse_progress(prog[-1])["k"] == 120


def test_computes_and_python_agree_on_a_polydisperse_packing(lognormal_gauss_run):
    d, text = lognormal_gauss_run
    res = result_line(text)
    snap = packing.read_dump(d / "final.dump", last_only=True)
    zlo, zhi = float(res["zlo"]), float(res["zhi"])
    assert zhi > zlo
    # the same definitions (exact sphere-slab volumes with each particle's radius; contact
    # r_ij <= r_i + r_j): equal to the dump's 12 digits
    assert float(res["phi"]) == pytest.approx(packing.phi_slab(snap, zlo, zhi), rel=1e-8)
    assert float(res["Z"]) == pytest.approx(
        packing.coordination_stats(snap, zlo, zhi)["Z"], rel=1e-8)
    cls = packing.by_class(snap, None, zlo, zhi)
    n_all = sum(c["n"] for c in cls["classes"] if c["class"] == "all")
    n_cls = sum(c["n"] for c in cls["classes"] if c["class"] != "all")
    assert n_all == n_cls > 0


def test_mixture_area_and_bipolar_charges_and_species(build_dir, tmp_path):
    """Two species by number 1 : 3, species 1 uniform 1.5-2.5 um charged by area, species 2 a
    discrete 1.5 / 3 um (1 : 3) bipolar +-300 e_0 with 30 % positive, its own material; rain
    (one by one)."""
    sigma = 2e-6
    text = lmp_run(build_dir, DECK, tmp_path, {
        "N": 120, "L_rp": 10, "species": 2, "frac": 1, "frac_2": 3,
        "r_dist": "uniform", "rp_lo": 1.5e-6, "rp_hi": 2.5e-6, "q_dist": "area",
        "q_sigma": sigma, "r_dist_2": "discrete", "radii_2": "1.5e-6 3e-6", "rfrac_2": "1 3",
        "q_dist_2": "bipolar", "q_2": 300, "q_pos_2": 0.3, "q_sigma_2": 0, "rho_2": 4000, "E_2": 1e9,
        "gamma_2": 0.02, "inject": "rain", "settle_max": 100, "zlo_rp": 2, "top_rp": 3})
    assert "GC PROTOCOL inject rain" in text
    snap = packing.read_dump(tmp_path / "final.dump", last_only=True)
    t, r, q = snap["type"].astype(int), snap["radius"], snap["q"] / E0
    n2 = int((t == 2).sum())
    # binomial(120, 3/4): sd 4.7; 4 sd either way
    assert abs(n2 - 90) < 4 * math.sqrt(120 * 0.75 * 0.25)
    # charge proportional to the area, particle by particle (the dump's 12 digits... %g: 6)
    np.testing.assert_allclose(q[t == 1], population.area_charge(r[t == 1], sigma), rtol=1e-5)
    assert stats.kstest(r[t == 1], stats.uniform(1.5e-6, 1e-6).cdf).pvalue > 0.01
    assert set(np.round(r[t == 2] * 1e7).astype(int)) <= {15, 30}
    big = int((np.abs(r[t == 2] - 3e-6) < 1e-9).sum())
    assert abs(big - 0.75 * n2) < 4 * math.sqrt(n2 * 0.75 * 0.25)
    pos = int((q[t == 2] > 0).sum())
    np.testing.assert_allclose(np.abs(q[t == 2]), 300.0, rtol=1e-5)
    assert abs(pos - 0.3 * n2) < 4 * math.sqrt(n2 * 0.3 * 0.7)
    # each species' mass from its own density
    mass_ratio = None  # masses are not in the dump; the density is checked through the restart
    del mass_ratio


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
    from granular_charged import figures
    texts = []

    def capture(fig, path, data=None, tight=True):
        for t in fig.findobj(lambda a: hasattr(a, "get_text")):
            texts.append(t.get_text())
        import matplotlib.pyplot as plt
        plt.close(fig)
        return path

    monkeypatch.setattr(figures, "save", capture)
    fn(results, out)
    return " ".join(texts)


def test_figures_carry_the_users_material_not_the_paper(monkeypatch, tmp_path):
    """The paper's annotations only on the paper's material; a user's runs are labelled with
    theirs (all_figures decides; rdf and fZ are drawn here from two kept paper-size runs)."""
    import copy
    from granular_charged import figures
    from granular_charged.runner import load_result_files
    kept = SRC / "doc" / "data" / "paper-size" / "runs"
    res = load_result_files([kept / "rp2um_U1_g10mJ_q0_N2000_s1" / "result.json",
                             kept / "rp2um_U1_g10mJ_q400_N2000_s1_exact" / "result.json"])
    assert len(res) == 2
    figures.PAPER.update(on=not figures.material_label(res), material=figures.material_label(res))
    assert "paper" in _figure_texts(monkeypatch, figures.rdf, res, tmp_path)
    mine = copy.deepcopy(res)
    for r in mine:
        r["params"]["rho"] = 3000.0
        r["params"]["extra"] = dict(r["params"].get("extra") or {}, r_dist="uniform")
    lab = figures.material_label(mine)
    assert lab == "rho 3000, uniform radii"
    figures.PAPER.update(on=False, material=lab)
    for fn in (figures.rdf, figures.fZ, figures.phi_vs_q):
        t = _figure_texts(monkeypatch, fn, mine, tmp_path)
        assert "paper" not in t.lower() and "rho 3000" in t, fn.__name__
    figures.PAPER.update(on=True, material="")
