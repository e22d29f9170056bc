// GRANULAR-CHARGED FMM core library (gcfmm).
// The exact far field (doc/theory.md, eq. (4.6)): Chebyshev interpolation of the smooth far
// kernel R over a column of boxes. Conventions: include/gcfmm/far_field.hpp; parameters and
// measurements: doc/fmm-far-field.md.
#include "gcfmm/far_field.hpp"

#include <Eigen/Dense>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "gcfmm/lattice_sum.hpp"

namespace gcfmm {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

namespace {

// Parameter sets from the calibration scan in unittest/fmm/test_lattice_sum.cpp
// (DISABLED_Calibration; table in doc/fmm-far-field.md): `measured` is the largest relative RMS
// far-field error measured for the deposition geometry (2000 charges +-1) and a thin neutral
// layer (300 charges +-1). A request takes the first set whose `from` it reaches; each set keeps
// `measured` at least 3 times below the requests it serves (2.4 times at 1e-8). The loosest set
// starts at 3e-3, not at 3 x 6.3e-4: below 3e-3 its estimate would take the printed total
// (near-field model plus far field) above the request.
struct ParamSet {
  double from;
  int pxy, pz;
  double hz_over_l, measured;
};
constexpr ParamSet kParams[] = {
    {3e-3, 6, 6, 1.0, 6.3e-4},
    {1e-3, 8, 6, 1.0, 7.7e-5},
    {1e-4, 8, 8, 1.0, 3.2e-5},
    {1e-5, 10, 8, 1.0, 2.6e-6},
    {1e-6, 12, 10, 1.0, 7.8e-8},
    {1e-7, 14, 12, 1.0, 4.3e-9},
    {0.0, 14, 12, 0.7, 4.3e-9},    // down to 1e-8
};

const ParamSet &params_for(double accuracy) {
  const ParamSet *ps = kParams;
  while (accuracy < ps->from) ++ps;    // the last set's `from` is 0
  return *ps;
}

}  // namespace

void PeriodicFarField::parameters_for(double accuracy, int *pxy, int *pz, double *hz_over_l) {
  if (!(accuracy >= 1e-8) || !(accuracy < 1.0))
    throw std::invalid_argument("gcfmm::PeriodicFarField: accuracy must be in [1e-8, 1), got " +
                                std::to_string(accuracy));
  const ParamSet &ps = params_for(accuracy);
  *pxy = ps.pxy;
  *pz = ps.pz;
  *hz_over_l = ps.hz_over_l;
}

void PeriodicFarField::setup(double x0, double y0, double lx, double ly, double zlo, double zhi,
                             int images, double accuracy) {
  // one Chebyshev grid spans the whole cell in x and y, so the kernel's variation on the
  // scale of the short side must be resolved along the long side: the parameter sets meet
  // their accuracy up to an aspect ratio of 2 (scan in doc/fmm-far-field.md)
  if (lx > 0 && ly > 0 && std::max(lx, ly) > kMaxAspect * std::min(lx, ly)) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "gcfmm::PeriodicFarField: the exact far field supports cells with max(lx, ly) / min(lx, ly) "
                  "<= %g, got %g (lx = %g, ly = %g); use FarField::Average or FarField::None, or a cell closer "
                  "to square",
                  kMaxAspect, std::max(lx, ly) / std::min(lx, ly), lx, ly);
    throw std::invalid_argument(buf);
  }
  int pxy = 0, pz = 0;
  double hzl = 0;
  parameters_for(accuracy, &pxy, &pz, &hzl);
  // Rectangular cells: the images across the short side come closer (in units of the long
  // side) to the interpolation domain; two more nodes in x and y restore the margin (seen in
  // the 28 x 20 thin-layer test).
  if (std::max(lx, ly) > 1.04 * std::min(lx, ly)) pxy += 2;
  setup_explicit(x0, y0, lx, ly, zlo, zhi, images, pxy, pz, hzl * std::min(lx, ly));
  compress(kCompressionPerAccuracy * accuracy);
  accuracy_ = accuracy;
  // the sample sees the compressed operator
  est_error_ = std::max(20.0 * sample_error(), params_for(accuracy).measured);
}

