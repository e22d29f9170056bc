/* GRANULAR-CHARGED: the packing-analysis computes coord/dist, rdf/slab and packing/slab against
   closed forms: perfect lattices of touching spheres (Z, phi, g(r) peaks and shell counts), an
   ideal gas in a slab (g(r) = 1 with a slab-truncated normalisation), hand-built clusters and a
   JKR contact in tension (active vs geometric contacts), and every input error. Run with 1 rank
   and under mpirun -np 2 (every closed form must hold on 2 ranks, and 2 ranks must agree with
   1 rank on MPI_COMM_SELF to round-off). */
#include "gc_testing.h"

#include "atom.h"
#include "exceptions.h"
#include "library.h"
#include "gtest/gtest.h"

#include <array>
#include <cmath>
#include <regex>
#include <string>
#include <vector>

using gctest::JKR;
using gctest::Lmp;
using gctest::nprocs;
using gctest::error_of;

namespace {

// ---- compute outputs through the library interface (collective: invokes the compute) --------
void *extract(Lmp &l, const std::string &id, int style, int type)
{
  void *p = lammps_extract_compute(l.lmp, id.c_str(), style, type);
  if (!p) {
    char msg[1024] = "";
    lammps_get_last_error_message(l.lmp, msg, sizeof(msg));
    ADD_FAILURE() << "compute " << id << " gave no data: " << msg;
  }
  return p;
}
double cscalar(Lmp &l, const std::string &id)
{
  auto p = (double *) extract(l, id, LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR);
  return p ? *p : NAN;
}
std::vector<double> cvector(Lmp &l, const std::string &id, int n)
{
  auto p = (double *) extract(l, id, LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR);
  if (!p) return std::vector<double>(n, NAN);
  return std::vector<double>(p, p + n);
}
// rows x cols, row-major
std::vector<std::vector<double>> carray(Lmp &l, const std::string &id, int rows, int cols)
{
  auto p = (double **) extract(l, id, LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY);
  std::vector<std::vector<double>> a(rows, std::vector<double>(cols, NAN));
  if (p)
    for (int i = 0; i < rows; i++)
      for (int j = 0; j < cols; j++) a[i][j] = p[i][j];
  return a;
}
// per-atom vector gathered by atom ID (index 0 unused), on every rank of comm
std::vector<double> cperatom(Lmp &l, const std::string &id, MPI_Comm comm)
{
  auto p = (double *) extract(l, id, LMP_STYLE_ATOM, LMP_TYPE_VECTOR);
  const int natoms = (int) l.lmp->atom->natoms;
  std::vector<double> loc(natoms + 1, 0.0), all(natoms + 1, 0.0);
  if (p)
    for (int i = 0; i < l.lmp->atom->nlocal; i++) loc[l.lmp->atom->tag[i]] = p[i];
  MPI_Allreduce(loc.data(), all.data(), natoms + 1, MPI_DOUBLE, MPI_SUM, comm);
  return all;
}

void expect_match(const std::string &msg, const std::string &re)
{
  EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
}

// ---- lattices of touching spheres, d = 1 (units metal: the lattice scale is the cell edge) ----
struct Lattice {
  std::string style;
  double a;         // cubic cell edge for touching spheres of diameter 1
  double layer;     // spacing of the (001) layers
  int per_layer;    // atoms per layer and cell
  int Z;            // coordination number
  double phi;       // volume fraction
};
const double SQ2 = std::sqrt(2.0), SQ3 = std::sqrt(3.0);
const Lattice FCC{"fcc", SQ2, SQ2 / 2, 2, 12, M_PI / (3 * SQ2)};
const Lattice BCC{"bcc", 2 / SQ3, 1 / SQ3, 1, 8, M_PI *SQ3 / 8};
const Lattice SC{"sc", 1.0, 1.0, 1, 6, M_PI / 6};

constexpr int NX = 4, NY = 4, NZ = 8;

void make_lattice(Lmp &l, const Lattice &lat, int nx = NX, int ny = NY, int nz = NZ,
                  const std::string &newton = "on")
{
  l.cmds({"units metal", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton " + newton, fmt::format("lattice {} {:.17g}", lat.style, lat.a),
          fmt::format("region box block 0 {} 0 {} 0 {}", nx, ny, nz), "create_box 1 box",
          "create_atoms 1 box", "set type 1 diameter 1.0", "pair_style granular",
          "pair_coeff * * hooke 1000 0.5 tangential linear_nohistory 1 0.3",
          "comm_modify vel yes cutoff 3.0", "neighbor 0.3 bin", "thermo_style custom step atoms"});
}

// number of lattice atoms with centres in [zlo, zhi] (heights in box units)
double atoms_in(const Lattice &lat, double zlo, double zhi, int nz = NZ, int nx = NX, int ny = NY)
{
  double n = 0;
  const int nlayers = (int) std::lround(nz * lat.a / lat.layer);
  for (int k = 0; k < nlayers; k++) {
    const double z = k * lat.layer;
    if (z >= zlo && z <= zhi) n += lat.per_layer * nx * ny;
  }
  return n;
}

}    // namespace

