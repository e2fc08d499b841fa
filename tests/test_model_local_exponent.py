"""The hardening exponent read along the flow curve (``local_secant``: model/single.py,
model/coefficients.py, calibration/forms.py, calibration/jacobian.py) and the calibration
window of surface-band runs (calibration/dataset.py)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _slopes import assert_body_log_slopes
from calibration_synthetic import model_result
from test_calibration import KNOWN_CO, as_run
from test_model_counter_surface import check_predict_and_jacobian

from spherecontact.calibration.dataset import A_MIN_BAND_ELEMENTS, POLE_ELEMENT, build_dataset
from spherecontact.calibration.forms import CANDIDATES, FORMS
from spherecontact.model import Material, Sphere, contact, load_coefficients
from spherecontact.model.coefficients import Coefficients
from spherecontact.model.single import BodyLaw, capped_exponent, local_exponent

EPS_T = np.r_[0.0, np.geomspace(1e-5, 3.0, 120)]
VOCE = Material.from_table(2000.0, 0.3, EPS_T, 1.0 + 2.2 * (1.0 - np.exp(-4.8 * EPS_T)))
LINEAR = Material(E=1000.0, nu=0.3, sigma_y=1.0, K=5.0, n=1.0)
LUDWIK = Material(E=5000.0, nu=0.25, sigma_y=1.0, K=11.0, n=0.2)


def _local(co: Coefficients, window: float = 3.0, cap: float = 0.5) -> Coefficients:
    d = co.to_dict()
    d["hardening_exponent"] = {**d["hardening_exponent"], "method": "local_secant", "window": window,
                               "cap": cap}
    return Coefficients.from_dict(d)


CO = load_coefficients()
CO_LOCAL = CO if CO.exponent_local else _local(CO)


def test_the_exponent_follows_the_curve_and_its_slope_is_exact():
    eps = np.geomspace(1e-4, 0.5, 50)
    # a pure power law of the averaged curve: σ_Y + K εⁿ with K ≫ σ_Y reads n at every strain
    n, dn = local_exponent(Material(E=0.5, nu=0.3, sigma_y=1e-6, K=1.0, n=0.25), eps, CO_LOCAL)
    np.testing.assert_allclose(n, capped_exponent(0.25, CO_LOCAL.exponent_cap)[0], rtol=1e-5)
    np.testing.assert_allclose(dn, 0.0, atol=1e-5)
    # a saturating curve: its exponent rises, then falls to the plateau's 0
    n, _ = local_exponent(VOCE, eps, CO_LOCAL)
    assert n[0] < 0.01 and n.max() > 0.25 and 5 < np.argmax(n) < eps.size - 5 and n[-1] < 0.6 * n.max()
    assert local_exponent(VOCE, np.array([2.0]), CO_LOCAL)[0][0] < 0.05
    # linear hardening stays below the cap, where the secant per material says 1 at large strain
    n, _ = local_exponent(LINEAR, eps, CO_LOCAL)
    assert np.all(n < CO_LOCAL.exponent_cap) and np.all(np.diff(n) > 0.0)
    for mat in (VOCE, LINEAR, LUDWIK):
        n, dn = local_exponent(mat, eps, CO_LOCAL)
        e = 1e-6
        n2, _ = local_exponent(mat, eps * (1 + e), CO_LOCAL)
        np.testing.assert_allclose((n2 - n) / e, dn, atol=2e-4)
    # elastic bodies: no exponent
    assert np.all(local_exponent(Material.elastic(200.0, 0.3), eps, CO_LOCAL)[0] == 0.0)


@pytest.mark.parametrize("mat", [VOCE, LINEAR, LUDWIK], ids=["voce", "linear", "ludwik"])
@pytest.mark.parametrize("z", [0.0, 1.5])
def test_body_law_slopes_carry_the_exponent_along_the_curve(mat, z):
    """Every log slope of the response includes dn/d ln x (the κ solve and the fast path read
    them), in Levels II, III and through the collapse blend, and the pressure-only response is
    the full one's p_m."""
    law = BodyLaw(mat, CO_LOCAL)
    x = np.geomspace(2e-3, 0.8, 37)
    r = assert_body_log_slopes(law, x, 0.8 * x, z, atol=5e-6)
    p = law.response(x, 0.8 * x, z, pressure_only=True)
    np.testing.assert_array_equal(p.p_m, r.p_m)
    np.testing.assert_allclose(p.dlnp_dlnx, r.dlnp_dlnx, rtol=1e-12)
    # the fully plastic pressure H̄_III(n(x)) σ_rep and its slope
    e = 1e-6
    s, _, P, dP = law.plastic_state_at(x)
    P2 = law.plastic_state_at(x * (1 + e))[2]
    np.testing.assert_allclose(np.log(P2 / P) / e, dP, atol=5e-6)


