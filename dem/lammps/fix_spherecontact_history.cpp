/* fix spherecontact/history: see fix_spherecontact_history.h */
#include "fix_spherecontact_history.h"

#include "atom.h"
#include "error.h"
#include "memory.h"

#include <cstring>
#include <utility>

using namespace LAMMPS_NS;

FixSphereContactHistory::FixSphereContactHistory(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), nmax(0), count(nullptr), rec(nullptr), next_count(nullptr),
    next_rec(nullptr)
{
  if (narg != 5) error->all(FLERR, "Illegal fix spherecontact/history command: NVALUE MAXCONTACTS");
  nv = utils::inumeric(FLERR, arg[3], false, lmp);
  maxc = utils::inumeric(FLERR, arg[4], false, lmp);
  if (nv < 1 || maxc < 1) error->all(FLERR, "fix spherecontact/history: NVALUE, MAXCONTACTS >= 1");
  stride = nv + 1;
  restart_peratom = 1;
  create_attribute = 1;
  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) count[i] = 0;
}

FixSphereContactHistory::~FixSphereContactHistory()
{
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(count);
  memory->destroy(rec);
  memory->destroy(next_count);
  memory->destroy(next_rec);
}

void FixSphereContactHistory::begin(int nlocal)
{
  for (int i = 0; i < nlocal; i++) next_count[i] = 0;
}

void FixSphereContactHistory::commit()
{
  std::swap(rec, next_rec);
  std::swap(count, next_count);
}

void FixSphereContactHistory::grow_arrays(int n)
{
  memory->grow(count, n, "spherecontact/history:count");
  memory->grow(rec, n, maxc * stride, "spherecontact/history:rec");
  memory->grow(next_count, n, "spherecontact/history:next_count");
  memory->grow(next_rec, n, maxc * stride, "spherecontact/history:next_rec");
  nmax = n;
}

void FixSphereContactHistory::copy_arrays(int i, int j, int /*delflag*/)
{
  count[j] = count[i];
  std::memcpy(rec[j], rec[i], count[i] * stride * sizeof(double));
}

void FixSphereContactHistory::set_arrays(int i)
{
  count[i] = 0;
}

int FixSphereContactHistory::pack_exchange(int i, double *buf)
{
  buf[0] = count[i];
  std::memcpy(buf + 1, rec[i], count[i] * stride * sizeof(double));
  return 1 + count[i] * stride;
}

int FixSphereContactHistory::unpack_exchange(int nlocal, double *buf)
{
  if (nlocal >= nmax) grow_arrays(atom->nmax);
  count[nlocal] = static_cast<int>(buf[0]);
  std::memcpy(rec[nlocal], buf + 1, count[nlocal] * stride * sizeof(double));
  return 1 + count[nlocal] * stride;
}

// restart record of one atom: [size including this slot, count, records...]
int FixSphereContactHistory::pack_restart(int i, double *buf)
{
  int n = 2 + count[i] * stride;
  buf[0] = n;
  buf[1] = count[i];
  std::memcpy(buf + 2, rec[i], count[i] * stride * sizeof(double));
  return n;
}

void FixSphereContactHistory::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);    // skip other fixes
  int c = static_cast<int>(extra[nlocal][m + 1]);
  if (c > maxc)
    error->one(FLERR, "fix spherecontact/history: restart holds {} contacts of an atom, more than "
               "the {} allowed (pair_style spherecontact ... contacts N)", c, maxc);
  count[nlocal] = c;
  std::memcpy(rec[nlocal], &extra[nlocal][m + 2], c * stride * sizeof(double));
}

int FixSphereContactHistory::size_restart(int i)
{
  return 2 + count[i] * stride;
}

int FixSphereContactHistory::maxsize_restart()
{
  return 2 + maxc * stride;
}

double FixSphereContactHistory::memory_usage()
{
  return 2.0 * nmax * (sizeof(int) + maxc * stride * sizeof(double));
}
