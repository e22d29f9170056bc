/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// One Marshall contact (kinematics, JKR normal force from its root, damping, sliding, rolling,
// twisting, torques), the one contact assembly of pair_style granular/opt and fix
// wall/gran/opt (a wall is a fixed partner of radius 0 at rest), as a template on the number
// type of marshall_kernels.h: double for one contact (the scalar kernel, the reference), a GCC
// vector type of W doubles for W contacts at once (so the vector code needs no
// auto-vectoriser). Every decision of a contact is a select (the double instantiation computes
// a value needed on one side only where it is needed: NumberOps::only_where); the only branches
// of the lanes are on history_update, the same for every contact of a step. A contact's inputs
// and outputs are flat arrays indexed by the enums below; the lanes kernel reads them as
// structure-of-arrays blocks, WIDTH contacts of each input next to each other, each SIMD path
// as vectors of its register width. Free of LAMMPS classes.

#ifndef LMP_GC_MARSHALL_LANES_H
#define LMP_GC_MARSHALL_LANES_H

#include "marshall_kernels.h"

#include <cstddef>
#include <type_traits>

namespace gcsimd {
enum class SimdPath;    // gcsimd/simd.hpp: the instruction-set paths
}

namespace LAMMPS_NS {
namespace MarshallLanes {

  // contacts per lanes block of the buffers: one AVX-512 register of doubles
  constexpr int WIDTH = 8;
  // a vector of W contacts' values (W = 2, 4 or 8: one SSE2, AVX2 or AVX-512 register) and its
  // mask; each path evaluates a block as WIDTH / W such vectors, so that its values stay in
  // registers
  // (GCC drops a vector_size that depends on a template parameter: one definition per width)
#define GC_LANES_OF(W)                                                                          \
  template <> struct LanesOf<W> {                                                               \
    using T = double __attribute__((vector_size(8 * W)));                                       \
    using Mask = decltype(T{} < T{});                                                           \
    using InMemory = double __attribute__((vector_size(8 * W), aligned(alignof(double)), may_alias)); \
  };
  // InMemory: T in the blocks of the buffers (any alignment of a double, and read or written
  // as doubles elsewhere)
  template <int W> struct LanesOf;
  GC_LANES_OF(2)
  GC_LANES_OF(4)
  GC_LANES_OF(8)
#undef GC_LANES_OF
  using Lanes = LanesOf<WIDTH>::T;
  using LaneMask = LanesOf<WIDTH>::Mask;
  using LanesInMemory = LanesOf<WIDTH>::InMemory;
}    // namespace MarshallLanes

// GCC notes that a 64-byte vector passed by value has another ABI without AVX-512: these
// functions are always inlined, so no such call exists
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
namespace MarshallKernels {
  // lanes of W contacts as a number type of the equations (marshall_kernels.h). The square root
  // of a vector is one per lane, which GCC turns into one vector square root (the lanes code is
  // compiled with -fno-math-errno); abs clears the sign bit, as fabs does.
  template <int W> struct LaneOps {
    using T = typename MarshallLanes::LanesOf<W>::T;
    using Mask = typename MarshallLanes::LanesOf<W>::Mask;
    static GC_KERNEL_INLINE T select(Mask c, T a, T b) { return c ? a : b; }
    template <class F> static GC_KERNEL_INLINE T only_where(Mask, F value) { return value(); }
    static GC_KERNEL_INLINE T sqrt(T x)
    {
      T r;
      for (int k = 0; k < W; k++) r[k] = __builtin_sqrt(x[k]);
      return r;
    }
    static GC_KERNEL_INLINE T abs(T x)
    {
      const Mask magnitude = Mask{} + 0x7fffffffffffffffL;
      return __builtin_bit_cast(T, __builtin_bit_cast(Mask, x) & magnitude);
    }
  };
  template <> struct NumberOps<MarshallLanes::LanesOf<2>::T> : LaneOps<2> {};
  template <> struct NumberOps<MarshallLanes::LanesOf<4>::T> : LaneOps<4> {};
  template <> struct NumberOps<MarshallLanes::LanesOf<8>::T> : LaneOps<8> {};
}    // namespace MarshallKernels
#pragma GCC diagnostic pop

namespace MarshallLanes {

