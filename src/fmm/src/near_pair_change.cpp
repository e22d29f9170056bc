// GRANULAR-CHARGED FMM core library (gcfmm): the near pairs' change between evaluations
// (near_pair_change.hpp; doc/polarization.md, section 8).
#include "gcfmm/near_pair_change.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "gcfmm/dipole_kernels.hpp"

namespace gcfmm {

namespace {

// the cells of one axis next to cell c (itself included), each once: periodic axes wrap, and
// with fewer than three cells a neighbour seen twice is visited once
int neighbour_cells(int c, int cells, bool periodic, int out[3]) {
  int m = 0;
  for (int o = -1; o <= 1; ++o) {
    int k = c + o;
    if (periodic) {
      k = (k % cells + cells) % cells;
    } else if (k < 0 || k >= cells) {
      continue;
    }
    if (std::find(out, out + m, k) == out + m) out[m++] = k;
  }
  return m;
}

// the field terms of one source at a target displaced by d from it (gradient only for a dipole
// target: the force needs G p)
FieldTerms<double> source_terms(const double q, const double *p, const double d[3], bool gradient) {
  FieldTerms<double> t;
  const double rinv = 1.0 / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (gradient) {
    charge_terms<true>(q, d[0], d[1], d[2], rinv, t);
    if (p) dipole_terms<true>(p[0], p[1], p[2], d[0], d[1], d[2], rinv, t);
  } else {
    charge_terms<false>(q, d[0], d[1], d[2], rinv, t);
    if (p) dipole_terms<false>(p[0], p[1], p[2], d[0], d[1], d[2], rinv, t);
  }
  return t;
}

// diff += a - b, term by term: per pair, now minus then (the small change of two large terms)
void add_change(const FieldTerms<double> &a, const FieldTerms<double> &b, FieldTerms<double> &diff) {
  diff.pot += a.pot - b.pot;
  diff.ex += a.ex - b.ex;
  diff.ey += a.ey - b.ey;
  diff.ez += a.ez - b.ez;
  diff.gxx += a.gxx - b.gxx;
  diff.gxy += a.gxy - b.gxy;
  diff.gxz += a.gxz - b.gxz;
  diff.gyy += a.gyy - b.gyy;
  diff.gyz += a.gyz - b.gyz;
  diff.gzz += a.gzz - b.gzz;
}

}  // namespace

NearPairChange::NearPairChange(double cutoff, const NearGeometry &geometry) : cutoff_(cutoff), geo_(geometry) {
  if (!(cutoff > 0.0) || !std::isfinite(cutoff))
    throw std::invalid_argument("gcfmm: the near cutoff must be > 0, got " + std::to_string(cutoff));
  if (geo_.periodic && !(geo_.lx > 0.0 && geo_.ly > 0.0))
    throw std::invalid_argument("gcfmm: a periodic near refresh needs periods > 0");
}

bool NearPairChange::fits(double max_displacement) const {
  if (!geo_.periodic) return true;
  return cutoff_ + 2.0 * max_displacement < 0.5 * std::min(geo_.lx, geo_.ly);
}

bool NearPairChange::compute(std::size_t n, const double *now, const double *then, const double *q,
                             const double *p, const std::size_t *targets, std::size_t nt, NearChange &out) {
  double dmax2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) d2 += (now[3 * i + a] - then[3 * i + a]) * (now[3 * i + a] - then[3 * i + a]);
    dmax2 = std::max(dmax2, d2);
    if (geo_.electrode && !(now[3 * i + 2] > geo_.electrode_z))
      throw std::invalid_argument("gcfmm: particle " + std::to_string(i) + " is not above the electrode");
  }
  const double dmax = std::sqrt(dmax2);
  if (!fits(dmax)) return false;
  out.field.assign(3 * nt, 0.0);
  out.pot.assign(nt, 0.0);
  out.force.assign(3 * nt, 0.0);
  pairs_ = 0;
  if (n == 0) return true;
  // every pair near at either end is closer than reach now
  const double reach = cutoff_ + 2.0 * dmax, rc2 = cutoff_ * cutoff_;

  sources_.clear();
  for (std::size_t j = 0; j < n; ++j) {
    Source s{};
    for (int a = 0; a < 3; ++a) {
      s.now[a] = now[3 * j + a];
      s.then[a] = then[3 * j + a];
      s.p[a] = p ? p[3 * j + a] : 0.0;
    }
    s.q = q[j];
    s.particle = j;
    s.image = false;
    sources_.push_back(s);
  }
  // an image is near a particle only if its own particle is within the cutoff of the plane
  if (geo_.electrode) {
    const double z0 = geo_.electrode_z;
    for (std::size_t j = 0; j < n; ++j) {
      if (std::min(now[3 * j + 2], then[3 * j + 2]) - z0 >= cutoff_) continue;
      Source s = sources_[j];
      s.now[2] = 2.0 * z0 - s.now[2];
      s.then[2] = 2.0 * z0 - s.then[2];
      s.q = image_charge(s.q);
      const Vec3 ip = image_dipole({s.p[0], s.p[1], s.p[2]});
      s.p[0] = ip.x;
      s.p[1] = ip.y;
      s.p[2] = ip.z;
      s.image = true;
      sources_.push_back(s);
    }
  }

  // cells of at least `reach` on the sources' positions now (periodic axes: the period)
  const std::size_t ns = sources_.size();
  double lo[3], extent[3];
  int cells[3];
  const bool wrap[3] = {geo_.periodic, geo_.periodic, false};
  for (int a = 0; a < 3; ++a) {
    double mn = sources_[0].now[a], mx = mn;
    for (const Source &s : sources_) {
      mn = std::min(mn, s.now[a]);
      mx = std::max(mx, s.now[a]);
    }
    lo[a] = wrap[a] ? 0.0 : mn;
    extent[a] = wrap[a] ? (a == 0 ? geo_.lx : geo_.ly) : mx - mn;
    cells[a] = std::max(1, (int) std::floor(extent[a] / reach));
  }
  // a tall, sparse column: no more cells than a few per source
  const long cap = 4 * (long) ns + 64;
  if ((long) cells[0] * cells[1] * cells[2] > cap) cells[2] = std::max(1L, cap / ((long) cells[0] * cells[1]));
  auto cell_of = [&](const double *r, int c[3]) {
    for (int a = 0; a < 3; ++a) {
      double f = extent[a] > 0.0 ? (r[a] - lo[a]) / extent[a] : 0.0;
      if (wrap[a]) f -= std::floor(f);
      c[a] = std::min(cells[a] - 1, std::max(0, (int) (f * cells[a])));
    }
    return (c[2] * cells[1] + c[1]) * cells[0] + c[0];
  };
  const std::size_t ncells = (std::size_t) cells[0] * cells[1] * cells[2];
  cell_start_.assign(ncells + 1, 0);
  cell_items_.resize(ns);
  std::vector<std::size_t> cell_index(ns);
  int c[3];
  for (std::size_t k = 0; k < ns; ++k) {
    cell_index[k] = cell_of(sources_[k].now, c);
    ++cell_start_[cell_index[k] + 1];
  }
  for (std::size_t k = 0; k < ncells; ++k) cell_start_[k + 1] += cell_start_[k];
  std::vector<std::size_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t k = 0; k < ns; ++k) cell_items_[fill[cell_index[k]]++] = k;

  for (std::size_t t = 0; t < nt; ++t) {
    const std::size_t i = targets[t];
    const double *ri = now + 3 * i, *ri_then = then + 3 * i;
    const bool gradient = p != nullptr;
    cell_of(ri, c);
    int nb[3][3], m[3];
    for (int a = 0; a < 3; ++a) m[a] = neighbour_cells(c[a], cells[a], wrap[a], nb[a]);
    FieldTerms<double> diff;
    for (int cz = 0; cz < m[2]; ++cz)
      for (int cy = 0; cy < m[1]; ++cy)
        for (int cx = 0; cx < m[0]; ++cx) {
          const std::size_t cell = ((std::size_t) nb[2][cz] * cells[1] + nb[1][cy]) * cells[0] + nb[0][cx];
          for (std::size_t it = cell_start_[cell]; it < cell_start_[cell + 1]; ++it) {
            const Source &s = sources_[cell_items_[it]];
            if (s.particle == i) continue;    // itself; its own image is added below
            double dn[3], dt[3];
            for (int a = 0; a < 3; ++a) dn[a] = ri[a] - s.now[a];
            // the copy of the source nearest now, the same copy then
            double shift[3] = {0.0, 0.0, 0.0};
            if (geo_.periodic) {
              shift[0] = geo_.lx * std::round(dn[0] / geo_.lx);
              shift[1] = geo_.ly * std::round(dn[1] / geo_.ly);
            }
            for (int a = 0; a < 3; ++a) {
              dn[a] -= shift[a];
              dt[a] = ri_then[a] - s.then[a] - shift[a];
            }
            const double r2n = dn[0] * dn[0] + dn[1] * dn[1] + dn[2] * dn[2];
            const double r2t = dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2];
            if (!(r2n < rc2 || r2t < rc2)) continue;
            ++pairs_;
            const double *sp = p ? s.p : nullptr;
            const FieldTerms<double> a = source_terms(s.q, sp, dn, gradient);
            const FieldTerms<double> b = source_terms(s.q, sp, dt, gradient);
            add_change(a, b, diff);
          }
        }
    // its own image at any height: the image force -q^2 / (4 h^2) of a particle falling onto
    // the electrode changes fastest of all its far terms
    if (geo_.electrode) {
      const double z0 = geo_.electrode_z;
      const Vec3 ip = p ? image_dipole({p[3 * i], p[3 * i + 1], p[3 * i + 2]}) : Vec3{};
      const double ipv[3] = {ip.x, ip.y, ip.z};
      const double dn[3] = {0.0, 0.0, 2.0 * (ri[2] - z0)}, dt[3] = {0.0, 0.0, 2.0 * (ri_then[2] - z0)};
      const FieldTerms<double> a = source_terms(image_charge(q[i]), p ? ipv : nullptr, dn, gradient);
      const FieldTerms<double> b = source_terms(image_charge(q[i]), p ? ipv : nullptr, dt, gradient);
      ++pairs_;
      add_change(a, b, diff);
    }
    PointField change;
    add_terms(diff, change);
    const Vec3 &de = change.e;
    const Vec3 pi = p ? Vec3{p[3 * i], p[3 * i + 1], p[3 * i + 2]} : Vec3{};
    const Vec3 df = point_force(q[i], pi, change);
    out.pot[t] = change.pot;
    out.field[3 * t] = de.x;
    out.field[3 * t + 1] = de.y;
    out.field[3 * t + 2] = de.z;
    out.force[3 * t] = df.x;
    out.force[3 * t + 1] = df.y;
    out.force[3 * t + 2] = df.z;
  }
  return true;
}

}  // namespace gcfmm
