"""The scaling analyses of `reproduce` on synthetic runs with known answers."""
import numpy as np
import pandas as pd

from granular_charged import tables


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
