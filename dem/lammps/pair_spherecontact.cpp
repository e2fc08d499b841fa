/* pair_style spherecontact: see pair_spherecontact.h and docs/guides/dem-lammps.md.
 *
 * For each neighbour pair i, j (n = (x_i - x_j)/r from j to i):
 *   overlap           h = R_i + R_j - r
 *   stencil           the ratio stencil of R_i, R_j (sct_stencil_for), kept per neighbour-list
 *                     slot and re-used while the slot's radii and types are the same
 *   normal (table)    F, dF/dh, a, h1 = sct_eval_parts(h, h_max)        dem/FORMAT.md
 *                     (a and h1 only with friction: they serve the tangential force alone)
 *   history           h_max <- max(h_max, h)
 *   damping (Eq. N)   F_n = max(0, F - 2 gamma sqrt(m* dF/dh) v_n)
 *   tangential (Eq. T) F_t = -8 G* a xi,  |F_t| <= mu F_n
 *   force on i        F_n n + F_t;  torque on i  -d_i n x F_t, d_i = R_i - (i's share of h)
 * Each rank keeps the records of its own atoms (both atoms of a pair when both are owned), so
 * with newton_pair off a pair across ranks is computed identically on both. */
#include "pair_spherecontact.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_spherecontact_history.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace spherecontact_lmp;

PairSphereContact::PairSphereContact(LAMMPS *lmp) :
    Pair(lmp), mu(0.0), gamma(0.0), maxcontacts(24), law_of(nullptr), body1_of(nullptr),
    maxrad(nullptr), minmass(nullptr), history(nullptr), history_id("SPHERECONTACT_HISTORY")
{
  single_enable = 0;
  restartinfo = 0;
  finitecutflag = 1;
  one_coeff = 0;
}

PairSphereContact::~PairSphereContact()
{
  for (auto &l : laws) free_law(l);
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
    memory->destroy(law_of);
    memory->destroy(body1_of);
    delete[] maxrad;
    delete[] minmass;
  }
}

void PairSphereContact::allocate()
{
  allocated = 1;
  int n = atom->ntypes + 1;
  memory->create(setflag, n, n, "pair:setflag");
  memory->create(cutsq, n, n, "pair:cutsq");
  memory->create(law_of, n, n, "pair:law_of");
  memory->create(body1_of, n, n, "pair:body1_of");
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      // every pair counts as set for LAMMPS' generic check: init_style names a missing table
      setflag[i][j] = 1;
      law_of[i][j] = -1;
      body1_of[i][j] = 0;
    }
  maxrad = new double[n]();
  minmass = new double[n]();
}

void PairSphereContact::settings(int narg, char **arg)
{
  for (int k = 0; k < narg; k += 2) {
    if (k + 1 >= narg) error->all(FLERR, "pair_style spherecontact: keyword {} needs a value", arg[k]);
    std::string key = arg[k];
    if (key == "friction")
      mu = utils::numeric(FLERR, arg[k + 1], false, lmp);
    else if (key == "damping")
      gamma = utils::numeric(FLERR, arg[k + 1], false, lmp);
    else if (key == "contacts")
      maxcontacts = utils::inumeric(FLERR, arg[k + 1], false, lmp);
    else
      error->all(FLERR, "pair_style spherecontact: unknown keyword {} (friction MU, damping GAMMA, "
                 "contacts N)", key);
  }
  if (mu < 0.0 || gamma < 0.0 || maxcontacts < 1)
    error->all(FLERR, "pair_style spherecontact: friction and damping must be >= 0, contacts >= 1");
}

int PairSphereContact::law_index(const std::string &file)
{
  for (size_t k = 0; k < laws.size(); k++)
    if (laws[k].file == file) return static_cast<int>(k);
  Law law;
  std::string err;
  if (!load_law(file, law, err)) error->all(FLERR, "pair_coeff spherecontact: {}", err);
  laws.push_back(law);
  return static_cast<int>(laws.size()) - 1;
}

