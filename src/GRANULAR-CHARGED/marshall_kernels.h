/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The equations of the Marshall (2009) contact model as stateless inline functions: the one
// home of each formula, called by the sub-model classes (gran_sub_mod_*_marshall*.cpp, which
// are the plumbing between LAMMPS's GranularModel and these functions), by fix wall/gran/opt
// and by the fused kernel of pair_style granular/opt (marshall_lanes.h), which evaluates them
// for one contact (double) or for several in SIMD lanes (the per-contact functions are
// templates on the number type, below). Same shape as the gran_sub_mod_*_kernel.h headers of
// LAMMPS's development branch. Depends only on the header-only MathConst and MathExtra and on
// jkr_scaled.h.
// Equation numbers: doc/theory.md.

#ifndef LMP_GC_MARSHALL_KERNELS_H
#define LMP_GC_MARSHALL_KERNELS_H

#include "jkr_scaled.h"
#include "math_const.h"
#include "math_extra.h"

#include <cmath>

// the templates below are inlined into each SIMD path's function of marshall_lanes.cpp (a
// call would leave its instruction set and pass vectors through memory)
#if defined(__GNUC__)
#define GC_KERNEL_INLINE inline __attribute__((always_inline))
#define GC_KERNEL_LAMBDA __attribute__((always_inline))
#else
#define GC_KERNEL_INLINE inline
#define GC_KERNEL_LAMBDA
#endif

namespace LAMMPS_NS {
namespace MarshallKernels {

  // delta_C = a_0^2 / (2 6^(1/3) R) with a_0^3 = 9 pi gamma R^2 / E
  //         = DELTAC_PREFIX * (R gamma^2 / E^2)^(1/3)
  static constexpr double DELTAC_PREFIX = 2.5537664411075656;    // (9 pi)^(2/3) / (2 6^(1/3))
  static constexpr double THREEPI_16 = 0.5890486225480862;    // 3 pi / 16
  // frame-rotation threshold of the tangential history, LAMMPS's EPSILON in
  // gran_sub_mod_tangential.cpp (rotating a history already in the plane changes nothing)
  static constexpr double FRAME_EPSILON = 1e-10;

  /* ---------------------------------------------------------------------
     JKR scales of one effective radius R (doc/theory.md, eqs. (1.2), (1.4a))
  --------------------------------------------------------------------- */

  // critical overlap delta_C: the contact breaks at delta = -delta_C (0 without adhesion)
  inline double critical_overlap(double reff, double gamma, double emix)
  {
    if (gamma == 0.0 || reff <= 0.0) return 0.0;
    return DELTAC_PREFIX * cbrt(reff * gamma * gamma / (emix * emix));
  }

  struct JKRScales {
    double deltac = 0.0;         // delta_C
    double inv_deltac = 0.0;     // 1 / delta_C (0 without adhesion)
    double asep = 0.0;           // contact radius at separation, a_0 / 6^(2/3)
    double fc = 0.0;             // F_C = 3 pi gamma R
    double sqrt_kn_sep = 0.0;    // sqrt(4/3 E* a_sep): sqrt(k_N) = s sqrt_kn_sep, as a = a_sep s^2
  };

  // delta_C, a_sep = (pi gamma R^2 / (4 E*))^(1/3) and F_C for radius R (two cube roots: a
  // caller with one R for many contacts computes them once, outside its loop)
  inline JKRScales jkr_scales(double reff, double gamma, double emix)
  {
    JKRScales sc;
    sc.deltac = critical_overlap(reff, gamma, emix);
    sc.inv_deltac = (sc.deltac > 0.0) ? 1.0 / sc.deltac : 0.0;
    sc.asep = cbrt(MathConst::MY_PI * gamma * reff * reff / (4.0 * emix));
    sc.fc = 3.0 * MathConst::MY_PI * gamma * reff;
    sc.sqrt_kn_sep = sqrt(4.0 / 3.0 * emix * sc.asep);
    return sc;
  }

  // R_eff = R_i R_j / (R_i + R_j)
  inline double effective_radius(double radi, double radj)
  {
    return radi * radj / (radi + radj);
  }

  // contact life (Marshall 2009): forms at delta >= 0, persists in tension to delta = -delta_C
  inline bool jkr_touch(bool was_touching, double rsq, double radsum, double deltac)
  {
    const double dist_break = was_touching ? radsum + deltac : radsum;
    return rsq < dist_break * dist_break;
  }