// ------------------------------------------------------------------------------------------
// Z of every interior atom is 12 / 8 / 6, for slabs at arbitrary heights; the whole FCC crystal
// (free (001) faces with Z = 8) has <Z> = (2 * 8 + (2 NZ - 2) * 12) / (2 NZ).
// Lattice positions are exact to ~1e-15; the tolerance 1e-9 (in d) only absorbs that round-off
// and is far below the gap to the second shell (sqrt(2) - 1, 2/sqrt(3) - 1, sqrt(2) - 1).
TEST(PackingComputes, LatticeCoordination)
{
  const double heights[][2] = {{1.2345, 3.9528}, {0.6931, 2.7183}, {2.0001, 4.5}};
  for (const Lattice &lat : {FCC, BCC, SC}) {
    Lmp l;
    make_lattice(l, lat);
    const int nlayers = (int) std::lround(NZ * lat.a / lat.layer);
    const double top = (nlayers - 1) * lat.layer;
    int n = 0;
    for (auto &h : heights) {
      const double zlo = h[0] * lat.a, zhi = h[1] * lat.a;
      ASSERT_TRUE(zlo > 0.0 && zhi < top) << "the slab must exclude the free faces";
      l.cmd(
          fmt::format("compute z{} all coord/dist z {:.17g} {:.17g} tolerance 1e-9", n, zlo, zhi));
      ++n;
    }
    l.cmd("compute zall all coord/dist tolerance 1e-9");
    l.cmd("run 0");
    for (int k = 0; k < n; k++) {
      const std::string id = "z" + std::to_string(k);
      const double nslab = atoms_in(lat, heights[k][0] * lat.a, heights[k][1] * lat.a);
      ASSERT_GT(nslab, 0);
      EXPECT_DOUBLE_EQ(cscalar(l, id), lat.Z) << lat.style << " slab " << k;
      auto f = carray(l, id, 21, 3);
      for (int z = 0; z <= 20; z++) {
        EXPECT_EQ(f[z][0], z);
        EXPECT_EQ(f[z][1], z == lat.Z ? nslab : 0.0) << lat.style << " Z = " << z;
        EXPECT_EQ(f[z][2], z == lat.Z ? 1.0 : 0.0) << lat.style << " Z = " << z;
      }
    }
    // per-atom Z over the whole crystal: interior layers Z, the free faces fewer
    auto zat = cperatom(l, "zall", MPI_COMM_WORLD);
    int interior = 0;
    for (size_t i = 1; i < zat.size(); i++) {
      const long layer = std::lround(l.var(fmt::format("z[{}]", i)) / lat.layer);
      if (layer >= 1 && layer <= nlayers - 2) {
        EXPECT_EQ(zat[i], lat.Z) << lat.style << " atom " << i;
        ++interior;
      } else
        EXPECT_LT(zat[i], lat.Z) << lat.style << " face atom " << i;
    }
    EXPECT_EQ(interior, (nlayers - 2) * lat.per_layer * NX * NY);
    if (lat.style == "fcc")
      EXPECT_NEAR(cscalar(l, "zall"), (2 * 8.0 + (2 * NZ - 2) * 12.0) / (2 * NZ), 1e-12);
  }
}

// phi of a slab whose thickness is a whole number of (001) periods is the bulk value wherever the
// slab sits (the integral of the periodic z-profile over whole periods); the cap volumes make it
// exact to round-off (~1e-15 relative), so 1e-9 is a tolerance with room, and a missing or wrong
// cap term changes phi by > 1e-2. NULL NULL: the bed from the lowest bottom to the highest top.
TEST(PackingComputes, LatticePackingFraction)
{
  const double z0[] = {0.7391, 1.5, 2.0137, 3.2689};    // in units of a; thickness 3 a
  for (const Lattice &lat : {FCC, BCC, SC}) {
    Lmp l;
    make_lattice(l, lat);
    for (int k = 0; k < 4; k++)
      l.cmd(fmt::format("compute phi{} all packing/slab {:.17g} {:.17g}", k, z0[k] * lat.a,
                        (z0[k] + 3) * lat.a));
    l.cmd("compute phibed all packing/slab NULL NULL");
    l.cmd("run 0");
    const double area = NX * NY * lat.a * lat.a;
    for (int k = 0; k < 4; k++) {
      const std::string id = "phi" + std::to_string(k);
      EXPECT_NEAR(cscalar(l, id), lat.phi, 1e-9) << lat.style << " z0 = " << z0[k];
      auto v = cvector(l, id, 3);
      EXPECT_NEAR(v[0], lat.phi, 1e-9);
      // spheres reaching into the slab: centres within r = 0.5 of it
      EXPECT_EQ(v[1],
                atoms_in(lat, z0[k] * lat.a - 0.5 + 1e-12, (z0[k] + 3) * lat.a + 0.5 - 1e-12));
      EXPECT_NEAR(v[2], area * 3 * lat.a, 1e-12 * area * 3 * lat.a);
    }
    const double natoms = l.lmp->atom->natoms;
    const double top = (std::lround(NZ * lat.a / lat.layer) - 1) * lat.layer;
    EXPECT_NEAR(cscalar(l, "phibed"), natoms * M_PI / 6 / (area * (top + 1.0)), 1e-12);
  }
}

