"""Coefficient schema 2 (collapse blend) as the model reads it: validation, limits, exact slopes."""

import copy
import math

import numpy as np
import pytest
from _slopes import assert_body_log_slopes

from spherecontact.model import ContactLaw, Material, Sphere, contact, levels
from spherecontact.model.coefficients import LITERATURE, SCHEMA_VERSION, Coefficients
from spherecontact.model.single import BodyLaw

LIT = Coefficients.from_dict(LITERATURE)
COLLAPSE = {
    "H_bar": {"prefactor": 1.3, "exponent": 0.8, "x_poly": [0.2], "exp_poly": [0.5], "z_poly": [0.2]},
    "c2": {"prefactor": 0.9, "exponent": 0.0, "x_poly": [-0.3, 0.3], "exp_poly": [], "z_poly": [0.3, -0.1]},
    "sharpness": 1.6,
}


def v2(collapse=COLLAPSE, ratio="a_over_R") -> Coefficients:
    d = LIT.to_dict()
    d["schema_version"] = 2
    d["level_II"]["smooth"] = False
    d["collapse"] = copy.deepcopy(collapse)
    d["finite_size"] = {"ratio": ratio, "H_bar": [0.3], "c2": [0.1], "H_bar_plastic": [-0.2],
                        "c2_plastic": [0.05]}
    return Coefficients.from_dict(d)


def test_schema_1_still_read_and_round_trips():
    assert SCHEMA_VERSION == 2
    assert LIT.schema_version == 1 and not LIT.has_collapse
    assert "collapse" not in LIT.to_dict()
    co = v2()
    assert co.schema_version == 2 and co.has_collapse
    assert Coefficients.from_dict(co.to_dict()) == co


@pytest.mark.parametrize("mutate, key", [
    (lambda d: d.pop("collapse"), "collapse"),
    (lambda d: d.update(collapse=3), "collapse"),
    (lambda d: d["collapse"]["H_bar"].update(exponent=0.0), "collapse.H_bar.exponent"),
    (lambda d: d["collapse"]["c2"].update(prefactor=-1.0), "collapse.c2.prefactor"),
    (lambda d: d["collapse"].update(sharpness=0.0), "collapse.sharpness"),
    (lambda d: d["collapse"]["c2"].update(x_poly="a"), "collapse.c2.x_poly"),
    (lambda d: d.update(schema_version=3), "schema_version"),
])
def test_bad_collapse_blocks_name_the_key(mutate, key):
    d = v2().to_dict()
    mutate(d)
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        Coefficients.from_dict(d)


def test_schema_1_file_with_collapse_is_rejected():
    d = v2().to_dict()
    d["schema_version"] = 1
    with pytest.raises(ValueError, match="schema_version 2"):
        Coefficients.from_dict(d)


def test_null_collapse_equals_schema_1_model():
    d = LIT.to_dict()
    d["schema_version"] = 2
    d["level_II"]["smooth"] = False
    d["finite_size"].update(H_bar_plastic=[], c2_plastic=[])
    d["collapse"] = None
    co = Coefficients.from_dict(d)
    m = Material(E=300.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    a = np.geomspace(1e-3, 0.6, 40)
    r1 = BodyLaw(m, co).response(a)
    r0 = BodyLaw(m, LIT).response(a)
    for f in r0._fields:
        np.testing.assert_array_equal(getattr(r1, f), getattr(r0, f))


def test_blend_vanishes_as_ratio_goes_to_zero():
    co = v2()
    x = np.array([1e-8, 1e-6, 1e-4])
    b = levels.collapse_blend(np.full(3, 3.0), np.full(3, 1.4), x, co, 0.1)
    assert np.all(b.w < 1e-4) and np.all(np.diff(b.w) > 0)
    np.testing.assert_allclose(b.H_bar, 3.0, rtol=1e-4)
    # elastic body: H_hs = 0 never collapses
    b0 = levels.collapse_blend(np.zeros(3), np.full(3, 0.5), x, co)
    assert np.all(b0.w == 0.0) and np.all(b0.c2 == 0.5)


def test_blend_is_a_smooth_minimum():
    co = v2()
    x = np.array([0.3])
    Hc = co.collapse_H_bar(x, 0.0)
    for H_hs in (0.1 * Hc, Hc, 10 * Hc):
        b = levels.collapse_blend(H_hs, np.full(1, 1.0), x, co, 0.0)
        assert b.H_bar < min(H_hs, Hc) + 1e-12
        assert b.H_bar > min(H_hs, Hc) * 2.0 ** (-1.0 / co.collapse_sharpness) - 1e-12


@pytest.mark.parametrize("mat", [Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3),
                                 Material(E=50.0, nu=0.3, sigma_y=1.0),
                                 Material.from_table(200.0, 0.3, [0, 0.05, 0.5], [1.0, 1.5, 2.2])])
@pytest.mark.parametrize("z", [0.0, 0.6, -0.4])
def test_collapse_log_slopes_are_exact(mat, z):
    law = BodyLaw(mat, v2())
    x = np.geomspace(0.01, 0.8, 9)
    y = 0.7 * x
    assert_body_log_slopes(law, x, y, z)


