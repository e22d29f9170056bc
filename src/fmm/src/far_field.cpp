// GRANULAR-CHARGED FMM core library (gcfmm).
// The exact far field (doc/theory.md, eq. (4.6)), evaluation: anterpolation of the charges to
// the Chebyshev nodes of the column's boxes, the operator applied between boxes, interpolation
// of potential and field at the targets, and the sampled error of the interpolated kernel.
// Set-up: far_field_setup.cpp. Conventions: include/gcfmm/far_field.hpp.
#include "gcfmm/far_field.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "far_field_batch.hpp"
#include "gcfmm/lattice_sum.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

// the per-particle arrays of one anterpolation or interpolation, kept between calls (one set
// per thread: callers may evaluate on several threads)
struct PeriodicFarField::FarFieldScratch {
  std::vector<int> box_of;
  std::vector<double> t_all;
  std::vector<std::size_t> box_start, fill, order;
  std::vector<double> tx, ty, tz, q, sx, dsx, sy, dsy, sz, dsz, f, gx, gy, gz;
  int tgt_lo = 0, tgt_hi = 0;
  // weights of n particles (and their derivatives) for p nodes in x and y, pz in z
  void weights(std::size_t n, int p, int pz, bool derivatives) {
    sx.resize(n * p);
    sy.resize(n * p);
    sz.resize(n * pz);
    if (!derivatives) return;
    dsx.resize(n * p);
    dsy.resize(n * p);
    dsz.resize(n * pz);
  }
};

PeriodicFarField::FarFieldScratch &PeriodicFarField::far_field_scratch() {
  thread_local FarFieldScratch scratch;
  return scratch;
}

void PeriodicFarField::interp_weights(double t, int p, const double *tab, double *s, double *ds, double *d2s) {
  detail::chebyshev_lagrange_weights<double>(t, p, tab, s, ds, d2s);
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
  if (end <= begin) return;
  const int p = pxy_, pz = pz_;
  const std::size_t n = end - begin;
  FarFieldScratch &sc = far_field_scratch();
  sort_by_box(begin, end, x, y, z, nullptr, sc);
  sc.weights(n, p, pz, true);
  detail::chebyshev_weights(simd_path_, n, sc.tx.data(), p, tab_xy_.data(), n, sc.sx.data(), sc.dsx.data());
  detail::chebyshev_weights(simd_path_, n, sc.ty.data(), p, tab_xy_.data(), n, sc.sy.data(), sc.dsy.data());
  detail::chebyshev_weights(simd_path_, n, sc.tz.data(), pz, tab_z_.data(), n, sc.sz.data(), sc.dsz.data());
  sc.f.resize(n);
  sc.gx.resize(n);
  sc.gy.resize(n);
  sc.gz.resize(n);
  for (int b = 0; b < nb_; ++b) {
    const std::size_t r0 = sc.box_start[b], r1 = sc.box_start[b + 1];
    if (r1 == r0) continue;
    detail::interpolate_box(simd_path_, r1 - r0, p, pz, phi + static_cast<std::size_t>(b) * p * p * pz,
                            sc.sx.data() + r0, sc.dsx.data() + r0, sc.sy.data() + r0, sc.dsy.data() + r0,
                            sc.sz.data() + r0, sc.dsz.data() + r0, n, sc.f.data() + r0, sc.gx.data() + r0,
                            sc.gy.data() + r0, sc.gz.data() + r0);
  }
  const double fx = 2.0 / lx_, fy = 2.0 / ly_, fz = 2.0 / hz_;
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = sc.order[r];
    if (pot) pot[i] += sc.f[r];
    ex[i] -= fx * sc.gx[r];
    ey[i] -= fy * sc.gy[r];
    ez[i] -= fz * sc.gz[r];
  }
}

