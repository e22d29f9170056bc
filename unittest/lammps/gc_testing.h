/* GRANULAR-CHARGED test helpers: LAMMPS instances on a chosen communicator, commands,
   variables, and closed forms of the JKR model written independently of the package. */
#ifndef GC_TESTING_H
#define GC_TESTING_H

#include "atom.h"
#include "exceptions.h"
#include "input.h"
#include "lammps.h"
#include "library.h"
#include "variable.h"

#include "gtest/gtest.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// Run `lines` in a separate lmp process (the executable `lmp`), as a user's run is, then return
// x y z vx omegax of every atom sorted by ID (empty, with a test failure, if the run failed).
// Separate processes matter for restarts: LAMMPS 4Jul2026 names pair granular's history fix
// after a per-process instance counter, and read_restart restores the history only into a fix
// of the same name.
inline std::vector<double> lmp_process(const std::string &lmp, const std::vector<std::string> &lines,
                                       const std::string &tag, bool *ok)
{
  const std::string input = "in.gctest_" + tag, dump = "gctest_" + tag + ".state";
  {
    FILE *fp = fopen(input.c_str(), "w");
    for (const auto &l : lines) fprintf(fp, "%s\n", l.c_str());
    fprintf(fp, "write_dump all custom %s id x y z vx omegax modify sort id format float %%.17g\n",
            dump.c_str());
    fclose(fp);
  }
  const std::string cmd = lmp + " -in " + input + " -log none -screen none";
  std::vector<double> s;
  *ok = std::system(cmd.c_str()) == 0;
  FILE *fp = *ok ? fopen(dump.c_str(), "r") : nullptr;
  char line[512];
  while (fp && fgets(line, sizeof line, fp)) {
    int id;
    double v[5];
    if (sscanf(line, "%d %lg %lg %lg %lg %lg", &id, v, v + 1, v + 2, v + 3, v + 4) == 6)
      s.insert(s.end(), v, v + 5);
  }
  if (fp) fclose(fp);
  std::remove(input.c_str());
  std::remove(dump.c_str());
  return s;
}

// the message of the LAMMPS error that `cmds` raise in a fresh instance, or "no error"
inline std::string error_of(const std::vector<std::string> &cmds)
{
  Lmp l;
  try {
    l.cmds(cmds);
  } catch (LAMMPS_NS::LAMMPSException &e) {
    return e.what();
  }
  return "no error";
}

// the size of MPI_COMM_WORLD and this process's rank in it
inline int nprocs()
{
  int n;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}
inline int rank()
{
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  return me;
}

// per-atom property `name` (cols values each) of all atoms, ordered by atom ID
inline std::vector<double> gather(Lmp &l, const char *name, int cols)
{
  const int n = (int) l.var("count(all)");
  std::vector<double> v((size_t) n * cols);
  lammps_gather_atoms(l.lmp, (char *) name, 1, cols, v.data());
  return v;
}

// relative RMS difference |f - ref| / |ref| over all components
inline double rel_rms(const std::vector<double> &f, const std::vector<double> &ref)
{
  double num = 0.0, den = 0.0;
  for (size_t k = 0; k < f.size(); ++k) {
    num += (f[k] - ref[k]) * (f[k] - ref[k]);
    den += ref[k] * ref[k];
  }
  return std::sqrt(num / den);
}

// the values of every line "id v_1 ... v_ncols" of a text dump (read on this rank), in file order
inline std::vector<double> dump_rows(const std::string &path, int ncols)
{
  std::vector<double> rows;
  FILE *fp = fopen(path.c_str(), "r");
  char line[1024];
  while (fp && fgets(line, sizeof line, fp)) {
    std::vector<double> v(ncols);
    int id, used = 0, n = 0;
    const char *p = line;
    if (sscanf(p, "%d%n", &id, &used) != 1) continue;
    p += used;
    while (n < ncols && sscanf(p, "%lg%n", &v[n], &used) == 1) {
      p += used;
      n++;
    }
    if (n == ncols) rows.insert(rows.end(), v.begin(), v.end());
  }
  if (fp) fclose(fp);
  return rows;
}

// records of 6 values per atom and step (force, torque): each component within tol of the
// largest of its kind (force or torque) over the whole record; natoms per step for the message
inline void expect_same_forces(const std::vector<double> &a, const std::vector<double> &b,
                               double tol, int natoms)
{
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  double scale[2] = {0.0, 0.0};
  for (size_t k = 0; k < a.size(); ++k)
    scale[(k % 6) / 3] = std::fmax(scale[(k % 6) / 3], std::fabs(a[k]));
  int bad = 0;
  for (size_t k = 0; k < a.size() && bad < 10; ++k)
    if (!(std::fabs(a[k] - b[k]) <= tol * scale[(k % 6) / 3])) {
      ++bad;
      ADD_FAILURE() << "record " << k / 6 << " (step " << k / (6 * natoms) << ") component "
                    << k % 6 << ": " << a[k] << " vs " << b[k];
    }
}

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
