"""The per-run measures of the paper's claims (granular_charged.measures) on inputs with known
answers."""
import math

import numpy as np
import pytest

from granular_charged import measures, packing


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