void PeriodicFarField::interpolate_gradient(const double *phi, const double *x, const double *y, const double *z,
                                            std::size_t begin, std::size_t end, double *pot, double *ex,
                                            double *ey, double *ez, double *g6) const {
  const int p = pxy_, pz = pz_;
  double sx[32], sy[32], sz[32], dsx[32], dsy[32], dsz[32], d2sx[32], d2sy[32], d2sz[32];
  const double fx = 2.0 / lx_, fy = 2.0 / ly_, fz = 2.0 / hz_;
  for (std::size_t i = begin; i < end; ++i) {
    double tx, ty, tz;
    const int b = locate(i, x[i], y[i], z[i], &tx, &ty, &tz);
    interp_weights(tx, p, tab_xy_.data(), sx, dsx, d2sx);
    interp_weights(ty, p, tab_xy_.data(), sy, dsy, d2sy);
    interp_weights(tz, pz, tab_z_.data(), sz, dsz, d2sz);
    const double *col = phi + static_cast<std::size_t>(b) * p * p * pz;
    // derivatives of the interpolant in the reference coordinates t
    const auto d = detail::contract_interpolant<true, double>(p, pz, col, sx, dsx, d2sx, sy, dsy, d2sy, sz, dsz, d2sz);
    if (pot) pot[i] += d.f;
    ex[i] -= fx * d.gx;
    ey[i] -= fy * d.gy;
    ez[i] -= fz * d.gz;
    double *g = g6 + 6 * i;  // G = -Hessian of the potential
    g[0] -= fx * fx * d.hxx;
    g[1] -= fx * fy * d.hxy;
    g[2] -= fx * fz * d.hxz;
    g[3] -= fy * fy * d.hyy;
    g[4] -= fy * fz * d.hyz;
    g[5] -= fz * fz * d.hzz;
  }
}

void PeriodicFarField::evaluate_dipoles(std::size_t n, const double *x, const double *y, const double *z,
                                        const double *q, const double *px, const double *py, const double *pz,
                                        std::size_t begin, std::size_t end, double *pot, double *ex, double *ey,
                                        double *ez, double *g6) const {
  if (!ready()) throw std::logic_error("gcfmm::PeriodicFarField::evaluate_dipoles: setup() not called");
  if (end > n || begin > end)
    throw std::invalid_argument("gcfmm::PeriodicFarField::evaluate_dipoles: bad target range");
  const int p = pxy_, nz = pz_, nn = p * p * nz;
  const double fx = 2.0 / lx_, fy = 2.0 / ly_, fz = 2.0 / hz_;
  double sx[32], sy[32], sz[32], dsx[32], dsy[32], dsz[32];
  std::vector<double> w(static_cast<std::size_t>(nn) * nb_, 0.0);
  int src_lo = nb_, src_hi = 0, tgt_lo = nb_, tgt_hi = 0;
  // node charges W_b = sum_j (q_j + p_j . grad_j) S_b(r_j): a dipole is the limit of two
  // opposite charges, so its potential is p . grad_y R(x - y) and its weights p . grad S
  for (std::size_t j = 0; j < n; ++j) {
    double tx, ty, tz;
    const int b = locate(j, x[j], y[j], z[j], &tx, &ty, &tz);
    tgt_lo = std::min(tgt_lo, b);
    tgt_hi = std::max(tgt_hi, b + 1);
    const double qj = q ? q[j] : 0.0;
    const double pxj = px ? px[j] : 0.0, pyj = py ? py[j] : 0.0, pzj = pz ? pz[j] : 0.0;
    if (qj == 0.0 && pxj == 0.0 && pyj == 0.0 && pzj == 0.0) continue;
    src_lo = std::min(src_lo, b);
    src_hi = std::max(src_hi, b + 1);
    interp_weights(tx, p, tab_xy_.data(), sx, dsx);
    interp_weights(ty, p, tab_xy_.data(), sy, dsy);
    interp_weights(tz, nz, tab_z_.data(), sz, dsz);
    double *col = w.data() + static_cast<std::size_t>(nn) * b;
    for (int a = 0; a < p; ++a) {
      const double wa = qj * sx[a] + pxj * fx * dsx[a];  // the part without a y or z derivative
      const double wya = pyj * fy * sx[a], wza = pzj * fz * sx[a];
      for (int bb = 0; bb < p; ++bb) {
        const double c0 = wa * sy[bb] + wya * dsy[bb], cz = wza * sy[bb];
        double *dst = col + (a * p + bb) * nz;
        for (int c = 0; c < nz; ++c) dst[c] += c0 * sz[c] + cz * dsz[c];
      }
    }
  }
  if (src_hi <= src_lo) return;
  Eigen::MatrixXd phi(nn, nb_);
  apply(w.data(), phi.data(), src_lo, src_hi, tgt_lo, tgt_hi);
  if (g6)
    interpolate_gradient(phi.data(), x, y, z, begin, end, pot, ex, ey, ez, g6);
  else
    interpolate(phi.data(), x, y, z, begin, end, pot, ex, ey, ez);
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
  const int nn = pxy_ * pxy_ * pz_;
  // anterpolation: node charges W_b = sum_j q_j S(r_j) (exact total charge per box). Every
  // node sums over j in the same order whichever partition computes it, so splitting the x
  // nodes a in [a0, a1) among the partitions keeps W bit-identical.
  const bool split = sum && nparts > 1;
  const int a0 = split ? pxy_ * part / nparts : 0, a1 = split ? pxy_ * (part + 1) / nparts : pxy_;
  std::vector<double> w;
  // the boxes holding particles (targets) and charges (sources): taken over all n particles,
  // not over [begin, end), so that every partition applies the same products and the sum of
  // the partitions stays bit-identical to one evaluation of all targets
  int src_lo, src_hi, tgt_lo, tgt_hi;
  anterpolate(n, x, y, z, q, a0, a1, w, &src_lo, &src_hi, &tgt_lo, &tgt_hi);
  // only the source boxes' node charges are nonzero (columns are contiguous)
  if (split && src_hi > src_lo)
    sum(w.data() + static_cast<std::size_t>(nn) * src_lo, static_cast<std::size_t>(nn) * (src_hi - src_lo));
  Eigen::MatrixXd phi(nn, nb_);
  apply(w.data(), phi.data(), src_lo, src_hi, tgt_lo, tgt_hi);
  interpolate(phi.data(), x, y, z, begin, end, pot, ex, ey, ez);
}