  // the inputs of one contact
  enum Input {
    DX = 0,              // x_i - x_j (3)
    VR = 3,              // v_i - v_j (3)
    OMEGA_I = 6,         // spin of i (3)
    OMEGA_J = 9,         // spin of j (3)
    RAD_I = 12,          // radius of i
    RAD_J,               // radius of j
    REFF,                // R_eff
    ROOT,                // root s of the scaled JKR law (jkr_scaled.h) at this overlap
    ASEP,                // a_sep, F_C, sqrt(4/3 E* a_sep): JKRScales
    FC,
    SQRT_KN_SEP,
    MASS_FACTOR,         // damping marshall 2, marshall/printed 1
    MASS_I,              // mass of i
    MASS_J,              // mass of j
    FIXED,               // FIXED_NONE, FIXED_I or FIXED_J: which one is frozen
    ALPHA,               // damping alpha(e)
    K_T,                 // 8 G*
    MU,                  // sliding friction coefficient
    DT,                  // time step
    XI_CRIT,             // rolling limit theta_crit R (0 without rolling)
    ROLLING,             // 1: rolling marshall defined, 0: none
    TWISTING,            // 1: twisting marshall/jkr defined, 0: none
    HERTZ,               // 1: no adhesion, Hertz's law (the scalar instantiation only)
    EMIX,                // E* (for Hertz's law)
    LEVER_SHIFT,         // the torque's lever arm is R - LEVER_SHIFT delta: 1/2 between two
                         // particles, 0 at a wall (dist_to_contact of GranularModel)
    HIST_T,              // tangential history (3)
    HIST_R = HIST_T + 3, // rolling history (3)
    HIST_TW = HIST_R + 3,    // twisting history (1)
    N_INPUT
  };
  // LEVER_SHIFT of a contact between two particles and of a contact with a wall
  constexpr double LEVER_SHIFT_PAIR = 0.5, LEVER_SHIFT_WALL = 0.0;

  // the outputs of one contact: force on i, torques on i and j (before factor_lj), histories
  enum Output {
    FORCE = 0,
    TORQUE_I = 3,
    TORQUE_J = 6,
    OUT_HIST_T = 9,
    OUT_HIST_R = 12,
    OUT_HIST_TW = 15,
    N_OUTPUT
  };

  // an atom of fix freeze is a fixed body: m* is the other's mass (PairGranular's rule for
  // freeze_group_bit, j's before i's)
  constexpr double FIXED_NONE = 0.0, FIXED_I = 1.0, FIXED_J = 2.0;
  template <class T> GC_KERNEL_INLINE T effective_mass(T mass_i, T mass_j, T fixed)
  {
    using N = MarshallKernels::NumberOps<T>;
    return N::select(fixed == FIXED_J, mass_i,
                     N::select(fixed == FIXED_I, mass_j, mass_i * mass_j / (mass_i + mass_j)));
  }

  /* ---------------------------------------------------------------------
     GranularModel::calculate_forces with the Marshall set, in its order of operations
  --------------------------------------------------------------------- */

