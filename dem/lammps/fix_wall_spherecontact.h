/* fix ID group wall/spherecontact xplane|yplane|zplane LO HI table_lo.sct [table_hi.sct]
 *     [friction MU] [damping GAMMA]
 *
 * Two rigid flat walls normal to x, y or z at LO and HI (NULL: no wall there), each with its own
 * table (one table: both walls), the particle being the table's body 1 and the wall body 2
 * (a table written with --radius2 inf). Same force as pair_style spherecontact (overlap
 * h = R - distance to the plane), the history of each particle-wall contact kept in a fix
 * spherecontact/history "<ID>_HISTORY". LO or HI may be v_name, an equal-style variable evaluated
 * every step (a moving wall, as in LAMMPS' fix wall styles); the wall's velocity is the change of
 * the variable over the last step divided by dt. Global vector: the force of the particles on the LO and HI wall
 * along the wall normal's axis, then the LO and HI positions (4 values).
 * Documentation: docs/guides/dem-lammps.md. */
#ifndef SPHERECONTACT_FIX_WALL_H
#define SPHERECONTACT_FIX_WALL_H

#include "contact_common.h"
#include "fix.h"

#include <string>

namespace LAMMPS_NS {

class FixWallSphereContact : public Fix {
 public:
  FixWallSphereContact(class LAMMPS *, int, char **);
  ~FixWallSphereContact() override;
  int setmask() override;
  void post_constructor() override;
  void init() override;
  void setup(int) override;
  void min_setup(int) override;
  void post_force(int) override;
  void min_post_force(int) override;
  double compute_vector(int) override;

 private:
  int axis;                // 0, 1, 2
  int has[2];              // wall at LO, at HI
  double pos[2];           // their coordinates
  std::string varname[2];  // v_name: the position is an equal-style variable ("" = constant)
  int varindex[2];
  double vwall[2];         // the walls' velocity along the axis (moving walls)
  double prevpos[2];       // their position at the previous evaluation
  bool prevset[2];
  void wall_positions();
  spherecontact_lmp::Law law[2];
  double mu, gamma;
  double wforce[2], wforce_all[2];
  int force_flag;
  class FixSphereContactHistory *history;
  std::string history_id;
};

}    // namespace LAMMPS_NS
#endif
