"""Collapse limits with z·n terms (``zn_poly``: the pressing surface's curvature z acting with
the hardening exponent n): schema key, numbers of files without it, the limit's value and
z-slope, continuation beyond the calibrated z, the calibration form and its Jacobian columns."""

import copy
import math
import re

import numpy as np
import pytest
from calibration_synthetic import model_result
from test_calibration import KNOWN_CO, as_run
from test_calibration_schema import COLLAPSE, v2
from test_model_counter_surface import check_predict_and_jacobian

from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.forms import FORMS
from spherecontact.model import Material
from spherecontact.model.coefficients import Coefficients, CollapseLimit

ZN = copy.deepcopy(COLLAPSE)
ZN["H_bar"]["zn_poly"] = [-0.4]
ZN["c2"]["zn_poly"] = [1.2, -0.3]
FORM = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn"]


def test_key_round_trips_and_is_written_only_when_present():
    co = v2(ZN)
    assert co.collapse_H_bar.zn_poly == (-0.4,) and co.collapse_c2.zn_poly == (1.2, -0.3)
    again = Coefficients.from_dict(co.to_dict())
    assert again == co
    plain = v2(COLLAPSE)
    assert plain.collapse_c2.zn_poly == () and "zn_poly" not in plain.to_dict()["collapse"]["c2"]


@pytest.mark.parametrize("mutate, key", [
    (lambda c: c["H_bar"].update(zn_poly="a"), "collapse.H_bar.zn_poly"),
    (lambda c: c["c2"].update(zn_poly=[1.0, math.nan]), "collapse.c2.zn_poly[1]"),
])
def test_bad_values_name_the_key(mutate, key):
    d = v2(ZN).to_dict()
    mutate(d["collapse"])
    with pytest.raises(ValueError, match=re.escape(f"'{key}'")):
        Coefficients.from_dict(d)


def test_limit_value_and_z_slope():
    lim = CollapseLimit(prefactor=1.3, exponent=0.7, x_poly=(0.2,), exp_poly=(0.5,), z_poly=(0.3,),
                        zn_poly=(1.5, -0.6))
    x = np.geomspace(0.02, 1.0, 7)
    n = np.linspace(0.0, 0.6, 7)
    z = 0.8
    lnL, _, dz = lim.log_and_slope(x, n, z)
    expect = (math.log(1.3) - 0.7 * np.log(x) + 0.2 * x + 0.5 * n + 0.3 * z
              + n * (1.5 * z - 0.6 * z**2))
    np.testing.assert_allclose(lnL, expect, rtol=1e-14)
    np.testing.assert_allclose(dz, 0.3 + n * (1.5 - 1.2 * z), rtol=1e-13)
    # a perfectly plastic body (n = 0) gets the limit without the terms
    plain = CollapseLimit(prefactor=1.3, exponent=0.7, x_poly=(0.2,), exp_poly=(0.5,), z_poly=(0.3,))
    assert lim.log_and_slope(x, 0.0, z)[0].tolist() == plain.log_and_slope(x, 0.0, z)[0].tolist()


def test_continued_beyond_the_calibrated_z_in_value_and_slope():
    """Beyond z_max the z·n part is continued C¹ in ln(1 + z), like z_poly, and stays bounded."""
    lim = CollapseLimit(prefactor=1.0, exponent=0.5, zn_poly=(2.0, 1.0))
    n, zm, e = 0.4, 1.0, 1e-7
    ln = lambda z: lim.log_and_slope(0.3, n, z, None, zm)[0]  # noqa: E731
    dz = lambda z: lim.log_and_slope(0.3, n, z, None, zm)[2]  # noqa: E731
    assert abs(ln(zm + e) - ln(zm - e)) < 1e-6
    np.testing.assert_allclose(dz(zm + 1e-9), dz(zm - 1e-9), rtol=1e-6)
    np.testing.assert_allclose((ln(3.0 + e) - ln(3.0 - e)) / (2 * e), dz(3.0), rtol=1e-6)
    S = (1 + zm) * n * (2.0 + 2 * zm)  # d/d ln(1 + z) at z_max
    assert ln(1e6) - ln(zm) < S * 1.0000001  # the continued part tends to a constant


