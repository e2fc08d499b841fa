"""Robustness of the closed-form model for every valid input (issue 16).

* F(h) and a(h) finite and strictly increasing up to the end of the model's domain — in
  ``contact``, ``contact_from_radius`` and the fast path — also for strong hardening and
  small rigid indenters, where the fitted large-deformation polynomials used to fold h(a)
  and the inversion h → a failed ("root solve did not converge");
* beyond the domain (a sphere's own approach above its radius) a ValueError naming the
  parameter, its value and the allowed range;
* the calibrated-range axes hardening magnitude K/σ_Y and rigid-partner radius ratio.
"""

import copy
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from _slopes import assert_body_log_slopes

from spherecontact.model import (
    CalibrationRangeWarning,
    ContactLaw,
    Material,
    Sphere,
    contact,
    contact_from_radius,
    levels,
)
from spherecontact.model import unified as U
from spherecontact.model.calibrated_range import (
    DEFAULT_K_OVER_SIGMA_Y,
    DEFAULT_R_OVER_R_RIGID,
    DEFAULT_RANGE,
    CalibratedRange,
)
from spherecontact.model.coefficients import (
    LITERATURE,
    Coefficients,
    CollapseLimit,
    default_coefficients,
)
from spherecontact.model.fast import contact_table
from spherecontact.model.roots import solve_increasing
from spherecontact.model.single import BodyLaw, hardening_magnitude
from spherecontact.model.unified import UnifiedPair, pair

CO = default_coefficients()
SHIPPED_FILE = Path(__file__).resolve().parents[1] / "model" / "coefficients.json"
RIGID = Material.rigid()
FLAT = Sphere(math.inf, RIGID)
EPS = np.linspace(0.0, 2.0, 41)
#: Voce-type saturating flow curve σ_Y + Q(1 − exp(−b ε_p)) as a table (Q = σ_Y, b = 10)
VOCE = Material.from_table(E=200.0, nu=0.3, eps_p=EPS, sigma=1.0 + 1.0 * (1.0 - np.exp(-10.0 * EPS)))
LINEAR = Material(E=200.0, nu=0.3, sigma_y=1.0, K=5.0, n=1.0)      # Ludwik linear hardening
PARTNER = Material(E=300.0, nu=0.3, sigma_y=2.0, K=1.0, n=0.3)


class _quiet(warnings.catch_warnings):
    """Silence the calibrated-range warnings (these tests leave the range on purpose)."""

    def __enter__(self):
        out = super().__enter__()
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        return out


def _assert_increasing(F, a, k=None, what=""):
    for name, v in (("F", F), ("a", a)) + ((("stiffness", k),) if k is not None else ()):
        assert np.all(np.isfinite(v)), f"{what}: {name} not finite"
    assert np.all(np.diff(F) > 0.0), f"{what}: F(h) not increasing"
    assert np.all(np.diff(a) > 0.0), f"{what}: a(h) not increasing"
    if k is not None:
        assert np.all(k > 0.0), f"{what}: dF/dh <= 0"


# ------------------------------------------------------------------ reproductions of issue 16
def test_strong_hardening_on_a_flat_to_h_over_R_0_8():
    """Failed before: 'root solve did not converge for 25 of 50 elements' (h(a) folded at
    h/R ≈ 0.40: the finite-size polynomials extrapolated beyond a/R = 0.72)."""
    s1 = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=10.0, n=0.6))
    h = np.linspace(1e-4, 0.8, 50)
    with _quiet():
        st = contact(s1, FLAT, h)
    _assert_increasing(st.F, st.a, st.stiffness)
    assert np.allclose(st.h1, h, rtol=1e-12)


