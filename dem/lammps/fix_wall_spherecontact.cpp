/* fix wall/spherecontact: see fix_wall_spherecontact.h. For a particle i (body 1) and a wall
 * (body 2, rigid, flat) with n the wall's normal into the box:
 *   overlap h = R_i - (x_i - LO) (LO wall) or R_i - (HI - x_i) (HI wall); LO, HI constants or
 *   equal-style variables (v_name) evaluated every step, the wall velocity v_w = (LO_n - LO_{n-1})/dt
 *   F, dF/dh, a, h1 = sct_eval_parts(h, h_max) at R1 = R_i, R2 = inf (a, h1 with friction);  h_max <- max(h_max, h)
 *   F_n = max(0, F - 2 gamma sqrt(m_i dF/dh) v_n), v = v_i - v_w         (Eq. N, m* = m_i)
 *   F_t = -8 G* a xi, |F_t| <= mu F_n, v_t = v - v_n n - d_i w_i x n    (Eq. T, d_i = R_i - h1)
 *   force on i: F_n n + F_t; torque -d_i n x F_t */
#include "fix_wall_spherecontact.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_spherecontact_history.h"
#include "group.h"
#include "input.h"
#include "modify.h"
#include "update.h"
#include "variable.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;
using namespace spherecontact_lmp;

FixWallSphereContact::FixWallSphereContact(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), axis(2), mu(0.0), gamma(0.0), force_flag(0), history(nullptr)
{
  const char *usage = "fix ID group wall/spherecontact xplane|yplane|zplane LO HI table_lo.sct "
                      "[table_hi.sct] [friction MU] [damping GAMMA]";
  if (narg < 7) error->all(FLERR, "Illegal fix wall/spherecontact command: {}", usage);
  std::string dir = arg[3];
  if (dir == "xplane") axis = 0;
  else if (dir == "yplane") axis = 1;
  else if (dir == "zplane") axis = 2;
  else error->all(FLERR, "fix wall/spherecontact: unknown wall {} ({})", dir, usage);
  for (int w = 0; w < 2; w++) {
    has[w] = std::strcmp(arg[4 + w], "NULL") != 0;
    varindex[w] = -1;
    vwall[w] = prevpos[w] = 0.0;
    prevset[w] = false;
    if (has[w] && std::strncmp(arg[4 + w], "v_", 2) == 0) {
      varname[w] = arg[4 + w] + 2;
      pos[w] = 0.0;
    } else {
      pos[w] = has[w] ? utils::numeric(FLERR, arg[4 + w], false, lmp) : 0.0;
    }
  }
  if (!has[0] && !has[1]) error->all(FLERR, "fix wall/spherecontact: both walls NULL");
  if (has[0] && has[1] && varname[0].empty() && varname[1].empty() && pos[0] >= pos[1])
    error->all(FLERR, "fix wall/spherecontact: LO >= HI");
  int iarg = 7;
  std::string files[2] = {arg[6], arg[6]};
  if (iarg < narg && std::strcmp(arg[iarg], "friction") != 0 && std::strcmp(arg[iarg], "damping") != 0)
    files[1] = arg[iarg++];
  for (; iarg < narg; iarg += 2) {
    if (iarg + 1 >= narg) error->all(FLERR, "fix wall/spherecontact: {} needs a value", arg[iarg]);
    if (std::strcmp(arg[iarg], "friction") == 0)
      mu = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
    else if (std::strcmp(arg[iarg], "damping") == 0)
      gamma = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
    else
      error->all(FLERR, "fix wall/spherecontact: unknown keyword {} ({})", arg[iarg], usage);
  }
  if (mu < 0.0 || gamma < 0.0) error->all(FLERR, "fix wall/spherecontact: friction, damping >= 0");
  for (int w = 0; w < 2; w++) {
    if (!has[w]) continue;
    std::string err;
    if (!load_law(files[w], law[w], err)) error->all(FLERR, "fix wall/spherecontact: {}", err);
    if (!std::isinf(law[w].ratio_hi))
      error->all(FLERR, "fix wall/spherecontact: table {} is not a wall table (R2/R1 range {} to "
                 "{}; write it with --radius2 inf)", files[w], law[w].ratio_lo, law[w].ratio_hi);
    if (mu > 0.0 && law[w].gstar <= 0.0)
      error->all(FLERR, "fix wall/spherecontact friction: table {} gives no E and nu in its meta "
                 "line", files[w]);
  }
  vector_flag = 1;
  size_vector = 4;
  global_freq = 1;
  extvector = 1;
  history_id = std::string(id) + "_HISTORY";
}