  /* ---------------------------------------------------------------------
     the number types of the equations below: double (one contact) and the lanes of
     marshall_lanes.h (several contacts at once, a GCC vector type). The per-contact functions
     are templates on the number type T and use only + - * / and NumberOps<T>: select() for
     each decision of a contact (both sides are computed, one is kept), sqrt() and abs(). The
     IEEE operations are exact in every lane, so the same operation order gives the same bits
     as the double instantiation, which is the scalar code.
  --------------------------------------------------------------------- */

  template <class T> struct NumberOps;

  template <> struct NumberOps<double> {
    using Mask = bool;
    static GC_KERNEL_INLINE double select(bool c, double a, double b) { return c ? a : b; }
    // a value used only where c holds (under select(c, ...)): one contact computes it only
    // then, lanes compute it in every lane
    template <class F> static GC_KERNEL_INLINE double only_where(bool c, F value)
    {
      return c ? value() : 0.0;
    }
    static GC_KERNEL_INLINE double sqrt(double x) { return std::sqrt(x); }
    static GC_KERNEL_INLINE double abs(double x) { return std::fabs(x); }
  };

  // small vector helpers in MathExtra's operation order (math_extra.h), for every T
  template <class T> GC_KERNEL_INLINE T dot3(const T *a, const T *b)
  {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  }
  template <class T> GC_KERNEL_INLINE T lensq3(const T *v)
  {
    return v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  }
  template <class T> GC_KERNEL_INLINE void cross3(const T *a, const T *b, T *ans)
  {
    ans[0] = a[1] * b[2] - a[2] * b[1];
    ans[1] = a[2] * b[0] - a[0] * b[2];
    ans[2] = a[0] * b[1] - a[1] * b[0];
  }
  /* ---------------------------------------------------------------------
     normal force
  --------------------------------------------------------------------- */

  template <class T> struct NormalForceT {
    T a;           // contact radius
    T fne;         // elastic-adhesive normal force F_ne (positive: repulsive)
    T adhesive;    // adhesive part 4 F_C (a/a_0)^(3/2), for rolling marshall
    T pulloff;     // F_C (0 without adhesion)
    T sqrt_kn;     // sqrt(k_N), k_N = 4/3 E* a: the normal stiffness the damping scales with
  };
  using NormalForce = NormalForceT<double>;

  // Delta = delta / delta_C: the overlap of the scaled law (jkr_scaled.h) whose root s gives a
  inline double scaled_overlap(const JKRScales &sc, double delta)
  {
    return delta * sc.inv_deltac;
  }

  // JKR contact radius on the stable branch, a = a_sep s^2 with s^4 - 4 s = 3 delta / delta_C
  // (eq. (1.4a); jkr_scaled.h), and F_ne = 4 F_C ((a/a_0)^3 - (a/a_0)^(3/2))
  // = F_C (s^6 / 9 - 2 s^3 / 3)  (Marshall 2009, eq. 8), from the root s and the scales
  // a_sep, F_C, sqrt(4/3 E* a_sep) of JKRScales
  template <class T>
  GC_KERNEL_INLINE NormalForceT<T> jkr_normal_force_of_root(T asep, T fc, T sqrt_kn_sep,
                                                            T s)
  {
    NormalForceT<T> n;
    n.a = asep * s * s;
    n.adhesive = JKRScaled::adhesive_over_fc(s) * fc;
    n.fne = JKRScaled::force_over_fc(s) * fc;
    n.pulloff = fc;
    n.sqrt_kn = s * sqrt_kn_sep;
    return n;
  }

  inline NormalForce jkr_normal_force_of_root(const JKRScales &sc, double s)
  {
    return jkr_normal_force_of_root(sc.asep, sc.fc, sc.sqrt_kn_sep, s);
  }

  // without adhesion Hertz's law: a = sqrt(delta R), F_ne = 4 E* a^3 / (3 R)
  inline NormalForce hertz_normal_force(double emix, double delta, double reff)
  {
    NormalForce n;
    const double dR = delta * reff;
    n.a = sqrt(dR > 0.0 ? dR : 0.0);
    n.fne = 4.0 / 3.0 * emix * n.a * n.a * n.a / reff;
    n.adhesive = 0.0;
    n.pulloff = 0.0;
    n.sqrt_kn = sqrt(4.0 / 3.0 * emix * n.a);
    return n;
  }

  // the same from the overlap delta (Hertz's law without adhesion)
  inline NormalForce jkr_normal_force(const JKRScales &sc, double gamma, double emix,
                                      double delta, double reff)
  {
    if (gamma == 0.0) return hertz_normal_force(emix, delta, reff);
    return jkr_normal_force_of_root(sc, JKRScaled::root(scaled_overlap(sc, delta)));
  }