// g(r) of FCC (d = 1, r in diameters): peaks at 1, sqrt 2, sqrt 3, 2 only, and the shell counts
// 12, 6, 24, 12 (cumulative 12, 18, 42, 54) for reference atoms whose shells up to 2 d lie in
// the crystal. Bin width 0.07: the peaks sit >= 0.2 bins from a bin edge, so round-off cannot
// move a pair across an edge; the counts are integers over integers and exact.
TEST(PackingComputes, LatticeRDF)
{
  Lmp l;
  make_lattice(l, FCC, 4, 4, 8);
  const double zlo = 2.1 * FCC.a, zhi = 5.3 * FCC.a;    // >= 2 d = 1.414 a from both crystal faces
  l.cmd(fmt::format("compute g all rdf/slab 30 2.1 z {:.17g} {:.17g} units diameter", zlo, zhi));
  l.cmd("compute gbox all rdf/slab 30 2.1 z NULL NULL");
  l.cmd("run 0");
  auto g = carray(l, "g", 30, 3);
  const double peaks[] = {1.0, SQ2, SQ3, 2.0};
  const double cum[] = {12, 18, 42, 54};
  for (int k = 0; k < 30; k++) {
    EXPECT_NEAR(g[k][0], (k + 0.5) * 0.07, 1e-12);
    int p = -1, below = 0;
    for (int m = 0; m < 4; m++) {
      if (static_cast<int>(peaks[m] / 0.07) == k) p = m;
      if (peaks[m] < (k + 1) * 0.07) below = m + 1;
    }
    if (p >= 0)
      EXPECT_GT(g[k][1], 1.0) << "peak at r = " << peaks[p];
    else
      EXPECT_EQ(g[k][1], 0.0) << "bin " << k;
    EXPECT_NEAR(g[k][2], below ? cum[below - 1] : 0.0, 1e-12) << "bin " << k;
  }
  // box units give the same table with d = 1
  auto gb = carray(l, "gbox", 30, 3);
  for (int k = 0; k < 30; k++) EXPECT_NEAR(gb[k][0], g[k][0], 1e-12);
}

// Ideal gas (random points, number density 5, box 20 x 20 periodic in x, y): with the
// slab-truncated shell volumes g(r) = 1 in expectation at every r < rmax = 3, for
//   0: the gas filling the slab [0, 4] (H = 4 < 2 rmax: most shells cut by both faces),
//   1: a slab [3, 7] selected inside a gas [0, 10] (partners outside the slab ignored),
//   2: a thin slab [4.5, 5.5] inside a gas [0, 10]: every reference atom is within 0.5 of a face.
// Tolerance per bin: 5 sigma, sigma = sqrt(2 / m_k), m_k the expected number of ordered in-slab
// pairs of the bin (unordered pairs are Poisson, each counted twice). m_k comes from column 3
// (all partners, n_k): m_k = n_k for variant 0, n_k f(r_k, H) for 1 and 2, where the shells lie
// inside the gas and f(r, H) is the mean fraction of a sphere's surface inside a slab of
// thickness H (closed form: a spherical zone's area is proportional to its height). Without
// the truncation, g would be f: 0.64 (H = 4) and 0.17 (H = 1) at r = 2.9, hundreds of sigma off.
TEST(PackingComputes, IdealGasSlab)
{
  const double L = 20.0, RMAX = 3.0, RHO = 5.0;
  const int NBIN = 15;
  auto shell_fraction = [](double r, double H) {
    double s = 0.0;
    const int M = 20000;
    for (int m = 0; m < M; m++) {
      const double z = (m + 0.5) * H / M;
      s += (std::min(z + r, H) - std::max(z - r, 0.0)) / (2 * r);
    }
    return s / M;
  };
  EXPECT_NEAR(shell_fraction(2.9, 4.0), 0.64, 0.01) << "the test must discriminate";
  EXPECT_NEAR(shell_fraction(2.9, 1.0), 0.17, 0.01) << "the test must discriminate";

  struct Variant {
    double gas, zlo, zhi;
  };
  for (const Variant &v :
       {Variant{4.0, 0.0, 4.0}, Variant{10.0, 3.0, 7.0}, Variant{10.0, 4.5, 5.5}}) {
    Lmp l;
    const int n = (int) std::lround(RHO * L * L * v.gas);
    l.cmds({"units lj", "atom_style sphere", "atom_modify map array", "boundary p p f",
            fmt::format("region box block 0 {} 0 {} 0 {}", L, L, v.gas), "create_box 1 box",
            fmt::format("create_atoms 1 random {} 4711 NULL", n), "comm_modify cutoff 3.5",
            "neighbor 0.3 bin", "thermo_style custom step atoms",
            fmt::format("compute g all rdf/slab {} {} z {} {}", NBIN, RMAX, v.zlo, v.zhi),
            "run 0"});
    auto g = carray(l, "g", NBIN, 3);
    double nref = 0;
    for (int i = 1; i <= n; i++) {
      const double z = l.var(fmt::format("z[{}]", i));
      if (z >= v.zlo && z <= v.zhi) nref += 1;
    }
    const bool filled = (v.zlo == 0.0 && v.zhi == v.gas);
    double prev = 0.0, outer = 0.0;
    for (int k = 0; k < NBIN; k++) {
      const double nk = (g[k][2] - prev) * nref;
      prev = g[k][2];
      const double mk = filled ? nk : nk * shell_fraction(g[k][0], v.zhi - v.zlo);
      ASSERT_GT(mk, 100) << "bin " << k;
      EXPECT_NEAR(g[k][1], 1.0, 5.0 * std::sqrt(2.0 / mk))
          << "slab [" << v.zlo << ", " << v.zhi << "] bin " << k << " r = " << g[k][0];
      if (k >= NBIN / 2) outer += g[k][1] / (NBIN - NBIN / 2);
    }
    // the outer bins together: sigma < 0.5 %
    EXPECT_NEAR(outer, 1.0, 0.02) << "slab [" << v.zlo << ", " << v.zhi << "]";
  }
}

