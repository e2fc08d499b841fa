"""The transient of an oversized first step is left out of the reference curves
(``fem.io.reference_mask``): calibration and validation read the same increments."""

import numpy as np

from spherecontact.fem.io import START_TRANSIENT, loading_mask, reference_mask
from spherecontact.validation.cases import Case

OPTIONS = {"strain_increment": 0.005, "dh_first": 2e-4}


def _curves(h, branch=None):
    c = {"h": np.asarray(h, dtype=float), "F": np.asarray(h, dtype=float) ** 1.5,
         "a": np.sqrt(np.asarray(h, dtype=float))}
    if branch is not None:
        c["branch"] = np.asarray(branch)
    return c


def test_oversized_first_step_leaves_its_transient_out():
    h = [2e-4, 3e-4, 4e-4, 5e-4, 8e-4, 1e-3]
    mask = reference_mask(_curves(h), {"radius": 1.0, "options": OPTIONS})
    # first step 2e-4 R > (0.005)^2 R: increments below 2.5 x 2e-4 = 5e-4 are the transient
    assert START_TRANSIENT == 2.5
    np.testing.assert_array_equal(mask, [False, False, False, True, True, True])


def test_bounded_first_step_keeps_every_increment():
    h = [2.5e-5, 5e-5, 1e-4, 2e-4]
    curves = _curves(h)
    mask = reference_mask(curves, {"radius": 1.0, "options": OPTIONS})
    np.testing.assert_array_equal(mask, loading_mask(curves))
    assert mask.all()


def test_bound_scales_with_the_radius_and_unloading_stays_out():
    # radius 10: the bound is 2.5e-4, so a first step of 2e-4 is not oversized
    h = [2e-4, 4e-4, 6e-4, 3e-4, 6e-4, 8e-4]
    branch = [0, 0, 0, 1, 2, 0]
    curves = _curves(h, branch)
    np.testing.assert_array_equal(reference_mask(curves, {"radius": 10.0, "options": OPTIONS}),
                                  [True, True, True, False, False, True])
    # radius 1: oversized; the transient and the unloading/reloading increments are out
    np.testing.assert_array_equal(reference_mask(curves, {"radius": 1.0, "options": OPTIONS}),
                                  [False, False, True, False, False, True])


def test_validation_case_compares_on_the_reference_increments():
    h = np.array([2e-4, 3e-4, 5e-4, 1e-3])
    case = Case(key="k", set="validation", name="n", params={},
                inputs={"radius": 1.0, "indenter_radius": np.inf, "options": OPTIONS},
                curves=_curves(h))
    np.testing.assert_array_equal(case.h, [5e-4, 1e-3])
    np.testing.assert_array_equal(case.F, np.array([5e-4, 1e-3]) ** 1.5)
    assert case.raw_curve("h").size == 4


def test_calibration_resamples_only_the_reference_increments():
    from types import SimpleNamespace

    from spherecontact.calibration.dataset import run_curve
    from spherecontact.model.material import Material

    h = np.geomspace(2e-4, 0.05, 60)
    curves = _curves(h)
    curves["F"] = curves["F"].copy()
    curves["F"][0] *= 0.5  # the oversized first step's error
    inputs = {"radius": 1.0, "indenter_radius": np.inf, "mesh_density": 1.0, "options": OPTIONS}
    run = SimpleNamespace(h=curves["h"], F=curves["F"], a=curves["a"] + 0.02, inputs=inputs,
                          reference=reference_mask(curves, inputs),
                          material=lambda: Material(E=200.0, nu=0.3, sigma_y=1.0))
    rc = run_curve("k", run)
    assert rc.h_fe[0] >= START_TRANSIENT * 2e-4 * (1 - 1e-9)
    assert np.all(rc.F_fe == curves["F"][run.reference])