  // F_crit = |F_ne + 2 F_C|: the normal load the friction limits scale with (paper eq. 4;
  // LAMMPS's GranSubModNormalJKR::set_fncrit)
  template <class T> GC_KERNEL_INLINE T critical_force(const NormalForceT<T> &n)
  {
    return NumberOps<T>::abs(n.fne + 2.0 * n.pulloff);
  }

  /* ---------------------------------------------------------------------
     normal damping: F_nd = -eta_N v_n, eta_N = alpha(e) sqrt(mass_factor m* k_N),
     k_N = 4/3 E* a  (doc/theory.md, eqs. (1.5)-(1.6))
  --------------------------------------------------------------------- */

  // alpha(e) = 1.2728 - 4.2783 e + 11.087 e^2 - 22.348 e^3 + 27.467 e^4 - 18.022 e^5
  //            + 4.8218 e^6  (Tsuji et al., Powder Technol. 71, 239 (1992); paper eq. 2).
  // The fit is 1e-4 off zero at e = 1: no damping means none, and never negative damping.
  inline double damping_alpha(double e)
  {
    const double alpha = 1.2728 +
        e * (-4.2783 + e * (11.087 + e * (-22.348 + e * (27.467 + e * (-18.022 + e * 4.8218)))));
    return (e == 1.0 || alpha < 0.0) ? 0.0 : alpha;
  }

  // sqrt(mass_factor m*): the mass part of eta_N, a constant of a pair of particles
  template <class T> GC_KERNEL_INLINE T damping_sqrt_mass(T mass_factor, T meff)
  {
    return NumberOps<T>::sqrt(mass_factor * meff);
  }

  // eta_N = alpha sqrt(mass_factor m*) sqrt(k_N); a >= 0.30285 a_0 > 0 for every live JKR
  // contact, so k_N > 0 also in tension
  template <class T>
  GC_KERNEL_INLINE T damping_prefactor(T alpha, T sqrt_mass, const NormalForceT<T> &n)
  {
    return alpha * sqrt_mass * n.sqrt_kn;
  }

  /* ---------------------------------------------------------------------
     sliding: spring-dashpot-slider on the tangential displacement h (history, 3 values),
     F_t = -k_T h - eta_T v_t, k_T = 8 G* a, |F_t| <= mu F_crit  (Marshall 2009, eq. 24).
     h is first rotated into the current tangent plane keeping its length (Luding, Gran.
     Matter 10, 235 (2008), eq. 17), then advanced by v_t dt; on slip F_t is scaled to the limit
     and h reset to the spring length that gives its elastic part. LAMMPS 4Jul2026's mindlin
     with the history of the displacement and no unloading rescale, up to rounding (squares
     compared instead of lengths, one square root in the rotation).
  --------------------------------------------------------------------- */

  // v -= (v . n) n, then restore |v| (as LAMMPS's GranSubMod::rotate_rescale_vec, with one
  // square root) where `rotate` holds: the history of a contact follows the rotation of its
  // tangent plane
  template <class T, class M>
  GC_KERNEL_INLINE void rotate_into_plane(T *v, const T *n, T vn, M rotate)
  {
    using N = NumberOps<T>;
    const T lensq = lensq3(v);
    T p[3];
    for (int k = 0; k < 3; k++) p[k] = v[k] - vn * n[k];
    const T plensq = lensq3(p);
    const T rescale = N::only_where(rotate, [&]() GC_KERNEL_LAMBDA {
      return N::select(plensq > 0.0, N::sqrt(lensq / plensq), T{});
    });
    for (int k = 0; k < 3; k++) v[k] = N::select(rotate, p[k] * rescale, v[k]);
  }