def test_approach_beyond_the_sphere_raises_naming_h_and_the_range():
    """Failed before with 'root solve did not converge for 32 of 50 elements'."""
    s1 = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0))
    with _quiet(), pytest.raises(ValueError) as err:
        contact(s1, FLAT, np.linspace(1e-4, 5.0, 50))
    msg = str(err.value)
    assert "did not converge" not in msg
    assert msg.startswith("h = 5 (approach) is outside the model's domain 0 < h <= 1 ")
    assert "h_1 = R_1 = 1" in msg
    with _quiet():   # up to the end of the domain: h_1 = R_1
        st = contact(s1, FLAT, np.linspace(1e-4, 1.0, 50))
    _assert_increasing(st.F, st.a, st.stiffness)


def test_hardening_magnitude_outside_the_calibrated_range_warns():
    """The shipped range's hardening magnitude ends at 11.5: the Ludwik runs reach K/σY 10, a
    saturating table (Q 2.67σY, b 12.1) 11.5 (``single.hardening_magnitude``)."""
    s1 = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=12.0, n=0.3))
    with pytest.warns(CalibrationRangeWarning,
                      match=r"hardening magnitude K/sigma_y = 12 of sphere 1 is outside the calibrated "
                            r"range \[0, 11\.5\]"):
        contact(s1, FLAT, [0.1])


@pytest.mark.parametrize("order", ["rigid second", "rigid first"])
def test_small_rigid_indenter_warns_with_its_radius_ratio(order):
    body = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3))
    tip = Sphere(0.2, RIGID)
    s1, s2, i, j = (body, tip, 1, 2) if order == "rigid second" else (tip, body, 2, 1)
    with pytest.warns(CalibrationRangeWarning,
                      match=rf"radius ratio R_rigid/R = 0\.2 of rigid sphere {j} over sphere {i} is "
                            r"outside the calibrated range \[0\.25, inf\]"):
        contact(s1, s2, [0.05])


def test_calibration_scenes_are_in_range_for_the_new_axes():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    for s2 in (FLAT, Sphere(1.0, RIGID), Sphere(3.0, RIGID)):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            contact(Sphere(1.0, m), s2, np.geomspace(1e-4, 0.2, 5))
    with warnings.catch_warnings():   # a deformable flat: the half-space limit of every scene
        warnings.simplefilter("error")
        contact(Sphere(math.inf, m), Sphere(0.1, RIGID), [1e-4])


# ------------------------------------------------------------------ monotone over a grid
HARDENING = [(0.0, 1.0)] + [(K, n) for K in (2.0, 5.0, 10.0) for n in (0.1, 0.3, 0.6, 1.0)]
SCENES = {
    "flat": lambda m: (Sphere(1.0, m), FLAT),
    "equal": lambda m: (Sphere(1.0, m), Sphere(1.0, m)),
    "rigid sphere 0.4R": lambda m: (Sphere(1.0, m), Sphere(0.4, RIGID)),
    "rigid sphere 0.05R": lambda m: (Sphere(1.0, m), Sphere(0.05, RIGID)),
    "dissimilar": lambda m: (Sphere(1.0, m), Sphere(2.0, PARTNER)),
}


def _check_pair(s1, s2, n=120):
    p = pair(s1, s2, CO)
    h = p.domain.h_max * np.geomspace(1e-6, 1.0, n)
    with _quiet():
        st = contact(s1, s2, h)
        _assert_increasing(st.F, st.a, st.stiffness, "contact")
        fr = contact_from_radius(s1, s2, st.a)
        np.testing.assert_allclose(fr.h, h, rtol=1e-9)
        law = ContactLaw(s1, s2)
        F, k = law.loading_force(h)            # table up to its h_max, exact solve beyond
        full = law(h)
    _assert_increasing(F, full.a, k, "ContactLaw")
    np.testing.assert_allclose(F, st.F, rtol=1e-5)
    return p


@pytest.mark.parametrize("K, n", HARDENING)
@pytest.mark.parametrize("scene", SCENES)
def test_F_and_a_increase_up_to_the_domain_end(K, n, scene):
    m = Material(E=200.0, nu=0.3, sigma_y=1.0, K=K, n=n)
    _check_pair(*SCENES[scene](m))


