"""Dimensionless groups and JKR scales against numbers worked out by hand (doc/theory.md)."""
import math

import pytest

from granular_charged import params as P


def test_Ad_Estar_Adstar_units():
    # r_p = 2 um, U0 = 1 m/s, gamma = 10 mJ/m^2, rho = 2500: Ad = 0.01 / (2500 * 1 * 2e-6) = 2
    g0 = P.dimensionless(0.010, 2500.0, 1.0, 2e-6, 0.0)
    assert g0["Ad"] == pytest.approx(2.0, rel=1e-12)
    assert g0["Estar"] == 0.0 and g0["Adstar"] == pytest.approx(2.0, rel=1e-12)
    # q = 400 e_0: E* = 51 (400 e)^2 / (eps0 * 1 * (2e-6)^4 * 2500) = 0.591 (hand: 51 * 4.107e-33
    # / 3.542e-31); Ad* = Ad / (1 - E*)
    g = P.dimensionless(0.010, 2500.0, 1.0, 2e-6, 400.0)
    q = 400 * 1.602176634e-19
    assert g["Estar"] == pytest.approx(51 * q * q / (8.8541878128e-12 * 16e-24 * 2500), rel=1e-12)
    assert g["Estar"] == pytest.approx(0.5914, abs=5e-4)
    assert g["Adstar"] == pytest.approx(2.0 / (1 - g["Estar"]), rel=1e-12)
    # doc/theory.md, eq. (2.2): E* = 1 near q = 520 e_0 (r_p = 2 um) and 130 e_0 (r_p = 1 um)
    assert P.dimensionless(0.01, 2500, 1, 2e-6, 520)["Estar"] == pytest.approx(1.0, abs=0.01)
    assert P.dimensionless(0.01, 2500, 1, 1e-6, 130)["Estar"] == pytest.approx(1.0, abs=0.01)
    assert math.isinf(P.dimensionless(0.01, 2500, 1, 2e-6, 600)["Adstar"])


def test_contact_time_and_step():
    # doc/theory.md, eq. (1.10): t_c ~ 6e-8 s for r_p = 1 um at 1 m/s; t_c ~ r_p (m ~ r^3: (r^6/r)^(1/5) = r)
    t1 = P.contact_time(1e-6, 2500, 2e8, 0.33, 1.0)
    assert t1 == pytest.approx(6.1e-8, rel=0.02)
    assert P.contact_time(2e-6, 2500, 2e8, 0.33, 1.0) == pytest.approx(2 * t1, rel=1e-12)
    assert P.time_step(1e-6, 2500, 2e8, 0.33, 1.0, 20) == pytest.approx(t1 / 20)


def test_jkr_check_points():
    # doc/theory.md, eq. (1.4) check points: zero load, pull-off, separation
    R, Es, gam = 1e-6, P.pair_modulus(2e8, 0.33), 0.01
    s = P.jkr_scales(R, Es, gam)
    F = P.jkr_force_of_overlap([1.21141 * s["deltaC"], -0.48075 * s["deltaC"],
                                -(1 - 1e-12) * s["deltaC"]], R, Es, gam) / s["FC"]
    assert F[0] == pytest.approx(0.0, abs=2e-5)
    assert F[1] == pytest.approx(-1.0, abs=1e-5)
    assert F[2] == pytest.approx(-5.0 / 9.0, abs=1e-3)
    assert s["FC"] == pytest.approx(3 * math.pi * gam * R)