bool PeriodicFarField::needs_setup(double x0, double y0, double lx, double ly, double zlo,
                                   double zhi, int images, double accuracy) const {
  if (!ready()) return true;
  const double tol = 1e-12 * std::max(lx_, ly_);
  if (std::fabs(x0 - x0_) > tol || std::fabs(y0 - y0_) > tol || std::fabs(lx - lx_) > tol ||
      std::fabs(ly - ly_) > tol)
    return true;
  if (images != images_ || accuracy != accuracy_) return true;
  if (zlo < zlo_ || zhi > zhi_) return true;
  // much smaller than the stored range: re-setup to save boxes
  if ((zhi - zlo) + std::min(lx_, ly_) < 0.5 * (zhi_ - zlo_)) return true;
  return false;
}

std::size_t PeriodicFarField::memory_bytes() const {
  std::size_t b = 0;
  for (const auto &m : ops_) b += sizeof(double) * m.size();
  return b;
}

void PeriodicFarField::interp_weights(double t, int p, const double *tab, double *s, double *ds) {
  // Lagrange basis of the first-kind Chebyshev nodes t_i = cos(pi (2i+1) / 2p), written with
  // the discrete orthogonality of T_k: S_i(t) = 1/p + (2/p) sum_{k=1}^{p-1} T_k(t_i) T_k(t),
  // S_i'(t) = (2/p) sum_k T_k(t_i) k U_{k-1}(t). Stable everywhere on [-1, 1] and slightly beyond.
  double tk[32], dtk[32];
  tk[0] = 1.0;
  dtk[0] = 0.0;
  if (p > 1) {
    tk[1] = t;
    dtk[1] = 1.0;
  }
  double um1 = 1.0, u = 2.0 * t;  // U_0, U_1
  for (int k = 2; k < p; ++k) {
    tk[k] = 2.0 * t * tk[k - 1] - tk[k - 2];
    dtk[k] = k * u;  // T_k' = k U_{k-1}
    const double un = 2.0 * t * u - um1;
    um1 = u;
    u = un;
  }
  for (int i = 0; i < p; ++i) {
    const double *ti = tab + static_cast<std::size_t>(i) * p;
    double a = 0.5, b = 0.0;
    for (int k = 1; k < p; ++k) {
      a += ti[k] * tk[k];
      b += ti[k] * dtk[k];
    }
    s[i] = 2.0 * a / p;
    if (ds) ds[i] = 2.0 * b / p;
  }
}

namespace {

std::vector<double> cheb_nodes(int p) {
  std::vector<double> t(p);
  for (int i = 0; i < p; ++i) t[i] = std::cos(kPi * (2 * i + 1) / (2.0 * p));
  return t;
}

std::vector<double> cheb_table(int p) {
  std::vector<double> tab(static_cast<std::size_t>(p) * p);
  const auto t = cheb_nodes(p);
  for (int i = 0; i < p; ++i)
    for (int k = 0; k < p; ++k) tab[static_cast<std::size_t>(i) * p + k] = std::cos(k * std::acos(t[i]));
  return tab;
}

// distinct values (to a relative tolerance) of a list and the index of each entry
void uniq(const std::vector<double> &v, double tol, std::vector<double> &vals, std::vector<int> &idx) {
  std::vector<int> order(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return v[a] < v[b]; });
  vals.clear();
  idx.assign(v.size(), -1);
  for (int i : order) {
    if (vals.empty() || v[i] - vals.back() > tol) vals.push_back(v[i]);
    idx[i] = static_cast<int>(vals.size()) - 1;
  }
}

}  // namespace

