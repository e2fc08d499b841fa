"""Collapse limits with z·n terms (``zn_poly``: the pressing surface's curvature z acting with
the hardening exponent n): schema key, numbers of files without it, the limit's value and
z-slope, continuation beyond the calibrated z, the calibration form and its Jacobian columns."""

import copy
import math
import re

import numpy as np
import pytest
from test_calibration import KNOWN_CO, as_run
from test_calibration_schema import COLLAPSE, v2
from test_model_counter_surface import check_predict_and_jacobian

from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.forms import FORMS
from spherecontact.calibration.synthetic import model_result
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