def test_form_writes_the_key_and_its_jacobian_columns_are_exact():
    base = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn"]
    assert FORM.n_params == base.n_params + 2
    assert {"Hc_zn0", "c2c_zn0"} <= set(FORM.names)
    x = FORM.start()
    j = [FORM.names.index("Hc_zn0"), FORM.names.index("c2c_zn0")]
    x[j] = (-0.3, 0.6)
    d = FORM.to_dict(x)
    assert d["collapse"]["H_bar"]["zn_poly"] == [-0.3] and d["collapse"]["c2"]["zn_poly"] == [0.6]
    assert "zn_poly" not in base.to_dict(base.start())["collapse"]["c2"]
    hard = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    runs = [(f"sphere-{Ri}", as_run(model_result(hard, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 2.0, 1.0)]  # z = 0, 0.5, 1: within the fitted z
    ds = build_dataset(runs)
    check_predict_and_jacobian(FORM, ds, x, columns=j, atol=1e-5)


def test_z_variable_key_round_trips_and_names_bad_values():
    d = v2(ZN).to_dict()
    assert "z_variable" not in d["collapse"]  # the default, z, is not written
    d["collapse"]["z_variable"] = "ln(1+z)"
    co = Coefficients.from_dict(d)
    assert co.collapse_z_variable == "ln(1+z)"
    assert Coefficients.from_dict(co.to_dict()) == co
    d["collapse"]["z_variable"] = "log"
    with pytest.raises(ValueError, match=re.escape("'collapse.z_variable'")):
        Coefficients.from_dict(d)


def test_log_variable_reads_ln_R_over_rho_and_is_constant_below_z_0():
    """With ``z_variable`` ln(1+z) the limits read ζ = ln(1 + max(z, 0)) = ln(R/ρ_c): the body's
    limits against a rigid sphere of radius R_i are those of the z form at ζ = ln(1 + R/R_i),
    and a body pressed by a surface flatter than its own (z < 0, a stiffer partner; no calibration
    run lies there) keeps the limits of z = 0."""
    from spherecontact.model import levels

    d = v2(ZN).to_dict()
    d["collapse"]["z_variable"] = "ln(1+z)"
    log_co, lin_co = Coefficients.from_dict(d), v2(ZN)
    x, n = np.geomspace(0.05, 0.7, 6), 0.3
    H_hs, c_hs = np.full(6, 3.0), np.full(6, 1.2)
    for z in (0.25, 0.5, 1.0):  # within the default set's fitted z (beyond, the continuations differ)
        a = levels.collapse_blend(H_hs, c_hs, x, log_co, n, z)
        b = levels.collapse_blend(H_hs, c_hs, x, lin_co, n, math.log1p(z))
        np.testing.assert_allclose(a.H_bar, b.H_bar, rtol=1e-14)
        np.testing.assert_allclose(a.c2, b.c2, rtol=1e-14)
        np.testing.assert_allclose(a.dlnc2c_dz, b.dlnc2c_dz / (1.0 + z), rtol=1e-12)
    flat = levels.collapse_blend(H_hs, c_hs, x, log_co, n, 0.0)
    for z in (-0.5, -0.99):
        below = levels.collapse_blend(H_hs, c_hs, x, log_co, n, z)
        assert below.c2.tolist() == flat.c2.tolist() and np.all(below.dlnc2c_dz == 0.0)


def test_log_form_writes_the_key_and_its_jacobian_columns_are_exact():
    form = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_lz"]
    x = form.start()
    names = ["Hc_z0", "c2c_z0", "Hc_zn0", "c2c_zn0"]
    j = [form.names.index(n) for n in names]
    x[j] = (0.2, -0.4, -0.3, 0.6)
    assert form.to_dict(x)["collapse"]["z_variable"] == "ln(1+z)"
    hard = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    runs = [(f"sphere-{Ri}", as_run(model_result(hard, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 2.0, 1.0)]
    check_predict_and_jacobian(form, build_dataset(runs), x, columns=j, atol=1e-5)