// Hand-built clusters with a small overlap (1 nm = 0.25 delta_C): a chain of 3, a triangle and a
// tetrahedron. Z = (1,2,1), (2,2,2), (3,3,3,3): f(1) = 2, f(2) = 4, f(3) = 4, <Z> = 2.2, for
// both contact definitions (counts are integers: exact); newton on and off.
namespace {
constexpr double RP = 1.0e-6, EMOD = 2.0e8, NU = 0.33, GAMMA = 0.01;
const std::string JKR_COEFF = "pair_coeff * * jkr/marshall 2e8 0.7 0.33 0.01 damping marshall "
                              "tangential marshall 0.3";
const JKR jkr{RP / 2, EMOD / (2.0 * (1.0 - NU * NU)), GAMMA};

// ranks side by side along x (processors * 1 1): the clusters below straddle x = 0, so with
// 2 ranks their contacts cross the subdomain boundary (ghost atoms, reverse communication)
void jkr_box(Lmp &l, const std::string &newton = "on")
{
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
          "newton " + newton, "processors * 1 1", "comm_modify vel yes",
          "region box block -1e-5 1e-5 -1e-5 1e-5 -1e-5 1e-5", "create_box 1 box"});
}
void jkr_pair(Lmp &l)
{
  l.cmds({"set type 1 diameter 2e-6", "set type 1 density 2500", "pair_style granular", JKR_COEFF,
          "neighbor 2e-7 bin", "thermo_style custom step atoms"});
}
void atom_at(Lmp &l, double x, double y, double z)
{
  l.cmd(fmt::format("create_atoms 1 single {:.17g} {:.17g} {:.17g}", x, y, z));
}

void clusters(const std::string &newton)
{
  Lmp l;
  jkr_box(l, newton);
  const double D = 2 * RP - 1e-9;
  // chain along x, straddling x = 0 (2 ranks: across the subdomain boundary)
  for (int k = -1; k <= 1; k++) atom_at(l, k * D, -5e-6, 1e-7);
  // triangle in the xy plane around the origin
  for (int k = 0; k < 3; k++)
    atom_at(l, D / SQ3 * std::cos(2 * M_PI * k / 3), D / SQ3 * std::sin(2 * M_PI * k / 3), 0.0);
  // regular tetrahedron around (0, 5e-6, 0): alternate cube corners, edge 2 sqrt2 s = D
  const double s = D / (2 * SQ2);
  for (auto &c : std::vector<std::array<int, 3>>{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}})
    atom_at(l, c[0] * s, 5e-6 + c[1] * s, c[2] * s);
  jkr_pair(l);
  l.cmds({"compute geo all coord/dist zmax 4", "compute act all coord/dist contact active zmax 4",
          "compute geoz all coord/dist z 5e-7 NULL", "run 0"});
  const double zexp[] = {0, 1, 2, 1, 2, 2, 2, 3, 3, 3, 3};
  for (const char *id : {"geo", "act"}) {
    EXPECT_NEAR(cscalar(l, id), 2.2, 1e-12) << id;
    auto f = carray(l, id, 5, 3);
    const double count[] = {0, 2, 4, 4, 0};
    for (int z = 0; z <= 4; z++) {
      EXPECT_EQ(f[z][1], count[z]) << id << " Z = " << z;
      EXPECT_NEAR(f[z][2], count[z] / 10.0, 1e-15) << id << " Z = " << z;
    }
    auto zat = cperatom(l, id, MPI_COMM_WORLD);
    for (int i = 1; i <= 10; i++) EXPECT_EQ(zat[i], zexp[i]) << id << " atom " << i;
  }
  // a group holding chain atoms 1 and 2: partners outside the group count (atom 2 touches 3)
  l.cmds({"group ends id 1 2", "compute gz ends coord/dist zmax 4", "run 0"});
  auto fg = carray(l, "gz", 5, 3);
  EXPECT_EQ(fg[1][1], 1.0);
  EXPECT_EQ(fg[2][1], 1.0);
  EXPECT_DOUBLE_EQ(cscalar(l, "gz"), 1.5);
  auto zg = cperatom(l, "gz", MPI_COMM_WORLD);
  EXPECT_EQ(zg[4], 0.0) << "atoms outside the group get Z = 0";
  // slab z >= 5e-7: the two upper tetrahedron atoms (z = s); 2 of their 3 contacts are with
  // atoms outside the slab and count all the same
  EXPECT_EQ(cscalar(l, "geoz"), 3.0);
  EXPECT_EQ(carray(l, "geoz", 21, 3)[3][1], 2.0);
}
}    // namespace

