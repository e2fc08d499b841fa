"""Unloading and reloading: the law (model/unloading.py), contact(h_max=), the fast path with
history, cycle() and the coefficient section."""

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from spherecontact.model import (
    Coefficients,
    ContactLaw,
    Material,
    Sphere,
    contact,
    cycle,
    load_coefficients,
    residual_approach,
)
from spherecontact.model.coefficients import UNLOADING_OPTIONAL, UnloadingCoefficients
from spherecontact.model.unified import pair
from spherecontact.model.unloading import EXPONENT_RANGE, branch, features, peak_parameters, unloading_law

WALL = Sphere(math.inf, Material.rigid())
EPP = Material(E=200.0, nu=0.3, sigma_y=1.0)
HARD = Material(E=600.0, nu=0.25, sigma_y=3.0, K=2.0, n=0.3)


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


@pytest.fixture(scope="module")
def co():
    return load_coefficients()


def test_shipped_file_has_a_calibrated_unloading_law(co):
    assert co.unloading != UnloadingCoefficients()
    assert co.unloading.stiffness > 1.0  # a flattened sphere is stiffer than Sneddon's half-space
    assert co.unloading.m_plastic < 1.5  # plastic peaks unload flatter than Hertz


def test_default_law_is_thornton():
    """Defaults: Hertz from the peak, δ_e = 3F/(4E*a), m = 3/2 (Thornton 1997)."""
    Ep = 200.0 / (1 - 0.09)
    F, a, h = np.array([2.0, 5.0]), np.array([0.1, 0.2]), np.array([0.05, 0.1])
    f = features(h, F, a, np.stack([h, 0 * h], axis=1), [1 / Ep, 0.0], [0.3, 0.3], [1.0, math.inf],
                 [0.0, 0.0], 1.0, [1.0, 1.0])
    m, delta_e, h_res, h1_res = unloading_law(f, UnloadingCoefficients())
    np.testing.assert_allclose(m, 1.5)
    np.testing.assert_allclose(delta_e, np.minimum(3 * F / (4 * Ep * a), h))
    np.testing.assert_allclose(h1_res, h_res)


def _peaks():
    """A plastic peak with pile-up (c² = 1.5, λ ≈ 0.06) against a flat and the same against a
    rigid sphere of radius 1/2 (u = 0.6)."""
    Ep = 200.0 / (1 - 0.09)
    F, a, h = np.full(2, 0.5), np.full(2, 0.3), np.full(2, 0.03)
    return features(h, F, a, np.stack([h, 0 * h], axis=1), [1 / Ep, 0.0], [0.3, 0.3], [1.0, math.inf],
                    [0.0, 2.0], 1.0, [1.0, 1.0])


BASE = UnloadingCoefficients(stiffness=1.1, size_a=0.5, size_h=1.0, m_plastic=1.25, m_c2=0.1,
                             m_counter=1.2, elastic_weight=2.0)


def test_counter_surface_softens_the_size_terms():
    """g_i = 1 + size_i (1 − g_U U): no change on a flat (U = 0), δ_e ∝ 1/g against a sphere."""
    f = _peaks()
    m0, d0, *_ = unloading_law(f, BASE)
    m1, d1, *_ = unloading_law(f, replace(BASE, size_counter=0.8))
    size = 0.5 * 0.3**2 + 1.0 * 0.06
    np.testing.assert_allclose(m1, m0)
    np.testing.assert_allclose(d1[0], d0[0], rtol=1e-14)
    np.testing.assert_allclose(d1[1] / d0[1], (1 + size) / (1 + size * (1 - 0.8 * f.U[1])), rtol=1e-12)


def test_pile_up_stiffens_a_plastic_peak():
    """C ∝ (c²)^(−s_c (1 − w)): with c² > 1 and s_c > 0 the recovery δ_e shrinks by that factor."""
    f = _peaks()
    assert np.all(f.log_c2 > 0.0) and np.all(f.lam < 0.1)
    w = f.lam ** BASE.elastic_weight
    _, d0, *_ = unloading_law(f, BASE)
    _, d1, *_ = unloading_law(f, replace(BASE, stiffness_c2=0.2))
    np.testing.assert_allclose(d1 / d0, np.exp(-0.2 * (1 - w) * f.log_c2), rtol=1e-12)
    assert np.all(d1 < d0)