void PeriodicFarField::anterpolate(std::size_t n, const double *x, const double *y, const double *z,
                                   const double *q, int a0, int a1, std::vector<double> &w, int *src_lo,
                                   int *src_hi, int *tgt_lo, int *tgt_hi) const {
  const int p = pxy_, pz = pz_, nn = p * p * pz;
  w.assign(static_cast<std::size_t>(nn) * nb_, 0.0);
  FarFieldScratch &sc = far_field_scratch();
  // every particle is located (and checked); the charged ones are kept, in their order per box
  sort_by_box(0, n, x, y, z, q, sc);
  *tgt_lo = sc.tgt_lo;
  *tgt_hi = sc.tgt_hi;
  *src_lo = nb_;
  *src_hi = 0;
  for (int b = 0; b < nb_; ++b)
    if (sc.box_start[b + 1] > sc.box_start[b]) {
      *src_lo = std::min(*src_lo, b);
      *src_hi = b + 1;
    }
  const std::size_t m = sc.order.size();
  if (a0 == a1 || m == 0) return;
  sc.weights(m, p, pz, false);
  detail::chebyshev_weights(simd_path_, m, sc.tx.data(), p, tab_xy_.data(), m, sc.sx.data(), nullptr);
  detail::chebyshev_weights(simd_path_, m, sc.ty.data(), p, tab_xy_.data(), m, sc.sy.data(), nullptr);
  detail::chebyshev_weights(simd_path_, m, sc.tz.data(), pz, tab_z_.data(), m, sc.sz.data(), nullptr);
  for (int b = *src_lo; b < *src_hi; ++b) {
    const std::size_t r0 = sc.box_start[b], r1 = sc.box_start[b + 1];
    if (r1 == r0) continue;
    detail::anterpolate_box(simd_path_, r1 - r0, sc.q.data() + r0, p, pz, a0, a1, sc.sx.data() + r0,
                            sc.sy.data() + r0, sc.sz.data() + r0, m, w.data() + static_cast<std::size_t>(nn) * b);
  }
}