void PeriodicFarField::setup_explicit(double x0, double y0, double lx, double ly, double zlo,
                                      double zhi, int images, int pxy, int pz, double hz_max) {
  const auto t_start = std::chrono::steady_clock::now();
  if (!(lx > 0) || !(ly > 0) || !std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(lx) ||
      !std::isfinite(ly))
    throw std::invalid_argument("gcfmm::PeriodicFarField: bad cell");
  if (!(zhi >= zlo) || !std::isfinite(zlo) || !std::isfinite(zhi))
    throw std::invalid_argument("gcfmm::PeriodicFarField: need finite zlo <= zhi");
  if (images < 1)
    throw std::invalid_argument(
        "gcfmm::PeriodicFarField: images must be >= 1 (the far kernel is singular inside the "
        "cell for images = 0)");
  if (pxy < 2 || pxy > 30 || pxy % 2 || pz < 2 || pz > 30 || !(hz_max > 0))
    throw std::invalid_argument(
        "gcfmm::PeriodicFarField: bad interpolation parameters (need even 2 <= pxy <= 30, 2 <= pz <= 30)");
  x0_ = x0;
  y0_ = y0;
  lx_ = lx;
  ly_ = ly;
  images_ = images;
  pxy_ = pxy;
  pz_ = pz;
  const double lmin = std::min(lx, ly);
  const double pad = 0.1 * (zhi - zlo) + 0.1 * lmin;  // headroom for a growing column
  zlo_ = zlo - pad;
  zhi_ = zhi + pad;
  nb_ = std::max(1, static_cast<int>(std::ceil((zhi_ - zlo_) / hz_max - 1e-9)));
  hz_ = (zhi_ - zlo_) / nb_;
  tab_xy_ = cheb_table(pxy);
  tab_z_ = cheb_table(pz);
  const auto tn = cheb_nodes(pxy), tz = cheb_nodes(pz);

  // distinct |dx|, |dy| between nodes (R is even in each component)
  std::vector<double> dxv(pxy * pxy), dyv(pxy * pxy);
  for (int a = 0; a < pxy; ++a)
    for (int b = 0; b < pxy; ++b) {
      dxv[a * pxy + b] = std::fabs(0.5 * lx * (tn[a] - tn[b]));
      dyv[a * pxy + b] = std::fabs(0.5 * ly * (tn[a] - tn[b]));
    }
  std::vector<double> ux, uy, uz;
  std::vector<int> ix, iy, iz;
  uniq(dxv, 1e-13 * lx, ux, ix);
  uniq(dyv, 1e-13 * ly, uy, iy);
  std::vector<double> dzv(static_cast<std::size_t>(nb_) * pz * pz);
  for (int o = 0; o < nb_; ++o)
    for (int c = 0; c < pz; ++c)
      for (int d = 0; d < pz; ++d)
        dzv[(static_cast<std::size_t>(o) * pz + c) * pz + d] = std::fabs(o * hz_ + 0.5 * hz_ * (tz[c] - tz[d]));
  uniq(dzv, 1e-13 * hz_, uz, iz);

  // table of R on the distinct differences
  const std::size_t nx = ux.size(), ny = uy.size(), nz = uz.size();
  std::vector<double> tab(nx * ny * nz);
  const bool square = (lx == ly);
  for (std::size_t a = 0; a < nx; ++a)
    for (std::size_t b = 0; b < ny; ++b) {
      if (square && b < a) {
        for (std::size_t c = 0; c < nz; ++c) tab[(a * ny + b) * nz + c] = tab[(b * ny + a) * nz + c];
        continue;
      }
      for (std::size_t c = 0; c < nz; ++c)
        far_kernel(ux[a], uy[b], uz[c], lx, ly, images, &tab[(a * ny + b) * nz + c], nullptr, nullptr,
                   nullptr);
    }

  // Operators M_o, o = target box - source box >= 0; node index (a p + b) pz + c. R is even
  // in dx and dy and the nodes are symmetric (t_{p-1-a} = -t_a), so M_o commutes with the
  // mirror maps a -> p-1-a and b -> p-1-b: in the basis of even/odd node combinations it is
  // block diagonal with 4 blocks K_s, s = (sx, sy) in {+,-}^2, of size (p^2/4 pz)^2:
  //   K_s[(a,b,c),(a',b',c')] = sum_{gx,gy in {0,1}} sx^gx sy^gy M_o[(a,b,c),(m_gx(a'),m_gy(b'),c')]
  // for a, b, a', b' < p/2 (m_1(a) = p-1-a): 4 times less memory and work.
  const int h = pxy / 2, nh = h * h * pz;
  ops_.assign(4 * static_cast<std::size_t>(nb_), std::vector<double>(static_cast<std::size_t>(nh) * nh, 0.0));
  for (int o = 0; o < nb_; ++o)
    for (int sym = 0; sym < 4; ++sym) {
      const double sx = (sym & 1) ? -1.0 : 1.0, sy = (sym & 2) ? -1.0 : 1.0;
      Eigen::Map<Eigen::MatrixXd> m(ops_[4 * o + sym].data(), nh, nh);
      for (int a2 = 0; a2 < h; ++a2)
        for (int b2 = 0; b2 < h; ++b2)
          for (int c2 = 0; c2 < pz; ++c2) {
            double *mc = m.col((a2 * h + b2) * pz + c2).data();
            const int *izp = &iz[(static_cast<std::size_t>(o) * pz) * pz + c2];
            for (int gx = 0; gx < 2; ++gx)
              for (int gy = 0; gy < 2; ++gy) {
                const double w = (gx ? sx : 1.0) * (gy ? sy : 1.0);
                const int am = gx ? pxy - 1 - a2 : a2, bm = gy ? pxy - 1 - b2 : b2;
                for (int a = 0; a < h; ++a) {
                  const std::size_t ka = ix[a * pxy + am] * ny;
                  for (int b = 0; b < h; ++b) {
                    const std::size_t kab = (ka + iy[b * pxy + bm]) * nz;
                    double *dst = mc + (a * h + b) * pz;
                    for (int c = 0; c < pz; ++c) dst[c] += w * tab[kab + izp[static_cast<std::size_t>(c) * pz]];
                  }
                }
              }
          }
    }

  rank_.assign(4 * static_cast<std::size_t>(nb_), nh);
  // sampled kernel error, scaled by 20 (the ratio of the far-field error to this sample in the
  // calibration scan: doc/fmm-far-field.md)
  est_error_ = 20.0 * sample_error();
  accuracy_ = 0.0;
  setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
}

