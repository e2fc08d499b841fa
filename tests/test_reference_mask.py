"""The transient of an oversized first step is left out of the reference curves
(``fem.io.reference_mask``): calibration and validation read the same increments."""

import numpy as np

from spherecontact.fem.io import START_TRANSIENT, loading_mask, reference_mask, start_steps
from spherecontact.model.material import Material
from spherecontact.validation.cases import Case

OPTIONS = {"strain_increment": 0.005, "dh_first": 2e-4}
#: EPP E/σY = 1000 on a flat: first yield at h ≈ 5.3e-6 R, well below a first step of 2e-4 R
STIFF = {"radius": 1.0, "indenter_radius": np.inf, "options": OPTIONS,
         "material": Material(E=1000.0, nu=0.3, sigma_y=1.0).describe()}


def _curves(h, branch=None):
    c = {"h": np.asarray(h, dtype=float), "F": np.asarray(h, dtype=float) ** 1.5,
         "a": np.sqrt(np.asarray(h, dtype=float))}
    if branch is not None:
        c["branch"] = np.asarray(branch)
    return c


def test_first_step_is_bounded_by_first_yield():
    first, h_y = start_steps(STIFF)
    assert 5e-6 < h_y < 6e-6 and first == h_y  # below dh_first and the strain bound 2.5e-5
    soft = {**STIFF, "material": Material(E=10.0, nu=0.3, sigma_y=1.0).describe()}
    assert start_steps(soft) == (2.5e-5, start_steps(soft)[1]) and start_steps(soft)[1] > 0.01


def test_oversized_first_step_leaves_its_transient_out():
    h = [2e-4, 4e-4, 1e-3, 1.9e-3, 2e-3, 3e-3]
    mask = reference_mask(_curves(h), STIFF)
    # a first step of 2e-4 R across first yield: increments below 10 x 2e-4 are the transient
    assert START_TRANSIENT == 10.0
    np.testing.assert_array_equal(mask, [False, False, False, False, True, True])


def test_bounded_first_step_keeps_every_increment():
    h1 = start_steps(STIFF)[0]
    curves = _curves(h1 * np.array([1.0, 2.0, 3.5, 5.0]))
    mask = reference_mask(curves, STIFF)
    np.testing.assert_array_equal(mask, loading_mask(curves))
    assert mask.all()


def test_elastic_first_increment_keeps_every_increment_and_unloading_stays_out():
    # E/σY = 10: first yield at h ≈ 0.05 R, so a first step of 2e-4 R stayed elastic
    soft = {**STIFF, "material": Material(E=10.0, nu=0.3, sigma_y=1.0).describe()}
    h = [2e-4, 4e-4, 6e-4, 3e-4, 6e-4, 8e-4]
    branch = [0, 0, 0, 1, 2, 0]
    curves = _curves(h, branch)
    np.testing.assert_array_equal(reference_mask(curves, soft), [True, True, True, False, False, True])
    # the stiff material: the transient and the unloading/reloading increments are out
    h = [2e-4, 1e-3, 2e-3, 1e-3, 2e-3, 3e-3]
    np.testing.assert_array_equal(reference_mask(_curves(h, branch), STIFF),
                                  [False, False, True, False, False, True])


def test_validation_case_compares_on_the_reference_increments():
    h = np.array([2e-4, 5e-4, 2e-3, 3e-3])
    case = Case(key="k", set="validation", name="n", params={}, inputs=STIFF, curves=_curves(h))
    np.testing.assert_array_equal(case.h, [2e-3, 3e-3])
    np.testing.assert_array_equal(case.F, np.array([2e-3, 3e-3]) ** 1.5)
    assert case.raw_curve("h").size == 4


def test_calibration_resamples_only_the_reference_increments():
    from types import SimpleNamespace

    from spherecontact.calibration.dataset import run_curve

    h = np.geomspace(2e-4, 0.05, 60)
    curves = _curves(h)
    curves["F"] = curves["F"].copy()
    curves["F"][0] *= 0.5  # the oversized first step's error
    inputs = {**STIFF, "mesh_density": 1.0}
    run = SimpleNamespace(h=curves["h"], F=curves["F"], a=curves["a"] + 0.02, inputs=inputs,
                          reference=reference_mask(curves, inputs),
                          material=lambda: Material(E=1000.0, nu=0.3, sigma_y=1.0))
    rc = run_curve("k", run)
    assert rc.h_fe[0] >= START_TRANSIENT * 2e-4 * (1 - 1e-9)
    assert np.all(rc.F_fe == curves["F"][run.reference])