FixWallSphereContact::~FixWallSphereContact()
{
  for (auto &l : law) free_law(l);
}

// the history store: a fix of its own, so that read_restart finds and restores it by ID
void FixWallSphereContact::post_constructor()
{
  auto *f = modify->get_fix_by_id(history_id);
  if (!f)
    f = modify->add_fix(fmt::format("{} {} spherecontact/history 4 2", history_id, group->names[igroup]));
  history = static_cast<FixSphereContactHistory *>(f);
}

int FixWallSphereContact::setmask()
{
  return POST_FORCE | MIN_POST_FORCE;
}

void FixWallSphereContact::init()
{
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "fix wall/spherecontact requires per-atom radius and mass (atom_style sphere)");
  if (mu > 0.0 && (!atom->omega_flag || !atom->torque_flag))
    error->all(FLERR, "fix wall/spherecontact with friction requires omega and torque");
  history = static_cast<FixSphereContactHistory *>(modify->get_fix_by_id(history_id));
  if (!history) error->all(FLERR, "fix wall/spherecontact: its history fix {} was deleted", history_id);
  for (int w = 0; w < 2; w++) {
    if (varname[w].empty()) continue;
    varindex[w] = input->variable->find(varname[w].c_str());
    if (varindex[w] < 0)
      error->all(FLERR, "fix wall/spherecontact: variable {} for the {} wall does not exist",
                 varname[w], w ? "HI" : "LO");
    if (!input->variable->equalstyle(varindex[w]))
      error->all(FLERR, "fix wall/spherecontact: variable {} is not equal-style", varname[w]);
    prevset[w] = false;    // the first evaluation of a run gives the wall no velocity
  }
  // critical time step of the stiffest particle-wall contact: 2 sqrt(m_min / k_max(R_max))
  double rmax = 0.0, mmin = INFINITY, g[2];
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->mask[i] & groupbit) {
      rmax = std::fmax(rmax, atom->radius[i]);
      mmin = std::fmin(mmin, atom->rmass[i]);
    }
  MPI_Allreduce(&rmax, &g[0], 1, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(&mmin, &g[1], 1, MPI_DOUBLE, MPI_MIN, world);
  for (int w = 0; w < 2 && g[0] > 0.0; w++) {
    if (!has[w]) continue;
    sct_stencil st;
    if (sct_stencil_for(law[w].tab, g[0], INFINITY, &st, nullptr, 0) != SCT_OK) continue;
    double k = sct_max_stiffness(law[w].tab, &st, sct_h_max(law[w].tab, &st));
    double dtc = 2.0 * std::sqrt(g[1] / k);
    if (comm->me == 0)
      utils::logmesg(lmp, "fix wall/spherecontact {} {} wall: critical time step 2*sqrt(m/k_max) = "
                     "{:.6g} (k_max = {:.6g}, radius {:.6g}; m = {:.6g}); timestep = {:.4g} of it\n",
                     id, w ? "HI" : "LO", dtc, k, g[0], g[1], update->dt / dtc);
  }
}

void FixWallSphereContact::setup(int vflag)
{
  post_force(vflag);
}

void FixWallSphereContact::min_setup(int vflag)
{
  post_force(vflag);
}

void FixWallSphereContact::min_post_force(int vflag)
{
  post_force(vflag);
}