// the particles [begin, end) (with q: those with a nonzero charge) in the order of their boxes,
// each box's in their own order (a stable counting sort): their reference coordinates, index and
// charge, where each box's run starts, and the boxes holding any of [begin, end)
void PeriodicFarField::sort_by_box(std::size_t begin, std::size_t end, const double *x, const double *y,
                                   const double *z, const double *q, FarFieldScratch &sc) const {
  const std::size_t n = end - begin;
  sc.box_of.resize(n);
  sc.t_all.resize(3 * n);
  sc.box_start.assign(static_cast<std::size_t>(nb_) + 1, 0);
  sc.tgt_lo = nb_;
  sc.tgt_hi = 0;
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = begin + k;
    const int b = locate(i, x[i], y[i], z[i], &sc.t_all[3 * k], &sc.t_all[3 * k + 1], &sc.t_all[3 * k + 2]);
    sc.tgt_lo = std::min(sc.tgt_lo, b);
    sc.tgt_hi = std::max(sc.tgt_hi, b + 1);
    if (q && q[i] == 0.0) {
      sc.box_of[k] = -1;
      continue;
    }
    sc.box_of[k] = b;
    ++sc.box_start[b + 1];
    ++kept;
  }
  for (int b = 0; b < nb_; ++b) sc.box_start[b + 1] += sc.box_start[b];
  sc.order.resize(kept);
  sc.tx.resize(kept);
  sc.ty.resize(kept);
  sc.tz.resize(kept);
  if (q) sc.q.resize(kept);
  sc.fill.assign(sc.box_start.begin(), sc.box_start.end() - 1);
  for (std::size_t k = 0; k < n; ++k) {
    const int b = sc.box_of[k];
    if (b < 0) continue;
    const std::size_t r = sc.fill[b]++;
    sc.order[r] = begin + k;
    sc.tx[r] = sc.t_all[3 * k];
    sc.ty[r] = sc.t_all[3 * k + 1];
    sc.tz[r] = sc.t_all[3 * k + 2];
    if (q) sc.q[r] = q[begin + k];
  }
}

void PeriodicFarField::node_potentials(std::size_t n, const double *x, const double *y, const double *z,
                                       const double *q, std::vector<double> &phi) const {
  if (!ready()) throw std::logic_error("gcfmm::PeriodicFarField::node_potentials: setup() not called");
  const std::size_t size = static_cast<std::size_t>(pxy_) * pxy_ * pz_ * nb_;
  phi.assign(size, 0.0);
  if (n == 0) return;
  std::vector<double> w;
  int src_lo, src_hi, tgt_lo, tgt_hi;
  anterpolate(n, x, y, z, q, 0, pxy_, w, &src_lo, &src_hi, &tgt_lo, &tgt_hi);
  if (src_hi <= src_lo) return;  // no charge
  // the targets may be anywhere in the column: the node potentials of every box
  apply(w.data(), phi.data(), src_lo, src_hi, 0, nb_);
}

void PeriodicFarField::interpolate_at(const std::vector<double> &phi, std::size_t n, const double *x,
                                      const double *y, const double *z, double *pot, double *ex, double *ey,
                                      double *ez) const {
  if (!ready()) throw std::logic_error("gcfmm::PeriodicFarField::interpolate_at: setup() not called");
  if (phi.size() != static_cast<std::size_t>(pxy_) * pxy_ * pz_ * nb_)
    throw std::invalid_argument("gcfmm::PeriodicFarField::interpolate_at: node potentials of another set-up");
  interpolate(phi.data(), x, y, z, 0, n, pot, ex, ey, ez);
}

}  // namespace gcfmm
