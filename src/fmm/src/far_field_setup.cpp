// GRANULAR-CHARGED FMM core library (gcfmm).
// The exact far field (doc/theory.md, eq. (4.6)), set-up: the parameter sets, the operator
// blocks of the column (the smooth far kernel R on the Chebyshev nodes) and their low-rank
// compression. Evaluation: far_field.cpp. Conventions: include/gcfmm/far_field.hpp;
// parameters and measurements: doc/fmm-far-field.md.
#include "gcfmm/far_field.hpp"

#include <Eigen/Dense>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "gcfmm/lattice_sum.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

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
    {0.0, 14, 12, 0.7, 4.3e-9},    // down to kFinestFarFieldAccuracy
};

const ParamSet &params_for(double accuracy) {
  const ParamSet *ps = kParams;
  while (accuracy < ps->from) ++ps;    // the last set's `from` is 0
  return *ps;
}

}  // namespace

void PeriodicFarField::parameters_for(double accuracy, int *pxy, int *pz, double *hz_over_l) {
  if (!(accuracy >= kFinestFarFieldAccuracy) || !(accuracy < 1.0)) {
    char what[96];
    std::snprintf(what, sizeof what, "gcfmm::PeriodicFarField: accuracy must be in [%g, 1), got %g",
                  kFinestFarFieldAccuracy, accuracy);
    throw std::invalid_argument(what);
  }
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
  const auto t_start = std::chrono::steady_clock::now();
  build_operator(x0, y0, lx, ly, zlo, zhi, images, pxy, pz, hzl * std::min(lx, ly));
  compress(kCompressionPerAccuracy * accuracy);
  accuracy_ = accuracy;
  // the sample sees the compressed operator
  est_error_ = std::max(kSampleToError * sample_error(), params_for(accuracy).measured);
  setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
}

void PeriodicFarField::setup_explicit(double x0, double y0, double lx, double ly, double zlo,
                                      double zhi, int images, int pxy, int pz, double hz_max) {
  const auto t_start = std::chrono::steady_clock::now();
  build_operator(x0, y0, lx, ly, zlo, zhi, images, pxy, pz, hz_max);
  accuracy_ = 0.0;
  est_error_ = kSampleToError * sample_error();
  setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
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

// the stored column: the caller's range padded for a growing column, split into boxes of
// height <= hz_max
int column_boxes(double zlo, double zhi, double lmin, double hz_max, double *zlo_p, double *zhi_p) {
  const double pad = 0.1 * (zhi - zlo) + 0.1 * lmin;  // headroom for a growing column
  *zlo_p = zlo - pad;
  *zhi_p = zhi + pad;
  const double boxes = std::ceil((*zhi_p - *zlo_p) / hz_max - 1e-9);
  // a count beyond int (H/L ~ 1e9) is refused by the memory limit all the same
  return boxes > 1e9 ? 1000000000 : std::max(1, static_cast<int>(boxes));
}

}  // namespace

double PeriodicFarField::setup_bytes(double lx, double ly, double zlo, double zhi, int pxy, int pz,
                                     double hz_max, int *boxes) {
  double zlo_p = 0, zhi_p = 0;
  const int nb = column_boxes(zlo, zhi, std::min(lx, ly), hz_max, &zlo_p, &zhi_p);
  if (boxes) *boxes = nb;
  // at the peak of build_operator(): the dense blocks (4 per box offset, (p^2 pz / 4)^2), the
  // table of R on the distinct node differences (|dx| and |dy| as counted there; in z at most
  // the distinct t_c - t_d per box offset) and the z differences with their indices (12 bytes)
  std::vector<double> vals;
  std::vector<int> idx;
  const auto distinct = [&](int p, bool absolute) {
    const auto t = cheb_nodes(p);
    std::vector<double> d(static_cast<std::size_t>(p) * p);
    for (int a = 0; a < p; ++a)
      for (int b = 0; b < p; ++b) d[a * p + b] = absolute ? std::fabs(t[a] - t[b]) : t[a] - t[b];
    uniq(d, 1e-13, vals, idx);
    return static_cast<double>(vals.size());
  };
  const double nh = 0.25 * pxy * pxy * pz, nxy = distinct(pxy, true);
  const double nz = double(nb) * distinct(pz, false), ndz = double(nb) * pz * pz;
  return sizeof(double) * (4.0 * nb * nh * nh + nxy * nxy * nz) + 12.0 * ndz;
}

void PeriodicFarField::build_operator(double x0, double y0, double lx, double ly, double zlo,
                                      double zhi, int images, int pxy, int pz, double hz_max) {
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
  // the cost grows with the column's height: refuse before allocating anything
  int nb = 0;
  const double bytes = setup_bytes(lx, ly, zlo, zhi, pxy, pz, hz_max, &nb);
  if (bytes > kMaxSetupBytes) {
    double zlo_p = 0, zhi_p = 0;
    column_boxes(zlo, zhi, std::min(lx, ly), hz_max, &zlo_p, &zhi_p);
    const double hl = (zhi_p - zlo_p) / std::min(lx, ly);    // padded, as stored
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "gcfmm::PeriodicFarField: the exact far field of a column %.3g cell sides high "
                  "needs %d boxes and about %.3g GB to set up (limit %.3g GB, per process): use "
                  "FarField::Average or FarField::None, or a lower column",
                  hl, nb, bytes / 1e9, kMaxSetupBytes / 1e9);
    throw FarFieldTooLarge(bytes, nb, hl, buf);
  }
  x0_ = x0;
  y0_ = y0;
  lx_ = lx;
  ly_ = ly;
  images_ = images;
  pxy_ = pxy;
  pz_ = pz;
  nb_ = column_boxes(zlo, zhi, std::min(lx, ly), hz_max, &zlo_, &zhi_);
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

}  // namespace gcfmm
