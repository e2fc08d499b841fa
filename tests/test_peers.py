"""Published peer laws: Hertz limits, regime-switch continuity, independently checkable values."""

import math

import numpy as np
import pytest

from spherecontact import peers

R, E, NU, SY = 1e-3, 210e9, 0.3, 400e6
EP = E / (1 - NU**2)


def test_hertz_values():
    c = peers.hertz(np.array([-1.0, 0.0, 1e-6]), EP, R)
    assert c.F[0] == 0.0 and c.a[1] == 0.0
    # F = 4 E* a³/(3R) and a² = R h: two forms of Hertz agree
    assert c.F[2] == pytest.approx(4 * EP * c.a[2] ** 3 / (3 * R), rel=1e-14)
    assert c.a[2] == pytest.approx(math.sqrt(1e-9), rel=1e-14)


def test_jackson_green_critical_values_and_hertz_below_1_9():
    wc, Pc, C = peers.jackson_green_critical(R, EP, SY, NU)
    assert C == pytest.approx(1.295 * math.exp(0.736 * 0.3))
    assert C == pytest.approx(1.615, abs=1e-3)
    # P_c is the Hertz force at ω_c
    assert Pc == pytest.approx(float(peers.hertz(wc, EP, R).F), rel=1e-12)
    w = wc * np.array([0.1, 1.0, 1.89])
    assert np.allclose(peers.jackson_green(w, R, EP, SY, NU).F, peers.hertz(w, EP, R).F,
                       rtol=1e-13)


def test_jackson_green_continuity_at_1_9_and_hardness_limit():
    wc, Pc, _ = peers.jackson_green_critical(R, EP, SY, NU)
    w = 1.9 * wc * np.array([1 - 1e-12, 1 + 1e-12])
    c = peers.jackson_green(w, R, EP, SY, NU)
    assert c.a[1] == pytest.approx(c.a[0], rel=1e-10)  # (ω*/1.9)^B = 1 at the switch
    assert abs(c.F[1] / c.F[0] - 1) < 0.01             # the published fit joins within 1 %
    # large interference: mean pressure tends to the geometric limit H_G ≈ 2.84 S_y at small a/R
    big = peers.jackson_green(1e3 * wc, R, EP, SY, NU)
    pm = big.F / (math.pi * big.a**2)
    assert 2.0 * SY < pm < 2.84 * SY
    F = peers.jackson_green(np.geomspace(1e-3, 1e4, 200) * wc, R, EP, SY, NU).F
    assert np.all(np.diff(F) > 0)


def test_kogut_etsion_switches_and_mean_pressure_fits():
    wc, Pc, Ac, K = peers.kogut_etsion_critical(R, EP, SY, NU)
    assert K == pytest.approx(0.454 + 0.41 * 0.3)
    assert Pc == pytest.approx(float(peers.hertz(wc, EP, R).F), rel=1e-12)
    for s in (1.0, 6.0, 110.0):  # published piecewise fits: jumps of a few per cent
        c = peers.kogut_etsion(s * wc * np.array([1 - 1e-12, 1 + 1e-12]), R, EP, SY, NU)
        assert abs(c.F[1] / c.F[0] - 1) < 0.08 and abs(c.a[1] / c.a[0] - 1) < 0.04
    # Kogut & Etsion also fit the mean pressure: p/Y = 1.19 ω*^0.289 (1-6), 1.61 ω*^0.117 (6-110)
    for s, coef, ex in ((3.0, 1.19, 0.289), (30.0, 1.61, 0.117)):
        c = peers.kogut_etsion(s * wc, R, EP, SY, NU)
        assert float(c.F / (math.pi * c.a**2)) / SY == pytest.approx(coef * s**ex, rel=0.01)


def test_thornton_is_c1_at_yield():
    py = 1.6 * SY
    dy = (math.pi * py / (2 * EP)) ** 2 * R
    d = dy * np.array([1 - 1e-9, 1 + 1e-9])
    c = peers.thornton(d, EP, R, py)
    assert c.F[1] == pytest.approx(c.F[0], rel=1e-8)
    below = peers.thornton(dy * np.array([0.2, 0.9]), EP, R, py)
    assert np.allclose(below.F, peers.hertz(dy * np.array([0.2, 0.9]), EP, R).F, rtol=1e-14)
    # beyond yield the slope is π p_y R*, equal to the Hertz slope 2E* a_y at δ_y
    k = np.diff(peers.thornton(dy * np.array([2.0, 3.0]), EP, R, py).F) / dy
    assert k[0] == pytest.approx(math.pi * py * R, rel=1e-12)
    assert 2 * EP * math.sqrt(R * dy) == pytest.approx(math.pi * py * R, rel=1e-12)