@pytest.mark.parametrize("m", [LINEAR, VOCE, Material.elastic(200.0, 0.3),
                               Material(E=5.0, nu=0.3, sigma_y=1.0),
                               Material(E=1e5, nu=0.45, sigma_y=1.0, K=10.0, n=0.6),
                               Material.from_table(30.0, 0.3, [0.0, 0.05, 0.5], [1.0, 1.0, 3.0])],
                         ids=["ludwik-linear", "voce-table", "elastic", "E5", "E1e5", "late-table"])
@pytest.mark.parametrize("scene", ["flat", "equal", "rigid sphere 0.4R", "dissimilar"])
def test_linear_saturating_and_extreme_materials(m, scene):
    _check_pair(*SCENES[scene](m))


@pytest.mark.parametrize("m", [LINEAR, VOCE], ids=["ludwik-linear", "voce-table"])
def test_fast_path_on_a_flat_to_h_over_R_0_8(m):
    s1 = Sphere(1.0, m)
    h = np.linspace(1e-4, 0.8, 200)
    with _quiet():
        law = contact_table(s1, FLAT, h_max=0.8)
        ex = contact(s1, FLAT, h)
        F, k = law.loading_force(h)
        full = law(h)
    assert law.monotone and law.error["F"] <= 1e-6
    _assert_increasing(F, full.a, k)
    np.testing.assert_allclose(F, ex.F, rtol=1e-6)
    np.testing.assert_allclose(full.a, ex.a, rtol=1e-6)


# ------------------------------------------------------------------ the domain
def test_domain_ends_where_a_sphere_is_flattened():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    assert pair(Sphere(1.0, m), FLAT, CO).domain.h_max == 1.0
    assert pair(FLAT, Sphere(1.0, m), CO).domain.h_max == 1.0
    assert pair(Sphere(1.0, m), Sphere(0.4, RIGID), CO).domain.h_max == 1.0
    assert pair(Sphere(1.0, m), Sphere(1.0, m), CO).domain.h_max == 2.0
    assert math.isinf(pair(Sphere(math.inf, m), Sphere(0.1, RIGID), CO).domain.h_max)
    s1, s2 = Sphere(1.0, m), Sphere(3.0, PARTNER)
    d = pair(s1, s2, CO).domain
    with _quiet():
        st = contact(s1, s2, np.array([d.h_max]))
        assert max(st.h1[0] / 1.0, st.h2[0] / 3.0) == pytest.approx(1.0, rel=1e-9)
        assert st.a[0] == pytest.approx(d.a_max, rel=1e-9)
        assert 1.0 < d.h_max < 4.0
        with pytest.raises(ValueError, match=r"^h = [\d.]+ \(approach\) is outside the model's "
                                             r"domain 0 < h <= [\d.]+ .*h_1 = R_1 = 1 "):
            contact(s1, s2, np.array([0.5, 1.001 * d.h_max]))


def test_domain_errors_name_the_parameter_in_every_entry_point():
    s1 = Sphere(2.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3))
    with _quiet():
        law = ContactLaw(s1, FLAT)
        with pytest.raises(ValueError, match=r"^h = 2\.5 \(approach\) .* 0 < h <= 2 "):
            law.loading_force(np.array([0.1, 2.5]))
        with pytest.raises(ValueError, match=r"^h = 3 \(approach\)"):
            law(3.0)
        with pytest.raises(ValueError, match=r"^h_max = 2\.1 \(approach\) .* 0 < h <= 2 "):
            ContactLaw(s1, FLAT, h_max=2.1)
        a_max = pair(s1, FLAT, CO).domain.a_max
        contact_from_radius(s1, FLAT, [a_max])
        with pytest.raises(ValueError, match=r"^a = [\d.]+ \(contact radius\) is outside the model's "
                                             rf"domain 0 < a <= {a_max:.6g}"):
            contact_from_radius(s1, FLAT, [0.1, 1.01 * a_max])
        st = contact(s1, FLAT, np.array([-1.0, 0.0, 2.0]))   # no contact and the domain end
    assert st.F[0] == st.F[1] == 0.0 and st.F[2] > 0.0