void PeriodicFarField::compress(double rel_tol) {
  // K_{o,s} ~ U W, U = Q_r U_s, W = S V^T: a column-pivoted QR K P = Q R truncated where
  // |R_kk| <= rel_tol ref / 100 (rank-revealing, robust), then the SVD of the small factor
  // R_r P^T = U_s S V^T truncated where sigma_k <= rel_tol ref (the ranks of an SVD of K,
  // without its cost). ref = the largest column norm of the four symmetry blocks of the same
  // offset: a block much smaller than its siblings (odd-odd symmetry far away) is truncated
  // against the offset's scale, not its own. Stored where that halves the work (doc/theory.md, after eq. (4.6)); the
  // blocks are smooth kernels between boxes, so their rank falls fast with the box offset o.
  // (Eigen 3.4's divide-and-conquer SVD of the whole block returned NaN for some of these
  // blocks and read out of bounds for others.) A block whose factors do not reproduce it to
  // 10 rel_tol ref stays dense.
  const int nh = pxy_ * pxy_ * pz_ / 4;
  // above nh = 256 (accuracy 1e-6 and tighter) the factorisations cost more set-up (seconds per
  // column) than they save in the few evaluations such runs make: the operator stays dense
  if (nh > kMaxCompressedBlock) return;
  std::vector<double> ref(nb_, 0.0);
  for (std::size_t k = 0; k < ops_.size(); ++k)
    ref[k / 4] = std::max(ref[k / 4],
                          Eigen::Map<const Eigen::MatrixXd>(ops_[k].data(), nh, nh).colwise().norm().maxCoeff());
  for (std::size_t k = 0; k < ops_.size(); ++k) {
    const Eigen::Map<const Eigen::MatrixXd> m(ops_[k].data(), nh, nh);
    const double scale = ref[k / 4];
    if (!std::isfinite(scale) || !(scale > 0.0)) continue;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(m);
    const Eigen::MatrixXd &packed_qr = qr.matrixQR();
    int rq = 0;
    while (rq < nh && std::fabs(packed_qr(rq, rq)) > 0.01 * rel_tol * scale) ++rq;
    if (4 * rq > 3 * nh) continue;
    if (rq == 0) {
      // every column is below 0.01 rel_tol ref (a far odd-odd block at a loose accuracy): the
      // block is zero to the tolerance. (Eigen's JacobiSVD of the empty factor crashed here.)
      std::vector<double>().swap(ops_[k]);
      rank_[k] = 0;
      continue;
    }
    const Eigen::MatrixXd rr = packed_qr.topRows(rq).triangularView<Eigen::Upper>();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rr * qr.colsPermutation().transpose(),
                                                Eigen::ComputeThinU | Eigen::ComputeThinV);
    const auto &sv = svd.singularValues();
    if (!sv.allFinite()) continue;
    int r = 0;
    while (r < sv.size() && sv[r] > rel_tol * scale) ++r;
    if (2 * r >= nh) continue;
    const Eigen::MatrixXd uf =
        qr.householderQ() * Eigen::MatrixXd::Identity(nh, rq) * svd.matrixU().leftCols(r);
    const Eigen::MatrixXd wf = sv.head(r).asDiagonal() * svd.matrixV().leftCols(r).transpose();
    if (!uf.allFinite() || !wf.allFinite() ||
        !((uf * wf - m).cwiseAbs().maxCoeff() <= 10.0 * rel_tol * scale))
      continue;
    std::vector<double> packed(2 * static_cast<std::size_t>(nh) * r);
    Eigen::Map<Eigen::MatrixXd>(packed.data(), nh, r) = uf;
    Eigen::Map<Eigen::MatrixXd>(packed.data() + static_cast<std::size_t>(nh) * r, r, nh) = wf;
    ops_[k].swap(packed);
    rank_[k] = r;
  }
}

