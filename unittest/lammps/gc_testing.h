/* GRANULAR-CHARGED test helpers: LAMMPS instances on a chosen communicator, commands,
   variables, and closed forms of the JKR model written independently of the package. */
#ifndef GC_TESTING_H
#define GC_TESTING_H

#include "atom.h"
#include "input.h"
#include "lammps.h"
#include "variable.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <mpi.h>

namespace gctest {

// A quiet LAMMPS instance on `comm`, deleted at scope exit.
class Lmp {
 public:
  explicit Lmp(MPI_Comm comm = MPI_COMM_WORLD, bool quiet = true)
  {
    std::vector<char *> args;
    static char a0[] = "gctest", a1[] = "-log", a2[] = "none", a3[] = "-screen", a4[] = "none",
                a5[] = "-nocite";
    args = {a0, a1, a2, a5};
    if (quiet) args = {a0, a1, a2, a3, a4, a5};
    lmp = new LAMMPS_NS::LAMMPS((int) args.size(), args.data(), comm);
  }
  ~Lmp() { delete lmp; }
  Lmp(const Lmp &) = delete;
  Lmp &operator=(const Lmp &) = delete;

  void cmd(const std::string &line) { lmp->input->one(line); }
  void cmds(const std::vector<std::string> &lines)
  {
    for (const auto &l : lines) cmd(l);
  }
  double var(const std::string &name)    // value of an equal-style expression
  {
    cmd("variable gctest_tmp equal " + name);
    return lmp->input->variable->compute_equal("v_gctest_tmp");
  }
  // torque component d of the atom with tag `id` (single-rank tests only)
  double torque(int id, int d) { return lmp->atom->torque[lmp->atom->map(id)][d]; }
  LAMMPS_NS::LAMMPS *lmp;
};

// ---- JKR closed forms (doc/theory.md, eqs. (1.2)-(1.4)), independent of LAMMPS's implementation ----------
struct JKR {
  double R, E, gamma;    // effective radius, effective modulus E*, surface energy
  double FC() const { return 3.0 * M_PI * gamma * R; }
  double a0() const { return std::cbrt(9.0 * M_PI * gamma * R * R / E); }
  double deltaC() const { return a0() * a0() / (2.0 * std::cbrt(6.0) * R); }
  // delta / delta_C as a function of a-hat (the squared form; the paper's "2 a^3" is a typo)
  static double delta_of_ahat(double ah) { return std::cbrt(6.0) * (2.0 * ah * ah - 4.0 / 3.0 * std::sqrt(ah)); }
  static double force_of_ahat(double ah) { return 4.0 * (ah * ah * ah - std::pow(ah, 1.5)); }
  // a-hat on the stable branch for delta/delta_C >= -1, by bisection
  static double ahat_of_delta(double dd)
  {
    double lo = std::pow(6.0, -2.0 / 3.0), hi = 1.0;
    while (delta_of_ahat(hi) < dd) hi *= 2.0;
    for (int it = 0; it < 200; ++it) {
      double mid = 0.5 * (lo + hi);
      (delta_of_ahat(mid) < dd ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  // F / F_C at overlap delta (contact assumed alive)
  double force(double delta) const { return FC() * force_of_ahat(ahat_of_delta(delta / deltaC())); }
};

}    // namespace gctest
#endif
