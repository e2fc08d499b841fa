/* fix spherecontact/history: per-atom store of contact records for pair_style spherecontact and
 * fix wall/spherecontact (created by them; not for input scripts).
 *
 *   fix ID all spherecontact/history NVALUE MAXCONTACTS
 *
 * Each owned atom holds up to MAXCONTACTS records (key, NVALUE doubles): the key is the partner
 * atom's ID (pair) or the wall's index (wall fix). The records move with their atom between MPI
 * ranks (pack_exchange/unpack_exchange), follow it when LAMMPS sorts atoms (copy_arrays) and go
 * into restart files (pack_restart/unpack_restart; re-created with the same ID after read_restart
 * they are restored). The owner rewrites an atom's records every time it computes its contacts
 * (begin/add/commit below): a record not re-added is dropped. */
#ifndef SPHERECONTACT_FIX_HISTORY_H
#define SPHERECONTACT_FIX_HISTORY_H

#include "fix.h"

namespace LAMMPS_NS {

class FixSphereContactHistory : public Fix {
 public:
  FixSphereContactHistory(class LAMMPS *, int, char **);
  ~FixSphereContactHistory() override;
  int setmask() override { return 0; }

  int nvalue() const { return nv; }
  int maxcontacts() const { return maxc; }
  // the stored record of owned atom i for key, or nullptr (NVALUE doubles)
  const double *find(int i, tagint key) const
  {
    const double *r = rec[i];
    for (int k = 0; k < count[i]; k++, r += stride)
      if (static_cast<tagint>(ubuf(r[0]).i) == key) return r + 1;
    return nullptr;
  }

  // ask the cache for atom i's stored records ahead of find(i, ...)
  void prefetch(int i) const { __builtin_prefetch(rec[i]); }

  // rewriting: begin(nlocal) clears the next records, add() appends a record to them (false: atom
  // full), commit() makes them the stored ones (the two stores swap; atoms 0..nlocal-1 count)
  void begin(int nlocal);
  bool add(int i, tagint key, const double *values)
  {
    if (next_count[i] >= maxc) return false;
    double *r = next_rec[i] + next_count[i] * stride;
    r[0] = ubuf(static_cast<int64_t>(key)).d;
    for (int c = 0; c < nv; c++) r[c + 1] = values[c];
    next_count[i]++;
    return true;
  }
  void commit();

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;
  double memory_usage() override;

 private:
  int nv, maxc, stride;    // values per record, records per atom, nv + 1
  int nmax;
  int *count;              // records of each atom
  double **rec;            // [atom][k * stride]: key (as ubuf), then nv values
  int *next_count;         // the records being written in this step (begin/add), same layout
  double **next_rec;
};

}    // namespace LAMMPS_NS
#endif