def test_the_model_with_it_stays_monotone_to_large_approach():
    """Linear hardening was where an uncapped exponent turned F(h) non-monotone (d ln h/d ln a
    down to −0.35 at E/σY 100 and 1000)."""
    for mat in (LINEAR, dataclasses.replace(LINEAR, E=100.0), VOCE, LUDWIK):
        h = np.geomspace(1e-4, 0.6, 200)
        st = contact(Sphere(1.0, mat), Sphere(math.inf, Material.rigid()), h, CO_LOCAL)
        assert np.all(np.diff(st.F) > 0.0) and np.all(np.diff(st.a) > 0.0)


def test_coefficient_file_keys_are_checked_and_round_trip():
    d = CO_LOCAL.to_dict()
    assert d["hardening_exponent"]["method"] == "local_secant"
    assert Coefficients.from_dict(d) == CO_LOCAL
    for key, bad, rng in (("window", 1.2, r"\[1\.5, 10\]"), ("cap", 5.0, r"\[0\.1, 2\]")):
        e = dict(d, hardening_exponent={**d["hardening_exponent"], key: bad})
        with pytest.raises(ValueError, match=rf"'hardening_exponent\.{key}' must lie in {rng}"):
            Coefficients.from_dict(e)
    e = dict(d, hardening_exponent={k: v for k, v in d["hardening_exponent"].items() if k != "cap"})
    with pytest.raises(ValueError, match="cap"):
        Coefficients.from_dict(e)
    # a per-material set writes no window
    plain = dict(d, hardening_exponent={"method": "secant_loglog", "eps_lo": 0.01, "eps_hi": 0.1})
    written = Coefficients.from_dict(plain).to_dict()["hardening_exponent"]
    assert set(written) == {"method", "eps_lo", "eps_hi"}


def test_calibration_prediction_and_jacobian_match_the_model_with_a_flow_table():
    """The fit's vectorised prediction equals the body law run by run and its β, γ columns (which
    move n through ε_rep) equal forward differences, with a saturating table among the runs."""
    assert all(FORMS[n].exponent_window == 3.0 for n in CANDIDATES if n != "seed")
    form = FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_lz_nl"]
    runs = [(f"{name}-{Ri}", as_run(model_result(m, KNOWN_CO, indenter_radius=Ri, n=50)))
            for name, m in (("voce", VOCE), ("ludwik", LUDWIK)) for Ri in (math.inf, 1.0)]
    ds = build_dataset(runs)
    x = form.start() + 0.01 * np.random.default_rng(7).standard_normal(form.n_params)
    x = np.clip(x, *form.bounds())
    cols = [form.names.index(n) for n in ("beta", "beta_growth", "H_III", "Hc_n0", "c2c_xn0")]
    check_predict_and_jacobian(form, ds, x, columns=cols, atol=2e-5)


def test_band_mesh_runs_count_from_the_validation_window():
    """Surface-band runs (20 elements across a = 0.01 R) keep their points from a = 0.01 R, the
    validation window's start; runs on the default mesh from 0.02 R (seven pole elements)."""
    res = model_result(LUDWIK, KNOWN_CO, n=80)
    plain = as_run(res)
    band = dataclasses.replace(plain, inputs=dict(plain.inputs, edge_band=0.03))
    lo_plain = build_dataset([("plain", plain)]).curves[0].a_min
    lo_band = build_dataset([("band", band)]).curves[0].a_min
    assert lo_band == pytest.approx(A_MIN_BAND_ELEMENTS * POLE_ELEMENT) == pytest.approx(0.01)
    assert lo_plain == pytest.approx(0.02)
    assert build_dataset([("band", band)]).size > build_dataset([("plain", plain)]).size
