"""The representative stress averaged over a spread of strains, and counter-surface terms that
move with the level (model/single.py, model/coefficients.py, calibration/forms.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from calibration_synthetic import model_result
from test_calibration import KNOWN_CO, as_run
from test_model_counter_surface import check_predict_and_jacobian

from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.forms import CANDIDATES, FORMS
from spherecontact.model import Material, Sphere, contact, default_coefficients
from spherecontact.model.coefficients import SPREAD_MAX, Coefficients
from spherecontact.model.single import (
    BodyLaw,
    flow_log_slope,
    representative_stress,
    spread_factors,
)

LUDWIK = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
VOCE = Material.from_table(800.0, 0.3, np.linspace(0.0, 1.0, 41),
                           1.0 + 2.0 * (1.0 - np.exp(-5.0 * np.linspace(0.0, 1.0, 41))))
EPS = np.geomspace(1e-4, 0.5, 40)


def test_no_spread_is_the_flow_curve_bit_for_bit():
    for mat in (LUDWIK, VOCE, Material(E=300.0, nu=0.3, sigma_y=1.0)):
        sig, m = representative_stress(mat, EPS, 0.0)
        assert np.array_equal(sig, mat.flow_stress(EPS))
        assert np.array_equal(m, flow_log_slope(mat, EPS))


def test_three_point_rule_and_power_law_scaling():
    f = spread_factors(1.0)
    assert [w for _, w in f] == pytest.approx([2 / 3, 1 / 6, 1 / 6])
    assert sum(w * math.log(x) ** 2 for x, w in f) == pytest.approx(1.0)  # unit log-variance
    # a pure power law K εⁿ keeps its exponent: σ_rep = σ_f(ε_rep) Σ w e^(n W t)
    pure = Material.from_table(1.0, 0.3, np.r_[0.0, np.geomspace(1e-8, 5.0, 4000)],
                               np.r_[1e-6, 2.0 * np.geomspace(1e-8, 5.0, 4000) ** 0.25])
    e = np.geomspace(1e-3, 0.5, 12)
    sig, m = representative_stress(pure, e, 1.0)
    ratio = sig / pure.flow_stress(e)
    np.testing.assert_allclose(ratio, sum(w * x**0.25 for x, w in f), rtol=2e-3)
    np.testing.assert_allclose(m, 0.25, atol=2e-3)


def test_log_slope_is_the_derivative_of_the_average():
    eps = EPS * 1.0137  # off the table's breakpoints (a one-sided slope there)
    for mat in (LUDWIK, VOCE):
        sig, m = representative_stress(mat, eps, 1.0)
        d = 1e-6
        up = representative_stress(mat, eps * math.exp(d), 1.0)[0]
        dn = representative_stress(mat, eps * math.exp(-d), 1.0)[0]
        np.testing.assert_allclose(m, (np.log(up) - np.log(dn)) / (2 * d), atol=2e-4)


def test_spread_weighs_a_saturating_curve_below_its_point_value():
    """Past saturation the average reads the lower strains too; on a linear curve the higher."""
    sig, _ = representative_stress(VOCE, np.array([0.3]), 1.0)
    assert sig[0] < VOCE.flow_stress(0.3)
    lin = Material(E=500.0, nu=0.3, sigma_y=1.0, K=5.0, n=1.0)
    sig, _ = representative_stress(lin, np.array([0.05]), 1.0)
    assert sig[0] > lin.flow_stress(0.05)


def test_schema_key_range_and_round_trip():
    co = default_coefficients()
    d = co.to_dict()
    d["strain_spread"] = SPREAD_MAX * 1.01
    with pytest.raises(ValueError, match="strain_spread"):
        Coefficients.from_dict(d)
    d["strain_spread"] = 0.7
    assert Coefficients.from_dict(d).strain_spread == 0.7
    d.pop("strain_spread")
    assert Coefficients.from_dict(d).strain_spread == 0.0
    assert "strain_spread" not in Coefficients.from_dict(d).to_dict()  # older files unchanged


def _with(co: Coefficients, **counter) -> Coefficients:
    return co.replace(counter_surface=counter)


def test_counter_terms_by_level_reduce_to_one_value_without_the_plastic_keys():
    co = default_coefficients()
    one = _with(co, H_bar=0.3, c2=-0.2)
    same = _with(co, H_bar=0.3, c2=-0.2, H_bar_plastic=0.3, c2_plastic=-0.2)
    law1, law2 = BodyLaw(LUDWIK, one), BodyLaw(LUDWIK, same)
    x = np.geomspace(0.01, 1.2, 50)
    r1, r2 = law1.response(x, 0.3 * x, 2.0), law2.response(x, 0.3 * x, 2.0)
    np.testing.assert_allclose(r1.p_m, r2.p_m, rtol=1e-14)
    np.testing.assert_allclose(r1.dlnp_dlnx, r2.dlnp_dlnx, rtol=1e-12, atol=1e-14)
    assert one.counter_H_bar_plastic is None and "H_bar_plastic" not in one.to_dict()["counter_surface"]
    # the Level III value acts where the body is fully plastic and not in Level I
    diff = _with(co, H_bar=0.3, c2=-0.2, H_bar_plastic=-1.0, c2_plastic=0.5)
    r3 = BodyLaw(LUDWIK, diff).response(x, 0.3 * x, 2.0)
    lev1 = r3.Lambda <= co.Lambda_I
    np.testing.assert_allclose(r3.p_m[lev1], r1.p_m[lev1], rtol=1e-14)
    assert np.all(r3.p_m[~lev1 & (x > 0.4)] < r1.p_m[~lev1 & (x > 0.4)])


@pytest.mark.parametrize("Ri", [0.3, 1.0])
def test_stiffness_is_dF_dh_with_spread_and_counter_terms_by_level(Ri):
    co = _with(default_coefficients(), H_bar=0.4, c2=-0.1, H_bar_plastic=-1.0, c2_plastic=0.2)
    d = co.to_dict()
    d["strain_spread"] = 1.0
    co = Coefficients.from_dict(d)
    s1, s2 = Sphere(1.0, LUDWIK), Sphere(Ri, Material.rigid())
    h = np.geomspace(1e-4, 0.2 * Ri, 30)
    st = contact(s1, s2, h, co)
    e = 1e-6
    fd = (contact(s1, s2, h * (1 + e), co).F - contact(s1, s2, h * (1 - e), co).F) / (2 * e * h)
    np.testing.assert_allclose(st.stiffness, fd, rtol=2e-5)


def test_calibration_form_with_spread_and_counter_levels_has_exact_jacobian_columns():
    form = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1"]
    # every candidate but the seed's is this form with more terms
    assert all(FORMS[n].strain_spread == 1.0 and FORMS[n].counter_by_level for n in CANDIDATES if n != "seed")
    assert form.names[-4:] == ["counter_H", "counter_c2", "counter_H3", "counter_c23"]
    runs = [(f"sphere-{Ri}", as_run(model_result(mat, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 0.5, 0.25) for mat in (LUDWIK, VOCE)]
    ds = build_dataset(runs)
    x = form.start()
    x[-4:] = (-0.6, 0.5, 0.8, -0.4)
    co = form.coefficients(x)
    assert co.strain_spread == 1.0 and co.counter_H_bar_plastic == pytest.approx(0.8)
    check_predict_and_jacobian(form, ds, x)


def test_level_II_shape_terms_per_hardening_exponent():
    """level_II.H_bar_shape_n, c2_shape_n: P(t) = Σ (b_k + bn_k n) t^k. Absent: the shape as
    before; present: Level II moves with n, Levels I and III do not (t²(1 − t)² vanishes there)."""
    from spherecontact.model import levels

    d = default_coefficients().to_dict()
    for key in ("H_bar_shape_n", "c2_shape_n"):  # the shipped form may carry them: start without
        d["level_II"].pop(key, None)
    co = Coefficients.from_dict(d)
    assert co.H_bar_shape_n == () and co.c2_shape_n == ()
    d["level_II"].update(H_bar_shape_n=[0.8, -0.5], c2_shape_n=[-0.6, 0.3])
    co_n = Coefficients.from_dict(d)
    assert co_n.H_bar_shape_n == (0.8, -0.5) and co_n.to_dict()["level_II"]["c2_shape_n"] == [-0.6, 0.3]
    lam = np.geomspace(0.5 * co.Lambda_I, 2.0 * co.Lambda_III, 80)
    for n in (0.0, 0.3):
        H3, c3 = float(co.H_bar_III(n)), float(co.c2_III(n))
        H0, sH0, c0, sc0, _ = levels.levels_scalar_n(lam, co, H3, c3, n)
        H1, sH1, c1, sc1, _ = levels.levels_scalar_n(lam, co_n, H3, c3, n)
        outside = (lam <= co.Lambda_I) | (lam >= co.Lambda_III)
        np.testing.assert_array_equal(H1[outside], H0[outside])
        if n == 0.0:
            np.testing.assert_array_equal(H1, H0)
            np.testing.assert_array_equal(c1, c0)
        else:
            assert np.abs(H1 / H0 - 1)[~outside].max() > 1e-3
        # the vectorised form (one n per point) agrees with the scalar one
        Hv, sHv = levels.H_bar_and_slope(lam, co_n, np.full(lam.size, n))
        np.testing.assert_allclose(Hv, H1, rtol=1e-12)
        np.testing.assert_allclose(sHv, sH1, rtol=1e-12, atol=1e-14)


def test_calibration_form_with_shape_terms_per_exponent_has_exact_jacobian_columns():
    form = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn"]
    assert form.n_params == FORMS["smooth2_fs2_xn2n_x2_g_csl_w1"].n_params + 4
    mats = (LUDWIK, VOCE, Material(E=2000.0, nu=0.3, sigma_y=1.0, K=5.0, n=0.5))
    runs = [(f"s-{Ri}-{i}", as_run(model_result(m, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 0.5) for i, m in enumerate(mats)]
    ds = build_dataset(runs)
    x = form.start()
    for name, v in dict(H_shape0=0.2, H_shape_n0=0.3, H_shape_n1=-0.2, c2_shape_n0=0.5,
                        c2_shape_n1=-0.4, counter_H=-0.6, counter_H3=0.8).items():
        x[form.names.index(name)] = v
    check_predict_and_jacobian(form, ds, x)
