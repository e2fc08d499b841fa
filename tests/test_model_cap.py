"""The rigid partner's exact cap in the gap a body closes (model/cap.py, model/unified.py,
calibration/dataset.py, ``counter_cap`` of model/coefficients.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spherecontact.model import Material, Sphere, load_coefficients
from spherecontact.model.cap import T_CONTINUE, cap_excess_factor, cap_gap_factor
from spherecontact.model.coefficients import Coefficients
from spherecontact.model.unified import UnifiedPair, harder_partner_weight

CO = load_coefficients()
EXACT = CO if CO.counter_cap == "exact" else CO.replace(counter_cap="exact")
PARABOLOID = CO.replace(counter_cap="paraboloid")  # the same fit, the paraboloid in h
BODY = Material(E=500.0, nu=0.3, sigma_y=1.0, K=1.0, n=0.3)
HARD = Material(E=500.0, nu=0.3, sigma_y=4.0)


def test_phi_is_the_exact_cap_depth_and_continues_smoothly():
    R = 0.7
    a = R * np.linspace(0.01, T_CONTINUE, 200)
    phi, dphi = cap_excess_factor(a / R)
    exact = R - np.sqrt(R * R - a * a)  # loses digits to cancellation at small a itself
    np.testing.assert_allclose(a * a / (2.0 * R) * (1.0 + phi), exact, rtol=1e-10)
    np.testing.assert_allclose(phi[:5], (a[:5] / R) ** 2 / 4.0, rtol=1e-3)  # φ ≈ t²/4
    t = np.linspace(0.05, 2.0, 400)
    phi, dphi = cap_excess_factor(t)
    e = 1e-7
    np.testing.assert_allclose((cap_excess_factor(t + e)[0] - cap_excess_factor(t - e)[0]) / (2 * e), dphi,
                               rtol=1e-5)
    assert np.all(np.isfinite(phi)) and np.all(np.diff(phi) > 0.0)  # beyond a = R_o: finite, rising
    lo, hi = cap_excess_factor(np.array([T_CONTINUE - 1e-9, T_CONTINUE + 1e-9]))
    assert abs(lo[1] - lo[0]) < 1e-8 and abs(hi[1] - hi[0]) < 1e-6  # C¹ at the joint


def test_gap_factor_is_one_without_a_weight_or_a_radius():
    a = np.geomspace(1e-300, 3.0, 50)
    for radius, w in ((math.inf, 1.0), (0.5, 0.0)):
        G, dG = cap_gap_factor(a, 2.0, radius, w)
        assert np.all(G == 1.0) and np.all(dG == 0.0)
    G, dG = cap_gap_factor(a, 2.0, 0.5, 1.0)
    assert np.all(np.isfinite(G)) and np.all(np.isfinite(dG)) and G[0] == 1.0


def test_rigid_sphere_approach_carries_the_cap_and_its_slope():
    Ri = 0.3
    s1, s2 = Sphere(1.0, BODY), Sphere(Ri, Material.rigid())
    exact, para = UnifiedPair(s1, s2, EXACT), UnifiedPair(s1, s2, PARABOLOID)
    a = np.geomspace(0.01, 0.25, 30)
    se, sp = exact.state_at_a(a), para.state_at_a(a)
    Rs = 1.0 / (1.0 + 1.0 / Ri)
    phi = cap_excess_factor(a / Ri)[0]
    np.testing.assert_allclose(se.h / sp.h, 1.0 + Rs * phi / Ri, rtol=1e-12)  # same c², deeper gap
    np.testing.assert_allclose(se.F, sp.F, rtol=1e-14)
    e = 1e-6
    hp, hm = exact.state_at_a(a * math.exp(e)).h, exact.state_at_a(a * math.exp(-e)).h
    np.testing.assert_allclose((np.log(hp) - np.log(hm)) / (2 * e), se.dlnh_dlna, rtol=2e-6)
    # the inversion h -> a and the stiffness follow: a smaller contact at the same approach
    h = np.geomspace(1e-3, 0.09, 12)
    assert np.all(exact.state_from_h(h).a < para.state_from_h(h).a)


def test_a_much_harder_partner_deepens_the_softer_body_only():
    s1, s2 = Sphere(1.0, BODY), Sphere(0.33, HARD)
    pe, pp = UnifiedPair(s1, s2, EXACT), UnifiedPair(s1, s2, PARABOLOID)
    a = np.geomspace(0.01, 0.2, 25)
    ue = pe.solve_u(a)
    se, du = pe._two_body_state(a, ue)
    sp, _ = pp._two_body_state(a, ue)  # the same κ root: the cap does not enter the pressures
    np.testing.assert_allclose(se.F, sp.F, rtol=1e-14)
    np.testing.assert_allclose(se.h2, sp.h2, rtol=1e-14)
    assert np.all(se.h1 > sp.h1)
    for name, f in (("h", lambda s: s.h), ("h1", lambda s: s.h1)):
        e = 1e-6
        up, um = pe.solve_u(a * math.exp(e)), pe.solve_u(a * math.exp(-e))
        fp = f(pe._two_body_state(a * math.exp(e), up)[0])
        fm = f(pe._two_body_state(a * math.exp(-e), um)[0])
        slope = se.dlnh_dlna if name == "h" else se.dlnh1_dlna
        np.testing.assert_allclose((np.log(fp) - np.log(fm)) / (2 * e), slope, rtol=1e-5, err_msg=name)
    # equal yield stresses and moduli: no weight, the paraboloid split to the bit; equal yield
    # stresses and a stiffer partner: the stiffer is the harder (``harder_partner_weight``)
    a2 = np.geomspace(0.01, 0.2, 9)
    s2e = Sphere(0.33, Material(E=500.0, nu=0.3, sigma_y=1.0))
    assert harder_partner_weight(s1, s2e) == harder_partner_weight(s2e, s1) == 0.0
    assert np.array_equal(UnifiedPair(s1, s2e, EXACT).state_at_a(a2).h,
                          UnifiedPair(s1, s2e, PARABOLOID).state_at_a(a2).h)
    stiff = Sphere(0.33, Material(E=900.0, nu=0.3, sigma_y=1.0))
    assert harder_partner_weight(s1, stiff) > 0.8 and harder_partner_weight(stiff, s1) == 0.0
    se2, sp2 = UnifiedPair(s1, stiff, EXACT).state_at_a(a2), UnifiedPair(s1, stiff, PARABOLOID).state_at_a(a2)
    assert np.all(se2.h1 > sp2.h1)
    # a yield ratio of 1.5 decides alone: a partner of lower yield stress is no harder, whatever its
    # modulus
    soft_y = Sphere(0.33, Material(E=5000.0, nu=0.3, sigma_y=1.0 / 1.5))
    assert harder_partner_weight(s1, soft_y) == 0.0 and harder_partner_weight(soft_y, s1) > 0.5


def test_counter_cap_key_round_trips_and_names_bad_values():
    d = EXACT.to_dict()
    assert d["counter_cap"] == "exact"
    assert Coefficients.from_dict(d) == EXACT
    assert "counter_cap" not in PARABOLOID.to_dict()  # the default is not written
    d["counter_cap"] = "sphere"
    with pytest.raises(ValueError, match=r"'counter_cap' must be one of \('paraboloid', 'exact'\)"):
        Coefficients.from_dict(d)

