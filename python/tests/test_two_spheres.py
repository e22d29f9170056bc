"""The two-sphere multipole reference (granular_charged.analysis.two_spheres) against closed forms: the
re-expansion pointwise, the point-dipole pair at n_max = 1, and Kelvin's image series for
touching conducting spheres."""
import numpy as np
import pytest
from scipy.special import lpmv, zeta

from granular_charged.analysis import two_spheres as ts


@pytest.mark.parametrize("m", [0, 1])
def test_translation_reproduces_the_shifted_multipole(m):
    # r'^-(n+1) P_n^m(cos theta') about a centre at +d e_z, summed as regular terms about the
    # origin to order 60 at |r| < 0.7 < d - 0.7 (ratio < 0.45: the truncation is ~1e-20)
    rng = np.random.default_rng(3)
    d, n_max = 2.3, 60
    t = ts.translation(n_max, m, d)
    ks = np.arange(m, n_max + 1)
    for x, y, z in rng.uniform(-0.4, 0.4, (5, 3)):
        r = np.sqrt(x * x + y * y + z * z)
        rp = np.sqrt(x * x + y * y + (z - d) ** 2)
        for n in range(m, 6):
            exact = rp ** -(n + 1) * lpmv(m, n, (z - d) / rp)
            series = np.sum(t[:, n - m] * r ** ks * lpmv(m, ks, z / r))
            assert series == pytest.approx(exact, rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("m", [0, 1])
@pytest.mark.parametrize("d", [2.0, 2.5, 6.0])
def test_dipoles_alone_are_the_point_dipole_pair(m, d):
    # n_max = 1 keeps only the mutual induction of two point dipoles: the closed forms of
    # doc/polarization.md, section 3, to round-off (the force to the finite difference's
    # ~1e-9 relative error)
    p_exact, f_exact = ts.point_dipole(d, 3.8, m)
    assert ts.solve(d, 3.8, m, 1) == pytest.approx(p_exact, rel=1e-13)
    assert ts.force(d, 3.8, m, 1) == pytest.approx(f_exact, rel=1e-7)


def test_far_apart_spheres_are_isolated():
    # at d = 40 a the mutual field is ~beta / 40^3 ~ 1e-5 of the applied one
    beta = ts.clausius_mossotti(3.8)
    for m in (0, 1):
        assert ts.solve(40.0, 3.8, m, 16) == pytest.approx(beta, rel=3e-5)


def test_touching_conductors_across_the_field_follow_kelvins_images():
    # two touching perfectly conducting spheres (kappa -> infinity), field across the line of
    # centres: Kelvin's image dipoles converge on the contact point with strengths
    # (-1)^(k+1) a^3 E / k^3, so each sphere carries (3/4) zeta(3) a^3 E (the series of images;
    # the multipole series converges geometrically here). kappa = 1e9 differs from the
    # conductor by ~1e-9. Without the mirror parity of the re-expansion from the far sphere
    # this fails. (A re-expansion off by diag(k(k+1)) / diag(n(n+1)) is only a rescaling of the
    # higher multipoles and gives the same dipoles: the pointwise test above catches that.)
    p = ts.solve(2.0, 1e9, 1, 256)
    assert p == pytest.approx(0.75 * zeta(3), rel=1e-7)


def test_touching_spheres_attract_more_than_point_dipoles_along_the_field():
    # the converged series at contact: along the field more attraction, across it less
    # repulsion than the point-dipole pair, and the difference grows with kappa (the values
    # themselves are doc/polarization.md's table; here only their order)
    ratios = []
    for kappa in (2.0, 3.8, 10.0):
        _, f_along, _ = ts.converged(2.0, kappa, 0)
        _, f_across, _ = ts.converged(2.0, kappa, 1)
        r_along = f_along / ts.point_dipole(2.0, kappa, 0)[1]
        r_across = f_across / ts.point_dipole(2.0, kappa, 1)[1]
        assert r_along > 1.0 and 0.0 < r_across < 1.0
        ratios.append((r_along, r_across))
    assert ratios[0][0] < ratios[1][0] < ratios[2][0]
    assert ratios[0][1] > ratios[1][1] > ratios[2][1]


def test_overlap_is_refused():
    with pytest.raises(ValueError, match="overlap"):
        ts.solve(1.9, 3.8, 0, 8)