def test_pile_up_exponent_terms():
    """P = (c²)^q, q = s_c (1 − w) + s_U U + s_z z̄ + s_2 ln c²: the three terms divide δ_e by
    exp((s_U U + s_z z̄ + s_2 ln c²) ln c²) and leave m alone; on a flat (U = 0) s_U does nothing."""
    f = _peaks()
    z_bar = f.z[:, 0]  # one deformable body
    m0, d0, *_ = unloading_law(f, BASE)
    m1, d1, *_ = unloading_law(f, replace(BASE, stiffness_c2_counter=-0.3, stiffness_c2_depth=-0.1,
                                          stiffness_c2_c2=-0.2))
    q = -0.3 * f.U - 0.1 * z_bar - 0.2 * f.log_c2
    np.testing.assert_allclose(m1, m0)
    np.testing.assert_allclose(d1 / d0, np.exp(-q * f.log_c2), rtol=1e-12)
    _, d2, *_ = unloading_law(f, replace(BASE, stiffness_c2_counter=-0.3))
    np.testing.assert_allclose(d2[0], d0[0], rtol=1e-14)
    assert d2[1] > d0[1]  # less pile-up stiffening under the curved counter-surface


def test_plastic_exponent_grows_with_lambda():
    """m = (1 − w)[(1 − U)(… + m_λ λ) + U m_counter] + w (…): the term is m_λ λ (1 − w)(1 − U)."""
    f = _peaks()
    w = f.lam ** BASE.elastic_weight
    m0, *_ = unloading_law(f, BASE)
    m1, *_ = unloading_law(f, replace(BASE, m_lambda=0.5))
    np.testing.assert_allclose(m1 - m0, 0.5 * f.lam * (1 - w) * (1 - f.U), rtol=1e-12)


def test_deep_dent_exponent_leaves_the_recovery_alone():
    """m = m₀ + (1 − w) m_Uz U z̄² with δ_e = m₀ F C/s₀: the term lowers m by exactly that, keeps
    δ_e and h_res, and does nothing on a flat (U = 0)."""
    f = _peaks()
    assert f.U[0] == 0.0 and f.U[1] > 0.0
    w = f.lam ** BASE.elastic_weight
    m0, d0, r0, _ = unloading_law(f, BASE)
    m1, d1, r1, _ = unloading_law(f, replace(BASE, m_counter_depth=-0.7))
    np.testing.assert_allclose(m1 - m0, -0.7 * (1 - w) * f.U * f.z[:, 0] ** 2, rtol=1e-12, atol=1e-15)
    assert m1[0] == m0[0] and m1[1] < m0[1]
    np.testing.assert_array_equal(d1, d0)
    np.testing.assert_array_equal(r1, r0)


def test_branch_is_continuous_at_the_peak_and_vanishes_at_h_res(co):
    s1 = Sphere(1.0, EPP)
    for hm in (1e-3, 0.03, 0.3):
        peak = contact(s1, WALL, hm)
        st = contact(s1, WALL, np.array([hm * (1 - 1e-12), hm]), h_max=hm)
        np.testing.assert_allclose(st.F, peak.F, rtol=1e-9)
        h_res = residual_approach(s1, WALL, hm)
        assert 0.0 < h_res < hm
        below = contact(s1, WALL, np.array([0.0, 0.5 * h_res, h_res]), h_max=hm)
        assert np.all(below.F == 0.0) and np.all(below.a == 0.0)
        h = np.linspace(h_res, hm, 200)
        F = contact(s1, WALL, h, h_max=hm).F
        assert np.all(np.diff(F) > 0.0)  # the branch rises from 0 to F_max


def test_unloading_below_the_loading_curve_and_reloading_retraces(co):
    s1 = Sphere(1.0, EPP)
    h = np.linspace(0.01, 0.1, 50)
    un = contact(s1, WALL, h, h_max=0.1)
    load = contact(s1, WALL, h)
    assert np.all(un.F[:-1] < load.F[:-1])  # hysteresis
    again = contact(s1, WALL, h[::-1], h_max=np.full(h.size, 0.1))
    np.testing.assert_array_equal(again.F[::-1], un.F)
    past = contact(s1, WALL, np.array([0.12, 0.2]), h_max=0.1)  # loading past the maximum
    np.testing.assert_array_equal(past.F, contact(s1, WALL, np.array([0.12, 0.2])).F)


def test_stiffness_is_the_branch_slope(co):
    for s2 in (WALL, Sphere(0.5, HARD), Sphere(2.0, Material.rigid())):
        s1 = Sphere(1.0, EPP)
        hm = 0.05
        h_res = residual_approach(s1, s2, hm)
        h = h_res + (hm - h_res) * np.linspace(0.05, 0.95, 19)
        d = 1e-7 * hm
        Fp = contact(s1, s2, h + d, h_max=hm).F
        Fm = contact(s1, s2, h - d, h_max=hm).F
        k = contact(s1, s2, h, h_max=hm).stiffness
        np.testing.assert_allclose((Fp - Fm) / (2 * d), k, rtol=1e-5)