// positions of variable walls at this step, and their velocity from the previous evaluation
void FixWallSphereContact::wall_positions()
{
  bool any = false;
  for (int w = 0; w < 2; w++) {
    if (varindex[w] < 0) continue;
    if (!any) modify->clearstep_compute();
    any = true;
    pos[w] = input->variable->compute_equal(varindex[w]);
    vwall[w] = (prevset[w] && !update->setupflag && update->dt > 0.0)
        ? (pos[w] - prevpos[w]) / update->dt : 0.0;
    prevpos[w] = pos[w];
    prevset[w] = true;
  }
  if (any) {
    modify->addstep_compute(update->ntimestep + 1);
    if (has[0] && has[1] && pos[0] >= pos[1])
      error->all(FLERR, "fix wall/spherecontact {}: LO {} >= HI {} at step {}", id, pos[0], pos[1],
                 update->ntimestep);
  }
}

void FixWallSphereContact::post_force(int /*vflag*/)
{
  wall_positions();
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  double *radius = atom->radius, *rmass = atom->rmass;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const bool advance = !update->setupflag;
  const double dt = update->dt;
  const bool rot = mu > 0.0;
  force_flag = 0;
  wforce[0] = wforce[1] = 0.0;

  history->begin(nlocal);
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    for (int w = 0; w < 2; w++) {
      if (!has[w]) continue;
      const double dist = w == 0 ? x[i][axis] - pos[0] : pos[1] - x[i][axis];
      const double h = radius[i] - dist;
      const double *old = history->find(i, w);
      if (h <= 0.0 && !old) continue;
      char err[256];
      sct_stencil st;
      if (sct_stencil_for(law[w].tab, radius[i], INFINITY, &st, err, sizeof err) != SCT_OK)
        error->one(FLERR, "fix wall/spherecontact: atom {}: {}", atom->tag[i], err);
      double rec[4] = {0.0, 0.0, 0.0, 0.0};    // h_max, spring xi
      if (old) std::memcpy(rec, old, sizeof rec);
      sct_result res;
      sct_eval_parts(law[w].tab, &st, h, rec[0], rot ? SCT_WANT_ALL : 0, &res);
      if (h > rec[0]) rec[0] = h;
      if (res.F > 0.0) {
        double n[3] = {0.0, 0.0, 0.0};
        n[axis] = w == 0 ? 1.0 : -1.0;
        const double vrel[3] = {v[i][0] - (axis == 0 ? vwall[w] : 0.0),
                                v[i][1] - (axis == 1 ? vwall[w] : 0.0),
                                v[i][2] - (axis == 2 ? vwall[w] : 0.0)};
        const double vn = vrel[axis] * n[axis];
        double fn = damped_normal(res.F, res.dF_dh, vn, rmass[i], gamma), ft[3] = {0.0, 0.0, 0.0};
        if (rot) {
          const double d = radius[i] - res.h1;
          const double *om = omega[i];
          double vt[3];
          vt[0] = vrel[0] - vn * n[0] - d * (om[1] * n[2] - om[2] * n[1]);
          vt[1] = vrel[1] - vn * n[1] - d * (om[2] * n[0] - om[0] * n[2]);
          vt[2] = vrel[2] - vn * n[2] - d * (om[0] * n[1] - om[1] * n[0]);
          tangential(8.0 * law[w].gstar * res.a, mu, fn, n, vt, dt, advance, rec + 1, ft);
          const double nxf[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                                 n[0] * ft[1] - n[1] * ft[0]};
          for (int k = 0; k < 3; k++) torque[i][k] -= d * nxf[k];
        } else {
          rec[1] = rec[2] = rec[3] = 0.0;
        }
        for (int k = 0; k < 3; k++) f[i][k] += fn * n[k] + ft[k];
        wforce[w] -= fn * n[axis] + ft[axis];    // reaction on the wall
      } else {
        rec[1] = rec[2] = rec[3] = 0.0;
      }
      if (!history->add(i, w, rec))
        error->one(FLERR, "fix wall/spherecontact: history of atom {} is full", atom->tag[i]);
    }
  }
  history->commit();
}

double FixWallSphereContact::compute_vector(int n)
{
  if (n >= 2) return has[n - 2] ? pos[n - 2] : 0.0;
  if (!force_flag) {
    MPI_Allreduce(wforce, wforce_all, 2, MPI_DOUBLE, MPI_SUM, world);
    force_flag = 1;
  }
  return wforce_all[n];
}