void PairSphereContact::coeff(int narg, char **arg)
{
  if (narg != 3 && narg != 5)
    error->all(FLERR, "pair_coeff I J table.sct [body1 T] for pair_style spherecontact");
  if (!allocated) allocate();
  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);
  int b1 = 0;
  if (narg == 5) {
    if (std::strcmp(arg[3], "body1") != 0)
      error->all(FLERR, "pair_coeff spherecontact: unknown keyword {} (body1 T)", arg[3]);
    b1 = utils::inumeric(FLERR, arg[4], false, lmp);
  }
  int law = law_index(arg[2]);
  int count = 0;
  for (int i = ilo; i <= ihi; i++)
    for (int j = (jlo > i ? jlo : i); j <= jhi; j++) {
      if (b1 && b1 != i && b1 != j)
        error->all(FLERR, "pair_coeff {} {} {} body1 {}: the type of body 1 must be one of the pair",
                   i, j, arg[2], b1);
      law_of[i][j] = law_of[j][i] = law;
      body1_of[i][j] = body1_of[j][i] = b1 ? b1 : i;
      count++;
    }
  if (count == 0) error->all(FLERR, "Incorrect args for pair coefficients");
}

void PairSphereContact::init_style()
{
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "pair_style spherecontact requires per-atom radius and mass (atom_style "
               "sphere)");
  if (force->newton_pair)
    error->all(FLERR, "pair_style spherecontact requires newton_pair off (command: newton off): "
               "each rank keeps the contact history of its own atoms");
  if ((mu > 0.0 || gamma > 0.0) && !comm->ghost_velocity)
    error->all(FLERR, "pair_style spherecontact with friction or damping needs the velocities of "
               "ghost atoms: comm_modify vel yes");
  if (mu > 0.0 && (!atom->omega_flag || !atom->torque_flag))
    error->all(FLERR, "pair_style spherecontact with friction requires omega and torque (atom_style "
               "sphere)");
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (law_of[i][j] < 0)
        error->all(FLERR, "pair_style spherecontact: no table for atom types {} and {} "
                   "(pair_coeff {} {} table.sct)", i, j, i, j);
      if (mu > 0.0 && laws[law_of[i][j]].gstar <= 0.0)
        error->all(FLERR, "pair_style spherecontact friction: table {} gives no E and nu of both "
                   "bodies in its meta line (needed for k_t = 8 G* a)", laws[law_of[i][j]].file);
    }

  neighbor->add_request(this, NeighConst::REQ_SIZE);
  slots.clear();    // tables or radii may have changed since the last run

  // the history store: created once, re-used by later runs and restored by read_restart
  auto *f = modify->get_fix_by_id(history_id);
  if (f && (std::strcmp(f->style, "spherecontact/history") != 0 ||
            static_cast<FixSphereContactHistory *>(f)->maxcontacts() != maxcontacts ||
            static_cast<FixSphereContactHistory *>(f)->nvalue() != NVALUE)) {
    modify->delete_fix(history_id);
    f = nullptr;
  }
  if (!f)
    f = modify->add_fix(fmt::format("{} all spherecontact/history {} {}", history_id, NVALUE,
                                    maxcontacts));
  history = static_cast<FixSphereContactHistory *>(f);

  // largest radius and smallest mass of each type (neighbour cutoff, time step)
  int n = atom->ntypes + 1;
  std::vector<double> rloc(n, 0.0), mloc(n, INFINITY);
  for (int i = 0; i < atom->nlocal; i++) {
    int t = atom->type[i];
    rloc[t] = std::fmax(rloc[t], atom->radius[i]);
    mloc[t] = std::fmin(mloc[t], atom->rmass[i]);
  }
  MPI_Allreduce(rloc.data(), maxrad, n, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(mloc.data(), minmass, n, MPI_DOUBLE, MPI_MIN, world);
  print_time_step();
}

double PairSphereContact::init_one(int i, int j)
{
  // size-based neighbour list: pairs within R_i + R_j + skin; this only sizes bins and ghosts
  double cut = maxrad[i] + maxrad[j];
  return cut > 0.0 ? cut : 0.0;
}

/* Critical time step of the stiffest contact: k_max = largest dF/dh (loading or the start of
   unloading) for peaks up to the table's end at the largest radii of the two types, with the
   reduced mass m* of their lightest particles: dt_c = 2 sqrt(m* / k_max). */
