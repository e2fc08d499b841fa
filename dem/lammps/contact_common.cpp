/* Shared contact force pieces, see contact_common.h */
#include "contact_common.h"

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace spherecontact_lmp {

// value of "key": in the JSON object that starts at "obj": within meta (a number, or "inf" quoted)
static bool meta_number(const char *meta, const char *obj, const char *key, double &out)
{
  const char *o = std::strstr(meta, obj);
  if (!o) return false;
  const char *end = std::strchr(o, '}');
  const char *k = std::strstr(o, key);
  if (!k || (end && k > end)) return false;
  k += std::strlen(key);
  while (*k == ' ' || *k == ':' || *k == '"') k++;
  char *stop = nullptr;
  out = std::strtod(k, &stop);
  return stop != k;
}

static double shear_compliance(double E, double nu)    // (2 - nu) / G, G = E / (2 (1 + nu))
{
  if (std::isinf(E)) return 0.0;
  return (2.0 - nu) * 2.0 * (1.0 + nu) / E;
}

bool load_law(const std::string &file, Law &law, std::string &err)
{
  char buf[512];
  law.file = file;
  law.tab = sct_load(file.c_str(), buf, sizeof buf);
  if (!law.tab) {
    err = buf;
    return false;
  }
  sct_ratio_range(law.tab, &law.ratio_lo, &law.ratio_hi);
  double E1, nu1, E2, nu2;
  const char *meta = sct_meta(law.tab);
  if (meta_number(meta, "\"body1\"", "\"E\"", E1) && meta_number(meta, "\"body1\"", "\"nu\"", nu1) &&
      meta_number(meta, "\"body2\"", "\"E\"", E2) && meta_number(meta, "\"body2\"", "\"nu\"", nu2)) {
    double c = shear_compliance(E1, nu1) + shear_compliance(E2, nu2);
    law.gstar = c > 0.0 ? 1.0 / c : 0.0;
  }
  return true;
}

void free_law(Law &law)
{
  if (law.tab) sct_free(law.tab);
  law.tab = nullptr;
}

double damped_normal(double F, double dFdh, double vn, double meff, double gamma)
{
  if (F <= 0.0) return 0.0;
  double fn = F;
  if (gamma > 0.0 && dFdh > 0.0) fn -= 2.0 * gamma * std::sqrt(meff * dFdh) * vn;
  return fn > 0.0 ? fn : 0.0;
}

void tangential(double kt, double mu, double Fn, const double n[3], const double vt[3], double dt,
                bool advance, double xi[3], double ft[3])
{
  if (kt <= 0.0 || Fn <= 0.0 || mu <= 0.0) {
    xi[0] = xi[1] = xi[2] = ft[0] = ft[1] = ft[2] = 0.0;
    return;
  }
  // turn the spring into the current tangent plane, keeping its length
  double len0 = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
  double xn = xi[0] * n[0] + xi[1] * n[1] + xi[2] * n[2];
  for (int d = 0; d < 3; d++) xi[d] -= xn * n[d];
  double len1 = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
  if (len1 > 0.0)
    for (int d = 0; d < 3; d++) xi[d] *= len0 / len1;
  if (advance)
    for (int d = 0; d < 3; d++) xi[d] += vt[d] * dt;
  for (int d = 0; d < 3; d++) ft[d] = -kt * xi[d];
  double f = std::sqrt(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]);
  double fmax = mu * Fn;
  if (f > fmax) {    // sliding: Coulomb's limit, the spring stretched only as far as it holds
    double s = fmax / f;
    for (int d = 0; d < 3; d++) {
      ft[d] *= s;
      xi[d] = -ft[d] / kt;
    }
  }
}

}    // namespace spherecontact_lmp
