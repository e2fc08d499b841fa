"""Counter-surface terms exp(q s(u)) of H̄_hs and c²_hs, u = a/ρ − a/R (``counter_surface``;
``levels.counter_surface``): the function and its slopes, no effect on flats and equal spheres,
monotone F(h) far beyond a/R_i = 1, exact slopes of the body law, the schema key, bad values
named, the calibration form and its Jacobian columns."""

import json
import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
from _slopes import assert_body_log_slopes
from calibration_synthetic import model_result
from test_calibration import KNOWN_CO, as_run

from spherecontact.calibration import fit as fitmod
from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.forms import CANDIDATES, FORMS, predict, predict_exact
from spherecontact.calibration.jacobian import residual_jacobian
from spherecontact.model import (
    CalibrationRangeWarning,
    Material,
    Sphere,
    contact,
    default_coefficients,
    levels,
)
from spherecontact.model.coefficients import COUNTER_BOUND, LITERATURE, Coefficients
from spherecontact.model.single import BodyLaw

#: the shipped set without counter-surface terms (the baseline of every comparison here)
CO = default_coefficients().replace(counter_surface={"H_bar": 0.0, "c2": 0.0})
LUDWIK = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
FLAT = Sphere(math.inf, Material.rigid())


def _with_counter(co: Coefficients, qH: float, qc: float) -> Coefficients:
    return co.replace(counter_surface={"H_bar": qH, "c2": qc})


def test_counter_function_values_slopes_and_bound():
    x = np.array([0.1, 0.3, 0.5, 1.0, 3.0, 30.0])
    y = np.array([0.1, 0.2, 0.5, 0.25, 0.5, 1.0])
    s, sx, sy = levels.counter_surface(x, y)
    u = x - y
    np.testing.assert_allclose(s, np.maximum(u, 0) ** 2 / (1 + u * u))
    assert s[0] == s[2] == 0.0 and np.all(s < 1.0)   # u = 0: nothing; bounded by 1
    e = 1e-7
    np.testing.assert_allclose((levels.counter_surface(x * (1 + e), y)[0] - s) / e, sx, atol=1e-6)
    np.testing.assert_allclose((levels.counter_surface(x, y * (1 + e))[0] - s) / e, sy, atol=1e-6)
    # ds/d ln u ≤ ½ (the bound that keeps F(h) increasing for |q| ≤ 2)
    uu = np.geomspace(1e-3, 1e3, 2001)
    assert np.max(levels.counter_surface(uu, 0.0 * uu)[1]) <= 0.5 + 1e-12
    # a concave counter-surface (u < 0) is left alone, and the joint at u = 0 is C¹
    s_neg, sx_neg, _ = levels.counter_surface(np.array([0.1, 0.1 - 1e-9]), np.array([0.2, 0.1]))
    assert s_neg[0] == 0.0 and abs(sx_neg[1]) < 1e-8


def test_flats_and_equal_spheres_are_unchanged():
    co = _with_counter(CO, -1.5, 1.5)
    h = np.geomspace(1e-4, 0.3, 9)
    s1 = Sphere(1.0, LUDWIK)
    for partner in (FLAT, Sphere(1.0, LUDWIK)):
        a0, a1 = contact(s1, partner, h, CO), contact(s1, partner, h, co)
        np.testing.assert_array_equal(a1.F, a0.F)
        np.testing.assert_array_equal(a1.a, a0.a)