def test_default_table_stays_inside_the_domain():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    with _quiet():
        for s1, s2 in ((Sphere(1.0, m), FLAT), (Sphere(1.0, m), Sphere(1.0, m)),
                       (Sphere(1.0, m), Sphere(0.05, RIGID))):
            law = ContactLaw(s1, s2)
            assert law.h_max <= pair(s1, s2, CO).domain.h_max


def test_non_convergence_names_the_inputs(monkeypatch):
    def hurried(f, x0, **kw):
        kw["maxiter"] = 2
        return solve_increasing(f, x0, **kw)

    monkeypatch.setattr(U, "solve_increasing", hurried)
    m = Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    p = UnifiedPair(Sphere(1.0, m), Sphere(2.0, PARTNER), CO)
    with pytest.raises(ValueError, match=r"did not converge .*: interface-curvature solve at contact "
                                         r"radius a = 0\.1.*sphere 1: R = 1, E = 200, nu = 0\.3, "
                                         r"sigma_y = 1, K = 2, n = 0\.3; sphere 2: R = 2"):
        p.solve_u(np.array([0.1, 0.2]))
    p = UnifiedPair(Sphere(1.0, m), FLAT, CO)
    with pytest.raises(ValueError, match=r"did not converge .*: inversion h -> a at h = 0\.01, 0\.2 "
                                         r"\(sphere 1: R = 1, .*sphere 2: R = inf, rigid\)"):
        p._invert(np.array([0.01, 0.2]))


def test_solver_names_the_inputs_where_the_equation_is_undefined():
    with pytest.raises(ValueError, match=r"undefined \(NaN\) for 1 of 3 elements .*: at h = 7"):
        solve_increasing(lambda x, idx: (np.where(idx == 1, np.nan, x), np.ones_like(x)),
                         np.array([1.0, 2.0, 3.0]), describe=lambda idx: f"at h = {idx[0] * 7}")


# ------------------------------------------------------------------ the continuation itself
def _with_range(co: Coefficients, **entries) -> Coefficients:
    d = co.to_dict()
    d["provenance"]["calibrated_range"] = dict(DEFAULT_RANGE.to_dict(), **entries)
    return Coefficients.from_dict(d)


HARD = Material(E=200.0, nu=0.3, sigma_y=1.0, K=10.0, n=0.6)


def test_nothing_changes_inside_the_fitted_ratios():
    """Below x_max (a/R) and z_max the response is that of the fitted polynomials, bit for bit:
    the same set with both ends far away gives identical numbers."""
    far = _with_range(CO, a_over_R_max=1e6, R_over_R_rigid=[0.0, 1e6])
    x = np.geomspace(1e-4, CO.x_fit_max, 200)
    for z in (0.0, 0.5, 1.0):
        a, b = BodyLaw(HARD, CO).response(x, x, z), BodyLaw(HARD, far).response(x, x, z)
        for f in ("p_m", "c2", "dlnp_dlnx", "dlnp_dlny", "dlnc2_dlnx", "dlnc2_dlny"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)