void PairSphereContact::print_time_step()
{
  double dtc = INFINITY, kbest = 0.0, mbest = 0.0;
  int ti = 0, tj = 0;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (maxrad[i] <= 0.0 || maxrad[j] <= 0.0) continue;
      const Law &law = laws[law_of[i][j]];
      int b1 = body1_of[i][j], b2 = (b1 == i) ? j : i;
      double R1 = maxrad[b1], rho = maxrad[b2] / R1;
      rho = std::fmin(std::fmax(rho, law.ratio_lo), law.ratio_hi);
      sct_stencil st;
      if (sct_stencil_for(law.tab, R1, rho * R1, &st, nullptr, 0) != SCT_OK) continue;
      double k = sct_max_stiffness(law.tab, &st, sct_h_max(law.tab, &st));
      double m = minmass[i] * minmass[j] / (minmass[i] + minmass[j]);
      double d = 2.0 * std::sqrt(m / k);
      if (d < dtc) {
        dtc = d;
        kbest = k;
        mbest = m;
        ti = i;
        tj = j;
      }
    }
  if (!std::isfinite(dtc)) return;
  if (comm->me == 0)
    utils::logmesg(lmp, "pair_style spherecontact: critical time step 2*sqrt(m*/k_max) = {:.6g} "
                   "(types {} {}: k_max = {:.6g}, largest dF/dh for peaks to the table's end; "
                   "m* = {:.6g}, lightest particles); timestep = {:.4g} of it\n",
                   dtc, ti, tj, kbest, mbest, update->dt / dtc);
  if (update->dt > dtc)
    error->warning(FLERR, "pair_style spherecontact: timestep {:.6g} exceeds the critical time "
                   "step {:.6g}", update->dt, dtc);
}

/* The table of types it, jt, which atom is its body 1 (different types: pair_coeff's body1; same
   type: the smaller atom if the table's ratio range allows, else the other) and the stencil of
   the radii; an error naming the atoms if the ratio lies outside the table. */
void PairSphereContact::stencil_of(int i, int j, int it, int jt, SlotStencil &s)
{
  double *radius = atom->radius;
  const Law &law = laws[law_of[it][jt]];
  bool i1 = (it != jt) ? (it == body1_of[it][jt]) : (radius[i] <= radius[j]);
  char err[256];
  if (sct_stencil_for(law.tab, i1 ? radius[i] : radius[j], i1 ? radius[j] : radius[i], &s.st, err,
                      sizeof err) != SCT_OK) {
    if (it != jt || sct_stencil_for(law.tab, i1 ? radius[j] : radius[i], i1 ? radius[i] : radius[j],
                                    &s.st, nullptr, 0) != SCT_OK)
      error->one(FLERR, "pair_style spherecontact: contact of atoms {} (type {}, radius {}) and {} "
                 "(type {}, radius {}), table {}: {}", atom->tag[i], it, radius[i], atom->tag[j], jt,
                 radius[j], law.file, err);
    i1 = !i1;
  }
  s.Ri = radius[i];
  s.Rj = radius[j];
  s.ti = it;
  s.tj = jt;
  s.law = law_of[it][jt];
  s.i1 = i1;
}

