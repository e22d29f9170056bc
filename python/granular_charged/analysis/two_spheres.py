"""Two equal dielectric spheres in a uniform field: the multipole series against the point-dipole
model of `fix coul/fmm polarize` (doc/polarization.md, section 3.1).

The point-dipole model keeps only the dipole of each sphere. The full problem (Laplace's equation
inside and outside two spheres of radius a, relative permittivity kappa = eps_p / eps_m, centres
a distance d apart, a uniform field E_0 along the line of centres, m = 0, or across it, m = 1)
is solved here by the classical multipole re-expansion: outside sphere j the potential is the
applied one plus sum_n A_jn r_j^-(n+1) P_n^m(cos theta_j) cos(m phi); the other sphere's terms
are re-expanded about sphere j's centre (`translation`), and each multipole order n obeys the
boundary condition of a dielectric sphere (`reflection`). Truncated at order n_max the linear
system is solved directly; n_max = 1 is exactly the point-dipole pair, and n_max is raised until
the force stops changing.

Units: Gaussian-like bare units (the Coulomb constant 1, as in the solver), a = 1 and E_0 = 1
unless given; the dipole of an isolated sphere is beta a^3 E_0 (beta the Clausius-Mossotti
factor). The force follows from the energy at fixed applied field, U = -1/2 E_0 . (p_1 + p_2)
(linear dielectrics in the field of fixed external sources; Landau & Lifshitz, Electrodynamics of
Continuous Media, section 16), by a central (or, at contact, one-sided) finite difference in d.

`python3 -m granular_charged.analysis.two_spheres` prints the table of doc/polarization.md, section 3.1.
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy.special import gammaln


def clausius_mossotti(kappa: float) -> float:
    """beta = (kappa - 1) / (kappa + 2) (doc/polarization.md, eq. (3.1), eps_m = 1)."""
    return (kappa - 1.0) / (kappa + 2.0)


def translation(n_max: int, m: int, d: float, a: float = 1.0) -> np.ndarray:
    """T[k, n]: the coefficient of (r/a)^k P_k^m about centre O of the term
    a^(n+1) r'^-(n+1) P_n^m(cos theta') of a centre O' = O + d e_z (orders m..n_max, scaled by a
    so that every entry is bounded):
        r'^-(n+1) P_n^m = sum_k (-1)^(n+m) (n+k)! / ((n-m)! (k+m)!) r^k P_k^m / d^(n+k+1)
    (P_n^m with scipy's Condon-Shortley phase; checked pointwise by the tests)."""
    orders = np.arange(m, n_max + 1)
    n = orders[None, :]
    k = orders[:, None]
    log_c = gammaln(n + k + 1) - gammaln(n - m + 1) - gammaln(k + m + 1)
    return (-1.0) ** (n + m) * np.exp(log_c + (n + k + 1) * np.log(a / d))


def reflection(n_max: int, m: int, kappa: float) -> np.ndarray:
    """R_n: a dielectric sphere answers the regular term L_n (r/a)^n P_n^m of the field about
    its centre with the outer term R_n L_n (a/r)^(n+1) P_n^m, R_n = -(kappa - 1) n /
    (kappa n + n + 1) (continuity of the potential and of kappa d phi / dr at r = a)."""
    n = np.arange(m, n_max + 1)
    return -(kappa - 1.0) * n / (kappa * n + n + 1.0)


def solve(d: float, kappa: float, m: int, n_max: int, a: float = 1.0, e0: float = 1.0) -> float:
    """The dipole of each sphere along the field (the two are equal by symmetry) for spheres at
    0 and d e_z in the field E_0 along z (m = 0) or x (m = 1)."""
    if d < 2.0 * a:
        raise ValueError(f"the spheres overlap: d = {d} < 2 a = {2 * a}")
    size = n_max + 1 - m
    r = reflection(n_max, m, kappa)
    t_up = translation(n_max, m, d, a)                     # sphere 2 (at +d) seen from sphere 1
    parity = (-1.0) ** (np.arange(m, n_max + 1))
    # sphere 1 seen from sphere 2 (at -d): the mirror image z -> -z multiplies the orders by
    # (-1)^n (-1)^k
    t_down = parity[:, None] * t_up * parity[None, :]
    # applied field as regular terms: -E0 z = -E0 r P_1 (m = 0); -E0 x = E0 r P_1^1 cos phi (m = 1)
    applied = np.zeros(size)
    applied[1 - m] = (-e0 if m == 0 else e0) * a
    # unknowns: the scaled outer coefficients b_j = A_jn / a^(n+1) of both spheres
    # b_1 = R (applied + T_up b_2), b_2 = R (applied + T_down b_1)
    eye = np.eye(size)
    system = np.block([[eye, -r[:, None] * t_up], [-r[:, None] * t_down, eye]])
    rhs = np.concatenate([r * applied, r * applied])
    b = np.linalg.solve(system, rhs)
    dipole = b[1 - m] * a * a                               # A_1 = b_1 a^2
    # z-dipole: A_1 cos(theta) / r^2 = p / r^2 cos(theta); x-dipole: A_1 P_1^1 = -A_1 sin(theta)
    return dipole if m == 0 else -dipole


def energy(d, kappa, m, n_max, a=1.0, e0=1.0) -> float:
    """U = -1/2 E_0 . (p_1 + p_2) = -E_0 p at fixed applied field."""
    return -e0 * solve(d, kappa, m, n_max, a, e0)


def force(d, kappa, m, n_max, a=1.0, e0=1.0, h=1e-5) -> float:
    """The force on the sphere at +d along e_z (negative: attraction), -dU/dd; a second-order
    one-sided difference at contact, where d - h would overlap."""
    hh = h * a
    if d - hh >= 2.0 * a:
        return -(energy(d + hh, kappa, m, n_max, a, e0) - energy(d - hh, kappa, m, n_max, a, e0)) / (2 * hh)
    u0, u1, u2 = (energy(d + i * hh, kappa, m, n_max, a, e0) for i in range(3))
    return -(-3.0 * u0 + 4.0 * u1 - u2) / (2 * hh)


def point_dipole(d, kappa, m, a=1.0, e0=1.0) -> tuple[float, float]:
    """The point-dipole pair (doc/polarization.md, section 3): (dipole, force on the sphere at
    +d); along the axis p = alpha E / (1 - 2 alpha / d^3), force -6 p^2 / d^4; across it
    p = alpha E / (1 + alpha / d^3), force +3 p^2 / d^4."""
    alpha = clausius_mossotti(kappa) * a ** 3
    if m == 0:
        p = alpha * e0 / (1.0 - 2.0 * alpha / d ** 3)
        return p, -6.0 * p * p / d ** 4
    p = alpha * e0 / (1.0 + alpha / d ** 3)
    return p, 3.0 * p * p / d ** 4


def converged(d, kappa, m, a=1.0, e0=1.0, rtol=1e-4, n_start=8, n_limit=4096):
    """(dipole, force, n_max) with n_max doubled until the force changes by less than rtol."""
    n, last = n_start, None
    while n <= n_limit:
        f = force(d, kappa, m, n, a, e0)
        if last is not None and abs(f - last) <= rtol * abs(f):
            return solve(d, kappa, m, n, a, e0), f, n
        last, n = f, 2 * n
    raise RuntimeError(f"multipole series not converged to {rtol} at n_max = {n_limit} "
                       f"(d/a = {d / a}, kappa = {kappa})")


def table(kappas=(2.0, 3.8, 10.0), gaps=(2.0, 2.05, 2.2, 2.5, 3.0, 4.0), rtol=1e-4):
    rows = []
    for kappa in kappas:
        for m in (0, 1):
            for d in gaps:
                p, f, n = converged(d, kappa, m, rtol=rtol)
                pp, fp = point_dipole(d, kappa, m)
                rows.append(dict(kappa=kappa, field="along" if m == 0 else "across", d_over_a=d,
                                 dipole_ratio=p / pp, force_ratio=f / fp, n_max=n))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kappa", type=float, nargs="+", default=[2.0, 3.8, 10.0],
                    help="eps_p / eps_m (default 2 3.8 10)")
    ap.add_argument("--d", type=float, nargs="+", default=[2.0, 2.05, 2.2, 2.5, 3.0, 4.0],
                    help="centre distances in radii (default 2 2.05 2.2 2.5 3 4)")
    ap.add_argument("--rtol", type=float, default=1e-4, help="convergence of the force in n_max")
    a = ap.parse_args(argv)
    print("eps_p/eps_m  field   d/a    p / p_point-dipole  F / F_point-dipole  n_max")
    for r in table(a.kappa, a.d, a.rtol):
        print(f"{r['kappa']:11.1f}  {r['field']:6s}  {r['d_over_a']:4.2f}  {r['dipole_ratio']:18.4f}  "
              f"{r['force_ratio']:18.4f}  {r['n_max']:5d}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