def test_continuation_is_C1_with_exact_slopes_and_bounded():
    law = BodyLaw(HARD, CO)
    xm = CO.x_fit_max
    for z in (0.0, 1.0, 3.0):
        r = law.response(np.array([xm * (1 - 1e-9), xm * (1 + 1e-9)]), np.array([xm * (1 - 1e-9),
                                                                                 xm * (1 + 1e-9)]), z)
        for f in r._fields[:8]:
            v = getattr(r, f)
            assert abs(v[1] - v[0]) <= 1e-6 * max(1.0, abs(v[0])), f
        x = np.geomspace(0.8 * xm, 50.0, 40)
        # step 1e-8: moving x alone makes u = x − y > 0, where the counter-surface term's
        # curvature in ln x is 2 q x² (5e3 at x = 50): a forward difference of 1e-6 is off by ~1e-4
        assert_body_log_slopes(law, x, x, z, e=1e-8)
    # the x-dependence fades: the finite-size factor tends to a constant, never below 0
    poly = CO.finite_size_H_bar
    f, s = levels.finite_size_factor(np.array([1.0, 10.0, 1e6]), poly, xm)
    assert np.all(f > 0.0) and abs(s[-1]) < 1e-5
    # a polynomial that turns negative beyond the fitted ratio is continued positive
    falling = (0.2, -0.9)
    raw, _ = levels.finite_size_factor(np.array([10.0]), falling)
    assert raw[0] < 0.0
    f, s = levels.finite_size_factor(np.array([xm, 1.0, 10.0, 1e6]), falling, xm)
    assert np.all(f > 0.0) and abs(s[-1]) < 1e-5


def test_collapse_limit_z_terms_are_continued_beyond_the_fitted_curvature():
    lim = CollapseLimit(prefactor=2.0, exponent=0.2, x_poly=(-1.0,), z_poly=(0.5,))
    z = np.array([0.5, 1.0, 2.0, 50.0])
    lnL, _, dz = lim.log_and_slope(0.3, 0.0, z, None, 1.0)
    raw, _, dz_raw = lim.log_and_slope(0.3, 0.0, z)
    np.testing.assert_array_equal(lnL[:2], raw[:2])
    assert np.all(lnL[2:] < raw[2:]) and lnL[3] - raw[0] < 0.5 * 1.0 + 0.5 * 2.0   # bounded
    e = 1e-7   # d ln L/dz exact beyond z_max
    fd = (lim.log_and_slope(0.3, 0.0, z[2:] + e, None, 1.0)[0] - lnL[2:]) / e
    np.testing.assert_allclose(dz[2:], fd, rtol=1e-5)


def test_pair_cache_keys_on_the_calibrated_range():
    narrow = _with_range(CO, a_over_R_max=0.3)
    assert narrow == CO   # provenance is not compared ...
    s1 = Sphere(1.0, HARD)
    assert pair(s1, FLAT, narrow) is not pair(s1, FLAT, CO)   # ... but the continuation differs
    with _quiet():
        assert contact(s1, FLAT, [0.3], narrow).F[0] != contact(s1, FLAT, [0.3], CO).F[0]
        assert contact(s1, FLAT, [1e-3], narrow).F[0] == contact(s1, FLAT, [1e-3], CO).F[0]


# ------------------------------------------------------------------ the new range axes
def test_hardening_magnitude_of_ludwik_curves_and_tables():
    assert hardening_magnitude(Material(E=200.0, nu=0.3, sigma_y=2.0, K=5.0, n=0.3), CO) == 2.5
    assert hardening_magnitude(Material(E=200.0, nu=0.3, sigma_y=2.0), CO) == 0.0
    assert hardening_magnitude(Material.elastic(200.0, 0.3), CO) == 0.0
    e = [0.0, CO.eps_lo, CO.eps_hi, 0.5]
    lud = Material.from_table(200.0, 0.3, e, [1.0 + 1.5 * x**0.3 for x in e])
    assert hardening_magnitude(lud, CO) == pytest.approx(1.5, rel=1e-12)   # exact for Ludwik
    assert hardening_magnitude(Material.from_table(200.0, 0.3, [0.0, 1.0], [1.0, 1.0]), CO) == 0.0
    assert 0.0 < hardening_magnitude(VOCE, CO) < 10.0


def _lit_with(block) -> Coefficients:
    d = copy.deepcopy(LITERATURE)
    d["provenance"]["calibrated_range"] = block
    return Coefficients.from_dict(d)


