"""LAMMPS mdr in a periodic lattice (validation/lammps_lattice.py): geometry, contact counts, and
at small approach the lattice contact equals mdr's own two-sphere contact."""

import math

import numpy as np
import pytest

from spherecontact.validation.lammps_lattice import LatticeScene, lattice_sites, relative_density
from spherecontact.validation.lammps_mdr import MdrScene, MdrSettings

#: mdr's default approach per step (1e-6 R): coarser steps spread the lattice's equal contacts
FAST = MdrSettings()


@pytest.fixture(scope="module")
def lammps():
    from spherecontact.validation.lammps_mdr import LammpsUnavailable, import_lammps

    try:
        return import_lammps()
    except LammpsUnavailable as err:
        pytest.skip(str(err))


def test_lattice_geometry_without_lammps():
    sc, fcc = LatticeScene("sc", "isostatic", 200, 0.3, 1), LatticeScene("fcc", "isostatic", 200, 0.3, 1)
    assert relative_density(sc, 0.0) == pytest.approx(math.pi / 6, rel=1e-14)
    assert relative_density(fcc, 0.0) == pytest.approx(math.pi / (3 * math.sqrt(2)), rel=1e-14)
    die = LatticeScene("sc", "die", 200, 0.3, 1)
    assert relative_density(die, 0.2) == pytest.approx(math.pi / 6 * 2 / 1.8, rel=1e-14)
    # nearest neighbours (periodic images included) at 2R: 12 in fcc, 6 in sc
    shifts = np.stack(np.meshgrid(*[[-1, 0, 1]] * 3, indexing="ij"), -1).reshape(-1, 3)
    for scene, k in ((sc, 6), (fcc, 12)):
        x = lattice_sites(scene)
        images = (x[None, :, :] + (shifts * np.array(scene.box(0.0)))[:, None, :]).reshape(-1, 3)
        r = np.linalg.norm(x[:, None, :] - images[None, :, :], axis=-1)
        r[r < 1e-12] = np.inf
        assert r.min() == pytest.approx(2.0, rel=1e-14)
        assert np.all(np.sum(np.isclose(r, 2.0, rtol=1e-12), axis=1) == k)
    with pytest.raises(ValueError, match="lattice fcc: only the isostatic load"):
        LatticeScene("fcc", "die", 200, 0.3, 1)
    with pytest.raises(ValueError, match="lattice must be one of"):
        LatticeScene("bcc", "isostatic", 200, 0.3, 1)


def test_small_approach_lattice_contact_is_the_pair_contact(lammps):
    """SC isostatic to h/R = 0.01 (density 0.54): mdr's bulk term is off, each of the 24 contacts
    carries the force of mdr's two-sphere contact at the same approach (measured within 3.9e-4)."""
    from spherecontact.validation.lammps_lattice import run_lattice
    from spherecontact.validation.lammps_mdr import run_curve

    scene = LatticeScene("sc", "isostatic", 200.0, 0.3, 1.0)
    run = run_lattice(scene, 0.01, settings=FAST, samples=4, unload_samples=2)
    fam = run.family["axial"]
    assert fam["n"][: run.i_max + 1] == [24] * (run.i_max + 1)
    F_lat = np.array(fam["F"][: run.i_max + 1])
    # mdr updates its particles one after the other within a step: equal contacts differ by
    # ~1e-3 of F at 1e-6 R per step (measured 1.4e-3 at the first sample), more at coarser steps
    assert np.all(np.array(fam["F_spread"][: run.i_max + 1]) <= 5e-3 * F_lat)
    pair = run_curve(MdrScene("pair", 1.0, 1.0, 200.0, 0.3, 1.0), FAST, np.array(run.h[: run.i_max + 1]),
                     unload=False)
    F_pair = np.interp(run.h[: run.i_max + 1], pair.delta[pair.loading], pair.F[pair.loading])
    assert np.max(np.abs(F_lat / F_pair - 1)) < 2e-3
    s = run.stress
    assert s["axial"][run.i_max] == pytest.approx(s["lateral"][run.i_max], rel=1e-9)


def test_die_holds_the_lateral_box(lammps):
    """SC closed die: 8 axial contacts, the lateral ones stay at h = 0 (force only from mdr's
    growing apparent radius), axial stress above the lateral one."""
    from spherecontact.validation.lammps_lattice import run_lattice

    run = run_lattice(LatticeScene("sc", "die", 200.0, 0.3, 1.0), 0.06, settings=FAST, samples=3,
                      unload_samples=1)
    k = run.i_max
    assert run.family["axial"]["n"][k] == 8 and run.family["lateral"]["h"][k] == 0.0
    assert run.family["lateral"]["F"][k] < 0.05 * run.family["axial"]["F"][k]
    assert run.stress["axial"][k] > 10 * run.stress["lateral"][k] > 0
