"""The EPD study's table (granular_charged.studies.epd) on runs with known contacts, and its run list."""
import json

import numpy as np
import pytest

from granular_charged.figures.epd import epd_figures
from granular_charged.params import DepositionParams
from granular_charged.studies import epd


def _layers(path, nlayers):
    # nlayers square layers (4 x 4, spacing 2, radius 1) stacked along z in a box of 8 x 8
    xs = np.arange(4) * 2.0 + 1.0
    x, y = np.meshgrid(xs, xs)
    rows = []
    for layer in range(nlayers):
        for a, b in zip(x.ravel(), y.ravel()):
            rows.append((len(rows) + 1, a, b, 1.0 + 2.0 * layer))
    text = ["ITEM: TIMESTEP", "0", "ITEM: NUMBER OF ATOMS", str(len(rows)),
            "ITEM: BOX BOUNDS pp pp ff", "0 8", "0 8", "0 20", "ITEM: ATOMS id type x y z radius"]
    text += [f"{i} 1 {a} {b} {z} 1.0" for i, a, b, z in rows]
    path.write_text("\n".join(text) + "\n")


def _result(tmp_path, name, E0, eps, seed, phi, nlayers):
    d = tmp_path / name
    d.mkdir()
    _layers(d / "final.dump", nlayers)
    return {"key": name, "dir": str(d), "phi": phi, "Z": 4.0 + seed, "fZ": [0, 0.5, 0, 0, 0.5],
            "zlo": 0.0, "zhi": 100.0, "cpu_s": 100.0 * seed,
            "params": {"seed": seed, "extra": {"E0": E0, "eps_p": eps, "electrode": "yes"}}}


def test_table_means_and_orientation(tmp_path):
    # two seeds of one case: one layer (S = -1/2) and two layers (S = -0.2, measures' test):
    # the mean -0.35 with the sd of the two; phi and <Z> means and sds over the seeds
    rs = [_result(tmp_path, "a", "1e5", "3.8", 1, 0.30, 1), _result(tmp_path, "b", "1e5", "3.8", 2, 0.34, 2),
          _result(tmp_path, "c", "3e5", "0", 1, 0.25, 2)]
    t = epd.table(rs)
    assert list(t["E0"]) == [1e5, 3e5] and list(t["eps_p"]) == [3.8, 0.0]
    r = t.iloc[0]
    assert r["runs"] == 2
    assert r["phi"] == pytest.approx(0.32) and r["phi_sd"] == pytest.approx(np.std([0.30, 0.34], ddof=1))
    assert r["Z"] == pytest.approx(5.5)
    assert r["S"] == pytest.approx(-0.35) and r["S_sd"] == pytest.approx(np.std([-0.5, -0.2], ddof=1))
    assert r["fZ_1_2"] == pytest.approx(0.5) and r["fZ_4_6"] == pytest.approx(0.5)
    assert t.iloc[1]["S"] == pytest.approx(-0.2)
    assert r["cpu_s"] == pytest.approx(150.0)
    # printed with the digits the two seeds allow (two significant digits of the sd), one seed without sd
    text = epd.format_table(t)
    assert "0.320 +- 0.028" in text and "5.50 +- 0.71" in text and " 150" in text
    assert text.splitlines()[2].split()[3] == "0.25"


def test_study_runs_every_case_and_seed():
    ps = epd.study_params((1, 2, 3))
    assert len(ps) == len(epd.FIELDS) * len(epd.PERMITTIVITIES) * 3
    assert len({p.key() for p in ps}) == len(ps)
    assert all(p.extra["electrode"] == "yes" and p.N == 500 and p.q == 400 for p in ps)
    # the same folders as `granular-charged run --var L_rp 14 --var E0 1e5 --var eps_p 3.8 ...`
    run = DepositionParams(q=400, N=500, seed=1, extra={"L_rp": "14", "E0": "1e5",
                                                        "eps_p": "3.8", "electrode": "yes"})
    assert run.key() in {p.key() for p in ps}
    # the long key of the kept runs in doc/data
    assert any(p.legacy_key().endswith("_E01e5_L_rp14_electrodeyes_eps_p3.8") for p in ps)


def test_figures_draw_every_case_and_the_orientation(tmp_path):
    # two cases, one with two seeds: one packing panel per case (the side view from the dump:
    # no render here), and the |cos theta| densities averaged over the seeds: one layer has
    # only horizontal contacts (|cos| < 0.1), two layers a fifth vertical ones (|cos| > 0.9)
    rs = [_result(tmp_path, "a", "1e5", "3.8", 1, 0.30, 1), _result(tmp_path, "b", "1e5", "3.8", 2, 0.34, 2),
          _result(tmp_path, "c", "3e5", "0", 1, 0.25, 2)]
    for r in rs:
        r["params"]["q"] = 400.0
        r["natoms"] = 16
    paths = epd_figures(rs, tmp_path / "figures")
    assert [p.name for p in paths] == ["packings.png", "orientation.png"]
    assert all(p.stat().st_size > 10000 for p in paths)
    import pandas as pd
    panels = pd.read_csv(tmp_path / "figures" / "packings.csv")
    assert list(zip(panels["E0"], panels["eps_p"], panels["seed"])) == [(1e5, 3.8, 1), (3e5, 0.0, 1)]
    g = pd.read_csv(tmp_path / "figures" / "orientation.csv")
    one = g[(g["E0"] == 1e5)].sort_values("abs_cos")
    assert one["seeds"].iloc[0] == 2
    # one layer (periodic 4 x 4): 32 of 32 contacts horizontal -> density 10 in the first of 10
    # bins; two layers: 64 of 80 -> 8, and 16 vertical -> 2 in the last: means 9 and 1
    assert one["density"].iloc[0] == pytest.approx((10.0 + 10.0 * 64 / 80) / 2)
    assert one["density"].iloc[-1] == pytest.approx((0.0 + 10.0 * 16 / 80) / 2)
