/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_charge_scheme.h"

#include "coul_fmm_backend.h"
#include "coul_fmm_evaluator.h"
#include "coul_fmm_near_refresh.h"
#include "coul_fmm_state.h"
#include "coul_fmm_time_stepping.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix.h"
#include "force.h"
#include "modify.h"
#include "update.h"

#include "gcfmm/options.hpp"

#include <string>

using namespace LAMMPS_NS;
using MTS = CoulFMMTimeStepping;

CoulFMMChargeScheme::CoulFMMChargeScheme(LAMMPS *lmp, const Parts &parts) :
    Pointers(lmp), p(parts),
    eval(std::make_unique<CoulFMMEvaluator>(lmp, parts.fix->id, parts.fix->groupbit, *parts.backend)),
    nevaluations(0.0), forced(false), pending_absorbed(0.0)
{
}

CoulFMMChargeScheme::~CoulFMMChargeScheme() = default;

void CoulFMMChargeScheme::init()
{
  auto sleep = modify->get_fix_by_style("^sleep/gran$");
  eval->init(*p.opts, sleep.empty() || !p.sleepers_static ? nullptr : sleep[0],
             p.fix->thermo_virial, p.distributed);
  const auto &mts = p.stepping->settings();
  if (mts.tolerance > 0.0 && comm->me == 0)
    utils::logmesg(lmp,
                   "Fix coul/fmm {}: evaluation interval adapted between 1 and {} steps to "
                   "a time-stepping error of {:.3g}\n",
                   p.fix->id, mts.every, mts.tolerance);
  if (mts.near_cutoff > 0.0 && mts.every == 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: near has no effect with every 1 (each step is an "
                   "evaluation)",
                   p.fix->id);
  if (p.stepping->refreshes_near()) p.near->request(mts.near_cutoff);
  init_absorbing();
}

// keyword qchange: absorb if asked, or by default when a fix declares that it transfers
// charges (extract("charge_transfers") non-zero, e.g. fix tribo/charge); it needs the near
// refresh, without which every change is evaluated. The far part's allowance is the
// tolerance, or the accuracy with a fixed interval.
void CoulFMMChargeScheme::init_absorbing()
{
  bool wanted = p.qchange == QChange::ABSORB;
  std::string by = "qchange absorb";
  if (p.qchange == QChange::AUTO) {
    for (auto *fix : modify->get_fix_list()) {
      int dim = 0;
      auto *transfers = static_cast<int *>(fix->extract("charge_transfers", dim));
      if (transfers && *transfers != 0) {
        wanted = true;
        by = fmt::format("fix {} (transfers charges)", fix->id);
        break;
      }
    }
  }
  CoulFMMTimeStepping &mts = *p.stepping;
  const double tau = mts.settings().tolerance > 0.0 ? mts.settings().tolerance : p.opts->accuracy;
  mts.set_absorbing(wanted && mts.refreshes_near(), tau);
  // said once per setting: a deck that runs one short run per particle would repeat it
  const std::string setting = fmt::format("{} {} {} {}", wanted, mts.refreshes_near(), by, tau);
  if (setting == absorbing_said) return;
  absorbing_said = setting;
  if (wanted && !mts.refreshes_near() && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: charge changes are evaluated, not absorbed ({}): absorbing "
                   "needs every > 1 and near > 0",
                   p.fix->id, by);
  else if (mts.absorbs() && comm->me == 0)
    utils::logmesg(lmp,
                   "Fix coul/fmm {}: charge changes absorbed between evaluations ({}); their far "
                   "part is bounded to {:.3g} of the field\n",
                   p.fix->id, by, tau);
}

// continue the schedule of the previous run (or of the restart file) when its stored field
// still belongs to these atoms, charges and box: a run split into pieces, or continued from a
// restart, then evaluates on the same steps as the uninterrupted run. Charges added in between
// (create_atoms, static sources woken) are a known change: the run's first step evaluates them
// with the others, as an insertion within a run does, and the adapted interval and the other
// atoms' slopes go on (started again, the interval would climb from 1 after every insertion).
bool CoulFMMChargeScheme::continues()
{
  eval->update_sleepers();
  return p.state->continuation(*p.stepping, eval->boundary(),
                               [this](int i) { return eval->asleep(i); }) != MTS::Continuity::NONE;
}

// due on the schedule's steps, whenever atoms were added or removed (fix deposit, evaporate:
// a new atom must feel, and exert, the force from its first step) and whenever the charges,
// qqrd2e or the geometry changed (a stored field would belong to other charges)
// (also the absorbed charge changes' far part, when its bound exceeds the allowance: the
// evaluation is then brought forward, doc/theory.md, eq. (5.6); on a scheduled step such an
// evaluation does not adapt the interval either, as its error is the changes', not the
// interval's). On a step on which a charge changed, the ghosts get the local atoms' charges
// for the near refresh.
bool CoulFMMChargeScheme::evaluation_due()
{
  eval->update_sleepers();
  forced = false;
  pending_absorbed = 0.0;
  CoulFMMTimeStepping &mts = *p.stepping;
  const auto c =
      p.state->continuity(mts, eval->boundary(), [this](int i) { return eval->asleep(i); });
  const auto &changes = p.state->charge_changes();
  if (changes.since_applied > 0.0 && mts.refreshes_near()) p.near->share_charges();
  if (c != MTS::Continuity::SAME) return true;
  const bool scheduled = mts.scheduled(update->ntimestep);
  if (changes.absorbed > 0.0) {
    // in free space no two atoms are farther apart than the box diagonal: a near cutoff beyond
    // it refreshes every pair, and nothing of the changes is left out
    const bool periodic = p.opts->boundary == gcfmm::Boundary::Periodic2D;
    const double rc = mts.settings().near_cutoff, *prd = domain->prd;
    const bool all_near =
        !periodic && rc * rc > prd[0] * prd[0] + prd[1] * prd[1] + prd[2] * prd[2];
    const double bound = all_near
        ? 0.0
        : MTS::absorbed_far_bound(force->qqrd2e, changes.sum_abs_dq, changes.net_dq, rc,
                                  periodic ? domain->xprd * domain->yprd : 0.0);
    forced = mts.far_part_exceeds(bound);
    if (forced && !scheduled) mts.count_forced();
  }
  if (scheduled || forced) return true;
  pending_absorbed = changes.absorbed_now;
  return false;
}

// eq. (5.2); it cannot follow the atoms when a pair refreshed since the evaluation is about to
// leave the neighbor lists or has left them (CoulFMMNearRefresh::pair_leaving). With every 1
// the stored field is that of this step (a run continued on the step of its last evaluation).
bool CoulFMMChargeScheme::continue_last(double &energy)
{
  if (p.stepping->settings().every > 1 && !advance_field()) return false;
  p.stepping->count_absorbed(pending_absorbed);
  const int check = p.stepping->settings().check_every;
  if (check > 0 && update->ntimestep % check == 0) eval->measure_error(*p.stepping, *p.state);
  energy = apply_field();
  return true;
}

// a line search evaluates several trial positions within one step: a field of their own
double CoulFMMChargeScheme::evaluate(Evaluation why)
{
  compute_field(why != Evaluation::FRESH, why == Evaluation::BROUGHT_FORWARD || forced);
  forced = false;
  return apply_field();
}

// a full evaluation (doc/theory.md, eqs. (5.2)-(5.4)); with the same atoms as at the last one
// it first measures the error the time stepping had reached (CoulFMMTimeStepping::plan)
void CoulFMMChargeScheme::compute_field(bool with_slope, bool brought_forward)
{
  CoulFMMState &st = *p.state;
  st.check_charges(p.fix->id);
  CoulFMMTimeStepping &mts = *p.stepping;
  const int nlocal = atom->nlocal;
  eval->update_sleepers();
  auto asleep_now = [this](int i) { return eval->asleep(i); };
  const auto cont = with_slope && mts.settings().every > 1
      ? st.continuity(mts, eval->boundary(), asleep_now)
      : MTS::Continuity::NONE;
  MTS::Plan plan = mts.plan(cont, with_slope, update->ntimestep);
  if (brought_forward) plan.ends_interval = false;
  // the refresh the time stepping would have applied now (only to measure the interval's
  // error: not for an evaluation that does not end one), and D for a new slope
  const bool near_now = plan.near && plan.ends_interval;
  if (near_now)
    p.near->compute(mts, st, false, plan.keep_slope ? mts.trend_factor(plan.steps) : 0.0);
  const bool near_then = plan.near && plan.new_slope;
  if (near_then) p.near->compute(mts, st, true, -1.0);
  const int groupbit = p.fix->groupbit;
  for (int i = 0; i < nlocal; i++) {
    double xu[3];
    domain->unmap(atom->x[i], atom->image[i], xu);
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
    mts.begin_evaluation(plan, st.evaluation(i), xu, q, eval->asleep(i),
                         near_now ? p.near->now()[i] : nullptr,
                         near_then ? p.near->then()[i] : nullptr, st.field(i));
  }
  st.record(mts, eval->boundary());
  p.near->forget_pairs();    // the held pairs belong to the evaluation state overwritten above
  eval->evaluate([&st](int i) { return st.evaluated_field(i); }, true);
  if (mts.refreshes_near()) p.near->record_evaluation(mts.settings().near_cutoff);
  nevaluations += 1.0;
  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < nlocal; i++) {
    mts.end_evaluation(plan, st.evaluation(i), st.field(i), sums);
    st.apply_evaluated(i);
  }
  if (plan.same) p.backend->communication().sum(sums, 2);
  mts.finish_evaluation(plan, MTS::relative_rms(sums));
  if (mts.absorbs()) {
    double scale[2];
    st.field_scale_sums(scale);
    mts.set_field_scale(scale);
  }
}

