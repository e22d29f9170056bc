"""The scaling analyses of `reproduce` on synthetic runs with known answers."""
import numpy as np
import pandas as pd

from granular_charged.analysis import tables


def _runs(rows, estar=None):
    """rows with Ad* in the Adstar column; charged rows get E* from `estar` (q -> E*) and the
    Ad that gives that Ad* with the paper's definition Ad* = Ad / (1 - E*)."""
    cols = ["rp_um", "U0", "gamma_mJ", "q", "seed", "Adstar", "phi", "Z"]
    df = pd.DataFrame(rows, columns=cols)
    df["Estar"] = [(estar or {}).get(q, 0.0) for q in df["q"]]
    df["Ad"] = df["Adstar"] * (1.0 - df["Estar"])
    return df


def test_expansion_fit_recovers_a_power_law_and_its_scatter():
    # phi_0/phi - 1 = (q / 500)^2 exactly for the means; seeds scatter phi by +-0.002
    rows = []
    phi0 = 0.42
    for q in (0.0, 100.0, 200.0, 300.0, 400.0):
        phi = phi0 / (1.0 + (q / 500.0) ** 2)
        for s, d in zip((1, 2, 3), (-0.002, 0.0, 0.002)):
            rows.append((2.0, 1.0, 10.0, q, s, 2.0, phi + d, 4.0))
    fit = tables.expansion_fit(_runs(rows))
    assert abs(fit["slope"] - 2.0) < 0.05          # means: exact apart from the +-d symmetry
    assert fit["points"] == 4
    assert 0.0 < fit["sd"] < 1.0                    # the scatter gives a finite uncertainty
    assert fit["p16"] < fit["slope"] < fit["p84"]


def test_expansion_fit_without_enough_charges():
    rows = [(2.0, 1.0, 10.0, q, 1, 2.0, 0.4, 4.0) for q in (0.0, 100.0)]
    assert np.isnan(tables.expansion_fit(_runs(rows))["slope"])


def test_adstar_collapse_measures_the_charged_offset():
    # neutral cases on phi = 0.5 - 0.1 log10(Ad*); a charged case 0.03 above the line
    rows = []
    for ad, u0 in ((1.0, 1.414), (2.0, 1.0), (4.0, 0.707), (8.0, 0.5)):
        for s, d in zip((1, 2, 3), (-0.01, 0.0, 0.01)):
            rows.append((2.0, u0, 10.0, 0.0, s, ad, 0.5 - 0.1 * np.log10(ad) + d, 4.0))
    for s, d in zip((1, 2, 3), (-0.01, 0.0, 0.01)):
        rows.append((2.0, 1.0, 10.0, 400.0, s, 4.9, 0.5 - 0.1 * np.log10(4.9) + 0.03 + d, 4.0))
    runs = _runs(rows, estar={400.0: 0.6})
    c = tables.adstar_collapse(runs)
    charged = c[c["q"] > 0].iloc[0]
    assert abs(charged["Adstar"] - 4.9) < 1e-12
    assert abs(charged["phi"] - charged["phi_line"] - 0.03) < 1e-12
    assert abs(charged["phi_dev"] - 0.03 / (0.01 / np.sqrt(3))) < 1e-9
    assert np.allclose(c[c["q"] == 0]["phi_dev"], 0.0, atol=1e-9)
    # half the barrier: Ad* = Ad / (1 - E*/2), Ad = 4.9 x 0.4
    half = tables.adstar_collapse(runs, barrier_fraction=0.5)
    assert abs(half[half["q"] > 0].iloc[0]["Adstar"] - 4.9 * 0.4 / 0.7) < 1e-12


def _series(expansions, scatter, phi0=0.42, seeds=(1, 2, 3)):
    """Runs of one series: for each charge, phi = phi0 / (1 + expansion), the seeds spread by
    -scatter, 0, +scatter (so phi's sd is `scatter`)."""
    rows = []
    for q, e in expansions.items():
        for s, d in zip(seeds, (-scatter, 0.0, scatter)):
            rows.append((2.0, 1.0, 10.0, q, s, 2.0, phi0 / (1.0 + e) + d, 4.0))
    return _runs(rows)


def test_expansion_fit_leaves_out_charges_inside_the_noise():
    # phi_0/phi - 1 = 0.006 at 260 e0 with phi's sd 0.01 over 3 seeds: its standard error is
    # ~0.019 (sqrt(2) x 0.01 / sqrt(3) / 0.42), so 260 is unresolved; 300, 400, 450 are not
    runs = _series({0.0: 0.0, 260.0: 0.006, 300.0: 0.06, 400.0: 0.12, 450.0: 0.16}, 0.01)
    fit = tables.expansion_fit(runs)
    assert fit["resolved"]
    assert fit["charges"] == [300.0, 400.0, 450.0]
    assert fit["unresolved"] == [260.0]
    assert fit["p16"] <= fit["slope"] <= fit["p84"]


def test_expansion_fit_refuses_a_slope_from_two_resolved_charges():
    # the demo's case that printed "5.95 (2 points)": one expansion inside the noise
    runs = _series({0.0: 0.0, 260.0: 0.006, 400.0: 0.09}, 0.01)
    fit = tables.expansion_fit(runs)
    assert not fit["resolved"] and np.isnan(fit["slope"])
    assert "1 of 2 charges" in fit["reason"]
    assert tables.describe_fit(fit).startswith(tables.NOT_RESOLVED)
    # one seed per charge: no standard error, nothing resolved
    one = runs[runs["seed"] == 2]
    assert tables.expansion_fit(one)["points"] == 0