namespace {

void to_sym(int p, int pz, const Eigen::MatrixXd &w, Eigen::MatrixXd *v) {
  // v_s(a,b,c) = 1/4 sum_{gx,gy} sx^gx sy^gy w(m_gx(a), m_gy(b), c), a, b < p/2
  const int h = p / 2;
  for (int sym = 0; sym < 4; ++sym) v[sym].resize(h * h * pz, w.cols());
  for (Eigen::Index col = 0; col < w.cols(); ++col)
    for (int a = 0; a < h; ++a)
      for (int b = 0; b < h; ++b) {
        const double *w00 = w.col(col).data() + (a * p + b) * pz;
        const double *w10 = w.col(col).data() + ((p - 1 - a) * p + b) * pz;
        const double *w01 = w.col(col).data() + (a * p + p - 1 - b) * pz;
        const double *w11 = w.col(col).data() + ((p - 1 - a) * p + p - 1 - b) * pz;
        double *v0 = v[0].col(col).data() + (a * h + b) * pz, *v1 = v[1].col(col).data() + (a * h + b) * pz;
        double *v2 = v[2].col(col).data() + (a * h + b) * pz, *v3 = v[3].col(col).data() + (a * h + b) * pz;
        for (int c = 0; c < pz; ++c) {
          v0[c] = 0.25 * (w00[c] + w10[c] + w01[c] + w11[c]);
          v1[c] = 0.25 * (w00[c] - w10[c] + w01[c] - w11[c]);
          v2[c] = 0.25 * (w00[c] + w10[c] - w01[c] - w11[c]);
          v3[c] = 0.25 * (w00[c] - w10[c] - w01[c] + w11[c]);
        }
      }
}

void from_sym(int p, int pz, const Eigen::MatrixXd *u, Eigen::MatrixXd &phi) {
  // phi(m_fx(a), m_fy(b), c) = sum_s sx^fx sy^fy u_s(a,b,c)
  const int h = p / 2;
  phi.resize(p * p * pz, u[0].cols());
  for (Eigen::Index col = 0; col < u[0].cols(); ++col)
    for (int a = 0; a < h; ++a)
      for (int b = 0; b < h; ++b) {
        double *f00 = phi.col(col).data() + (a * p + b) * pz;
        double *f10 = phi.col(col).data() + ((p - 1 - a) * p + b) * pz;
        double *f01 = phi.col(col).data() + (a * p + p - 1 - b) * pz;
        double *f11 = phi.col(col).data() + ((p - 1 - a) * p + p - 1 - b) * pz;
        const double *u0 = u[0].col(col).data() + (a * h + b) * pz, *u1 = u[1].col(col).data() + (a * h + b) * pz;
        const double *u2 = u[2].col(col).data() + (a * h + b) * pz, *u3 = u[3].col(col).data() + (a * h + b) * pz;
        for (int c = 0; c < pz; ++c) {
          f00[c] = u0[c] + u1[c] + u2[c] + u3[c];
          f10[c] = u0[c] - u1[c] + u2[c] - u3[c];
          f01[c] = u0[c] + u1[c] - u2[c] - u3[c];
          f11[c] = u0[c] - u1[c] - u2[c] + u3[c];
        }
      }
}

}  // namespace