  // Memory: the type read and written (T, or T's unaligned twin); input q at inputs[q * STEP],
  // output q at out[q * STEP] (STEP > 1: part of a wider lanes block)
  template <class Memory, class T = Memory, int STEP = 1>
  GC_KERNEL_INLINE void marshall_contact(const Memory *inputs, Memory *outputs, bool history_update)
  {
    namespace MK = MarshallKernels;
    using N = MK::NumberOps<T>;
    auto in = [inputs](int q) -> T { return inputs[q * STEP]; };
    auto out = [outputs](int q) -> Memory & { return outputs[q * STEP]; };
    const T dx[3] = {in(DX), in(DX + 1), in(DX + 2)};
    const T vr[3] = {in(VR), in(VR + 1), in(VR + 2)};
    const T radi = in(RAD_I), radj = in(RAD_J), reff = in(REFF);

    // kinematics
    const T r = N::sqrt(MK::lensq3(dx));
    const T rinv = 1.0 / r;
    const T delta = radi + radj - r;
    T nx[3], vt[3], wr[3], temp[3], vtr[3];
    for (int k = 0; k < 3; k++) nx[k] = rinv * dx[k];
    const T vnnr = MK::dot3(vr, nx);
    for (int k = 0; k < 3; k++) vt[k] = vr[k] - vnnr * nx[k];
    for (int k = 0; k < 3; k++) wr[k] = radi * in(OMEGA_I + k) + radj * in(OMEGA_J + k);
    MK::cross3(wr, nx, temp);
    for (int k = 0; k < 3; k++) vtr[k] = vt[k] - temp[k];

    // normal: JKR from the root with Marshall damping
    MK::NormalForceT<T> nf = MK::jkr_normal_force_of_root(in(ASEP), in(FC), in(SQRT_KN_SEP),
                                                          in(ROOT));
    if constexpr (std::is_same_v<T, double>) {
      if (in(HERTZ) != 0.0) nf = MK::hertz_normal_force(in(EMIX), delta, reff);
    }
    const T meff = effective_mass(in(MASS_I), in(MASS_J), in(FIXED));
    const T sqrt_mass = MK::damping_sqrt_mass(in(MASS_FACTOR), meff);
    const T damp_prefactor = MK::damping_prefactor(in(ALPHA), sqrt_mass, nf);
    const T fntot = nf.fne + (-damp_prefactor * vnnr);
    const T fncrit = MK::critical_force(nf);

    // sliding
    T hist_t[3] = {in(HIST_T), in(HIST_T + 1), in(HIST_T + 2)};
    T fs[3];
    MK::tangential_force(hist_t, nx, vtr, in(DT), in(K_T) * nf.a, damp_prefactor,
                         fncrit * in(MU), history_update, fs);

    T force[3], torque_i[3], torque_j[3];
    for (int k = 0; k < 3; k++) force[k] = fntot * nx[k] + fs[k];
    T nxfs[3];
    MK::cross3(nx, fs, nxfs);
    const T lever_i = radi - in(LEVER_SHIFT) * delta, lever_j = radj - in(LEVER_SHIFT) * delta;
    for (int k = 0; k < 3; k++) {
      const T t = nxfs[k] * -1.0;
      torque_i[k] = t * lever_i;
      torque_j[k] = t * lever_j;
    }

    T relrot[3];
    for (int k = 0; k < 3; k++) relrot[k] = in(OMEGA_I + k) - in(OMEGA_J + k);

    // rolling velocity, eq. 31 of Wang et al, Particuology 23, 49 (2015)
    T vrl[3], fr[3], torroll[3];
    vrl[0] = reff * (relrot[1] * nx[2] - relrot[2] * nx[1]);
    vrl[1] = reff * (relrot[2] * nx[0] - relrot[0] * nx[2]);
    vrl[2] = reff * (relrot[0] * nx[1] - relrot[1] * nx[0]);
    T hist_r[3] = {in(HIST_R), in(HIST_R + 1), in(HIST_R + 2)};
    MK::rolling_force(hist_r, nx, vrl, in(DT), in(XI_CRIT), nf.adhesive / reff, history_update,
                      fr);
    MK::cross3(nx, fr, torroll);
    const auto rolling = in(ROLLING) != 0.0;
    for (int k = 0; k < 3; k++) {
      const T tr = torroll[k] * reff;
      torque_i[k] = N::select(rolling, torque_i[k] + tr, torque_i[k]);
      torque_j[k] = N::select(rolling, torque_j[k] - tr, torque_j[k]);
    }

    // twisting: omega_T (eq. 29 of Marshall 2009)
    const T magtwist = MK::dot3(relrot, nx);
    T phi = in(HIST_TW);
    const T moment = MK::twisting_moment(phi, magtwist, in(DT), nf.a, in(K_T), damp_prefactor,
                                         in(MU) * fncrit, history_update);
    const auto twisting = in(TWISTING) != 0.0;
    for (int k = 0; k < 3; k++) {
      const T tt = moment * nx[k];
      torque_i[k] = N::select(twisting, torque_i[k] + tt, torque_i[k]);
      torque_j[k] = N::select(twisting, torque_j[k] - tt, torque_j[k]);
    }

    for (int k = 0; k < 3; k++) {
      out(FORCE + k) = force[k];
      out(TORQUE_I + k) = torque_i[k];
      out(TORQUE_J + k) = torque_j[k];
      out(OUT_HIST_T + k) = hist_t[k];
      out(OUT_HIST_R + k) = N::select(rolling, hist_r[k], in(HIST_R + k));
    }
    out(OUT_HIST_TW) = N::select(twisting, phi, in(HIST_TW));
  }

  /* ---------------------------------------------------------------------
     pack and unpack of one contact: its inputs written into, and its results read from, a
     lanes block (stride WIDTH, from the contact's lane) or one contact's arrays (stride 1).
     Each value is its own store: a record built whole and copied stalls the store-to-load
     forwarding of its parts when the kernel reads them back.
  --------------------------------------------------------------------- */

  // the inputs of a contact's atoms and history: x_i - x_j, velocities, spins, the histories of
  // its sub-models (null: none, packed as 0), the JKR root s (any value without adhesion),
  // masses and which atom is frozen
  GC_KERNEL_INLINE void pack_contact_state(double *in, int stride, const double *dx,
                                           const double *v_i, const double *v_j,
                                           const double *omega_i, const double *omega_j,
                                           const double *history_t, const double *history_r,
                                           const double *history_tw, double root, double mass_i,
                                           double mass_j, double fixed)
  {
    auto put = [in, stride](int q, double value) GC_KERNEL_LAMBDA { in[q * stride] = value; };
    for (int k = 0; k < 3; k++) {
      put(DX + k, dx[k]);
      put(VR + k, v_i[k] - v_j[k]);
      put(OMEGA_I + k, omega_i[k]);
      put(OMEGA_J + k, omega_j[k]);
      put(HIST_T + k, history_t[k]);
      put(HIST_R + k, history_r ? history_r[k] : 0.0);
    }
    put(HIST_TW, history_tw ? history_tw[0] : 0.0);
    put(ROOT, root);
    put(MASS_I, mass_i);
    put(MASS_J, mass_j);
    put(FIXED, fixed);
  }

