"""The per-run measures of the paper's claims (granular_charged.analysis.measures) on inputs with known
answers."""
import math

import numpy as np
import pytest

from granular_charged.analysis import measures, packing


def test_rdf_peak_area_of_a_gaussian_on_a_sloping_background():
    # a Gaussian of area 0.05 and sd 0.015 at sqrt 3 on the background 1.2 - 0.1 x: the
    # straight line through the window's edges is the background to within the Gaussian's
    # tails at 4 sd (6e-5 of its height), so the area is recovered to ~1e-3 of itself
    x = np.arange(0.505, 3.0, measures.RDF_BIN)
    area, sd = 0.05, 0.015
    g = 1.2 - 0.1 * x + area / (sd * math.sqrt(2 * math.pi)) * np.exp(
        -0.5 * ((x - math.sqrt(3)) / sd) ** 2)
    a = measures.rdf_peak_areas(x, g)
    assert a["rdf_sqrt3"] == pytest.approx(area, rel=5e-3)
    # the other windows see only the straight background: no area
    assert abs(a["rdf_sqrt2"]) < 1e-6 and abs(a["rdf_sqrt5"]) < 1e-6


def test_fz_populations():
    f = [0.0, 0.1, 0.2, 0.3, 0.2, 0.1, 0.05, 0.05]
    p = measures.fz_populations(f)
    assert p["fZ_1_2"] == pytest.approx(0.3) and p["fZ_4_6"] == pytest.approx(0.35)
    assert math.isnan(measures.fz_populations([])["fZ_1_2"])


def test_force_stats():
    fn = np.array([-0.2, -0.05, 0.0, 0.05, 0.15])
    s = measures.force_stats(fn)
    assert s["Fn_mean"] == pytest.approx(-0.01)
    assert s["Fn_inside"] == pytest.approx(3 / 5)     # |F| < 0.1: -0.05, 0, 0.05
    assert s["Fn_tensile"] == pytest.approx(2 / 5)
    assert s["Fn_sd"] == pytest.approx(np.std(fn, ddof=1))


def test_conventions_on_a_square_layer():
    # one layer of touching spheres of radius 1 on the floor, a 4 x 4 square lattice in a
    # box of 8 x 8: phi of the whole bed is 16 (4/3 pi) / (64 x 2) with every H_p (all tops at
    # 2, 2<z> = 2), <Z> = 4 (square lattice, periodic), 5 with the floor
    xs = np.arange(4) * 2.0 + 1.0
    x, y = np.meshgrid(xs, xs)
    n = x.size
    snap = packing.Snapshot(0, np.array([[0, 8], [0, 8], [0, 10]], float),
                            {"id": np.arange(1, n + 1), "x": x.ravel(), "y": y.ravel(),
                             "z": np.ones(n), "radius": np.ones(n)})
    c = measures.conventions(snap, 1.0)
    want = 16 * 4 / 3 * math.pi / 128
    for k in ("phi_bed_top", "phi_bed_2z", "phi_bed_surface"):
        assert c[k] == pytest.approx(want), k
    assert c["Z_all"] == pytest.approx(4.0) and c["Z_all_floor"] == pytest.approx(5.0)


def test_contact_orientation_of_columns_and_layers():
    # a square layer of touching spheres (every contact across z: |cos| = 0, S = -1/2), then
    # the same with a second layer stacked on top (16 vertical contacts added to the 32
    # periodic in-plane ones of each layer: S = (16 x 1 + 64 x -1/2) / 80 = -0.2); the midpoint
    # window keeps only the vertical contacts between the layers (S = 1)
    xs = np.arange(4) * 2.0 + 1.0
    x, y = np.meshgrid(xs, xs)
    n = x.size
    box = np.array([[0, 8], [0, 8], [0, 10]], float)
    one = packing.Snapshot(0, box, {"id": np.arange(1, n + 1), "x": x.ravel(), "y": y.ravel(),
                                    "z": np.ones(n), "radius": np.ones(n)})
    o = measures.contact_orientation(one)
    assert o["contacts"] == 32 and o["S"] == pytest.approx(-0.5) and o["mean_abs_cos"] == pytest.approx(0.0)
    two = packing.Snapshot(0, box, {"id": np.arange(1, 2 * n + 1), "x": np.tile(x.ravel(), 2),
                                    "y": np.tile(y.ravel(), 2),
                                    "z": np.concatenate([np.ones(n), 3 * np.ones(n)]),
                                    "radius": np.ones(2 * n)})
    o = measures.contact_orientation(two)
    assert o["contacts"] == 80 and o["S"] == pytest.approx(-0.2)
    v = measures.contact_orientation(two, zlo=1.5, zhi=2.5)
    assert v["contacts"] == 16 and v["S"] == pytest.approx(1.0)
    assert v["abs_cos_hist"][-1] == pytest.approx(measures.ORIENTATION_BINS)


def test_contact_orientation_is_zero_for_isotropic_contacts():
    # 4000 random directions, each a (slightly overlapping) pair far from the others: S = 0 and mean |cos| =
    # 1/2 within their sampling error (sd of S 0.45 / sqrt(4000) = 0.007: 5 sd)
    rng = np.random.default_rng(3)
    v = rng.normal(size=(4000, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    centres = np.column_stack([(np.arange(4000) % 40) * 10.0 + 5, (np.arange(4000) // 40 % 10) * 10.0 + 5,
                               (np.arange(4000) // 400) * 10.0 + 5])
    xyz = np.concatenate([centres, centres + 1.999 * v])
    box = np.array([[0, 400], [0, 100], [0, 200]], float)
    snap = packing.Snapshot(0, box, {"id": np.arange(1, 8001), "x": xyz[:, 0], "y": xyz[:, 1],
                                     "z": xyz[:, 2], "radius": np.ones(8000)})
    o = measures.contact_orientation(snap)
    assert o["contacts"] == 4000
    assert abs(o["S"]) < 0.035 and o["mean_abs_cos"] == pytest.approx(0.5, abs=0.025)