void PeriodicFarField::apply(const double *wp, double *phip, int src_lo, int src_hi, int tgt_lo,
                             int tgt_hi) const {
  // phi_t = sum_s M_{t-s} w_s over the source boxes s in [src_lo, src_hi) and the target boxes
  // t in [tgt_lo, tgt_hi), per symmetry block (K_{-o} = K_o^T, doc/theory.md, eq. (4.6)); w is
  // zero outside the source boxes, phi is left zero outside the target boxes. A deposition
  // occupies a few boxes at the bottom of a column stored to the lid: the empty ones cost nothing.
  const int nn = pxy_ * pxy_ * pz_, nh = nn / 4;
  const Eigen::Map<const Eigen::MatrixXd> w(wp, nn, nb_);
  Eigen::MatrixXd v[4], u[4], phi, tmp;
  to_sym(pxy_, pz_, w, v);
  for (int sym = 0; sym < 4; ++sym) {
    u[sym].setZero(nh, nb_);
    for (int o = 0; o < nb_; ++o) {
      const std::size_t blk = 4 * static_cast<std::size_t>(o) + sym;
      const int r = rank_[blk];
      if (r == 0) continue;    // zero to the compression tolerance
      const double *data = ops_[blk].data();
      // targets t = s + o (K_o) for the sources s in [up_lo, up_hi); targets t = s - o
      // (K_{-o} = K_o^T) for the sources s in [down_lo, down_hi)
      const int up_lo = std::max(src_lo, tgt_lo - o), up_hi = std::min(src_hi, tgt_hi - o);
      const int down_lo = std::max(src_lo, tgt_lo + o), down_hi = std::min(src_hi, tgt_hi + o);
      const int up = up_hi - up_lo, down = o > 0 ? down_hi - down_lo : 0;
      if (r == nh) {
        const Eigen::Map<const Eigen::MatrixXd> k(data, nh, nh);
        if (up > 0) u[sym].middleCols(up_lo + o, up).noalias() += k * v[sym].middleCols(up_lo, up);
        if (down > 0)
          u[sym].middleCols(down_lo - o, down).noalias() += k.transpose() * v[sym].middleCols(down_lo, down);
      } else {
        // compressed: K_o = U W
        const Eigen::Map<const Eigen::MatrixXd> uf(data, nh, r), wf(data + static_cast<std::size_t>(nh) * r, r, nh);
        if (up > 0) {
          tmp.noalias() = wf * v[sym].middleCols(up_lo, up);
          u[sym].middleCols(up_lo + o, up).noalias() += uf * tmp;
        }
        if (down > 0) {
          tmp.noalias() = uf.transpose() * v[sym].middleCols(down_lo, down);
          u[sym].middleCols(down_lo - o, down).noalias() += wf.transpose() * tmp;
        }
      }
    }
  }
  from_sym(pxy_, pz_, u, phi);
  Eigen::Map<Eigen::MatrixXd>(phip, nn, nb_) = phi;
}

