// GRANULAR-CHARGED FMM core library (gcfmm): the exact far field's per-particle work for many
// particles at once (far_field_batch.hpp). Compiled with GCSIMD_BITWISE_OPTIONS
// (src/fmm/CMakeLists.txt): no fused multiply-adds, so that each lane rounds as the scalar
// formulas of far_field.cpp do. Lanes are particles: a block of as many particles as one register
// of the path holds doubles runs the scalar loops side by side.
#include "far_field_batch.hpp"

#include <algorithm>

#include "gcsimd/simd_paths.hpp"

namespace gcfmm {
namespace detail {

namespace {

constexpr int kMaxNodes = kFarFieldMaxNodes;

// W doubles operated on lane by lane (GCC/Clang vector extension), W the doubles of one register
// of the path (GCSIMD_DEFINE_WIDTH_PATHS): each lane rounds as the scalar code does
template <int W> struct LanesOf;
template <> struct LanesOf<2> { typedef double type __attribute__((vector_size(2 * sizeof(double)))); };
template <> struct LanesOf<4> { typedef double type __attribute__((vector_size(4 * sizeof(double)))); };
template <> struct LanesOf<8> { typedef double type __attribute__((vector_size(8 * sizeof(double)))); };

// the block of lanes starting at k0 of a weight row (zero beyond the m particles)
template <typename Lanes>
GCSIMD_ALWAYS_INLINE void load_lanes(Lanes &v, const double *row, std::size_t k0, int m) {
  v = Lanes{};
  for (int l = 0; l < m; ++l) v[l] = row[k0 + l];
}

template <typename Lanes>
GCSIMD_ALWAYS_INLINE void store_lanes(const Lanes &v, double *row, std::size_t k0, int m) {
  for (int l = 0; l < m; ++l) row[k0 + l] = v[l];
}

// chebyshev_lagrange_weights for the points t, kLanes at a time
template <int kLanes>
GCSIMD_ALWAYS_INLINE void weights_loop(std::size_t n, const double *__restrict t, int p,
                                       const double *__restrict tab, std::size_t stride, double *__restrict s,
                                       double *__restrict ds) {
  typedef typename LanesOf<kLanes>::type Lanes;
  for (std::size_t k0 = 0; k0 < n; k0 += kLanes) {
    const int m = static_cast<int>(std::min<std::size_t>(kLanes, n - k0));
    Lanes tl, sl[kMaxNodes], dsl[kMaxNodes];
    load_lanes(tl, t, k0, m);
    chebyshev_lagrange_weights<Lanes>(tl, p, tab, sl, ds ? dsl : nullptr, nullptr);
    for (int i = 0; i < p; ++i) {
      store_lanes(sl[i], s + static_cast<std::size_t>(i) * stride, k0, m);
      if (ds) store_lanes(dsl[i], ds + static_cast<std::size_t>(i) * stride, k0, m);
    }
  }
}

// the scalar anterpolation's loops, particle by particle in their order, the z nodes side by side
GCSIMD_ALWAYS_INLINE void anterpolate_loop(std::size_t m, const double *__restrict q, int p, int pz, int a0, int a1,
                                           const double *__restrict sx, const double *__restrict sy,
                                           const double *__restrict sz, std::size_t stride,
                                           double *__restrict col) {
  for (std::size_t k = 0; k < m; ++k) {
    if (q[k] == 0.0) continue;
    double szk[kMaxNodes];
    for (int c = 0; c < pz; ++c) szk[c] = sz[static_cast<std::size_t>(c) * stride + k];
    for (int a = a0; a < a1; ++a) {
      const double qa = q[k] * sx[static_cast<std::size_t>(a) * stride + k];
      for (int bb = 0; bb < p; ++bb) {
        const double qab = qa * sy[static_cast<std::size_t>(bb) * stride + k];
        double *dst = col + static_cast<std::size_t>(a * p + bb) * pz;
#pragma omp simd
        for (int c = 0; c < pz; ++c) dst[c] += qab * szk[c];
      }
    }
  }
}

// the interpolation (contract_interpolant without the second derivatives) for kLanes particles
// side by side; empty lanes of a last block have zero weights
template <int kLanes>
GCSIMD_ALWAYS_INLINE void interpolate_loop(std::size_t m, int p, int pz, const double *__restrict col,
                                           const double *__restrict sx, const double *__restrict dsx,
                                           const double *__restrict sy, const double *__restrict dsy,
                                           const double *__restrict sz, const double *__restrict dsz,
                                           std::size_t stride, double *__restrict fo, double *__restrict gxo,
                                           double *__restrict gyo, double *__restrict gzo) {
  typedef typename LanesOf<kLanes>::type Lanes;
  for (std::size_t k0 = 0; k0 < m; k0 += kLanes) {
    const int nl = static_cast<int>(std::min<std::size_t>(kLanes, m - k0));
    Lanes wx[kMaxNodes], dwx[kMaxNodes], wy[kMaxNodes], dwy[kMaxNodes], wz[kMaxNodes], dwz[kMaxNodes];
    for (int a = 0; a < p; ++a) {
      load_lanes(wx[a], sx + static_cast<std::size_t>(a) * stride, k0, nl);
      load_lanes(dwx[a], dsx + static_cast<std::size_t>(a) * stride, k0, nl);
      load_lanes(wy[a], sy + static_cast<std::size_t>(a) * stride, k0, nl);
      load_lanes(dwy[a], dsy + static_cast<std::size_t>(a) * stride, k0, nl);
    }
    for (int c = 0; c < pz; ++c) {
      load_lanes(wz[c], sz + static_cast<std::size_t>(c) * stride, k0, nl);
      load_lanes(dwz[c], dsz + static_cast<std::size_t>(c) * stride, k0, nl);
    }
    const auto d = contract_interpolant<false, Lanes>(p, pz, col, wx, dwx, nullptr, wy, dwy, nullptr, wz, dwz,
                                                      nullptr);
    store_lanes(d.f, fo, k0, nl);
    store_lanes(d.gx, gxo, k0, nl);
    store_lanes(d.gy, gyo, k0, nl);
    store_lanes(d.gz, gzo, k0, nl);
  }
}

#define GCFMM_WEIGHTS_PARAMS                                                                      \
  (std::size_t n, const double *t, int p, const double *tab, std::size_t stride, double *s, double *ds)
#define GCFMM_WEIGHTS_ARGS (n, t, p, tab, stride, s, ds)
GCSIMD_DEFINE_WIDTH_PATHS(void, weights_kernel, GCFMM_WEIGHTS_PARAMS, weights_loop, GCFMM_WEIGHTS_ARGS)

#define GCFMM_ANTERP_PARAMS                                                                        \
  (std::size_t m, const double *q, int p, int pz, int a0, int a1, const double *sx, const double *sy, \
   const double *sz, std::size_t stride, double *col)
#define GCFMM_ANTERP_ARGS (m, q, p, pz, a0, a1, sx, sy, sz, stride, col)
GCSIMD_DEFINE_PATHS(void, anterpolate_kernel, GCFMM_ANTERP_PARAMS, anterpolate_loop, GCFMM_ANTERP_ARGS)

#define GCFMM_INTERP_PARAMS                                                                         \
  (std::size_t m, int p, int pz, const double *col, const double *sx, const double *dsx, const double *sy, \
   const double *dsy, const double *sz, const double *dsz, std::size_t stride, double *f, double *gx,   \
   double *gy, double *gz)
#define GCFMM_INTERP_ARGS (m, p, pz, col, sx, dsx, sy, dsy, sz, dsz, stride, f, gx, gy, gz)
GCSIMD_DEFINE_WIDTH_PATHS(void, interpolate_kernel, GCFMM_INTERP_PARAMS, interpolate_loop, GCFMM_INTERP_ARGS)

}  // namespace

void chebyshev_weights(gcsimd::SimdPath path, std::size_t n, const double *t, int p, const double *tab,
                       std::size_t stride, double *s, double *ds) {
  weights_kernel_for(path)(n, t, p, tab, stride, s, ds);
}

void anterpolate_box(gcsimd::SimdPath path, std::size_t m, const double *q, int p, int pz, int a0, int a1,
                     const double *sx, const double *sy, const double *sz, std::size_t stride, double *col) {
  anterpolate_kernel_for(path)(m, q, p, pz, a0, a1, sx, sy, sz, stride, col);
}

void interpolate_box(gcsimd::SimdPath path, std::size_t m, int p, int pz, const double *col, const double *sx,
                     const double *dsx, const double *sy, const double *dsy, const double *sz,
                     const double *dsz, std::size_t stride, double *f, double *gx, double *gy, double *gz) {
  interpolate_kernel_for(path)(m, p, pz, col, sx, dsx, sy, dsy, sz, dsz, stride, f, gx, gy, gz);
}

}  // namespace detail
}  // namespace gcfmm
