// gcfmm::CoulombBackend: each implementation passes its solver's results through unchanged.
//   - ReplicatedBackend (one part) gives Solver's potential, field and energy potential bit for
//     bit, and two parts summed give the one-part result bit for bit (the LAMMPS fix's ranks);
//     its share() covers the particles once.
//   - DistributedBackend on one rank gives Solver's results bit for bit (DistributedSolver's
//     own guarantee on one rank) and reports this caller's counts (counts_whole false).
//   - PolarizableBackend gives PolarizableSolver's field, forces and energy terms bit for bit,
//     its energy potential is 2 e_i / q_i, and its statistics are the induction's report.
// Checked against broken code: with ex and ey swapped in PolarizableBackend::evaluate, or the
// part number ignored in ReplicatedBackend::evaluate, the tests fail.
#include "gcfmm/coulomb_backend.hpp"

#include "fmm_test_util.hpp"
#include "thread_communicator.hpp"

#include <gtest/gtest.h>

#include <numeric>

using namespace gcfmm;
using gcfmm_test::Field;
using gcfmm_test::Particles;

namespace {

Options periodic_options() {
  Options o;
  o.boundary = Boundary::Periodic2D;
  o.accuracy = 1e-4;
  o.farfield = FarField::Exact;
  return o;
}

Particles bed(std::size_t n) { return gcfmm_test::deposition(n, 7, 28.0, 28.0, 40.0); }

BackendInput input_of(const Particles &p) {
  BackendInput in;
  in.n = p.size();
  in.x = p.x.data();
  in.y = p.y.data();
  in.z = p.z.data();
  in.q = p.q.data();
  return in;
}

BackendOutput output_of(Field &f) {
  BackendOutput out;
  out.pot = f.pot.data();
  out.ex = f.ex.data();
  out.ey = f.ey.data();
  out.ez = f.ez.data();
  return out;
}

void expect_same(const Field &a, const Field &b) {
  for (std::size_t i = 0; i < a.pot.size(); ++i) {
    EXPECT_EQ(a.pot[i], b.pot[i]) << i;
    EXPECT_EQ(a.ex[i], b.ex[i]) << i;
    EXPECT_EQ(a.ey[i], b.ey[i]) << i;
    EXPECT_EQ(a.ez[i], b.ez[i]) << i;
  }
}

// Solver's field and energy potential of the particles in the 28 x 28 cell
void solver_reference(const Particles &p, Field &f, std::vector<double> &u) {
  Solver s(periodic_options());
  s.set_box(0.0, 0.0, 28.0, 28.0);
  s.set_z_range(0.0, 40.0);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
  u.resize(p.size());
  s.energy_potential(u.data());
}

}  // namespace

TEST(CoulombBackend, ReplicatedIsTheSolver) {
  const Particles p = bed(600);
  Field ref(p.size());
  std::vector<double> uref;
  solver_reference(p, ref, uref);

  ReplicatedBackend one(periodic_options(), 0, 1, nullptr);
  one.set_box(0.0, 0.0, 28.0, 28.0);
  one.set_z_range(0.0, 40.0);
  Field f(p.size());
  one.evaluate(input_of(p), output_of(f));
  expect_same(f, ref);
  std::vector<double> u(p.size());
  one.energy_potential(u.data());
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_EQ(u[i], uref[i]) << i;
  EXPECT_FALSE(one.distributed());
  EXPECT_TRUE(one.stats().counts_whole);
  EXPECT_GT(one.stats().m2l + one.stats().p2p, 0.0);

  // two parts, each computing its share, summed
  Field sum(p.size());
  std::size_t covered = 0;
  for (int part = 0; part < 2; ++part) {
    ReplicatedBackend half(periodic_options(), part, 2, nullptr);
    half.set_box(0.0, 0.0, 28.0, 28.0);
    half.set_z_range(0.0, 40.0);
    Field f2(p.size());
    half.evaluate(input_of(p), output_of(f2));
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum.pot[i] += f2.pot[i];
      sum.ex[i] += f2.ex[i];
      sum.ey[i] += f2.ey[i];
      sum.ez[i] += f2.ez[i];
    }
    std::size_t first = 0, last = 0;
    half.share(p.size(), first, last);
    covered += last - first;
  }
  expect_same(sum, ref);
  EXPECT_EQ(covered, p.size());
}

TEST(CoulombBackend, DistributedOnOneRankIsTheSolver) {
  const Particles p = bed(600);
  Field ref(p.size());
  std::vector<double> uref;
  solver_reference(p, ref, uref);
  gcfmm_test::run_ranks(1, [&](gcfmm_test::ThreadCommunicator &comm) {
    DistributedBackend b(periodic_options(), comm);
    b.set_box(0.0, 0.0, 28.0, 28.0);
    b.set_z_range(0.0, 40.0);
    std::vector<std::int64_t> ids(p.size());
    std::iota(ids.begin(), ids.end(), 1);
    BackendInput in = input_of(p);
    in.ids = ids.data();
    Field f(p.size());
    b.evaluate(in, output_of(f));
    expect_same(f, ref);
    std::vector<double> u(p.size());
    b.energy_potential(u.data());
    for (std::size_t i = 0; i < u.size(); ++i) EXPECT_EQ(u[i], uref[i]) << i;
    EXPECT_TRUE(b.distributed());
    EXPECT_FALSE(b.stats().counts_whole);
  });
}

TEST(CoulombBackend, PolarizableIsThePolarizableSolver) {
  Particles p = bed(300);
  const std::size_t n = p.size();
  std::vector<double> alpha(n, 0.01);
  PolarizableEnvironment env;
  env.applied_field = Vec3{0.0, 0.0, -0.2};

  PolarizableSolver s(periodic_options(), true);
  s.set_box(0.0, 0.0, 28.0, 28.0);
  s.set_z_range(0.0, 40.0);
  s.set_environment(env);
  std::vector<double> pref(3 * n, 0.0);
  PolarizableOutputs ref;
  s.compute(n, p.x.data(), p.y.data(), p.z.data(), p.q.data(), alpha.data(), pref.data(), ref);

  PolarizableBackend b(periodic_options(), true);
  b.set_box(0.0, 0.0, 28.0, 28.0);
  b.set_z_range(0.0, 40.0);
  b.solver().set_environment(env);
  std::vector<double> dip(3 * n, 0.0), force(3 * n), energy(n);
  BackendInput in = input_of(p);
  in.alpha = alpha.data();
  in.p = dip.data();
  Field f(n);
  BackendOutput out = output_of(f);
  out.force = force.data();
  out.energy = energy.data();
  b.evaluate(in, out);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(f.ex[i], ref.field[3 * i]) << i;
    EXPECT_EQ(f.ey[i], ref.field[3 * i + 1]) << i;
    EXPECT_EQ(f.ez[i], ref.field[3 * i + 2]) << i;
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(force[3 * i + a], ref.force[3 * i + a]) << i;
      EXPECT_EQ(dip[3 * i + a], pref[3 * i + a]) << i;
    }
    EXPECT_EQ(energy[i], ref.energy[i]) << i;
    EXPECT_EQ(f.pot[i], p.q[i] != 0.0 ? 2.0 * ref.energy[i] / p.q[i] : 0.0) << i;
  }
  const BackendStats st = b.stats();
  EXPECT_EQ(st.iterations, s.report().iterations);
  EXPECT_EQ(st.residual, s.report().residual);
  EXPECT_TRUE(st.converged);
  EXPECT_FALSE(b.distributed());
}
