"""The counter-surface terms' Level III values changing with the conformity ζ = z/(1 + z) of the
pressing surface (``counter_surface.H_bar_conformity``, ``c2_conformity``):
q = (1 − s_l) q + s_l (q_III + q_ζ ζ). Nothing changes on a flat, between equal spheres or in
Level I; under a rigid sphere the pressure moves by exactly exp(s_l q_ζ ζ s(u)); slopes stay
exact, F(h) monotone at the bound, the keys round-trip and bad values are named; the form's
Jacobian columns equal differences of its residual."""

import math
import re
import warnings

import numpy as np
import pytest
from _slopes import assert_body_log_slopes
from calibration_synthetic import model_result
from test_calibration import KNOWN_CO, as_run
from test_model_counter_surface import check_predict_and_jacobian, check_rise_beyond_a_small_indenter

from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.forms import FORMS, Form
from spherecontact.model import CalibrationRangeWarning, Material, Sphere, contact, default_coefficients
from spherecontact.model.coefficients import COUNTER_BOUND, Coefficients
from spherecontact.model.levels import counter_surface, level_weight
from spherecontact.model.single import BodyLaw

LUDWIK = Material(E=2000.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
BASE = default_coefficients().replace(counter_surface={"H_bar": 0.3, "c2": -0.2, "H_bar_plastic": -1.2,
                                                       "c2_plastic": 0.1})


def _with(qz_H: float, qz_c: float = 0.0) -> Coefficients:
    sec = dict(BASE.to_dict()["counter_surface"], H_bar_conformity=qz_H, c2_conformity=qz_c)
    return BASE.replace(counter_surface=sec)


def test_flats_equal_spheres_and_level_I_are_unchanged():
    co = _with(1.5, -0.8)
    h = np.geomspace(1e-4, 0.3, 9)
    s1 = Sphere(1.0, LUDWIK)
    for partner in (Sphere(math.inf, Material.rigid()), Sphere(1.0, LUDWIK)):
        a0, a1 = contact(s1, partner, h, BASE), contact(s1, partner, h, co)
        np.testing.assert_array_equal(a1.F, a0.F)
        np.testing.assert_array_equal(a1.a, a0.a)
    elastic = Material.elastic(E=2000.0, nu=0.3)  # Level I throughout
    ball = Sphere(0.25, Material.rigid())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        e0, e1 = (contact(Sphere(1.0, elastic), ball, h[:4], c) for c in (BASE, co))
    np.testing.assert_array_equal(e1.F, e0.F)


def test_pressure_under_a_rigid_sphere_moves_by_the_level_weighted_factor():
    """Half-space pressure ratio exp(s_l q_ζ ζ s(u)) against the set without the term, ζ = R/(R + R_i)."""
    qz = 0.9
    co0 = BASE.replace(collapse=None)
    co1 = _with(qz).replace(collapse=None)
    seen = 0.0
    for Ri in (0.25, 1.0, 3.0):
        z = 1.0 / Ri  # R/ρ − 1 of a rigid sphere of radius R_i against R = 1
        y = np.geomspace(0.01, 0.6, 13)  # a/R
        x = y * (1.0 + z)  # a/ρ
        r0 = BodyLaw(LUDWIK, co0).response(x, y, z)
        r1 = BodyLaw(LUDWIK, co1).response(x, y, z)
        s_l = level_weight(r0.Lambda, co0)[0]
        su = counter_surface(x, y)[0]
        np.testing.assert_allclose(r1.p_m / r0.p_m, np.exp(s_l * qz * z / (1.0 + z) * su), rtol=1e-12)
        np.testing.assert_array_equal(r1.c2, r0.c2)
        seen = max(seen, float(np.max(s_l * su)))
    assert seen > 0.1  # the comparison sees the term


def test_body_log_slopes_stay_exact():
    law = BodyLaw(LUDWIK, _with(1.1, -0.6))
    y = np.geomspace(0.01, 0.8, 29)
    for ratio in (1.5, 3.0, 5.0):  # z = 0.5, 2, 4
        assert_body_log_slopes(law, ratio * y, y, ratio - 1.0)


@pytest.mark.parametrize("q31", [COUNTER_BOUND, -COUNTER_BOUND])
def test_force_and_radius_rise_far_beyond_a_small_indenter_at_the_bound(q31):
    """q_III + q_ζ at ±2 for both terms (q_III = −1.2, 0.1): F and a keep rising beyond a/R_i = 2."""
    check_rise_beyond_a_small_indenter(_with(q31 + 1.2, -q31 - 0.1), LUDWIK)


def test_keys_round_trip_and_bad_values_are_named():
    co = _with(0.7, -0.3)
    d = co.to_dict()
    assert d["counter_surface"]["H_bar_conformity"] == 0.7 and d["counter_surface"]["c2_conformity"] == -0.3
    assert Coefficients.from_dict(d) == co
    assert "H_bar_conformity" not in BASE.to_dict()["counter_surface"]  # 0: not written
    d["counter_surface"]["H_bar_conformity"] = 3.2  # q_III + q_ζ = 2: the bound itself
    assert Coefficients.from_dict(d).counter_H_bar_conformity == 3.2
    d["counter_surface"]["H_bar_conformity"] = -0.9  # q_III + q_ζ = −2.1
    with pytest.raises(ValueError, match=re.escape("'counter_surface.H_bar_plastic' (default 'H_bar') plus "
                                                   "'H_bar_conformity' must lie in [-2, 2], got -2.1")):
        Coefficients.from_dict(d)
    d["counter_surface"]["H_bar_conformity"] = "1"
    with pytest.raises(ValueError, match=re.escape("'counter_surface.H_bar_conformity' must be a number")):
        Coefficients.from_dict(d)


def test_form_needs_the_level_values_and_its_jacobian_columns_are_exact():
    with pytest.raises(ValueError, match="counter_by_level"):
        Form("x", "", counter=True, counter_conformity="H")
    with pytest.raises(ValueError, match="counter_conformity"):
        Form("x", "", counter=True, counter_by_level=True, counter_conformity="c2")
    form = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz"]
    base = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl"]
    assert form.n_params == base.n_params + 2
    assert FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh"].n_params == base.n_params + 1
    names = ["counter_H", "counter_c2", "counter_H3", "counter_c23", "counter_H31", "counter_c231"]
    j = [form.names.index(n) for n in names]
    x = form.start()
    x[j] = (-0.6, 0.5, -0.8, 0.2, 0.7, -0.4)
    sec = form.to_dict(x)["counter_surface"]
    assert sec["H_bar_conformity"] == pytest.approx(1.5) and sec["c2_conformity"] == pytest.approx(-0.6)
    hard = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    runs = [(f"sphere-{Ri}", as_run(model_result(hard, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 1.0, 0.5, 0.25)]
    ds = build_dataset(runs)
    more = [form.names.index(n) for n in ("ln_Lambda_I", "ln_Lambda_III_over_I", "beta")]
    check_predict_and_jacobian(form, ds, x, columns=j + more, atol=1e-5)