void PairSphereContact::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  double *radius = atom->radius, *rmass = atom->rmass;
  int *type = atom->type;
  tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const bool advance = !update->setupflag;    // the spring moves only in real steps
  const bool rot = mu > 0.0;
  const double dt = update->dt;

  history->begin(nlocal);
  size_t slot = 0;    // running index of the neighbour-list slot
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    if (ii + 1 < list->inum) history->prefetch(list->ilist[ii + 1]);
    for (int jj = 0; jj < list->numneigh[i]; jj++, slot++) {
      const int j = jlist[jj] & NEIGHMASK;
      const double del[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double rsq = del[0] * del[0] + del[1] * del[1] + del[2] * del[2];
      const double radsum = radius[i] + radius[j];
      const double *old = history->find(i, tag[j]);
      if (rsq >= radsum * radsum && !old) continue;    // apart, no history
      const double r = std::sqrt(rsq);
      const double h = radsum - r;    // overlap

      // the table, which atom is its body 1 and the ratio stencil: the slot's, or a new one
      const int it = type[i], jt = type[j];
      if (slot >= slots.size()) slots.resize(2 * slot + 64);
      SlotStencil &ss = slots[slot];
      if (!(ss.Ri == radius[i] && ss.Rj == radius[j] && ss.ti == it && ss.tj == jt))
        stencil_of(i, j, it, jt, ss);
      const Law &law = laws[ss.law];
      const bool i1 = ss.i1;
      const sct_stencil &st = ss.st;

      double rec[NVALUE] = {0.0, 0.0, 0.0, 0.0};    // h_max, xi (spring of i against j)
      if (old) std::memcpy(rec, old, sizeof rec);
      sct_result res;
      sct_eval_parts(law.tab, &st, h, rec[0], rot ? SCT_WANT_ALL : 0, &res);
      if (h > rec[0]) rec[0] = h;

      double fn = 0.0, ft[3] = {0.0, 0.0, 0.0}, n[3], d_i = 0.0, d_j = 0.0;
      if (res.F > 0.0) {
        for (int k = 0; k < 3; k++) n[k] = del[k] / r;
        const double vr[3] = {v[i][0] - v[j][0], v[i][1] - v[j][1], v[i][2] - v[j][2]};
        const double vn = vr[0] * n[0] + vr[1] * n[1] + vr[2] * n[2];
        const double meff = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);
        fn = damped_normal(res.F, res.dF_dh, vn, meff, gamma);
        if (rot) {
          // lever arms to the contact plane: body 1 takes h1 of the overlap, body 2 the rest
          const double hb1 = res.h1, hb2 = h - res.h1;
          d_i = radius[i] - (i1 ? hb1 : hb2);
          d_j = radius[j] - (i1 ? hb2 : hb1);
          double w[3], vt[3];
          for (int k = 0; k < 3; k++) w[k] = d_i * omega[i][k] + d_j * omega[j][k];
          // v_t = v_r - v_n n - (d_i w_i + d_j w_j) x n
          vt[0] = vr[0] - vn * n[0] - (w[1] * n[2] - w[2] * n[1]);
          vt[1] = vr[1] - vn * n[1] - (w[2] * n[0] - w[0] * n[2]);
          vt[2] = vr[2] - vn * n[2] - (w[0] * n[1] - w[1] * n[0]);
          tangential(8.0 * law.gstar * res.a, mu, fn, n, vt, dt, advance, rec + 1, ft);
        } else {
          rec[1] = rec[2] = rec[3] = 0.0;
        }
      } else {
        rec[1] = rec[2] = rec[3] = 0.0;    // apart or separated below the residual overlap
      }

      if (fn > 0.0 || ft[0] != 0.0 || ft[1] != 0.0 || ft[2] != 0.0) {
        const double fx = fn * n[0] + ft[0], fy = fn * n[1] + ft[1], fz = fn * n[2] + ft[2];
        f[i][0] += fx;
        f[i][1] += fy;
        f[i][2] += fz;
        const double nxf[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                               n[0] * ft[1] - n[1] * ft[0]};
        if (rot)
          for (int k = 0; k < 3; k++) torque[i][k] -= d_i * nxf[k];
        if (j < nlocal) {
          f[j][0] -= fx;
          f[j][1] -= fy;
          f[j][2] -= fz;
          if (rot)
            for (int k = 0; k < 3; k++) torque[j][k] -= d_j * nxf[k];
        }
        if (evflag) ev_tally_xyz(i, j, nlocal, 0, 0.0, 0.0, fx, fy, fz, del[0], del[1], del[2]);
      }

      if (!history->add(i, tag[j], rec))
        error->one(FLERR, "pair_style spherecontact: atom {} has more than {} contacts (raise "
                   "pair_style ... contacts N)", tag[i], maxcontacts);
      if (j < nlocal) {
        const double recj[NVALUE] = {rec[0], -rec[1], -rec[2], -rec[3]};
        if (!history->add(j, tag[i], recj))
          error->one(FLERR, "pair_style spherecontact: atom {} has more than {} contacts (raise "
                     "pair_style ... contacts N)", tag[j], maxcontacts);
      }
    }
  }
  history->commit();
  if (vflag_fdotr) virial_fdotr_compute();
}
