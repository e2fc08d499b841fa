"""Property-based tests of the unified model over wide random materials and radii."""

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spherecontact.model import Material, Sphere, contact
from spherecontact.model.coefficients import LITERATURE, Coefficients
from spherecontact.model.unified import UnifiedPair

CO = Coefficients.from_dict(LITERATURE)
CO_FS = CO.replace(finite_size={"ratio": "a_over_rho", "H_bar": [0.3, 0.2], "c2": [-0.2]})
SETTINGS = settings(max_examples=150, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def materials(draw):
    kind = draw(st.sampled_from(["ludwik", "ludwik", "perfect", "table", "elastic", "rigid"]))
    if kind == "rigid":
        return Material.rigid()
    E = 10 ** draw(st.floats(8.0, 12.0))
    nu = draw(st.floats(-0.9, 0.49))
    if kind == "elastic":
        return Material.elastic(E, nu)
    sy = E / 10 ** draw(st.floats(1.0, 5.0))
    if kind == "perfect":
        return Material(E=E, nu=nu, sigma_y=sy)
    if kind == "table":
        k = draw(st.integers(1, 5))
        eps = np.concatenate([[0.0], np.sort(draw(st.lists(
            st.floats(1e-3, 2.0), min_size=k, max_size=k, unique=True)))])
        inc = draw(st.lists(st.floats(0.0, 1.0), min_size=k, max_size=k))
        sig = sy * np.cumprod([1.0, *[1 + i for i in inc]])
        return Material.from_table(E=E, nu=nu, eps_p=eps, sigma=sig)
    return Material(E=E, nu=nu, sigma_y=sy, K=sy * draw(st.floats(0.0, 10.0)),
                    n=draw(st.floats(0.0, 1.0, exclude_min=True)))


@st.composite
def sphere_pairs(draw):
    m1 = draw(materials())
    m2 = m1 if draw(st.booleans()) and draw(st.booleans()) else draw(materials())
    if m1.is_rigid and m2.is_rigid:
        m2 = Material(E=2e11, nu=0.3, sigma_y=3e8, K=5e8, n=0.4)
    R1 = 10 ** draw(st.floats(-6.0, 0.0))
    choice = draw(st.sampled_from(["free", "equal", "flat"]))
    R2 = {"free": 10 ** draw(st.floats(-6.0, 0.0)), "equal": R1, "flat": math.inf}[choice]
    return Sphere(R1, m1), Sphere(R2, m2)


def _h_grid(s1, s2, n=60):
    R = min(s1.radius, s2.radius)
    return R * np.geomspace(1e-9, 0.5, n)


@SETTINGS
@given(sphere_pairs(), st.sampled_from([CO, CO_FS]))
def test_force_and_radius_finite_and_strictly_increasing(pair, co):
    s1, s2 = pair
    h = _h_grid(s1, s2)
    c = contact(s1, s2, h, co)
    for f in ("F", "a", "h1", "h2", "stiffness"):
        assert np.all(np.isfinite(getattr(c, f))), f
    assert np.all(np.diff(c.F) > 0) and np.all(np.diff(c.a) > 0)
    assert np.all(c.stiffness > 0)
    assert np.allclose(c.h1 + c.h2, h, rtol=1e-12)
    # continuity: a 1e-9 relative step in h moves F by about (dF/dh) dh
    dh = 1e-9 * h
    F2 = contact(s1, s2, h + dh, co).F
    assert np.all(np.abs(F2 - c.F) <= 2.0 * c.stiffness * dh + 1e-12 * c.F)


@SETTINGS
@given(sphere_pairs(), st.sampled_from([CO, CO_FS]))
def test_inversion_round_trips(pair, co):
    s1, s2 = pair
    p = UnifiedPair(s1, s2, co)
    h = _h_grid(s1, s2, 40)
    st_h = p.state_from_h(h)
    back = p.state_at_a(st_h.a, None).h
    assert np.max(np.abs(back / h - 1)) < 1e-9


@SETTINGS
@given(sphere_pairs(), st.sampled_from([CO, CO_FS]))
def test_stiffness_matches_finite_differences(pair, co):
    s1, s2 = pair
    p = UnifiedPair(s1, s2, co)
    h = _h_grid(s1, s2, 25)
    d = 1e-6
    mid, plus, minus = p.state_from_h(h), p.state_from_h(h * (1 + d)), p.state_from_h(h * (1 - d))
    fd = (plus.F - minus.F) / (2 * d * h)
    smooth = (plus.piece == minus.piece) & (plus.piece == mid.piece)  # skip model kinks
    assert np.allclose(mid.stiffness[smooth], fd[smooth], rtol=2e-5)
