/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(tribo/charge,FixTriboCharge);
// clang-format on
#else

#ifndef LMP_FIX_TRIBO_CHARGE_H
#define LMP_FIX_TRIBO_CHARGE_H

#include "fix.h"

#include "marshall_kernels.h"

#include <string>
#include <utility>
#include <vector>

namespace LAMMPS_NS {

// Contact charging by the condenser model (tribo_charge_kernels.h, doc/fix_tribo_charge.rst):
// each step, every contact of two particles of the group (and of a particle with the plane of a
// fix wall/gran) whose area has grown beyond the area it has charged over moves charge between
// its two bodies by the work-function difference, less the drop of the normal field at the
// contact (fix coul/fmm's field). The adapter: keywords, the contact records, communication,
// restart; the equations are in tribo_charge_kernels.h.
//
// Charge is moved in whole quanta (force->qelectron / 2^16) and each particle keeps the count
// of quanta it gained, so the charge moved between particles sums to zero exactly on any
// number of ranks. A pair of two ranks is computed by both (a half list without newton): both
// find the same quanta from the same inputs in the same order (the atoms' positions as held by
// their owners and the periodic shift between them, their charges and fields), and each adds
// them to the atom it owns.
class FixTriboCharge : public Fix {
 public:
  FixTriboCharge(class LAMMPS *, int, char **);
  ~FixTriboCharge() override;
  int setmask() override;
  void init() override;
  void init_list(int, class NeighList *) override;
  void setup(int) override;
  void post_force(int) override;
  double compute_vector(int) override;
  void *extract(const char *, int &) override;
  double memory_usage() override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_forward_comm(int, int *, double *, int, int *) override;
  void unpack_forward_comm(int, int, double *) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 private:
  // the per-atom row: the charge the atom would have without contacts, the quanta it gained,
  // the charge this fix last gave it (a different one was set by someone else: rebased), and
  // its contact records (partner tag, or -1 - plane for a wall; area charged over; step seen;
  // the overlap of that area)
  enum Row : int { QBASE = 0, GAINED = 1, QSET = 2, NREC = 3, RECORDS = 4 };
  static constexpr int REC_SIZE = 4;

  struct Wall {
    class FixWallGran *fix;
    double potential;         // V_w as energy per charge
    double emix, gamma;       // its contact model (jkr/marshall)
    int axis;                 // 0, 1, 2
    double lo, hi;            // its planes (+-BIG: none)
  };

  double z0;                         // the condenser gap
  std::vector<double> potential;     // V per atom type, energy per charge (index 1..ntypes)
  std::vector<double> potential_volts;
  std::vector<std::pair<std::string, double>> wall_args;    // fix ID, V in volts
  std::vector<Wall> walls;
  bool field_on;
  int maxcontacts;
  int rowsize;
  int transfers_flag;    // extract("charge_transfers"): this fix changes charges in a run

  class NeighList *list;
  class Fix *coul;                   // fix coul/fmm (field yes)
  std::vector<double> emix, gamma;   // jkr/marshall per type pair, (ntypes+1)^2
  double quantum;                    // charge moved in whole multiples of this
  double coulomb, eps;               // force->qqrd2e, 1 / (4 pi qqrd2e)

  double **row;         // per-atom rows (local atoms)
  double **ghost;       // per atom, local and ghost: position as owned, periodic shift, field
  int nmax_ghost;
  int comm_stage;       // forward communication: 0 positions, shifts and fields; 1 charges

  // cumulative on this rank: quanta moved between particles, given by walls, events
  double moved_pair, given_wall, events_pair, events_wall;
  std::vector<int> changed;    // local atoms whose gained quanta changed this step (kept: no
                               // allocation per step)

  void check_pair_model();
  void find_walls();
  void rebase_charges();
  double *find_record(int i, double key);
  double *add_record(int i, double key);
  void sweep_records(int i, bigint step);
  void exchange_inputs();
  void charge_pair(int i, int j, bigint step, std::vector<int> &changed);
  void charge_walls(bigint step, std::vector<int> &changed);
  const double *field_of(int i) const;
  double cached_key[3];    // R_eff, gamma, E* of cached_scales
  MarshallKernels::JKRScales cached_scales;
  const MarshallKernels::JKRScales &scales_of(double reff, double gamma_, double emix_);
};

}    // namespace LAMMPS_NS

#endif
#endif