  // the inputs of a contact's model and radii, the same for every contact of one model between
  // atoms of the same two radii. Coeffs: MarshallFusedSet::Coeffs (emix, gamma, alpha,
  // mass_factor, k_t, mu, rolling, theta_crit, roll_radius_factor, twisting); lever_shift:
  // LEVER_SHIFT_PAIR or LEVER_SHIFT_WALL
  template <class Coeffs>
  GC_KERNEL_INLINE void pack_contact_model(double *in, int stride, const Coeffs &model, double dt,
                                           double rad_i, double rad_j, double reff,
                                           const MarshallKernels::JKRScales &scales,
                                           double lever_shift)
  {
    auto put = [in, stride](int q, double value) GC_KERNEL_LAMBDA { in[q * stride] = value; };
    put(RAD_I, rad_i);
    put(RAD_J, rad_j);
    put(REFF, reff);
    put(ASEP, scales.asep);
    put(FC, scales.fc);
    put(SQRT_KN_SEP, scales.sqrt_kn_sep);
    put(MASS_FACTOR, model.mass_factor);
    put(ALPHA, model.alpha);
    put(K_T, model.k_t);
    put(MU, model.mu);
    put(DT, dt);
    put(XI_CRIT, model.rolling ? model.theta_crit * (model.roll_radius_factor * reff) : 0.0);
    put(ROLLING, model.rolling ? 1.0 : 0.0);
    put(TWISTING, model.twisting ? 1.0 : 0.0);
    put(HERTZ, model.gamma == 0.0 ? 1.0 : 0.0);
    put(EMIX, model.emix);
    put(LEVER_SHIFT, lever_shift);
  }

  // the histories of a contact's sub-models back (null: the model has none)
  GC_KERNEL_INLINE void unpack_histories(const double *out, int stride, double *history_t,
                                         double *history_r, double *history_tw)
  {
    for (int k = 0; k < 3; k++) {
      history_t[k] = out[(OUT_HIST_T + k) * stride];
      if (history_r) history_r[k] = out[(OUT_HIST_R + k) * stride];
    }
    if (history_tw) history_tw[0] = out[OUT_HIST_TW * stride];
  }

  // the force on i and the torques on i and j, times factor (the special-bond factor)
  GC_KERNEL_INLINE void unpack_forces(const double *out, int stride, double factor,
                                      double *force, double *torque_i, double *torque_j)
  {
    for (int k = 0; k < 3; k++) {
      force[k] = factor * out[(FORCE + k) * stride];
      torque_i[k] = factor * out[(TORQUE_I + k) * stride];
      torque_j[k] = factor * out[(TORQUE_J + k) * stride];
    }
  }

  // nblocks blocks of WIDTH contacts: block b's input q of lane l at
  // in[(b * N_INPUT + q) * WIDTH + l], its output q at out[(b * N_OUTPUT + q) * WIDTH + l];
  // any alignment. Every lane is evaluated (pad a short block with a copy of a valid
  // contact). HERTZ must be 0: a contact without adhesion takes the scalar instantiation.
  void contacts_in_lanes(std::size_t nblocks, const double *in, double *out, bool history_update,
                         gcsimd::SimdPath path);
  // the same on the default path (gcsimd::default_simd_path(), capped by GCSIMD_MAX_PATH)
  void contacts_in_lanes(std::size_t nblocks, const double *in, double *out, bool history_update);

  // contact l's first input and output in such blocks: its input q at [q * WIDTH]
  inline double *lane_input(double *in, std::size_t l)
  {
    return in + (l / WIDTH) * N_INPUT * WIDTH + l % WIDTH;
  }
  inline double *lane_output(double *out, std::size_t l)
  {
    return out + (l / WIDTH) * N_OUTPUT * WIDTH + l % WIDTH;
  }
  // the lanes from nlanes to the end of its block copy the inputs of the block's first contact
  // (evaluated, not read back); returns the number of blocks
  inline std::size_t pad_last_block(double *in, std::size_t nlanes)
  {
    const std::size_t nblocks = (nlanes + WIDTH - 1) / WIDTH;
    for (std::size_t l = nlanes; l < nblocks * WIDTH; l++) {
      const double *first = lane_input(in, l - l % WIDTH);
      double *pad = lane_input(in, l);
      for (int q = 0; q < N_INPUT; q++) pad[q * WIDTH] = first[q * WIDTH];
    }
    return nblocks;
  }

}    // namespace MarshallLanes


}    // namespace LAMMPS_NS

#endif