TEST(PackingComputes, Clusters)
{
  for (const std::string newton : {"on", "off"}) {
    SCOPED_TRACE("newton " + newton);
    clusters(newton);
  }
}

// A JKR contact in tension: approach to 1 nm overlap, then pull apart. At a gap of 0.5 delta_C
// (delta_C = 4.04 nm) the contact is still held by pair granular (jkr/marshall breaks at
// -delta_C) but has no geometric overlap; at 1.5 delta_C it is broken, and moving back to
// 0.5 delta_C does not restore it (no snap-in without touching). The pair straddles x = 0;
// newton on and off.
TEST(PackingComputes, JKRContactInTension)
{
  const double dC = jkr.deltaC();
  EXPECT_NEAR(dC, 4.04e-9, 0.01e-9);
  for (const std::string newton : {"on", "off"}) {
    SCOPED_TRACE("newton " + newton);
    Lmp l;
    jkr_box(l, newton);
    atom_at(l, -RP + 0.5e-9, 0, 0);
    atom_at(l, RP - 0.5e-9, 0, 0);
    jkr_pair(l);
    l.cmds({"compute geo all coord/dist", "compute act all coord/dist contact active"});
    auto place = [&](double gap) {
      l.cmd(fmt::format("set atom 1 x {:.17g}", -RP - gap / 2));
      l.cmd(fmt::format("set atom 2 x {:.17g}", RP + gap / 2));
      l.cmd("run 0");
    };
    struct Step {
      double gap;
      double geo, act;
    };
    const Step steps[] = {{-1e-9, 1, 1},    {0.5 * dC, 0, 1}, {0.9 * dC, 0, 1},
                          {1.5 * dC, 0, 0}, {0.5 * dC, 0, 0}, {-1e-9, 1, 1}};
    for (auto &st : steps) {
      place(st.gap);
      EXPECT_EQ(cscalar(l, "geo"), st.geo) << "gap " << st.gap / dC << " delta_C";
      EXPECT_EQ(cscalar(l, "act"), st.act) << "gap " << st.gap / dC << " delta_C";
      auto za = cperatom(l, "act", MPI_COMM_WORLD);
      EXPECT_EQ(za[1], st.act);
      EXPECT_EQ(za[2], st.act);
    }
  }
}

// A box periodic in z as well: every FCC atom has Z = 12; phi of a slab of 3 periods is the
// bulk value also when the slab crosses the periodic z boundary (images of the spheres), and
// the whole box gives it too; the shell counts 12, 6, 24, 12 hold for every reference atom
// (partners through the z boundary are ghosts). Tolerances as in the open-box tests.
TEST(PackingComputes, PeriodicZ)
{
  Lmp l;
  make_lattice(l, FCC, 4, 4, 6);
  const double a = FCC.a;
  l.cmds({"change_box all boundary p p p", "compute z all coord/dist tolerance 1e-9",
          fmt::format("compute phi1 all packing/slab {:.17g} {:.17g}", -0.3123 * a, 2.6877 * a),
          fmt::format("compute phi2 all packing/slab {:.17g} {:.17g}", 4.1 * a, 7.1 * a),
          fmt::format("compute phi3 all packing/slab 0 {:.17g}", 6 * a),
          // far more periods than a loop over images could visit (2e10 / (6 a) ~ 2e9 each way):
          // whole periods count each sphere once, the remainder slab is a few images
          "compute phihuge all packing/slab -1e10 1e10",
          fmt::format("compute phimany all packing/slab {:.17g} {:.17g}", -0.3123 * a, (6 * 7 + 2.6877) * a),
          "compute g all rdf/slab 30 2.1 units diameter", "run 0"});
  EXPECT_DOUBLE_EQ(cscalar(l, "z"), 12.0);
  for (const char *id : {"phi1", "phi2", "phi3"}) EXPECT_NEAR(cscalar(l, id), FCC.phi, 1e-9) << id;
  // 7.5 periods: 7 whole ones plus half a period, which holds the bulk phi as well (any 3 a
  // of FCC (001) do); round-off of a slab of 2e10 is ~1e-16 relative
  EXPECT_NEAR(cscalar(l, "phimany"), FCC.phi, 1e-9);
  EXPECT_NEAR(cscalar(l, "phihuge"), FCC.phi, 1e-9);
  auto g = carray(l, "g", 30, 3);
  EXPECT_NEAR(g[14][2], 12.0, 1e-12);    // bin of r = 1
  EXPECT_NEAR(g[20][2], 18.0, 1e-12);    // sqrt 2
  EXPECT_NEAR(g[24][2], 42.0, 1e-12);    // sqrt 3
  EXPECT_NEAR(g[28][2], 54.0, 1e-12);    // 2
  // rdf/slab needs its slab inside the periodic z range
  l.cmd(fmt::format("compute gbad all rdf/slab 30 2.1 z -1 {:.17g}", 3 * a));
  l.cmd("thermo_style custom step c_gbad[1][2]");
  try {
    l.cmd("run 0");
    ADD_FAILURE() << "no error for a slab outside the periodic z range";
  } catch (LAMMPS_NS::LAMMPSException &e) {
    expect_match(e.what(), "rdf/slab slab \\[-1, .*\\] must lie inside the periodic z range");
  }
}