int PeriodicFarField::locate(std::size_t i, double x, double y, double z, double *tx, double *ty,
                             double *tz) const {
  const double mx = 0.01 * lx_, my = 0.01 * ly_, mz = 0.01 * std::min(lx_, ly_);
  if (!(x >= x0_ - mx && x <= x0_ + lx_ + mx && y >= y0_ - my && y <= y0_ + ly_ + my &&
        z >= zlo_ - mz && z <= zhi_ + mz))
    throw std::invalid_argument("gcfmm::PeriodicFarField::evaluate: particle " + std::to_string(i) +
                                " outside the primary cell or the stored z range (call setup again)");
  *tx = 2.0 * (x - x0_) / lx_ - 1.0;
  *ty = 2.0 * (y - y0_) / ly_ - 1.0;
  int b = static_cast<int>(std::floor((z - zlo_) / hz_));
  b = std::max(0, std::min(b, nb_ - 1));
  *tz = 2.0 * (z - zlo_ - b * hz_) / hz_ - 1.0;
  return b;
}

void PeriodicFarField::interpolate(const double *phi, const double *x, const double *y,
                                   const double *z, std::size_t begin, std::size_t end, double *pot,
                                   double *ex, double *ey, double *ez) const {
  const int p = pxy_, pz = pz_;
  double sx[32], sy[32], sz[32], dsx[32], dsy[32], dsz[32];
  const double fx = 2.0 / lx_, fy = 2.0 / ly_, fz = 2.0 / hz_;
  for (std::size_t i = begin; i < end; ++i) {
    double tx, ty, tz;
    const int b = locate(i, x[i], y[i], z[i], &tx, &ty, &tz);
    interp_weights(tx, p, tab_xy_.data(), sx, dsx);
    interp_weights(ty, p, tab_xy_.data(), sy, dsy);
    interp_weights(tz, pz, tab_z_.data(), sz, dsz);
    const double *col = phi + static_cast<std::size_t>(b) * p * p * pz;
    double f = 0, gx = 0, gy = 0, gz = 0;
    for (int a = 0; a < p; ++a) {
      double fa = 0, fya = 0, fza = 0;
      for (int bb = 0; bb < p; ++bb) {
        const double *src = col + (a * p + bb) * pz;
        double v = 0, vz = 0;
        for (int c = 0; c < pz; ++c) {
          v += sz[c] * src[c];
          vz += dsz[c] * src[c];
        }
        fa += sy[bb] * v;
        fya += dsy[bb] * v;
        fza += sy[bb] * vz;
      }
      f += sx[a] * fa;
      gx += dsx[a] * fa;
      gy += sx[a] * fya;
      gz += sx[a] * fza;
    }
    if (pot) pot[i] += f;
    ex[i] -= fx * gx;
    ey[i] -= fy * gy;
    ez[i] -= fz * gz;
  }
}

double PeriodicFarField::sample_error() const {
  // interpolated vs exact kernel gradient for unit sources at random points, each seen from
  // random targets (the operator applied from the source's box only)
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int ns = 12, nt = 48, p = pxy_, pz = pz_, nn = p * p * pz;
  std::vector<double> xt(nt), yt(nt), zt(nt), ex(nt), ey(nt), ez(nt);
  double sx[32], sy[32], sz[32];
  Eigen::MatrixXd w(nn, nb_), phi(nn, nb_);
  double sum2 = 0;
  for (int s = 0; s < ns; ++s) {
    const double xs = x0_ + lx_ * u01(rng), ys = y0_ + ly_ * u01(rng);
    const double zs = zlo_ + (zhi_ - zlo_) * u01(rng);
    double tx, ty, tz;
    const int bs = locate(0, xs, ys, zs, &tx, &ty, &tz);
    interp_weights(tx, p, tab_xy_.data(), sx, nullptr);
    interp_weights(ty, p, tab_xy_.data(), sy, nullptr);
    interp_weights(tz, pz, tab_z_.data(), sz, nullptr);
    w.setZero();
    for (int a = 0; a < p; ++a)
      for (int b = 0; b < p; ++b)
        for (int c = 0; c < pz; ++c) w((a * p + b) * pz + c, bs) = sx[a] * sy[b] * sz[c];
    apply(w.data(), phi.data(), bs, bs + 1, 0, nb_);
    for (int t = 0; t < nt; ++t) {
      xt[t] = x0_ + lx_ * u01(rng);
      yt[t] = y0_ + ly_ * u01(rng);
      zt[t] = zlo_ + (zhi_ - zlo_) * u01(rng);
      ex[t] = ey[t] = ez[t] = 0.0;
    }
    interpolate(phi.data(), xt.data(), yt.data(), zt.data(), 0, nt, nullptr, ex.data(), ey.data(), ez.data());
    for (int t = 0; t < nt; ++t) {
      double gx, gy, gz;
      far_kernel(xt[t] - xs, yt[t] - ys, zt[t] - zs, lx_, ly_, images_, nullptr, &gx, &gy, &gz);
      sum2 += (ex[t] + gx) * (ex[t] + gx) + (ey[t] + gy) * (ey[t] + gy) + (ez[t] + gz) * (ez[t] + gz);
    }
  }
  return std::sqrt(sum2 / (ns * nt)) / (2.0 * kPi / (lx_ * ly_));
}

