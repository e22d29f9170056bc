"""Depositions of in.deposition with particle populations (ctest python.powder; a few
minutes): the drawn radii and charges against their distributions, the computes against the
Python analysis on a polydisperse packing, a mixture of two species, a bipolar powder's charge
and Coulomb forces against a direct sum, and a narrow size spread against one size.

The runs are small (N = 60-200 in L = 9-10 r_p) and said so in each test."""
import math

import numpy as np
import pytest
from scipy import stats

from granular_charged.analysis import packing
from granular_charged.run import population
from granular_charged.params import E0
from lammps_runs import DECK, lmp_run, result_line


@pytest.fixture(scope="module")
def lognormal_gauss_run(build_dir, tmp_path_factory):
    """120 particles, lognormal radii (median 2 um, gsd 1.25, clipped to 1-4 um), Gaussian
    charges (mean 100, sd 30 e_0), plane rain."""
    d = tmp_path_factory.mktemp("lognormal")
    text = lmp_run(build_dir, DECK, d, {
        "N": 120, "L_rp": 10, "r_dist": "lognormal", "rp_gsd": 1.25, "rp_lo": 1.0e-6,
        "rp_hi": 4.0e-6, "q_dist": "gauss", "q": 100, "q_sd": 30, "inject": "plane",
        "settle_max": 100, "zlo_rp": 2, "top_rp": 3, "split_log": "yes"})
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
    # (split_log yes: the loop's runs in log.inject.lammps, the log goes on in log.lammps)
    assert text.count("Loop time") <= 4, "log.lammps holds the one-by-one loop's runs"
    prog = [ln for ln in text.splitlines() if ln.startswith("GC PROGRESS")]
    assert len(prog) >= 10 and prog[-1].startswith("GC PROGRESS 120 / 120")
    from granular_charged.run.runner import parse_progress
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


def test_bipolar_powder_charge_and_forces_against_a_direct_sum(build_dir, tmp_path):
    """A bipolar powder (N = 80, L = 10 r_p, r_p = 2 um, +-300 e_0, 40 % positive, plane rain)
    deposited by the deck: its total charge is (n+ - n-) 300 e_0 (the dump), and fix coul/fmm's
    forces on the packing, put in free space (boundary f f f), agree with pair coul/cut with a
    cutoff beyond the packing's diameter (a direct sum over all pairs): requested accuracy 1e-6
    relative RMS; asserted 1e-5 of the RMS force (10x margin for the FMM's error estimate)."""
    from lammps import lammps
    lmp_run(build_dir, DECK, tmp_path, {
        "N": 80, "L_rp": 10, "q_dist": "bipolar", "q": 300, "q_pos": 0.4, "settle_max": 100,
        "zlo_rp": 2, "top_rp": 3})
    snap = packing.read_dump(tmp_path / "final.dump", last_only=True)
    q = snap["q"] / E0
    npos = int((q > 0).sum())
    assert snap["q"].sum() / E0 == pytest.approx((2 * npos - snap.n) * 300.0, rel=1e-6)
    np.testing.assert_allclose(np.abs(q), 300.0, rtol=1e-6)
    # number of positives: binomial(80, 0.4), 4 sd either way
    assert abs(npos - 32) < 4 * math.sqrt(80 * 0.4 * 0.6)

    xyz = snap.xyz
    span = float(np.ptp(xyz, axis=0).max())
    forces = {}
    for solver in ("fmm", "direct"):
        l = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
        try:
            lo, hi = xyz.min(axis=0) - 1e-5, xyz.max(axis=0) + 1e-5
            for c in ["units si", "atom_style charge", "atom_modify map array", "boundary f f f",
                      f"region box block {lo[0]} {hi[0]} {lo[1]} {hi[1]} {lo[2]} {hi[2]} units box",
                      "create_box 1 box", "mass 1 1e-13"]:
                l.command(c)
            for (x, y, z), qq in zip(xyz, snap["q"]):
                l.command(f"create_atoms 1 single {x:.17g} {y:.17g} {z:.17g} units box")
            for k, qq in enumerate(snap["q"], start=1):
                l.command(f"set atom {k} charge {qq:.17g}")
            if solver == "fmm":
                l.commands_list(["pair_style zero 1e-5", "pair_coeff * *",
                                 "fix coul all coul/fmm accuracy 1e-6"])
            else:
                l.commands_list([f"pair_style coul/cut {3 * span:.6g}", "pair_coeff * *",
                                 f"comm_modify cutoff {3.1 * span:.6g}"])
            l.commands_list(["neighbor 1e-6 bin", "run 0 post no"])
            f = np.array(l.numpy.extract_atom("f")[: snap.n], dtype=float)
            ids = np.array(l.numpy.extract_atom("id")[: snap.n])
            forces[solver] = f[np.argsort(ids)]
        finally:
            l.close()
    rms = math.sqrt((forces["direct"] ** 2).sum(axis=1).mean())
    err = math.sqrt(((forces["fmm"] - forces["direct"]) ** 2).sum(axis=1).mean())
    assert rms > 0 and err / rms < 1e-5


def _phi_Z(build_dir, root, seeds, extra):
    out = []
    for s in seeds:
        d = root / f"s{s}"
        d.mkdir()
        res = result_line(lmp_run(build_dir, DECK, d, dict(extra, seed=s)))
        out.append((float(res["phi"]), float(res["Z"])))
    return np.array(out)


def test_narrow_spread_reproduces_one_size(build_dir, tmp_path):
    """Radii uniform in r_p +- 1 % against one radius r_p = 2 um: N = 120 in L = 8 r_p (the
    paper's particles per floor area, about), neutral rain, 3 seeds each. The means of phi and
    <Z> agree within 3 standard errors of their difference (the seed scatter): a 1 % spread
    changes phi and <Z> far less than that. (N = 200, L = 9 r_p, 6 seeds, doc/populations.md:
    phi 0.443 +- 0.014 vs 0.437 +- 0.010, <Z> 4.05 +- 0.08 vs 4.10 +- 0.08.)"""
    base = {"N": 120, "L_rp": 8, "zlo_rp": 3, "top_rp": 4}
    (tmp_path / "one").mkdir()
    (tmp_path / "spread").mkdir()
    one = _phi_Z(build_dir, tmp_path / "one", (1, 2, 3), base)
    spread = _phi_Z(build_dir, tmp_path / "spread", (1, 2, 3),
                    dict(base, r_dist="uniform", rp_lo=1.98e-6, rp_hi=2.02e-6))
    for k in range(2):
        a, b = one[:, k], spread[:, k]
        se = math.sqrt(a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b))
        assert abs(a.mean() - b.mean()) < 3 * se + 1e-12, (k, a, b)