def test_summary_expansion_standard_error():
    runs = _series({0.0: 0.0, 400.0: 0.1}, 0.01)
    runs = runs.assign(natoms=2000, lost=0, wall_s=1.0)
    s = tables.summary(runs).set_index("q")
    se = 0.01 / np.sqrt(3)
    phi, phi0 = 0.42 / 1.1, 0.42
    assert abs(s.loc[400.0, "expansion"] - 0.1) < 1e-12
    assert abs(s.loc[400.0, "expansion_se"] - phi0 / phi * np.hypot(se / phi0, se / phi)) < 1e-12
    assert np.isnan(s.loc[0.0, "expansion_se"])


def test_with_uncertainty_prints_the_digits_the_scatter_allows():
    assert tables.with_uncertainty(0.42594, 0.00151) == "0.4259 +- 0.0015"
    assert tables.with_uncertainty(0.39012, 0.0100) == "0.390 +- 0.010"
    assert tables.with_uncertainty(3.9402, 0.055) == "3.940 +- 0.055"
    assert tables.with_uncertainty(0.0061, 0.019, sig=1) == "0.01 +- 0.02"
    assert tables.with_uncertainty(0.40884, float("nan")) == "0.409"


def _params(N=2000, q=0.0, seed=1, extra=None, **material):
    return {"params": {"rp": 2e-6, "U0": 1.0, "gamma": 0.01, "q": q, "N": N, "seed": seed,
                       "farfield": "exact", "theta_crit": 0.01, "extra": extra or {}, **material}}


def test_variant_names_what_the_case_and_seed_leave_out():
    assert tables.variant(_params()["params"]) == "N=2000"
    assert tables.variant(_params(q=400.0, seed=3)["params"]) == "N=2000"
    assert tables.variant(_params(theta_crit=0.04)["params"]) == "N=2000 theta_crit=0.04"
    # deck variables as given on the command line (strings) or by a study (numbers) agree
    assert (tables.variant(_params(N=500, extra={"L_rp": "14", "inject": "rain"})["params"])
            == tables.variant(_params(N=500, extra={"inject": "rain", "L_rp": 14})["params"])
            == "N=500 L_rp=14 inject=rain")


def test_one_variant_refuses_to_average_several():
    """A folder with the default paper-size runs and the rolling-limit study's: before, the
    figures' summary averaged theta_crit 0.04 runs into the default cases."""
    import pytest
    from granular_charged.params import ParamError
    same = [_params(seed=s) for s in (1, 2)] + [_params(q=400.0)]
    assert tables.one_variant(same) == same
    mixed = same + [_params(theta_crit=0.04), _params(extra={"inject": "sequential"}, q=400.0)]
    with pytest.raises(ParamError, match="3 variants.*'N=2000' \\(3 runs\\).*--variant"):
        tables.one_variant(mixed)
    assert tables.one_variant(mixed, "N=2000") == same
    assert tables.one_variant(mixed, "N=2000 theta_crit=0.04") == [mixed[3]]
    with pytest.raises(ParamError, match="'N=500' is not among them"):
        tables.one_variant(mixed, "N=500")


def test_packing_images_of_several_series_get_their_own_names():
    """The nine neutral cases of the paper-size study are all q = 0, seed 1: with names by q and
    seed only they wrote one file in turn; one series keeps the short names (the demo's)."""
    from granular_charged.figures.packings import packing_image_names
    one = [_params(q=q, seed=s) for q in (0.0, 400.0) for s in (1, 2)]
    assert packing_image_names(one) == ["packing_q0_s1.png", "packing_q0_s2.png",
                                        "packing_q400_s1.png", "packing_q400_s2.png"]
    two = [_params(), {"params": dict(_params()["params"], rp=1e-6)}]
    names = packing_image_names(two)
    assert names == ["packing_rp2um_U1_g10mJ_q0_s1.png", "packing_rp1um_U1_g10mJ_q0_s1.png"]


def test_tracer_energy_claim_is_a_mean_over_the_seeds_that_followed_one():
    """The E_k/E_k0 line: mean +- sd and a verdict where several seeds followed a tracer, the
    single value (and no verdict) where one did."""
    from granular_charged.analysis import claims
    rows = []
    for q, eks in ((0.0, (1.01, 1.00, 1.02)), (260.0, (0.80, np.nan, np.nan)),
                   (400.0, (0.50, 0.55, 0.45))):
        for seed, ek in enumerate(eks, 1):
            row = {"rp_um": 2.0, "U0": 1.0, "gamma_mJ": 10.0, "q": q, "seed": seed, "Ad": 2.0,
                   "Estar": 0.0, "Adstar": 2.0, "phi": 0.42 - 1e-4 * q + 1e-3 * seed,
                   "Z": 3.9 - 1e-3 * q + 0.01 * seed}
            row.update({c: 0.1 for c in claims.MEASURE_COLUMNS})
            row["Ek_before_contact"] = ek
            rows.append(row)
    line = next(ln for ln in claims.claim_lines(pd.DataFrame(rows)) if "E_k/E_k0" in ln)
    assert "q = 0: 1.010 +- 0.010 (3 tracers)" in line
    assert "q = 260: 0.80 (one tracer)" in line
    assert "q = 400: 0.500 +- 0.050 (3 tracers)" in line
    # 0.51 lower, standard error sqrt(0.01^2 + 0.05^2) / sqrt 3 = 0.029: -17 standard errors
    assert "0 -> 400 e0: lower (-17.3 standard errors)" in line
