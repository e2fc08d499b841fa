"""Published peer laws: Hertz limits, regime-switch continuity, independently checkable values."""

import math

import numpy as np
import pytest

from spherecontact.validation import peers

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
