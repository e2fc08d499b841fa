"""The pressure profile a pair's less plastic body is loaded by (``pressure_profile``,
``model/profile.py``): the factor and its slope, an elastic body under a fully plastic partner
at 8/(3π) of its Hertz approach, equal spheres and rigid partners unchanged, exact stiffness,
monotone curves through the onset, the fast path, the key and its bad values."""

import math
import re

import numpy as np
import pytest

from spherecontact.model import ContactLaw, Material, Sphere, contact, default_coefficients
from spherecontact.model.coefficients import Coefficients
from spherecontact.model.profile import SMOOTHING, UNIFORM_OVER_HERTZ, profile_factor
from spherecontact.model.unified import pair

HERTZ = default_coefficients().replace(pressure_profile="hertz")
FLAT = HERTZ.replace(pressure_profile="flattened")
SOFT = Material(E=300.0, nu=0.3, sigma_y=1.0)
HARD = Material(E=300.0, nu=0.3, sigma_y=4.0)


def test_factor_values_and_slope():
    s = np.array([0.0, 0.2, 0.5, 0.0, 0.3])
    s_o = np.array([0.0, 0.1, 0.5, 1.0, 0.3 + 1e-3])
    ln_q, _ = profile_factor(s, 0.0 * s, s_o, 0.0 * s)
    assert ln_q[0] == ln_q[1] == ln_q[2] == 0.0  # partner no more plastic: nothing
    w = 1.0 / (1.0 + SMOOTHING)
    assert ln_q[3] == pytest.approx(-math.log(1.0 - (1.0 - UNIFORM_OVER_HERTZ) * w), rel=1e-14)
    assert 0.0 < ln_q[4] < 1e-5  # C¹ start: quadratic in s_o − s
    # d/d ln a through s_o and s against differences
    a = np.geomspace(0.01, 1.0, 7)
    so_of = lambda a: 0.9 * a / (0.3 + a)  # noqa: E731
    s_of = lambda a: 0.2 * a  # noqa: E731
    dso = 0.9 * 0.3 * a / (0.3 + a) ** 2
    ln_q, dln_q = profile_factor(s_of(a), 0.2 * a, so_of(a), dso)
    e = 1e-6
    fd = (profile_factor(s_of(a * (1 + e)), 0, so_of(a * (1 + e)), 0)[0]
          - profile_factor(s_of(a * (1 - e)), 0, so_of(a * (1 - e)), 0)[0]) / (2 * e)
    np.testing.assert_allclose(dln_q, fd, rtol=1e-6, atol=1e-10)


def test_elastic_body_under_a_fully_plastic_partner_takes_the_uniform_fraction():
    """At one p_m and a the elastic body's approach is 8/(3π) of the Hertz value once the
    partner is fully plastic (level weight 1); the plastic body's share rises accordingly."""
    soft = Sphere(1.0, Material(E=10000.0, nu=0.3, sigma_y=1.0))
    elastic = Sphere(1.0, Material.elastic(E=300.0, nu=0.3))
    a = np.array([0.15, 0.2])
    for co in (HERTZ, FLAT):
        p = pair(soft, elastic, co)
        assert np.all(p.law1.level_state_at(a * p._inv_rho_c[id(p.law1)])[0] == 1.0)
    st0, st1 = (pair(soft, elastic, co).state_at_a(a) for co in (HERTZ, FLAT))
    # the elastic body's Hertz approach at the pressure found, (3π/4) p_m a/E' (its finite-size
    # factors aside: 0.90–0.93 of it here, at a/R 0.15–0.2)
    hertz0 = 0.75 * math.pi * st0.p_m * a / elastic.material.E_prime
    hertz1 = 0.75 * math.pi * st1.p_m * a / elastic.material.E_prime
    np.testing.assert_allclose((st1.h2 / hertz1) / (st0.h2 / hertz0), UNIFORM_OVER_HERTZ, rtol=0.02)
    assert np.all(st1.h1 > st0.h1)


@pytest.mark.parametrize("partner", [Sphere(1.0, SOFT), Sphere(math.inf, Material.rigid()),
                                     Sphere(0.5, Material.rigid())])
def test_equal_spheres_and_rigid_partners_are_unchanged(partner):
    h = np.geomspace(1e-4, 0.3, 40)
    a, b = contact(Sphere(1.0, SOFT), partner, h, HERTZ), contact(Sphere(1.0, SOFT), partner, h, FLAT)
    np.testing.assert_array_equal(a.F, b.F)
    np.testing.assert_array_equal(a.h1, b.h1)


def test_unequal_yield_pair_moves_towards_the_softer_body_with_exact_stiffness():
    s1, s2 = Sphere(1.0, SOFT), Sphere(2.0, HARD)
    h = np.geomspace(1e-4, 0.3, 300)
    st0, st = contact(s1, s2, h, HERTZ), contact(s1, s2, h, FLAT)
    assert np.all(st.h1 >= st0.h1 - 1e-12) and np.max(st.h1 / h - st0.h1 / h) > 0.01
    assert np.all(np.isfinite(st.F)) and np.all(np.diff(st.F) > 0) and np.all(np.diff(st.a) > 0)
    eps = 1e-6
    hh = np.geomspace(1e-3, 0.25, 20)
    mid = contact(s1, s2, hh, FLAT)
    fd = (contact(s1, s2, hh * (1 + eps), FLAT).F - contact(s1, s2, hh * (1 - eps), FLAT).F) / (2 * eps * hh)
    np.testing.assert_allclose(mid.stiffness, fd, rtol=2e-4)


def test_fast_path_tabulates_it():
    s1, s2 = Sphere(1.0, SOFT), Sphere(2.0, HARD)
    law = ContactLaw(s1, s2, coeffs=FLAT, h_max=0.3)
    h = np.geomspace(1e-4, 0.3, 200)
    F, _ = law.loading_force(h)
    np.testing.assert_allclose(F, contact(s1, s2, h, FLAT).F, rtol=1e-5)


def test_key_round_trip_and_bad_value_named():
    d = FLAT.to_dict()
    assert d["pressure_profile"] == "flattened" and Coefficients.from_dict(d) == FLAT
    assert "pressure_profile" not in HERTZ.to_dict()  # the default is not written
    d["pressure_profile"] = "uniform"
    with pytest.raises(ValueError, match=re.escape("'pressure_profile'")):
        Coefficients.from_dict(d)