def test_an_elastic_body_has_no_hysteresis(co):
    e = Sphere(1.0, Material.elastic(200.0, 0.3))
    h = np.linspace(0.0, 0.1, 21)
    np.testing.assert_array_equal(contact(e, WALL, h, h_max=0.1).F, contact(e, WALL, h).F)
    assert residual_approach(e, WALL, 0.1) == 0.0
    np.testing.assert_allclose(cycle(e, WALL, [0.01, 0.1]).restitution, 1.0)


def test_a_peak_in_level_one_leaves_no_residual_approach(co):
    s1 = Sphere(1.0, EPP)
    p = pair(s1, WALL, co)
    h_el = 1e-7  # Λ far below Λ_I
    st = p.state_from_h(np.array([h_el]))
    assert st.Lambda1[0] < co.Lambda_I
    assert residual_approach(s1, WALL, h_el) == 0.0
    h = np.linspace(0.1, 1.0, 5) * h_el
    np.testing.assert_allclose(contact(s1, WALL, h, h_max=h_el).F, contact(s1, WALL, h).F, rtol=1e-12)


def test_a_yielded_body_below_lambda_one_leaves_a_residual_approach(co):
    """A soft, strongly hardening sphere (Ludwik K/σ_Y 10, n 0.6, E/σ_Y 10) on a flat: its σ_rep
    keeps Johnson's Λ below Λ_I to h/R = 0.3, yet the FE leaves h_res/h_max = 0.135 there. The
    onset reads Λ_u with √(σ_Y σ_rep) (``unloading.onset_Lambda_u``); with σ_rep it gave 0."""
    s1 = Sphere(1.0, Material(E=10.0, nu=0.3, sigma_y=1.0, K=10.0, n=0.6))
    st = pair(s1, WALL, co).state_from_h(np.array([0.3]))
    assert st.Lambda1[0] < co.Lambda_I
    assert 0.1 < residual_approach(s1, WALL, 0.3) / 0.3 < 0.16


def test_residual_approach_grows_with_the_largest_approach(co):
    for s2 in (WALL, Sphere(1.0, EPP), Sphere(0.5, HARD)):
        hm = np.geomspace(1e-5, 0.3, 60)
        r = residual_approach(Sphere(1.0, EPP), s2, hm)
        assert np.all(np.diff(r) >= 0.0)
        assert np.all(r < hm)


def test_each_body_takes_its_share_of_the_residual_dent(co):
    s1 = Sphere(1.0, EPP)
    for s2, check in ((WALL, "rigid"), (Sphere(1.0, EPP), "equal"), (Sphere(1.0, HARD), "harder")):
        p = pair(s1, s2, co)
        pk = peak_parameters(p, p.state_from_h(np.array([0.02, 0.2])))
        np.testing.assert_allclose(pk.h1_res + pk.h2_res, pk.h_res, rtol=1e-12)
        assert np.all(pk.h1_res >= 0.0) and np.all(pk.h2_res >= 0.0)
        if check == "rigid":
            assert np.all(pk.h2_res == 0.0)
        elif check == "equal":
            np.testing.assert_allclose(pk.h1_res, pk.h2_res, rtol=1e-9)
        else:  # the harder body keeps less of the dent
            assert np.all(pk.h2_res < pk.h1_res)
        assert np.all((pk.m >= EXPONENT_RANGE[0]) & (pk.m <= EXPONENT_RANGE[1]))
        br = branch(0.5 * (pk.h_max + pk.h_res), pk)
        np.testing.assert_allclose(br.h1 + br.h2, 0.5 * (pk.h_max + pk.h_res), rtol=1e-12)


@pytest.mark.parametrize("bad, match", [(-0.1, ">= 0"), (math.nan, "finite"), (np.ones(3), "shaped like h"),
                                        ("x", "real")])
def test_bad_history_is_named(bad, match):
    with pytest.raises(ValueError, match=f"h_max.*{match}"):
        contact(Sphere(1.0, EPP), WALL, np.array([0.1, 0.2]), h_max=bad)
    law = ContactLaw(Sphere(1.0, EPP), WALL)
    with pytest.raises(ValueError, match="h_max"):
        law.force(np.array([0.1, 0.2]), bad)


