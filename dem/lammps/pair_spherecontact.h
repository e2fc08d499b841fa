/* pair_style spherecontact [friction MU] [damping GAMMA] [contacts N]
 * pair_coeff I J table.sct [body1 T]
 *
 * Normal force of two elastic-plastic spheres from a spherecontact table (dem/FORMAT.md) with the
 * contact's largest overlap h_max as history, Mindlin tangential spring with Coulomb friction and
 * optional viscous normal damping. atom_style sphere, newton_pair off. Documentation:
 * docs/guides/dem-lammps.md. */
#ifndef SPHERECONTACT_PAIR_H
#define SPHERECONTACT_PAIR_H

#include "contact_common.h"
#include "pair.h"

#include <string>
#include <vector>

namespace LAMMPS_NS {

class PairSphereContact : public Pair {
 public:
  PairSphereContact(class LAMMPS *);
  ~PairSphereContact() override;
  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double init_one(int, int) override;

  // values of one contact record: h_max, tangential spring xi (3)
  static constexpr int NVALUE = 4;

 protected:
  double mu, gamma;
  int maxcontacts;
  std::vector<spherecontact_lmp::Law> laws;    // loaded tables (one per distinct file)
  int **law_of;                                // [I][J]: index into laws, -1 none
  int **body1_of;                              // [I][J]: the type that is the table's body 1
  double *maxrad, *minmass;                    // per type, over all atoms (init_style)
  class FixSphereContactHistory *history;
  std::string history_id;

  // the stencil of each neighbour-list slot from the last step, re-used while the slot holds a
  // pair of the same radii and types (between neighbour-list rebuilds: every step)
  struct SlotStencil {
    double Ri = -1.0, Rj = -1.0;
    int ti = 0, tj = 0, law = -1, i1 = 0;
    sct_stencil st;
  };
  std::vector<SlotStencil> slots;
  void stencil_of(int i, int j, int it, int jt, SlotStencil &s);

  void allocate();
  int law_index(const std::string &file);
  void print_time_step();
};

}    // namespace LAMMPS_NS
#endif
