/* GRANULAR-CHARGED: closed forms of the package's sub-models for LAMMPS's DEM harness.

   LAMMPS's unittest/granular/test_analytic_models.cpp selects a closed form by the YAML key
   'analytic_model'. It is compiled unchanged under the name lammps_check_analytic_model()
   (unittest/granular/CMakeLists.txt); this check_analytic_model() adds the models below and
   hands every other name to LAMMPS's. In an upstream contribution these branches would be
   added to LAMMPS's file. The JKR relations are the test suite's own (gc_testing.h, written
   from doc/theory.md independently of the package's jkr_scaled.cpp). Parameters come from
   the YAML 'variables' block: E, nu, gamma (surface energy), xmu, theta, radius, omega0.
   Like materials everywhere: E* = E / (2 (1 - nu^2)), G* = E / (4 (2 - nu)(1 + nu)).  */

#include "test_analytic_models.h"

#include "gc_testing.h"

#include "atom.h"
#include "lammps.h"
#include "update.h"

#include "gtest/gtest.h"

#include <cmath>
#include <map>
#include <string>

using namespace LAMMPS_NS;

void lammps_check_analytic_model(const TestConfig &cfg, LAMMPS *lmp, int segment);

namespace {

double var(const TestConfig &cfg, const std::string &name)
{
  for (const auto &v : cfg.variables)
    if (v.first == name) return std::stod(v.second);
  ADD_FAILURE() << "analytic model " << cfg.analytic_model << " needs variable '" << name << "'";
  return 0.0;
}

bool has_var(const TestConfig &cfg, const std::string &name)
{
  for (const auto &v : cfg.variables)
    if (v.first == name) return true;
  return false;
}

int local(LAMMPS *lmp, tagint id)
{
  for (int i = 0; i < lmp->atom->nlocal; ++i)
    if (lmp->atom->tag[i] == id) return i;
  return -1;
}

double estar(const TestConfig &cfg) { return var(cfg, "E") / (2.0 * (1.0 - var(cfg, "nu") * var(cfg, "nu"))); }

// the JKR scales of the contact of atom 1 with atom 2 (if there is one) or with the floor
// z = 0 (R = r_p, as the package's doc says for a flat wall); overlap and normal force on atom
// 1 (positive = repulsive) from the live state
struct Contact {
  gctest::JKR jkr;
  double delta, force;
};

Contact contact(const TestConfig &cfg, LAMMPS *lmp)
{
  Contact c{};
  const int i = local(lmp, 1), j = local(lmp, 2);
  EXPECT_GE(i, 0) << "atom 1 not found";
  if (i < 0) return c;
  double **x = lmp->atom->x, **f = lmp->atom->f, *r = lmp->atom->radius;
  if (j >= 0) {
    double n[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
    const double d = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    c.delta = r[i] + r[j] - d;
    c.force = (f[i][0] * n[0] + f[i][1] * n[1] + f[i][2] * n[2]) / d;
    c.jkr = {r[i] * r[j] / (r[i] + r[j]), estar(cfg), var(cfg, "gamma")};
  } else {
    c.delta = r[i] - x[i][2];
    c.force = f[i][2];
    c.jkr = {r[i], estar(cfg), var(cfg, "gamma")};
  }
  return c;
}

void expect_rel(double expected, double actual, double tol, const std::string &what)
{
  EXPECT_LE(std::fabs(actual - expected), tol * std::fabs(expected))
      << what << ": expected " << expected << " got " << actual;
}

}    // namespace

void check_analytic_model(const TestConfig &cfg, LAMMPS *lmp, int segment)
{
  const std::string &model = cfg.analytic_model;
  if (model != "pulloff_jkr_marshall" && model != "rolling_decay_marshall" &&
      model != "twisting_decay_marshall") {
    lammps_check_analytic_model(cfg, lmp, segment);
    return;
  }
  if (!cfg.analytic_enable) return;
  const int target = cfg.analytic_segment < 0 ? (int) cfg.run_segments.size() - 1 : cfg.analytic_segment;
  if (segment != target) return;
  const double t = lmp->update->ntimestep * lmp->update->dt;

  if (model == "pulloff_jkr_marshall") {
    // A contact held at rest (no damping force) at overlap delta: F = F_C Fhat(delta/delta_C)
    // on the stable branch while it lives (it forms at delta >= 0 and breaks at -delta_C),
    // F = 0 once broken ('detached 1'). 'dhat' and 'fhat' name the check point of
    // doc/theory.md the case was set up to reach (pull-off: -3^(-2/3), -1; separation:
    // -1, -5/9); they are compared with the live overlap and the closed form too.
    const Contact c = contact(cfg, lmp);
    const double FC = c.jkr.FC(), dC = c.jkr.deltaC();
    if (has_var(cfg, "dhat"))
      EXPECT_NEAR(c.delta / dC, var(cfg, "dhat"), 1e-6) << "set-up did not reach the overlap";
    if (has_var(cfg, "detached") && var(cfg, "detached") != 0.0) {
      EXPECT_LE(std::fabs(c.force), cfg.analytic_tol * FC)
          << "contact at delta/delta_C = " << c.delta / dC << " should be broken";
      return;
    }
    const double fhat = gctest::JKR::force_of_ahat(gctest::JKR::ahat_of_delta(c.delta / dC));
    if (has_var(cfg, "fhat"))
      EXPECT_NEAR(fhat, var(cfg, "fhat"), cfg.analytic_tol) << "closed form at the check point";
    expect_rel(fhat * FC, c.force, cfg.analytic_tol, "jkr/marshall normal force F/F_C");
  } else if (model == "rolling_decay_marshall" || model == "twisting_decay_marshall") {
    // Atom 1 on the floor at zero load (a = a_0, F_ne = 0), spinning at omega0 about y
    // (rolling: v_L = R omega x n) or about z (twisting). The moment grows on a spring to its
    // limit, then stays there: rolling M = k_R theta_crit R with k_R = 4 F_C (a/a_0)^(3/2) =
    // 4 F_C, reached when |xi| = R omega0 t_s = theta_crit R; twisting M = 3 pi a F_crit / 16
    // with F_crit = mu |F_ne + 2 F_C| = 2 mu F_C, reached after t_s = M / (k_tw omega0),
    // k_tw = k_T a^2 / 2, k_T = 8 G* a (damping in the stick phase only shortens it). The
    // spring phase loses M t_s / 2, so omega(t) = omega0 - M (t - t_s / 2) / I, I = 2/5 m r^2.
    // The spin decrement (omega0 - omega) is compared, the part the moment determines.
    const int i = local(lmp, 1);
    ASSERT_GE(i, 0) << "atom 1 not found";
    const double r = lmp->atom->radius[i], m = lmp->atom->rmass[i];
    const gctest::JKR jkr{r, estar(cfg), var(cfg, "gamma")};
    const double a = jkr.a0(), omega0 = var(cfg, "omega0");
    double M, ts, omega;
    if (model == "rolling_decay_marshall") {
      M = 4.0 * jkr.FC() * var(cfg, "theta") * r;
      ts = var(cfg, "theta") / omega0;
      omega = lmp->atom->omega[i][1];
    } else {
      const double nu = var(cfg, "nu");
      const double G = var(cfg, "E") / (4.0 * (2.0 - nu) * (1.0 + nu));
      M = 3.0 * M_PI * a * 2.0 * var(cfg, "xmu") * jkr.FC() / 16.0;
      ts = M / (8.0 * G * a * a * a / 2.0 * omega0);
      omega = lmp->atom->omega[i][2];
    }
    const double I = 0.4 * m * r * r;
    expect_rel(M * (t - 0.5 * ts) / I, omega0 - omega, cfg.analytic_tol, model + " spin decrement");
  }
}