def test_history_beyond_the_domain_is_named():
    with pytest.raises(ValueError, match="h_max"):
        contact(Sphere(1.0, EPP), WALL, 0.1, h_max=5.0)


def test_fast_path_with_history_matches_the_exact_law(co):
    for s2 in (WALL, Sphere(0.5, HARD), Sphere(1.0, EPP)):
        s1 = Sphere(1.0, EPP)
        law = ContactLaw(s1, s2)
        hm = np.array([1e-4, 1e-3, 0.01, 0.1, 0.3])
        h = hm[:, None] * np.linspace(0.0, 1.3, 27)[None, :]
        H = np.broadcast_to(hm[:, None], h.shape)
        ex = contact(s1, s2, h, h_max=H)
        F, k = law.force(h, H)
        scale = ex.F.max(axis=1, keepdims=True)
        assert np.max(np.abs(F - ex.F) / scale) < 2e-4
        assert np.max(np.abs(k - ex.stiffness) / ex.stiffness.max(axis=1, keepdims=True)) < 2e-3
        st = law(h, H)
        np.testing.assert_allclose(st.F, F, rtol=1e-12, atol=0)
        assert np.max(np.abs(st.a - ex.a) / ex.a.max(axis=1, keepdims=True)) < 1e-3
        assert np.max(np.abs(st.h1 - ex.h1) / hm[:, None]) < 1e-3


def test_fast_path_history_outside_the_table_and_scalars(co):
    s1 = Sphere(1.0, EPP)
    law = ContactLaw(s1, WALL, h_max=0.05)
    F, k = law.force(0.04, 0.1)  # peak above the table: exact solve
    ex = contact(s1, WALL, 0.04, h_max=0.1)
    assert math.isclose(F, ex.F, rel_tol=1e-9) and math.isclose(k, ex.stiffness, rel_tol=1e-9)
    F0, k0 = law.force(np.array([0.0, -1.0]), 0.01)
    assert np.all(F0 == 0.0) and np.all(k0 == 0.0)


def test_cycle_energies(co):
    s1 = Sphere(1.0, EPP)
    c = cycle(s1, WALL, np.array([0.01, 0.1]))
    for i, hm in enumerate((0.01, 0.1)):
        h = np.linspace(0.0, hm, 20001)
        w_in = np.trapezoid(contact(s1, WALL, h).F, h)
        assert math.isclose(c.work_in[i], w_in, rel_tol=1e-5)
        hb = np.linspace(c.h_res[i], hm, 20001)
        w_ret = np.trapezoid(contact(s1, WALL, hb, h_max=hm).F, hb)
        assert math.isclose(c.work_returned[i], w_ret, rel_tol=1e-5)
    assert np.all((c.restitution > 0.0) & (c.restitution < 1.0))
    assert c.restitution[1] < c.restitution[0]  # a deeper impact dissipates more of its energy
    np.testing.assert_allclose(c.dissipated, c.work_in - c.work_returned)
    with pytest.raises(ValueError, match="h_max"):
        cycle(s1, WALL, 0.0)


def test_unloading_section_round_trip_and_errors(co):
    d = co.to_dict()
    assert Coefficients.from_dict(d).unloading == co.unloading
    old = dict(d)
    old.pop("unloading")
    assert Coefficients.from_dict(old).unloading == UnloadingCoefficients()  # older files: Thornton
    bad = dict(d, unloading=dict(d["unloading"], stiffness=5.0))
    with pytest.raises(ValueError, match=r"unloading\.stiffness.*\[0\.5, 2\]"):
        Coefficients.from_dict(bad)
    bad = dict(d, unloading=dict(d["unloading"], extra=1.0))
    with pytest.raises(ValueError, match=r"unloading\.extra"):
        Coefficients.from_dict(bad)
    missing = dict(d, unloading={k: v for k, v in d["unloading"].items() if k != "m_c2"})
    with pytest.raises(ValueError, match=r"unloading\.m_c2"):
        Coefficients.from_dict(missing)
    bad = dict(d, unloading=dict(d["unloading"], size_counter=1.5))
    with pytest.raises(ValueError, match=r"unloading\.size_counter.*\[0, 1\]"):
        Coefficients.from_dict(bad)