BLOCK = {"E_over_sigma_y": [10, 1e4], "nu": [0.2, 0.45], "hardening_n": [0.0, 1.0],
         "h_over_R_max": 0.3, "a_over_R_max": 0.7, "Lambda": None}


def test_older_file_without_the_new_axes_uses_the_v1_design_values():
    old = _lit_with(BLOCK).calibrated_range
    assert old.K_over_sigma_y == DEFAULT_K_OVER_SIGMA_Y == (0.0, 2.0)
    assert old.R_over_R_rigid == DEFAULT_R_OVER_R_RIGID == (0.0, 1.0)
    assert DEFAULT_RANGE.K_over_sigma_y == (0.0, 2.0)
    nulls = _lit_with(dict(BLOCK, K_over_sigma_y=None, R_over_R_rigid=None)).calibrated_range
    assert nulls == old
    # the shipped file records both axes of its calibration runs, and they are read
    shipped = json.loads(SHIPPED_FILE.read_text())["provenance"]["calibrated_range"]
    assert CO.calibrated_range.K_over_sigma_y == tuple(shipped["K_over_sigma_y"])
    assert CO.calibrated_range.R_over_R_rigid == tuple(shipped["R_over_R_rigid"])
    new = _lit_with(dict(BLOCK, K_over_sigma_y=[0.0, 6.0], R_over_R_rigid=[0.0, 3.0])).calibrated_range
    assert new.K_over_sigma_y == (0.0, 6.0) and new.R_over_R_rigid == (0.0, 3.0)
    assert CalibratedRange.from_provenance({"calibrated_range": new.to_dict()}) == new


@pytest.mark.parametrize("key, bad", [("K_over_sigma_y", [2.0, 0.0]), ("K_over_sigma_y", [-1.0, 2.0]),
                                      ("R_over_R_rigid", "1"), ("R_over_R_rigid", [0.0, math.inf])])
def test_malformed_new_axes_raise_naming_the_key(key, bad):
    with pytest.raises(ValueError, match=f"calibrated_range.{key}"):
        _lit_with(dict(BLOCK, **{key: bad}))


def _messages(fun):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fun()
    return [str(w.message) for w in caught if issubclass(w.category, CalibrationRangeWarning)]


def test_new_axes_follow_the_recorded_range_and_warn_once_per_call():
    wide = _lit_with(dict(BLOCK, K_over_sigma_y=[0.0, 6.0], R_over_R_rigid=[0.0, 3.0]))
    narrow = _lit_with(BLOCK)
    s1 = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=5.0, n=0.3))
    tip = Sphere(0.4, RIGID)
    h = np.geomspace(1e-5, 0.05, 500)
    assert _messages(lambda: contact(s1, tip, h, wide)) == []
    msgs = _messages(lambda: contact(s1, tip, h, narrow))
    assert len(msgs) == 2   # one per cause and call, not per contact
    assert any(m.startswith("hardening magnitude K/sigma_y = 5 ") for m in msgs)
    assert any(m.startswith("radius ratio R_rigid/R = 0.4 ") and "[1, inf]" in m for m in msgs)
    assert len(_messages(lambda: contact(s1, tip, h, narrow))) == 2   # again on the next call
    law_msgs = _messages(lambda: ContactLaw(s1, tip, coeffs=narrow))
    assert len(law_msgs) == 2
    with warnings.catch_warnings():   # warned when built: evaluations add none
        warnings.simplefilter("ignore")
        built = ContactLaw(s1, tip, coeffs=narrow)
    assert _messages(lambda: [built.loading_force(h) for _ in range(3)]) == []
    both_ends = _lit_with(dict(BLOCK, R_over_R_rigid=[0.5, 1.0]))   # rigid R_rigid/R in [1, 2]
    assert any("[1, 2]" in m for m in _messages(lambda: contact(s1, FLAT, h, both_ends)))