void PeriodicFarField::evaluate(std::size_t n, const double *x, const double *y, const double *z,
                                const double *q, std::size_t begin, std::size_t end, double *pot,
                                double *ex, double *ey, double *ez, int part, int nparts,
                                const PartSum &sum) const {
  if (!ready()) throw std::logic_error("gcfmm::PeriodicFarField::evaluate: setup() not called");
  if (end > n || begin > end)
    throw std::invalid_argument("gcfmm::PeriodicFarField::evaluate: bad target range");
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument("gcfmm::PeriodicFarField::evaluate: need 0 <= part < nparts");
  const int p = pxy_, pz = pz_, nn = p * p * pz;
  double sx[32], sy[32], sz[32];
  // anterpolation: node charges W_b = sum_j q_j S(r_j) (exact total charge per box). Every
  // node sums over j in the same order whichever partition computes it, so splitting the x
  // nodes a in [a0, a1) among the partitions keeps W bit-identical.
  const bool split = sum && nparts > 1;
  const int a0 = split ? p * part / nparts : 0, a1 = split ? p * (part + 1) / nparts : p;
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(nn, nb_);
  // the boxes holding particles (targets) and charges (sources): taken over all n particles,
  // not over [begin, end), so that every partition applies the same products and the sum of
  // the partitions stays bit-identical to one evaluation of all targets
  int src_lo = nb_, src_hi = 0, tgt_lo = nb_, tgt_hi = 0;
  for (std::size_t j = 0; j < n; ++j) {
    double tx, ty, tz;
    const int b = locate(j, x[j], y[j], z[j], &tx, &ty, &tz);
    tgt_lo = std::min(tgt_lo, b);
    tgt_hi = std::max(tgt_hi, b + 1);
    if (q[j] == 0.0) continue;
    src_lo = std::min(src_lo, b);
    src_hi = std::max(src_hi, b + 1);
    if (a0 == a1) continue;
    interp_weights(tx, p, tab_xy_.data(), sx, nullptr);
    interp_weights(ty, p, tab_xy_.data(), sy, nullptr);
    interp_weights(tz, pz, tab_z_.data(), sz, nullptr);
    double *col = w.col(b).data();
    for (int a = a0; a < a1; ++a) {
      const double qa = q[j] * sx[a];
      for (int bb = 0; bb < p; ++bb) {
        const double qab = qa * sy[bb];
        double *dst = col + (a * p + bb) * pz;
        for (int c = 0; c < pz; ++c) dst[c] += qab * sz[c];
      }
    }
  }
  // only the source boxes' node charges are nonzero (columns are contiguous)
  if (split && src_hi > src_lo)
    sum(w.col(src_lo).data(), static_cast<std::size_t>(nn) * (src_hi - src_lo));
  Eigen::MatrixXd phi(nn, nb_);
  apply(w.data(), phi.data(), src_lo, src_hi, tgt_lo, tgt_hi);
  interpolate(phi.data(), x, y, z, begin, end, pot, ex, ey, ez);
}

}  // namespace gcfmm
