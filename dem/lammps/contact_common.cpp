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

}    // namespace spherecontact_lmp