// eq. (5.2) between evaluations; false (nothing advanced) if a near pair is leaving the lists
// on some rank: then the field must be evaluated now
bool CoulFMMChargeScheme::advance_field()
{
  CoulFMMTimeStepping &mts = *p.stepping;
  const double steps = (double) (update->ntimestep - mts.evaluated.step);
  const bool refresh = mts.settings().near_cutoff > 0.0;
  if (refresh) {
    p.near->compute(mts, *p.state, false, mts.trend_factor(steps));
    if (p.backend->communication().any(p.near->pair_leaving())) return false;
  }
  for (int i = 0; i < atom->nlocal; i++)
    mts.predict(p.state->evaluation(i), steps, refresh ? p.near->now()[i] : nullptr,
                p.state->field(i));
  return true;
}

// F_i = q_i E_i into the state's forces; returns this rank's energy 1/2 sum q_i phi_i
double CoulFMMChargeScheme::apply_field()
{
  double *q = atom->q;
  double energy = 0.0;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!acts_on(i)) continue;
    const double *e = p.state->field(i);
    double *f = p.state->force_on(i);
    for (int k = 0; k < 3; k++) f[k] = q[i] * e[k];
    energy += 0.5 * q[i] * e[3];
  }
  return energy;
}

bool CoulFMMChargeScheme::acts_on(int i) const
{
  return (atom->mask[i] & p.fix->groupbit) && atom->q[i] != 0.0;
}

// the static sleepers' pair energy with the awake charges and among themselves
double CoulFMMChargeScheme::total_energy(double atoms)
{
  if (!eval->split_active()) return atoms;
  return atoms + eval->sleeper_pair_energy() + eval->sleeper_source_energy();
}

const CoulFMMScheme::Diagnostics &CoulFMMChargeScheme::diagnostics() const
{
  return eval->diagnostics_of_last();
}

double CoulFMMChargeScheme::memory_usage() const
{
  return eval->memory_usage();
}