// slab bounds far outside a box periodic in z. The remainder beyond whole
// periods comes from the bounds wrapped into the box, and phi from the share of whole periods
// (not their count): a slab of +-1e300 in a box 1e-9 thick (2e309 periods, which overflowed to
// inf before) gives the same phi as +-1e10; bounds whose distance is not a finite number are
// an error (before: NaN without a word).
TEST(PackingComputes, SlabFarBeyondPeriodicBox)
{
  auto phi_of = [](double lo, double hi) {
    Lmp l;
    l.cmds({"units si", "atom_style sphere", "boundary p p p",
            "region box block 0 28e-6 0 28e-6 0 1e-9", "create_box 1 box",
            "create_atoms 1 random 50 5 NULL", "set group all diameter 2e-6",
            fmt::format("compute phi all packing/slab {:.17g} {:.17g}", lo, hi), "run 0 post no"});
    return cscalar(l, "phi");
  };
  const double ref = phi_of(-1e10, 1e10);
  EXPECT_TRUE(std::isfinite(ref));
  // the whole box (and whole periods of it) is phi of the box: 50 spheres of 4/3 pi (1e-6)^3
  // each, all whole periods; relative round-off of the sums ~1e-15
  const double box = 50 * 4.0 / 3.0 * M_PI * 1e-18 / (28e-6 * 28e-6 * 1e-9);
  EXPECT_NEAR(phi_of(0.0, 1e-9), box, 1e-12 * box);
  EXPECT_NEAR(ref, box, 1e-9 * box);
  EXPECT_NEAR(phi_of(-1e300, 1e300), box, 1e-9 * box);
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "boundary p p p",
          "region box block 0 28e-6 0 28e-6 0 1e-9", "create_box 1 box",
          "create_atoms 1 random 50 5 NULL", "set group all diameter 2e-6",
          "compute phi all packing/slab -1.5e308 1.5e308", "thermo_style custom step c_phi"});
  try {
    l.cmd("run 0 post no");
    ADD_FAILURE() << "no error for a slab of infinite thickness, phi = " << cscalar(l, "phi");
  } catch (LAMMPS_NS::LAMMPSException &e) {
    expect_match(e.what(), "Compute packing/slab phi: slab -1.5e\\+308 .. 1.5e\\+308 is not finite");
  }
}

// pair hybrid: "active" reads the granular sub-style's contact flags; a pair handled by another
// sub-style (zero) is a geometric contact but never an active one. Pair 1-2 (granular) is pulled
// to a gap of 0.5 delta_C (still held), pair 3-4 (zero) overlaps by 1 nm throughout.
TEST(PackingComputes, ActiveUnderPairHybrid)
{
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
          "comm_modify vel yes", "region box block -1e-5 1e-5 -1e-5 1e-5 -1e-5 1e-5",
          "create_box 2 box"});
  atom_at(l, -RP + 0.5e-9, 0, 0);
  atom_at(l, RP - 0.5e-9, 0, 0);
  l.cmds({"create_atoms 2 single 0 5e-6 0", "create_atoms 2 single 1.999e-6 5e-6 0",
          "set type * diameter 2e-6", "set type * density 2500",
          "pair_style hybrid granular zero 4e-6",
          "pair_coeff * * granular jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential "
          "marshall 0.3",
          "pair_coeff 2 2 zero", "neighbor 2e-7 bin", "thermo_style custom step atoms",
          "compute geo all coord/dist", "compute act all coord/dist contact active", "run 0"});
  auto za = cperatom(l, "act", MPI_COMM_WORLD), zg = cperatom(l, "geo", MPI_COMM_WORLD);
  EXPECT_EQ(za, (std::vector<double>{0, 1, 1, 0, 0}));
  EXPECT_EQ(zg, (std::vector<double>{0, 1, 1, 1, 1}));
  const double gap = 0.5 * jkr.deltaC();
  l.cmds({fmt::format("set atom 1 x {:.17g}", -RP - gap / 2),
          fmt::format("set atom 2 x {:.17g}", RP + gap / 2), "run 0"});
  za = cperatom(l, "act", MPI_COMM_WORLD);
  zg = cperatom(l, "geo", MPI_COMM_WORLD);
  EXPECT_EQ(za, (std::vector<double>{0, 1, 1, 0, 0}));
  EXPECT_EQ(zg, (std::vector<double>{0, 0, 0, 1, 1}));
}

