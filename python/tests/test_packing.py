"""packing.py on configurations whose answers are known in closed form."""
import math

import numpy as np
import pytest

from granular_charged.analysis import packing


def snap_from(x, y, z, r, L, H):
    n = len(x)
    cols = {"id": np.arange(1, n + 1), "x": np.asarray(x, float), "y": np.asarray(y, float),
            "z": np.asarray(z, float), "radius": np.full(n, r)}
    return packing.Snapshot(0, np.array([[0, L], [0, L], [0, H]], float), cols)


def test_sphere_slab_volume():
    r = 1.0
    full = 4 / 3 * math.pi
    assert packing.sphere_slab_volume(0.0, r, -5, 5) == pytest.approx(full)
    assert packing.sphere_slab_volume(0.0, r, 0, 5) == pytest.approx(full / 2)
    # cap of height h = 0.5: pi h^2 (3 r - h) / 3
    assert packing.sphere_slab_volume(0.0, r, 0.5, 5) == pytest.approx(math.pi * 0.25 * 2.5 / 3)
    assert packing.sphere_slab_volume(0.0, r, 2, 5) == 0.0


def simple_cubic(n, a, r):
    g = (np.arange(n) + 0.5) * a
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    return snap_from(X.ravel(), Y.ravel(), Z.ravel(), r, n * a, n * a)


def test_phi_and_Z_simple_cubic():
    # touching spheres (tiny overlap) on a simple cubic lattice: phi = pi/6, Z = 6 inside,
    # x, y periodic (so only the top and bottom layers lose a contact)
    a, r = 2.0, 1.0 + 1e-9
    s = simple_cubic(6, a, r)
    assert packing.phi_slab(s, 2 * a, 4 * a) == pytest.approx(math.pi / 6 * r ** 3, rel=1e-9)
    Z = packing.coordination(s)
    z = s["z"]
    assert np.all(Z[(z > a) & (z < 5 * a)] == 6)
    assert np.all(Z[(z < a) | (z > 5 * a)] == 5)
    # without overlap no geometric contact, with tolerance yes
    s2 = simple_cubic(4, a, 0.999)
    assert packing.coordination(s2).sum() == 0
    assert np.all(packing.coordination(s2, tol=0.01)[(s2["z"] > a) & (s2["z"] < 3 * a)] == 6)


def test_rdf_ideal_gas_is_one():
    rng = np.random.default_rng(1)
    n, L, H = 20000, 10.0, 10.0
    s = snap_from(rng.uniform(0, L, n), rng.uniform(0, L, n), rng.uniform(0, H, n), 0.01, L, H)
    rc, g = packing.rdf_slab(s, 2.0, 8.0, 2.0, nbins=20)
    assert np.all(np.abs(g[5:] - 1.0) < 0.05)   # 5 % ~ 3 sigma of the counts per bin here


def bcc(n, a, r):
    g = (np.arange(n) + 0.25) * a
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    pts = np.concatenate([np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]),
                          np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]) + a / 2])
    return snap_from(pts[:, 0], pts[:, 1], pts[:, 2], r, n * a, n * a)


def test_fz_keeps_Z_above_zmax_in_last_bin():
    # BCC of touching spheres (r = a sqrt(3)/4) with a tolerance that also reaches the 6 second
    # neighbours at distance a (third ones at a sqrt(2) stay out): Z = 14 inside, more than the
    # 12 the old Python f(Z) had bins for. compute coord/dist (doc/compute_coord_dist.rst)
    # counts Z >= zmax in its last row and has zmax = 20 by default; so must Python.
    a = 1.0
    r = a * math.sqrt(3) / 4
    tol = a - 2 * r + 1e-6
    s = bcc(5, a, r)
    zlo, zhi = 1.9 * a, 3.1 * a            # interior layers only (z open at both ends)
    Zall = packing.coordination(s, tol)
    inside = (s["z"] >= zlo) & (s["z"] <= zhi)
    assert np.all(Zall[inside] == 14)
    cs = packing.coordination_stats(s, zlo, zhi, tol)
    assert len(cs["fZ"]) == 21                       # Z = 0 .. 20, as the compute's array
    assert cs["fZ"][14] == 1.0 and sum(cs["fZ"]) == pytest.approx(1.0)
    cs12 = packing.coordination_stats(s, zlo, zhi, tol, zmax=12)
    assert len(cs12["fZ"]) == 13
    assert cs12["fZ"][12] == 1.0                     # Z = 14 >= zmax: in the last bin, not lost
    assert cs12["Z"] == 14.0                         # <Z> from the true Z
    f = packing.fz_histogram([0, 3, 12, 13, 40], zmax=12)
    assert f.tolist() == [0.2, 0, 0, 0.2] + [0] * 8 + [0.6]


def test_contact_is_r_le_ri_plus_rj_and_periodic_in_x_y_only():
    L, H = 10.0, 10.0
    # exactly touching (r_ij = r_i + r_j = 2, exact in binary): a contact, as in coord/dist
    s = snap_from([1.0, 3.0], [5.0, 5.0], [5.0, 5.0], 1.0, L, H)
    assert packing.coordination(s).tolist() == [1, 1]
    # across the periodic x and y boundaries: touching through the box edge
    s = snap_from([0.5, L - 0.5, 5.0, 5.0], [5.0, 5.0, 0.5, L - 0.5], [2.0, 2.0, 6.0, 6.0],
                  0.5, L, H)
    assert packing.coordination(s).tolist() == [1, 1, 1, 1]
    # z is open: particles at the bottom and top of a column never meet through z
    s = snap_from([5.0, 5.0], [5.0, 5.0], [0.5, 9.4], 0.5, L, H)
    assert packing.coordination(s, tol=0.2).tolist() == [0, 0]
    # directly 8.9 apart: a pair for rcut 9, none for rcut 5 (no image through z)
    assert len(packing.pair_distances(s, 9.0)[0]) == 1
    assert len(packing.pair_distances(s, 5.0)[0]) == 0


def test_surface_heights_vectorised_matches_loop():
    rng = np.random.default_rng(3)
    n, L = 500, 10.0
    s = snap_from(rng.uniform(0, L, n), rng.uniform(0, L, n), rng.uniform(0, 8, n), 0.3, L, 12)
    top = packing.surface_heights(s, 1.0)
    ref = np.full((10, 10), np.nan)
    for x, y, t in zip(s["x"], s["y"], s["z"] + 0.3):
        a, b = int(x // 1.0) % 10, int(y // 1.0) % 10
        ref[a, b] = t if np.isnan(ref[a, b]) else max(ref[a, b], t)
    np.testing.assert_array_equal(top, ref)


def test_phi_profile_is_exact_per_bin():
    rng = np.random.default_rng(4)
    n, L = 300, 10.0
    s = snap_from(rng.uniform(0, L, n), rng.uniform(0, L, n), rng.uniform(0.5, 6, n), 0.5, L, 8)
    zc, phi = packing.phi_profile(s, 0.25, 7.0)
    dz = 0.25
    for k in (0, 7, 13, 22):
        assert phi[k] == pytest.approx(packing.phi_slab(s, zc[k] - dz / 2, zc[k] + dz / 2), rel=1e-12)
    # all the sphere volume is in the bins
    assert (phi * L * L * dz).sum() == pytest.approx(n * 4 / 3 * math.pi * 0.125, rel=1e-12)