  template <class T>
  GC_KERNEL_INLINE void tangential_force(T *history, const T *nx, const T *vtr, T dt,
                                         T k_scaled, T damp, T fscrit, bool history_update,
                                         T *fs)
  {
    using N = NumberOps<T>;
    if (history_update) {
      const T rsht = dot3(history, nx);
      rotate_into_plane(history, nx, rsht, (N::abs(rsht) * k_scaled) > (FRAME_EPSILON * fscrit));
      for (int k = 0; k < 3; k++) history[k] = history[k] + dt * vtr[k];
    }
    T fdamp[3];
    for (int k = 0; k < 3; k++) {
      fdamp[k] = -damp * vtr[k];
      fs[k] = -k_scaled * history[k] + fdamp[k];
    }

    // slip: F_t scaled to mu F_crit and h reset to its elastic part (F_t = 0 without a spring)
    const T magfs_sq = lensq3(fs);
    const auto slip = magfs_sq > fscrit * fscrit;
    const auto spring = lensq3(history) != 0.0;
    const T ratio =
        N::only_where(slip, [&]() GC_KERNEL_LAMBDA { return fscrit / N::sqrt(magfs_sq); });
    const T inv_k = N::only_where(slip, [&]() GC_KERNEL_LAMBDA { return -1.0 / k_scaled; });
    for (int k = 0; k < 3; k++) {
      const T fslip = N::select(spring, fs[k] * ratio, T{});
      const T hslip = inv_k * (fslip - fdamp[k]);
      history[k] = N::select(slip, N::select(spring, hslip, history[k]), history[k]);
      fs[k] = N::select(slip, fslip, fs[k]);
    }
  }

  /* ---------------------------------------------------------------------
     rolling: rolling displacement xi = integral of v_L dt in the tangent plane (history,
     3 values), v_L = R (omega_i - omega_j) x n (Wang et al., Particuology 23, 49 (2015),
     eq. 31), rotated into the current plane keeping its length; moment M_r = -k_R n x xi with
     k_R = 4 F_C (a/a_0)^(3/2), |xi| capped at xi_crit = theta_crit R (paper eqs. 3-4).
     GranularModel applies torque_i += R n x fr, hence fr = -(k_R / R) xi.
  --------------------------------------------------------------------- */

  template <class T>
  GC_KERNEL_INLINE void rolling_force(T *history, const T *nx, const T *vrl, T dt, T xi_crit,
                            T k_over_reff, bool history_update, T *fr)
  {
    using N = NumberOps<T>;
    T xi[3] = {history[0], history[1], history[2]};
    if (history_update) {
      const T xin = dot3(xi, nx);
      rotate_into_plane(xi, nx, xin, xin != 0.0);
      for (int k = 0; k < 3; k++) xi[k] = xi[k] + dt * vrl[k];
    }
    // irreversible rolling beyond theta_crit R
    const T lensq = lensq3(xi);
    const auto capped = lensq > xi_crit * xi_crit;
    const T ratio =
        N::only_where(capped, [&]() GC_KERNEL_LAMBDA { return xi_crit / N::sqrt(lensq); });
    for (int k = 0; k < 3; k++) xi[k] = N::select(capped, ratio * xi[k], xi[k]);

    for (int k = 0; k < 3; k++) fr[k] = -k_over_reff * xi[k];
    if (history_update)
      for (int k = 0; k < 3; k++) history[k] = xi[k];
  }

  /* ---------------------------------------------------------------------
     twisting: M_t = -k_tw phi - eta_tw omega_T, k_tw = k_T a^2 / 2 = 4 G* a^3,
     eta_tw = eta_T a^2 / 2 (Marshall 2009, eqs. 29-32), |M_t| <= M_crit = 3 pi a F_crit / 16
     (paper eq. 4). On slip the moment keeps the sign of the trial moment and the twist angle
     phi (history, 1 value) is reset to the value that produces exactly M_crit.
     Arguments: k_t = 8 G* (per unit contact radius), eta_t = eta_N, mu_fcrit = mu F_crit.
  --------------------------------------------------------------------- */

  template <class T>
  GC_KERNEL_INLINE T twisting_moment(T &phi, T magtwist, T dt, T a, T k_t, T eta_t, T mu_fcrit,
                           bool history_update)
  {
    using N = NumberOps<T>;
    const T k = 0.5 * k_t * a * a * a;
    const T damp = 0.5 * eta_t * a * a;
    const T mcrit = THREEPI_16 * a * mu_fcrit;

    T angle = phi;
    if (history_update) angle = angle + magtwist * dt;

    const T trial = -k * angle - damp * magtwist;
    const auto slip = N::abs(trial) > mcrit;
    const T limited = N::select(trial > 0.0, mcrit, -mcrit);
    const T slip_angle = N::only_where(slip, [&]() GC_KERNEL_LAMBDA {
      return N::select(k > 0.0, -(limited + damp * magtwist) / k, T{});
    });
    if (history_update) phi = N::select(slip, slip_angle, angle);
    return N::select(slip, limited, trial);
  }

}    // namespace MarshallKernels
}    // namespace LAMMPS_NS

#endif