// Without contact history (hooke, no tangential history) "active" is the pair style's overlap
// test r < r_i + r_j; touching lattice spheres (r = d up to round-off) are not in contact, while
// a 1e-6 d compression makes all of them so.
TEST(PackingComputes, ActiveWithoutHistory)
{
  Lmp l;
  l.cmds({"units metal", "atom_style sphere", "boundary p p p", "lattice sc 1.0",
          "region box block 0 4 0 4 0 4", "create_box 1 box", "create_atoms 1 box",
          "set type 1 diameter 1.000001", "pair_style granular",
          "pair_coeff * * hooke 1000 0.5 tangential linear_nohistory 1 0.3", "comm_modify vel yes",
          "compute act all coord/dist contact active", "run 0"});
  EXPECT_EQ(cscalar(l, "act"), 6.0);
}

// ------------------------------------------------------------------------------------------
// 2 ranks agree with 1 rank (MPI_COMM_SELF on rank 0), newton on and off: a jittered FCC crystal
// (per-atom Z, f(Z), phi, g(r)). Counts are integers and must agree exactly; phi and g are sums
// in a different order: 1e-12 relative is far above round-off (~1e-15) and far below any
// miscount (one pair in a bin changes g by > 1e-4).
TEST(PackingComputes, OneVersusTwoRanks)
{
  if (nprocs() != 2) GTEST_SKIP() << "needs mpirun -np 2";
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  auto run = [](MPI_Comm comm, const std::string &newton, std::vector<double> &out) {
    Lmp l(comm);
    make_lattice(l, FCC, 4, 4, 6, newton);
    l.cmds({"change_box all boundary p p m",
            "displace_atoms all random 0.02 0.02 0.02 8675309 units box",
            "compute z all coord/dist z 1.0 6.0 tolerance 0.01",
            "compute g all rdf/slab 40 2.0 z 1.5 5.5 units diameter",
            "compute phi all packing/slab 1.1 6.3", "run 0"});
    out.clear();
    out.push_back(cscalar(l, "z"));
    for (auto &row : carray(l, "z", 21, 3)) out.insert(out.end(), row.begin(), row.end());
    auto zat = cperatom(l, "z", comm);
    out.insert(out.end(), zat.begin(), zat.end());
    for (auto &row : carray(l, "g", 40, 3)) out.insert(out.end(), row.begin(), row.end());
    auto v = cvector(l, "phi", 3);
    out.insert(out.end(), v.begin(), v.end());
  };
  for (const std::string newton : {"on", "off"}) {
    std::vector<double> two, one;
    run(MPI_COMM_WORLD, newton, two);
    one.resize(two.size());
    if (me == 0) run(MPI_COMM_SELF, "on", one);
    MPI_Bcast(one.data(), (int) one.size(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    ASSERT_EQ(one.size(), two.size());
    for (size_t k = 0; k < one.size(); k++)
      EXPECT_NEAR(two[k], one[k], 1e-12 * std::max(1.0, std::fabs(one[k])))
          << "newton " << newton << " entry " << k;
  }
}

// ------------------------------------------------------------------------------------------
TEST(PackingComputes, BadInput)
{
  const std::vector<std::string> sphere = {"units lj", "atom_style sphere", "boundary p p f",
                                           "region box block 0 5 0 5 0 5", "create_box 1 box"};
  auto err = [&](const std::vector<std::string> &base, const std::string &line) {
    auto c = base;
    c.push_back(line);
    return error_of(c);
  };
  auto with = [&](const std::vector<std::string> &extra) {
    auto c = sphere;
    c.insert(c.end(), extra.begin(), extra.end());
    return c;
  };
  // non-sphere atom style
  const std::vector<std::string> atomic = {"units lj", "atom_style atomic", "boundary p p f",
                                           "region box block 0 5 0 5 0 5", "create_box 1 box"};
  expect_match(err(atomic, "compute c all coord/dist"), "coord/dist requires atom style sphere");
  expect_match(err(atomic, "compute c all rdf/slab 10 2"), "rdf/slab requires atom style sphere");
  expect_match(err(atomic, "compute c all packing/slab 1 2"),
               "packing/slab requires atom style sphere");
  // non-periodic x or y where the slab normalisation assumes it
  for (const char *b : {"f p f", "p f f", "p s p"}) {
    const std::vector<std::string> box = {"units lj", "atom_style sphere",
                                          std::string("boundary ") + b,
                                          "region box block 0 5 0 5 0 5", "create_box 1 box"};
    expect_match(err(box, "compute c all rdf/slab 10 2"),
                 "rdf/slab requires a box periodic in x and y");
    expect_match(err(box, "compute c all packing/slab 1 2"),
                 "packing/slab requires a box periodic in x and y");
    EXPECT_EQ(err(box, "compute c all coord/dist z 1 2"), "no error")
        << "coord/dist needs no periodicity";
  }
  // zlo >= zhi
  expect_match(err(sphere, "compute c all coord/dist z 2 1"),
               "coord/dist z: zlo 2 must be < zhi 1");
  expect_match(err(sphere, "compute c all coord/dist z 1.5 1.5"), "zlo 1.5 must be < zhi 1.5");
  expect_match(err(sphere, "compute c all rdf/slab 10 2 z 3 1"),
               "rdf/slab z: zlo 3 must be < zhi 1");
  expect_match(err(sphere, "compute c all packing/slab 2 2"), "packing/slab zlo 2 must be < zhi 2");
  // bad counts and values
  expect_match(err(sphere, "compute c all rdf/slab 0 2"),
               "number of bins must be in \\[1, 1000000\\], got 0");
  expect_match(err(sphere, "compute c all rdf/slab -5 2"), "number of bins.*got -5");
  expect_match(err(sphere, "compute c all rdf/slab 10 0"), "rdf/slab rmax must be > 0, got 0");
  expect_match(err(sphere, "compute c all rdf/slab 10 -1.5"), "rmax must be > 0, got -1.5");
  expect_match(err(sphere, "compute c all rdf/slab 2.5 2"), "Expected integer.*2.5");
  expect_match(err(sphere, "compute c all coord/dist zmax 0"),
               "zmax must be in \\[1, 10000\\], got 0");
  expect_match(err(sphere, "compute c all coord/dist tolerance -1e-3"),
               "tolerance must be >= 0, got -0.001");
  expect_match(err(sphere, "compute c all coord/dist contact touching"),
               "contact must be 'geometric' or 'active', got 'touching'");
  expect_match(err(sphere, "compute c all coord/dist contact active tolerance 0.1"),
               "tolerance applies to contact geometric only");
  expect_match(err(sphere, "compute c all rdf/slab 10 2 units sigma"),
               "units must be 'box' or 'diameter', got 'sigma'");
  // unknown keywords and missing arguments
  expect_match(err(sphere, "compute c all coord/dist zz 1 2"),
               "Unknown compute coord/dist keyword: zz");
  expect_match(err(sphere, "compute c all rdf/slab 10 2 cutoff 3"),
               "Unknown compute rdf/slab keyword: cutoff");
  expect_match(err(sphere, "compute c all packing/slab 1 2 every"),
               "Unknown compute packing/slab keyword: every");
  expect_match(err(sphere, "compute c all rdf/slab 10"),
               "Illegal compute rdf/slab.*missing argument");
  expect_match(err(sphere, "compute c all packing/slab 1"),
               "Illegal compute packing/slab.*missing argument");
  expect_match(err(sphere, "compute c all coord/dist z 1"), "coord/dist z.*missing argument");
  // run-time checks
  const std::vector<std::string> gran = {
      "create_atoms 1 single 1 1 1", "set type 1 diameter 1", "pair_style granular",
      "pair_coeff * * hooke 1000 0.5 tangential linear_nohistory 1 0.3", "comm_modify vel yes"};
  auto c = with(gran);
  c.push_back("compute c all rdf/slab 10 4");
  c.push_back("thermo_style custom step c_c[1][2]");
  expect_match(err(c, "run 0"),
               "rdf/slab rmax plus skin 4.3 exceeds the ghost atom range .*comm_modify cutoff");
  c = with({"create_atoms 1 single 1 1 1", "set type 1 diameter 1", "pair_style zero 1.0",
            "pair_coeff * *", "compute c all coord/dist contact active"});
  expect_match(err(c, "run 0"), "contact active requires a granular pair style.*not zero");
  c = with({"create_atoms 1 single 1 1 1", "compute c all coord/dist"});
  c.push_back("thermo_style custom step c_c");
  expect_match(err(c, "run 0"), "coord/dist requires a pair style");
  c = with(gran);
  c.push_back("compute c all rdf/slab 10 1 units diameter");
  c.push_back("group none empty");
  c.push_back("compute d none rdf/slab 10 1 units diameter");
  expect_match(err(c, "run 0"), "units diameter needs atoms of non-zero size in group none");
  c = with(gran);
  c.push_back("compute c all coord/dist tolerance 0.5");
  expect_match(err(c, "run 0"), "coord/dist tolerance 0.5 exceeds the neighbor skin 0.3");
}
