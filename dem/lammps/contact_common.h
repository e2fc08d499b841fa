/* Pieces of the spherecontact contact force shared by pair_style spherecontact and
 * fix wall/spherecontact: a loaded table with its shear modulus, the damped normal force and the
 * Mindlin tangential spring with Coulomb's limit. Equations: docs/guides/dem-lammps.md. */
#ifndef SPHERECONTACT_CONTACT_COMMON_H
#define SPHERECONTACT_CONTACT_COMMON_H

#include "spherecontact_table.h"

#include <cmath>
#include <string>

namespace spherecontact_lmp {

// A .sct table and what the plugin derives from it.
struct Law {
  std::string file;
  sct_table *tab = nullptr;
  double ratio_lo = 0.0, ratio_hi = 0.0;    // R2/R1 range of the file
  // G* = 1 / ((2 - nu1)/G1 + (2 - nu2)/G2), G = E / (2 (1 + nu)): Mindlin's k_t = 8 G* a.
  // From the file's meta (body1, body2: E, nu); 0 if the meta does not give them.
  double gstar = 0.0;
};

// Load a table; on failure returns false with the evaluator's message (file and problem) in err.
bool load_law(const std::string &file, Law &law, std::string &err);
void free_law(Law &law);

// Normal force with viscous damping (Eq. N):  F_n = max(0, F - 2 gamma sqrt(m* dF/dh) v_n),
// F, dF/dh from the table, v_n = (v_i - v_j).n the normal relative velocity (n from j to i, so
// v_n < 0 on approach), m* the pair's reduced mass; gamma = fraction of the critical damping of
// the normal oscillator linearised at the current stiffness.
inline double damped_normal(double F, double dFdh, double vn, double meff, double gamma)
{
  if (F <= 0.0) return 0.0;
  double fn = F;
  if (gamma > 0.0 && dFdh > 0.0) fn -= 2.0 * gamma * std::sqrt(meff * dFdh) * vn;
  return fn > 0.0 ? fn : 0.0;
}

// Tangential force (Eq. T): spring xi (history, relative tangential displacement of i against j
// at the contact), F_t = -k_t xi with k_t = 8 G* a; xi is first turned into the current tangent
// plane keeping its length, then xi += v_t dt (if advance), and if |F_t| > mu F_n it is cut back
// to Coulomb's limit (xi = -F_t / k_t). kt <= 0 or F_n <= 0: xi = 0, F_t = 0.
inline void tangential(double kt, double mu, double Fn, const double n[3], const double vt[3],
                       double dt, bool advance, double xi[3], double ft[3])
{
  if (kt <= 0.0 || Fn <= 0.0 || mu <= 0.0) {
    xi[0] = xi[1] = xi[2] = ft[0] = ft[1] = ft[2] = 0.0;
    return;
  }
  // turn the spring into the current tangent plane, keeping its length
  double xn = xi[0] * n[0] + xi[1] * n[1] + xi[2] * n[2];
  if (xn != 0.0) {
    double len0 = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
    for (int d = 0; d < 3; d++) xi[d] -= xn * n[d];
    double len1 = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
    if (len1 > 0.0)
      for (int d = 0; d < 3; d++) xi[d] *= len0 / len1;
  }
  if (advance)
    for (int d = 0; d < 3; d++) xi[d] += vt[d] * dt;
  for (int d = 0; d < 3; d++) ft[d] = -kt * xi[d];
  double f2 = ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2];
  double fmax = mu * Fn;
  if (f2 > fmax * fmax) {    // sliding: Coulomb's limit, the spring stretched only as far as it holds
    double s = fmax / std::sqrt(f2);
    for (int d = 0; d < 3; d++) {
      ft[d] *= s;
      xi[d] = -ft[d] / kt;
    }
  }
}

}    // namespace spherecontact_lmp
#endif
