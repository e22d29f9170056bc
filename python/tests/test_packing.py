"""packing.py on configurations whose answers are known in closed form."""
import math

import numpy as np
import pytest

from granular_charged import packing


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