@pytest.mark.parametrize("ratio", ["a_over_R", "a_over_rho"])
def test_model_with_collapse_hertz_limit_and_fast_path(ratio):
    co = v2(ratio=ratio)
    m = Material(E=100.0, nu=0.3, sigma_y=1.0)
    steel = Material(E=300.0, nu=0.3, sigma_y=2.0, K=1.0, n=0.4)
    R = 1.0
    wall = Sphere(math.inf, Material.rigid())
    # Hertz as a/R -> 0 (Level I): F = 4/3 E' sqrt(R) h^1.5
    h = 1e-9
    st = contact(Sphere(R, m), wall, h, coeffs=co)
    assert st.F == pytest.approx(4.0 / 3.0 * m.E_prime * math.sqrt(R) * h**1.5, rel=1e-3)
    for s2 in (wall, Sphere(R, m), Sphere(2.0, steel), Sphere(2.0, Material.rigid())):
        law = ContactLaw(Sphere(R, m), s2, coeffs=co, h_max=0.4)
        assert law.error["F"] < 1e-6
        hs = np.geomspace(1e-6, 0.3, 50)
        F, k = law.loading_force(hs)
        assert np.all(np.diff(F) > 0) and np.all(k > 0)


def smooth(H_shape=(0.4, -0.2), c2_shape=(0.3,)) -> Coefficients:
    d = v2().to_dict()
    d["level_II"] = {"H_bar_shape": list(H_shape), "c2_shape": list(c2_shape), "smooth": True}
    return Coefficients.from_dict(d)


def test_smooth_level_II_is_C1_at_both_boundaries():
    co = smooth()
    for n in (0.0, 0.2):
        for L0 in (co.Lambda_I, co.Lambda_III):
            L = L0 * np.exp(np.array([-1e-7, 1e-7]))
            H, sH = levels.H_bar_and_slope(L, co, n)
            c, sc = levels.c2_and_slope(L, co, n)
            np.testing.assert_allclose(H[0], H[1], rtol=1e-6)
            np.testing.assert_allclose(sH[0], sH[1], atol=1e-5)
            np.testing.assert_allclose(c[0], c[1], rtol=1e-6)
            np.testing.assert_allclose(sc[0], sc[1], atol=1e-5)
    # inside Level II: slopes are the derivatives of the values
    L = np.geomspace(co.Lambda_I * 1.01, co.Lambda_III * 0.99, 20)
    H, sH = levels.H_bar_and_slope(L, co, 0.1)
    H2, _ = levels.H_bar_and_slope(L * (1 + 1e-7), co, 0.1)
    np.testing.assert_allclose(np.log(H2 / H) / 1e-7, sH, atol=1e-5)
    c, sc = levels.c2_and_slope(L, co, 0.1)
    c2b, _ = levels.c2_and_slope(L * (1 + 1e-7), co, 0.1)
    np.testing.assert_allclose(np.log(c2b / c) / 1e-7, sc, atol=1e-5)


def test_smooth_level_II_stiffness_is_continuous():
    co = smooth()
    m = Material(E=100.0, nu=0.3, sigma_y=1.0)
    law = BodyLaw(m, co)
    # Λ = E' x/σ_Y: x at both level boundaries
    for lam in (co.Lambda_I, co.Lambda_III):
        x = lam / m.E_prime * np.exp(np.array([-1e-7, 1e-7]))
        r = law.response(x)
        np.testing.assert_allclose(r.dlnp_dlnx[0], r.dlnp_dlnx[1], atol=1e-5)
        np.testing.assert_allclose(r.dlnc2_dlnx[0], r.dlnc2_dlnx[1], atol=1e-5)
    assert Coefficients.from_dict(co.to_dict()) == co
    d = co.to_dict()
    d["level_II"]["smooth"] = "yes"
    with pytest.raises(ValueError, match=r"level_II\.smooth"):
        Coefficients.from_dict(d)
    d["level_II"].pop("smooth")
    with pytest.raises(ValueError, match=r"level_II\.smooth"):
        Coefficients.from_dict(d)


def test_curvature_ratio_of_the_pair():
    from spherecontact.model.single import curvature_ratio
    from spherecontact.model.unified import UnifiedPair

    m = Material(E=100.0, nu=0.3, sigma_y=1.0)
    hard = Material(E=1e4, nu=0.3, sigma_y=1.0)
    co = v2()
    assert curvature_ratio(1.0, 1.0) == 0.0 and curvature_ratio(1.0, 0.5) == 1.0
    p = UnifiedPair(Sphere(1.0, m), Sphere(2.0, Material.rigid()), co)
    assert p._z[id(p.law1)] == pytest.approx(0.5)          # rigid sphere R_i = 2R: z = R/R_i
    p = UnifiedPair(Sphere(1.0, m), Sphere(1.0, m), co)
    assert p._z[id(p.law1)] == pytest.approx(0.0) and p._z[id(p.law2)] == pytest.approx(0.0)
    p = UnifiedPair(Sphere(1.0, m), Sphere(1.0, hard), co)  # soft on stiff: nearly a rigid sphere
    assert 0.9 < p._z[id(p.law1)] < 1.0 and -1.0 < p._z[id(p.law2)] < -0.9
    # the κ equation stays monotone: F(h) continuous and increasing for a dissimilar pair
    law = ContactLaw(Sphere(1.0, m), Sphere(2.0, hard), coeffs=co, h_max=0.4)
    F, k = law.loading_force(np.geomspace(1e-6, 0.35, 200))
    assert np.all(np.diff(F) > 0) and np.all(k > 0)