def test_a_small_rigid_sphere_feels_them_only_at_large_a_over_Ri():
    s1, ball = Sphere(1.0, LUDWIK), Sphere(0.25, Material.rigid())
    co = _with_counter(CO, -0.6, 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        h = np.array([1e-5, 0.1])
        a0, a1 = contact(s1, ball, h, CO), contact(s1, ball, h, co)
    small = a0.a[0] / 0.25
    assert small < 0.05 and abs(a1.F[0] / a0.F[0] - 1) < 10 * small**2
    # at a/R_i ≈ 0.8: q_H < 0 lowers the mean pressure, q_c > 0 widens the contact at a given h
    p0, p1 = (st.F[1] / (math.pi * st.a[1] ** 2) for st in (a0, a1))
    assert a0.a[1] / 0.25 > 0.6 and p1 < 0.9 * p0 and a1.a[1] > 1.03 * a0.a[1]


def check_rise_beyond_a_small_indenter(co: Coefficients, material: Material) -> None:
    """F, a and the stiffness of ``material`` under a rigid sphere of R/10 stay finite and rising
    to h/R = 0.9, well beyond a/R_i = 1."""
    s1, ball = Sphere(1.0, material), Sphere(0.1, Material.rigid())
    h = np.geomspace(1e-5, 0.9, 400)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        st = contact(s1, ball, h, co)
    assert np.all(np.isfinite(st.F)) and np.all(np.diff(st.F) > 0) and np.all(np.diff(st.a) > 0)
    assert st.a[-1] / 0.1 > 2.0   # well beyond u = 1
    assert np.all(st.stiffness > 0)


@pytest.mark.parametrize("q", [(-COUNTER_BOUND, COUNTER_BOUND), (COUNTER_BOUND, -COUNTER_BOUND)])
def test_force_and_radius_rise_far_beyond_the_indenter_radius(q):
    check_rise_beyond_a_small_indenter(_with_counter(CO, *q), LUDWIK)


def test_body_log_slopes_stay_exact():
    law = BodyLaw(LUDWIK, _with_counter(CO, -0.7, 0.9))
    y = np.geomspace(0.01, 0.8, 29)
    for ratio in (1.0, 1.5, 5.0):   # u = 0 (flat), u = y/2, u = 4y
        assert_body_log_slopes(law, ratio * y, y, ratio - 1.0)


def test_schema_key_round_trip_and_older_files():
    d = json.loads(json.dumps(LITERATURE))
    co = Coefficients.from_dict(d)
    assert not co.has_counter_surface and "counter_surface" not in co.to_dict()
    assert not CO.has_counter_surface and "counter_surface" not in CO.to_dict()
    again = Coefficients.from_dict(_with_counter(CO, -0.25, 0.5).to_dict())
    assert (again.counter_H_bar, again.counter_c2) == (-0.25, 0.5)


@pytest.mark.parametrize("bad, match", [({"H_bar": -2.5, "c2": 0.0}, r"counter_surface\.H_bar"),
                                        ({"H_bar": 0.0, "c2": math.nan}, r"counter_surface\.c2"),
                                        ({"H_bar": 0.1}, r"counter_surface\.c2"),
                                        ({"H_bar": "1", "c2": 0.0}, r"counter_surface\.H_bar")])
def test_bad_values_are_named(bad, match):
    d = CO.to_dict()
    d["counter_surface"] = bad
    with pytest.raises(ValueError, match=match):
        Coefficients.from_dict(d)


def test_they_need_the_ratio_a_over_R():
    d = _with_counter(CO, -0.5, 0.5).to_dict()
    d["finite_size"]["ratio"] = "a_over_rho"
    with pytest.raises(ValueError, match="a_over_R"):
        Coefficients.from_dict(d)


def check_predict_and_jacobian(form, ds, x, columns=None, atol: float = 2e-5) -> None:
    """The fit's vectorised prediction equals the model's law run by run, and the Jacobian
    columns ``columns`` (default all) equal forward differences of the residual."""
    co = form.coefficients(x)
    p1, c1 = predict(ds, co)
    p2, c2 = predict_exact(ds, co)
    np.testing.assert_allclose(p1, p2, rtol=1e-12)
    np.testing.assert_allclose(c1, c2, rtol=1e-12)
    res = fitmod.Residuals(form, ds)
    J = residual_jacobian(res, x)
    for j in range(form.n_params) if columns is None else columns:
        xj = x.copy()
        step = 1e-7 * max(1.0, abs(x[j]))
        xj[j] += step
        np.testing.assert_allclose(J[:, j], (res(xj) - res(x)) / step, atol=atol, err_msg=form.names[j])


def test_calibration_form_fits_them_with_exact_jacobian_columns():
    form = FORMS["smooth2_fs2_xn2n_x2_g_cs"]
    assert all(FORMS[n].has_counter for n in CANDIDATES if n != "seed")  # every candidate has them
    assert form.n_params == FORMS["smooth2_fs2_xn2n_x2_g"].n_params + 2
    assert form.names[-2:] == ["counter_H", "counter_c2"]
    runs = [(f"sphere-{Ri}", as_run(model_result(LUDWIK, KNOWN_CO, indenter_radius=Ri, n=60)))
            for Ri in (math.inf, 0.5, 0.25)]
    ds = build_dataset(runs)
    assert np.ptp(ds.x_rho - ds.x_R) > 0.5   # the small spheres reach u = a/R_i > 0.5
    x = form.start()
    x[-2:] = (-0.6, 0.5)
    check_predict_and_jacobian(form, ds, x, columns=(form.n_params - 2, form.n_params - 1), atol=1e-5)
    # the a/ρ variant of the form has no such terms (u would be 0)
    assert replace(form, ratio="a_over_rho").n_params == form.n_params - 2


def test_pairs_stay_consistent_and_monotone_with_the_counter_terms():
    """The counter-surface terms of a deformable pair read u = a/ρ_H − a/R (the Hertz partition,
    a constant of the pair), not the κ solve's ρ: with ρ their negative slope in a/ρ made the κ
    equation lose its single root, and for this EPP pair the model returned h₁ + h₂ = 0.102 for
    h = 0.13 and a force that fell from 0.90 to 0.77 between h = 0.125 and 0.13."""
    import numpy as np

    from spherecontact.model import Material, Sphere, contact, load_coefficients

    co = load_coefficients()
    assert co.has_counter_surface
    s1 = Sphere(1.0, Material(E=1400.24, nu=0.3227, sigma_y=1.0))
    s2 = Sphere(0.53612, Material(E=499.896, nu=0.3, sigma_y=1.48226))
    h = np.linspace(0.01, 0.3 * 0.53612, 200)
    st = contact(s1, s2, h, co)
    np.testing.assert_allclose(st.h1 + st.h2, h, rtol=1e-9)
    assert np.all(np.diff(st.F) > 0.0) and np.all(np.diff(st.a) > 0.0)
    rng = np.random.default_rng(7)
    for _ in range(25):  # random plastic pairs inside the calibrated range of h/R
        E = 10 ** rng.uniform(1.5, 4)
        m1 = Material(E=E, nu=rng.uniform(0.2, 0.45), sigma_y=1.0, K=rng.choice([0.0, 2.0]), n=0.3)
        m2 = Material(E=E * 10 ** rng.uniform(-0.5, 0.5), nu=rng.uniform(0.2, 0.45),
                      sigma_y=10 ** rng.uniform(-0.5, 0.5), K=m1.K, n=0.3)
        s2 = Sphere(10 ** rng.uniform(-0.6, 0.6), m2)
        h = min(1.0, s2.radius) * np.geomspace(1e-5, 0.3, 120)
        st = contact(Sphere(1.0, m1), s2, h, co)
        np.testing.assert_allclose(st.h1 + st.h2, h, rtol=1e-9)
        assert np.all(np.diff(st.F) > 0.0)


# two elastic–perfectly plastic spheres, the smaller one harder, that reach their plastic limit
# (the first: the test pair of 2026-11-27; the others: the two of 300 random plastic pairs whose
# inversion in a failed from h/R 0.46 on)
LIMIT_PAIRS = (((1.0, 2143.12, 0.268349, 1.0), (0.365052, 3342.54, 0.247789, 1.46889)),
               ((1.0, 6930.17, 0.319404, 1.0), (0.281771, 7320.47, 0.299329, 1.4421)),
               ((1.0, 1660.31, 0.275439, 1.0), (0.419466, 763.167, 0.285, 1.53664)))


@pytest.mark.parametrize("spheres", LIMIT_PAIRS)
def test_a_pair_at_its_plastic_limit_is_solved_along_the_branch(spheres):
    """Where both bodies are (nearly) fully plastic their pressures hardly depend on the
    partition: the κ root jumps and h(a) is nearly vertical (the load nearly constant while the
    approach moves from one body to the other). The inversion in a failed there (no consistent
    state, or no convergence, from h/R_min ≈ 0.42–0.47 on); the model solves those approaches along
    the branch in u and returns consistent states with F and a increasing to h/R_min = 0.5."""
    import numpy as np

    from spherecontact.model import Material, Sphere, contact
    from spherecontact.model.unified import pair

    s1, s2 = (Sphere(R, Material(E=E, nu=nu, sigma_y=sy)) for R, E, nu, sy in spheres)
    R_min = min(s1.radius, s2.radius)
    h = R_min * np.linspace(0.01, 0.5, 400)
    st = contact(s1, s2, h)
    np.testing.assert_allclose(st.h1 + st.h2, h, rtol=1e-9)
    assert np.all(np.isfinite(st.F)) and np.all(np.diff(st.F) > 0.0) and np.all(np.diff(st.a) > 0.0)
    assert np.all(st.stiffness > 0.0)
    # the branch solve reproduces the states of the inversion where both apply, and gives them
    # where the inversion does not
    P = pair(s1, s2)
    top = h[-40:]
    a_u, u_u = P._invert_in_u(top, st.a[-40:])
    np.testing.assert_allclose(a_u, st.a[-40:], rtol=1e-9)
    np.testing.assert_allclose(P.state_at_a(a_u, u_u).h, top, rtol=1e-9)


def test_the_first_pair_has_a_plateau_and_its_stiffness_drops():
    """At the plastic limit of the first pair F rises by less than 1 % over h/R₂ 0.45–0.5 (h by
    11 %), and dF/dh falls below 2 % of its value at h/R₂ = 0.3."""
    import numpy as np

    from spherecontact.model import Material, Sphere, contact

    s1, s2 = (Sphere(R, Material(E=E, nu=nu, sigma_y=sy)) for R, E, nu, sy in LIMIT_PAIRS[0])
    st = contact(s1, s2, s2.radius * np.array([0.3, 0.45, 0.5]))
    assert st.F[2] / st.F[1] - 1.0 < 0.01
    assert st.stiffness[2] < 0.02 * st.stiffness[0]


def test_the_fast_path_stops_its_table_before_the_plastic_limit():
    """A table in a cannot follow the branch where the κ root jumps: ContactLaw ends its table at
    the last grid node before the jump (``h_limit``: h/R₂ 0.40, the jump between 0.40 and 0.79)
    and the exact solve, which follows the branch, takes the approaches beyond; F and dF/dh then
    agree with ``contact`` within the table's error bounds over the whole range. An ordinary
    dissimilar pair keeps its table to h_max (h_limit = inf)."""
    import numpy as np

    from spherecontact.model import Material, Sphere, contact
    from spherecontact.model.fast import ContactLaw

    s1, s2 = (Sphere(R, Material(E=E, nu=nu, sigma_y=sy)) for R, E, nu, sy in LIMIT_PAIRS[0])
    law = ContactLaw(s1, s2)
    assert 0.35 * s2.radius < law.h_limit < 0.45 * s2.radius and law.h_max == law.h_limit
    h = s2.radius * np.linspace(0.01, 0.5, 40)
    F, k = law.loading_force(h)
    st = contact(s1, s2, h)
    assert law.error["F"] < 1e-6
    np.testing.assert_array_less(np.abs(F / st.F - 1.0), law.error["F"])  # within its own bounds
    np.testing.assert_array_less(np.abs(k / st.stiffness - 1.0), law.error["stiffness"])
    ordinary = ContactLaw(Sphere(1.0, Material(E=300.0, nu=0.3, sigma_y=1.0)),
                          Sphere(2.0, Material(E=900.0, nu=0.3, sigma_y=2.0)))
    assert ordinary.h_limit == np.inf and ordinary.h_max == 0.5  # 0.5 min(R_1, R_2)