def test_johnson_cavity_model():
    # ν = 1/2: p_m/Y = (2/3)(1 + ln(E a/(3 Y R)))
    x = np.array([1e-3, 1e-2])
    assert np.allclose(peers.johnson_cavity_hardness(x, E, 0.5, SY),
                       2 / 3 * (1 + np.log(E * x / (3 * SY))), rtol=1e-14)
    # increasing in a/R with slope 2/3 per unit ln(E a/(Y R)) at large E a/(Y R)
    h = peers.johnson_cavity_hardness(np.array([0.1, math.e * 0.1]), E, NU, SY)
    assert h[1] - h[0] == pytest.approx(2 / 3, rel=0.05)


def test_biwa_storakers_similarity():
    c0 = peers.biwa_storakers(np.array([1e-6, 2e-6]), R, SY, 0.0)
    assert c0.F[1] / c0.F[0] == pytest.approx(2.0)            # n = 0: F ∝ h
    assert c0.F[0] == pytest.approx(math.pi * 2 * 1.43 * R * 1e-6 * 3.07 * SY)
    c = peers.biwa_storakers(np.array([1e-6, 4e-6]), R, SY, 0.4)
    assert c.F[1] / c.F[0] == pytest.approx(4 ** (1 + 0.4 / 2))  # F ∝ h^(1 + n/2)
    assert c.a[0] ** 2 / (2 * R * 1e-6) == pytest.approx(1.43 * math.exp(-0.97 * 0.4))


def test_peer_bad_input():
    with pytest.raises(ValueError, match="E_star"):
        peers.hertz(1e-6, -1.0, R)
    with pytest.raises(ValueError, match="finite"):
        peers.jackson_green(np.array([np.nan]), R, EP, SY, NU)
    with pytest.raises(ValueError, match="n must"):
        peers.biwa_storakers(1e-6, R, SY, -0.5)


# ============================================================================ printed numbers
# Each test below reproduces a number printed in the law's source, or, where none could be
# reached, an identity the published equations must satisfy; the docstring says which.

def test_hertz_reproduces_a_textbook_worked_example():
    """Hertz (Johnson 1985 §4.2, a³ = 3PR/(4E*)): a textbook finite-element exercise prints the
    analytical contact radius of a sphere R = 8 mm on a rigid flat under F = 30·2π N,
    E = 1000 N/mm², ν = 0.3 as a = 1.010 mm. Read off our F(h), a(h) curve at that force."""
    R8, E8, F = 8.0, 1000.0, 30.0 * 2.0 * math.pi
    c = peers.hertz(np.geomspace(1e-4, 1.0, 20001), E8 / (1 - 0.3**2), R8)
    assert np.interp(F, c.F, c.a) == pytest.approx(1.010, abs=5e-4)


def test_first_yield_factors_reproduce_johnsons_1_60():
    """Johnson (1985) §6.2 prints the peak Hertz pressure at first yield of a sphere as
    p_0 = 1.60 Y (ν = 0.3). Jackson–Green's C(ν) and Kogut–Etsion's K(ν)H/Y = 2.8(0.454 + 0.41ν)
    are fits of that value: both give it within 1 % at ν = 0.3, and each law's ω_c is the
    approach at which the Hertz peak pressure 2E*a/(πR) reaches it."""
    wc, _, C = peers.jackson_green_critical(R, EP, SY, NU)
    wk, _, _, K = peers.kogut_etsion_critical(R, EP, SY, NU)
    assert C == pytest.approx(1.60, rel=0.01) and 2.8 * K == pytest.approx(1.60, rel=0.01)
    for w, p0 in ((wc, C * SY), (wk, 2.8 * K * SY)):
        a = float(peers.hertz(w, EP, R).a)
        assert 2 * EP * a / (math.pi * R) == pytest.approx(p0, rel=1e-12)


def test_kogut_etsion_reproduces_the_printed_dimensional_coefficients():
    """Kogut & Etsion (2003, Tribol. Trans. 46:383) print the 2002 fits in dimensional form,
    P = 1.37 E k^0.15 R^0.575 ω^1.425 (1 ≤ ω* ≤ 6) and P = 1.87 E k^0.474 R^0.737 ω^1.263
    (6 ≤ ω* ≤ 110), k = πKH/(2E); our P(ω) divided by the printed powers gives 1.37 and 1.87."""
    wc, _, _, K = peers.kogut_etsion_critical(R, EP, SY, NU)
    k = math.pi * K * 2.8 * SY / (2 * EP)
    for s, coef, ek, er, ew in ((3.0, 1.37, 0.15, 0.575, 1.425), (30.0, 1.87, 0.474, 0.737, 1.263)):
        w = s * wc
        P = float(peers.kogut_etsion(w, R, EP, SY, NU).F)
        assert P / (EP * k**ek * R**er * w**ew) == pytest.approx(coef, abs=0.005)


