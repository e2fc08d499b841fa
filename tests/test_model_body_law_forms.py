"""The forms a body law evaluates at its one hardening exponent n and one curvature ratio z are
the general (per-point) forms to rounding: the collapse limits with their n- and z-terms summed
once (``CollapseLimit.at``), the Level II shapes with b_k + bn_k n folded and their powers of t
shared (``levels_scalar_n``), and the overflow-free logistic weight of the collapse blend."""

import math

import numpy as np
import pytest

from spherecontact.model import Material, levels, load_coefficients
from spherecontact.model.single import BodyLaw

CO = load_coefficients()
X = np.geomspace(1e-4, 3.0, 801)  # beyond x_fit_max: the continuation too


@pytest.mark.parametrize("n", [0.0, 0.12, 0.45, 1.0])
@pytest.mark.parametrize("z", [0.0, 0.4, 3.0, 40.0])  # 40: beyond z_fit_max
def test_collapse_limits_at_one_n_and_z_are_the_general_ones(n, z):
    zm, xm = CO.collapse_z(CO.z_fit_max), CO.x_fit_max
    zv = float(CO.collapse_z(z))
    for limit in (CO.collapse_H_bar, CO.collapse_c2):
        lnL, s, dz = limit.log_and_slope(X, np.full(X.size, n), np.full(X.size, zv), xm, zm)
        lnL1, s1, dz1 = limit.at(n, zv, float(zm)).log_and_slope(X, xm)
        np.testing.assert_allclose(lnL1, lnL, rtol=0.0, atol=1e-13)
        np.testing.assert_allclose(s1, s, rtol=0.0, atol=1e-13)
        np.testing.assert_allclose(dz1, dz, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("n", [0.0, 0.3])
def test_collapse_blend_of_a_body_law_is_the_per_point_blend(n):
    rng = np.random.default_rng(3)
    H, c = rng.uniform(0.5, 3.0, X.size), rng.uniform(0.3, 1.5, X.size)
    H[:5] = 0.0  # an elastic body never collapses
    one = levels.collapse_blend(H, c, X, CO, n, 1.5)
    per_point = levels.collapse_blend(H, c, X, CO, np.full(X.size, n), np.full(X.size, 1.5))
    for name in one._fields:
        np.testing.assert_allclose(np.broadcast_to(getattr(one, name), X.shape),
                                   getattr(per_point, name), rtol=1e-12, atol=1e-14, err_msg=name)


def test_level_shapes_at_one_n_are_the_general_ones():
    lam = np.geomspace(0.5, 3000.0, 2001)
    for n in (0.0, 0.2, 0.6):
        H3, c3 = float(CO.H_bar_III(n)), float(CO.c2_III(n))
        H, sH, c, sc, lev = levels.levels_scalar_n(lam, CO, H3, c3, n)
        H0, sH0 = levels.H_bar_and_slope(lam, CO, n)
        c0, sc0 = levels.c2_and_slope(lam, CO, n)
        np.testing.assert_allclose(H, H0, rtol=1e-14)
        np.testing.assert_allclose(c, c0, rtol=1e-14)
        np.testing.assert_allclose(sH, sH0, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(sc, sc0, rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(lev, levels.level(lam, CO))


def test_logistic_weight_is_the_two_branch_formula_bit_for_bit():
    """w = e^z/(1 + e^z) and ln(1 + e^z) from one exponential of −|z|: the same bits as the
    branch formulas, and no overflow at ±inf or |z| ≫ 700."""
    z = np.concatenate([np.linspace(-50.0, 50.0, 4001), [-1e4, 1e4, -np.inf, np.inf, 0.0, -0.0]])
    w, lg = levels._weight(z)
    with np.errstate(over="ignore", invalid="ignore"):
        w0 = np.where(z > 0.0, 1.0 / (1.0 + np.exp(-z)), np.exp(z) / (1.0 + np.exp(z)))
        lg0 = np.where(z > 0.0, z + np.log1p(np.exp(-z)), np.log1p(np.exp(z)))
    finite = np.abs(z) < 700.0
    assert np.array_equal(w[finite], w0[finite]) and np.array_equal(lg[finite], lg0[finite])
    assert w[-6] == 0.0 and w[-5] == 1.0 and lg[-6] == 0.0 and lg[-5] == 1e4
    assert w[-4] == 0.0 and w[-3] == 1.0 and lg[-4] == 0.0 and lg[-3] == math.inf


@pytest.mark.parametrize("material", [
    Material(E=200.0, nu=0.3, sigma_y=1.0),
    Material(E=1e3, nu=0.3, sigma_y=1.0, K=5.0, n=0.3),
    Material.from_table(E=200.0, nu=0.3, eps_p=[0.0, 0.02, 0.1, 0.5], sigma=[1.0, 1.3, 1.6, 2.0]),
    Material.elastic(E=1.0, nu=0.3),  # elastic
])
@pytest.mark.parametrize("with_xc", [False, True])
def test_pressure_only_response_is_the_full_responses_pressure(material, with_xc):
    """The κ solve reads p_m and its slopes alone (``response(..., pressure_only=True)``): the same
    numbers as the full response, bit for bit, with c² and the piece left out."""
    law = BodyLaw(material, CO)
    y = 0.9 * X
    xc = 1.1 * X if with_xc else None
    full = law.response(X, y, 0.7, xc)
    p = law.response(X, y, 0.7, xc, pressure_only=True)
    for name in ("p_m", "dlnp_dlnx", "dlnp_dlny", "Lambda", "sigma_rep"):
        assert np.array_equal(getattr(p, name), getattr(full, name)), name
    assert p.c2 is None and p.piece is None and p.dlnc2_dlnx is None