def test_an_older_unloading_section_gives_the_law_without_the_new_terms(co):
    """Files written before size_counter, stiffness_c2 and m_lambda leave them out: 0."""
    d = co.to_dict()
    new = dict(d["unloading"], size_counter=0.5, stiffness_c2=0.1, m_lambda=0.2, stiffness_c2_counter=-0.3,
               stiffness_c2_depth=-0.1, stiffness_c2_c2=-0.2, m_counter_depth=-0.7)
    older = {k: v for k, v in new.items() if k not in UNLOADING_OPTIONAL}
    law_old = Coefficients.from_dict(dict(d, unloading=older)).unloading
    assert law_old == replace(Coefficients.from_dict(dict(d, unloading=new)).unloading,
                              **dict.fromkeys(UNLOADING_OPTIONAL, 0.0))
    # the law before these terms: g_i = 1 + [g_a y² + g_h z][1 + g_ν (ν − 0.3)], m without m_λ λ
    f, u = _peaks(), law_old
    Ci = f.compliance / (2 * f.a[:, None] * (1 + (u.size_a * f.y**2 + u.size_h * f.z)
                                             * (1 + u.size_nu * (f.nu - 0.3))))
    w = f.lam ** u.elastic_weight
    m_p = (1 - f.U) * (u.m_plastic + u.m_c2 * f.log_c2 + u.m_depth * f.z[:, 0]) + f.U * u.m_counter
    m = np.clip((1 - w) * m_p + w * (1.5 + u.m_elastic_size * f.y[:, 0] ** 2), *EXPONENT_RANGE)
    m_new, delta_e, *_ = unloading_law(f, law_old)
    np.testing.assert_allclose(m_new, m, rtol=1e-14)
    np.testing.assert_allclose(delta_e, np.minimum(m * f.F * Ci.sum(axis=1) / u.stiffness, f.h), rtol=1e-14)
    assert set(law_old.to_dict()) == set(new)  # written back with every key


def test_cli_curve_with_unloading(co):
    from spherecontact.model.cli import curve

    d = curve(Sphere(1.0, EPP), WALL, 0.1, points=5, coeffs=co, unload=True)
    assert d["branch"] == [0] * 5 + [1] * 5
    h, F = np.array(d["h"]), np.array(d["F"])
    assert np.all(np.diff(h[5:]) < 0.0) and np.all(np.diff(F[5:]) < 0.0)  # unloading
    assert F[-1] == 0.0 and h[-1] == pytest.approx(d["cycle"]["h_res"])
    assert 0.0 < d["cycle"]["restitution"] < 1.0
    assert d["cycle"]["h_res"] == pytest.approx(residual_approach(Sphere(1.0, EPP), WALL, 0.1))
    plain = curve(Sphere(1.0, EPP), WALL, 0.1, points=5, coeffs=co)
    assert "branch" not in plain and plain["F"] == d["F"][:5]


def _force_from_tables(tab, h, hm):
    """force(h, h_max) from ContactLaw.tables() alone, as a DEM code would (its docstring)."""
    s = tab["ln_h"]
    loading = (h >= hm) | (hm <= tab["h_elastic"])
    q = np.where(loading, h, hm)
    j = np.clip(np.searchsorted(s, np.log(q), side="right") - 1, 0, s.size - 2)
    width = s[j + 1] - s[j]
    t = (np.log(q) - s[j]) / width
    c = tab["ln_F_hermite"][j]
    lnF = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
    dlnF = (c[:, 1] + t * (2 * c[:, 2] + 3 * t * c[:, 3])) / width
    rec = tab["recovery"][j] + t * (tab["recovery"][j + 1] - tab["recovery"][j])
    m = tab["m"][j] + t * (tab["m"][j + 1] - tab["m"][j])
    delta = rec * q
    xi = np.clip((h - q) / delta + 1.0, 0.0, 1.0)
    Fq = np.exp(lnF)
    F = np.where(loading, Fq, Fq * xi**m)
    k = np.where(loading, Fq * dlnF / q, np.where(xi > 0, m * Fq * xi ** (m - 1) / delta, 0.0))
    return F, k


def test_exported_tables_reproduce_the_fast_path(co):
    for s2 in (WALL, Sphere(0.5, HARD)):
        law = ContactLaw(Sphere(1.0, EPP), s2)
        tab = law.tables()
        rng = np.random.default_rng(1)
        hm = np.exp(rng.uniform(np.log(1e-6), np.log(law.h_max), 2000))
        h = np.minimum(hm * rng.uniform(0.5, 1.2, hm.size), law.h_max)  # inside the table
        F, k = _force_from_tables(tab, h, hm)
        Ff, kf = law.force(h, hm)
        np.testing.assert_allclose(F, Ff, rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(k, kf, rtol=1e-9, atol=1e-300)
        assert tab["ln_F_hermite"].shape == (tab["ln_h"].size - 1, 4)