def test_thornton_reproduces_his_restitution_coefficient():
    """Thornton (1997) prints the restitution coefficient of his loading–unloading law in closed
    form, e(V_y/V_i), tending to 1.185 (V_y/V_i)^¼ for V_i ≫ V_y. Our loading
    (:func:`peers.thornton`) and unloading (:func:`peers.thornton_unloading`) integrated for
    the work in and out (½ m V² = work; V_y: the work to first yield) give both."""
    py = 1.6 * SY
    dy = (math.pi * py / (2 * EP)) ** 2 * R
    w_y = 8 / 15 * EP * math.sqrt(R) * dy**2.5
    ks = np.array([1.5, 10.0, 1e2, 1e4, 1e6])
    e, x = [], []
    for k in ks:  # one peak at a time (a few, not the points of a curve)
        d = np.linspace(0.0, k * dy, 100001)
        w_in = np.trapezoid(peers.thornton(d, EP, R, py).F, d)
        up, d_p = peers.thornton_unloading(d, k * dy, EP, R, py)
        w_out = np.trapezoid(up, d)
        e.append(math.sqrt(w_out / w_in))
        x.append(math.sqrt(w_y / w_in))
    e, x = np.array(e), np.array(x)
    np.testing.assert_allclose(e, peers.thornton_restitution(x), rtol=2e-4)
    assert e[-1] / x[-1] ** 0.25 == pytest.approx(1.185, abs=5e-4)


def test_thornton_unloading_starts_at_the_peak_and_leaves_a_residual():
    py = 1.6 * SY
    dy = (math.pi * py / (2 * EP)) ** 2 * R
    F_max = float(peers.thornton(20 * dy, EP, R, py).F)
    F, d_p = peers.thornton_unloading(np.array([0.0, 20 * dy]), 20 * dy, EP, R, py)
    assert F[1] == pytest.approx(F_max, rel=1e-12) and F[0] == 0.0 and 0 < d_p < 20 * dy
    F, d_p = peers.thornton_unloading(np.array([0.5 * dy]), 0.9 * dy, EP, R, py)  # elastic: Hertz back
    assert d_p == pytest.approx(0.0, abs=1e-12 * dy)
    assert F[0] == pytest.approx(float(peers.hertz(0.5 * dy, EP, R).F), rel=1e-10)


def test_biwa_storakers_linear_case_of_the_similarity_solution():
    """No printed table of Biwa & Storåkers could be reached. The similarity solution is exact
    for n = 1 (a linear material): c² = 1/2 (a² = R h, Hill, Storåkers & Zdunek 1989); the fit
    c² = 1.43 exp(−0.97 n) must give it within its accuracy (+8 %), and perfect plasticity
    (n = 0) gives the pile-up c² = 1.43 > 1/2."""
    for n, c2, tol in ((1.0, 0.5, 0.10), (0.0, 1.43, 1e-12)):
        c = peers.biwa_storakers(np.array([1e-6]), R, SY, n)
        assert c.a[0] ** 2 / (2 * R * 1e-6) == pytest.approx(c2, rel=tol)


def test_ranges_are_data_next_to_each_law():
    """Each law's stated range, in its own variable (ω/ω_c, δ/δ_y, E'a/(Yρ)), as a mask."""
    assert peers.HERTZ_RANGE == (0.0, 1.0)
    assert peers.JACKSON_GREEN_RANGE[1] == peers.KOGUT_ETSION_RANGE[1] == peers.THORNTON_RANGE[1] == 110
    assert peers.CAVITY_RANGE == (3.0, 40.0) and peers.BIWA_STORAKERS_RANGE[0] == peers.CAVITY_RANGE[1]
    m = peers.in_range(np.array([0.5, 1.0, 1.5, 110.0, 111.0]), peers.KOGUT_ETSION_RANGE)
    np.testing.assert_array_equal(m, [True, True, True, True, False])
    np.testing.assert_array_equal(peers.in_range([0.5, 1.5], peers.HERTZ_RANGE), [True, False])


def test_ekk_residual_vanishes_at_first_yield_and_reads_0_80_at_110():
    """Etsion, Kligerman & Kadin (2005), residual as quoted by Jackson, Chusoipin & Green (2007):
    h_res/h_max = 1.02[1 − ((ω* + 5.9)/6.9)^−0.54]. No printed table was reachable; the identity
    the fit is built on: the residual vanishes at first yield (ω* = 1), where the unloading is
    Hertz's (exponent 3/2), so the branch is continuous with the elastic one; it rises
    monotonically to 0.80 at the end of its range (ω* = 110)."""
    from spherecontact.validation.unloading import ekk_branch, ekk_residual

    assert float(ekk_residual(1.0)) == 0.0 and float(ekk_residual(0.3)) == 0.0
    r = ekk_residual(np.geomspace(1.0, 110.0, 50))
    assert np.all(np.diff(r) > 0) and r[-1] == pytest.approx(0.80, abs=0.003)
    h = np.linspace(0.0, 1.0, 11)
    below, _ = ekk_branch(h, 1.0, 1.0, omega_c=1.0 / (1 - 1e-9))
    above, h_res = ekk_branch(h, 1.0, 1.0, omega_c=1.0 / (1 + 1e-9))
    assert h_res < 1e-8
    np.testing.assert_allclose(above, below, atol=1e-8)
    np.testing.assert_allclose(below, h**1.5, atol=1e-12)
