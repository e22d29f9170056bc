// GRANULAR-CHARGED FMM core library (gcfmm).
// O(N^2) reference for charges, induced dipoles, applied field and grounded plane
// (direct_polarizable.hpp; doc/polarization.md).
#include "gcfmm/direct_polarizable.hpp"

#include <stdexcept>
#include <string>

namespace gcfmm {

namespace {

struct Sources {
  bool charges = true;
  bool dipoles = true;
};

// The field at particle i of every source: the other particles and the periodic copies of all
// (own copies included), and with an electrode the mirror images of all of those (own image
// included). Dipoles from p (3 n) when dipoles is set.
PointField field_at(const PolarizableSystem &s, std::size_t i, const double *p, Sources what)
{
  PointField f;
  const Vec3 ri{s.x[i], s.y[i], s.z[i]};
  const int m = (s.lx > 0.0 && s.ly > 0.0) ? s.images : 0;
  for (int a = -m; a <= m; ++a)
    for (int b = -m; b <= m; ++b)
      for (std::size_t j = 0; j < s.n; ++j) {
        const Vec3 rj{s.x[j] + a * s.lx, s.y[j] + b * s.ly, s.z[j]};
        const Vec3 pj = p ? Vec3{p[3 * j], p[3 * j + 1], p[3 * j + 2]} : Vec3{};
        const bool self = (j == i && a == 0 && b == 0);
        if (!self) {
          if (what.charges && s.q[j] != 0.0) add_charge(s.q[j], ri - rj, f);
          if (what.dipoles && p) add_dipole(pj, ri - rj, f);
        }
        if (s.electrode) {
          const Vec3 rj_img = mirror_point(rj, s.electrode_z);
          if (what.charges && s.q[j] != 0.0) add_charge(image_charge(s.q[j]), ri - rj_img, f);
          if (what.dipoles && p) add_dipole(image_dipole(pj), ri - rj_img, f);
        }
      }
  return f;
}

}  // namespace

PolarizableResult solve_polarizable_direct(const PolarizableSystem &s,
                                           const PolarizationSettings &settings,
                                           const std::vector<Vec3> *start)
{
  if (s.electrode)
    for (std::size_t i = 0; i < s.n; ++i)
      if (!(s.z[i] > s.electrode_z))
        throw std::invalid_argument("gcfmm: particle " + std::to_string(i) +
                                    " is not above the electrode");
  const std::size_t n = s.n;
  PolarizableResult res;
  // E0: charges (with their images and copies) and the applied field
  std::vector<PointField> f0(n);
  std::vector<double> e0(3 * n), p(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    f0[i] = field_at(s, i, nullptr, {true, false});
    e0[3 * i] = f0[i].e.x + s.applied_field.x;
    e0[3 * i + 1] = f0[i].e.y + s.applied_field.y;
    e0[3 * i + 2] = f0[i].e.z + s.applied_field.z;
  }
  if (s.alpha) {
    if (start)
      for (std::size_t i = 0; i < n; ++i) {
        p[3 * i] = (*start)[i].x;
        p[3 * i + 1] = (*start)[i].y;
        p[3 * i + 2] = (*start)[i].z;
      }
    const DipoleFieldOperator dipole_field = [&](const double *pv, double *out) {
      for (std::size_t i = 0; i < n; ++i) {
        const PointField f = field_at(s, i, pv, {false, true});
        out[3 * i] = f.e.x;
        out[3 * i + 1] = f.e.y;
        out[3 * i + 2] = f.e.z;
      }
    };
    res.report = solve_induced_dipoles(n, s.alpha, e0.data(), dipole_field, p.data(), settings);
  } else {
    res.report.converged = true;
  }
  res.dipole.resize(n);
  res.field.resize(n);
  res.force.resize(n);
  const Vec3 origin{0.0, 0.0, s.electrode ? s.electrode_z : 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 pi{p[3 * i], p[3 * i + 1], p[3 * i + 2]};
    const Vec3 ri{s.x[i], s.y[i], s.z[i]};
    PointField f = field_at(s, i, s.alpha ? p.data() : nullptr, {true, true});
    res.energy += polarizable_energy_term(s.q[i], f.pot, s.applied_field, ri - origin, pi);
    f.e = f.e + s.applied_field;
    f.pot -= dot(s.applied_field, ri - origin);
    res.dipole[i] = pi;
    res.field[i] = f;
    res.force[i] = point_force(s.q[i], pi, f);
  }
  return res;
}

}  // namespace gcfmm
