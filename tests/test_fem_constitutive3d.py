"""The 3D (3×3) exponential-map update against the axisymmetric one (fem/constitutive3d.py)."""

import numpy as np
import pytest

from spherecontact.fem.constitutive3d import PlasticState3, stress_update3, tangent3
from spherecontact.fem.plasticity import PlasticState, stress_update, tangent
from spherecontact.model import Material

MATERIALS = [
    Material(E=200.0, nu=0.3, sigma_y=1.0),  # EPP E/σY 200
    Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3),  # Ludwik K/σY 2, n 0.3, E/σY 500
]
#: axisymmetric F vector [rr, rz, zr, zz, θθ] → 3×3 with x = r, y = θ (hoop), z = z
AX = {0: (0, 0), 1: (0, 2), 2: (2, 0), 3: (2, 2), 4: (1, 1)}


def to3(Fv):
    F = np.zeros((Fv.shape[1], 3, 3))
    for k, (i, j) in AX.items():
        F[:, i, j] = Fv[k]
    return F


def path(n, steps, seed):
    """Axisymmetric F paths: strains growing to ~±0.08 (well past yield), with rotation."""
    rng = np.random.default_rng(seed)
    G = rng.normal(scale=0.03, size=(5, n))
    return [np.array([1, 0, 0, 1, 1.0])[:, None] + (s + 1) / steps * G for s in range(steps)]


@pytest.mark.parametrize("material", MATERIALS)
def test_axisymmetric_F_gives_the_axisymmetric_update(material):
    n = 400
    st2 = PlasticState.virgin(n)
    st3 = PlasticState3.virgin(n)
    worst = 0.0
    for Fv in path(n, 4, 1):
        r2 = stress_update(Fv, st2.cp_inv, st2.eps_p, material)
        r3 = stress_update3(to3(Fv), st3.cp_inv, st3.eps_p, material)
        scale = material.E
        assert np.max(np.abs(to3(r2.P) - r3.P)) < 1e-12 * scale
        cp2 = to3(np.stack([r2.cp_inv[0], r2.cp_inv[1], r2.cp_inv[1], r2.cp_inv[2], r2.cp_inv[3]]))
        assert np.max(np.abs(cp2 - r3.cp_inv)) < 1e-12
        assert np.max(np.abs(r2.eps_p - r3.eps_p)) < 1e-12
        assert np.max(np.abs(r2.psi - r3.psi)) < 1e-12 * scale
        worst = max(worst, np.max(np.abs(to3(r2.P) - r3.P)) / scale)
        st2 = PlasticState(r2.cp_inv, r2.eps_p)
        st3 = PlasticState3(r3.cp_inv, r3.eps_p)
    assert np.mean(st2.eps_p > 0) > 0.5  # the path is plastic at most points


@pytest.mark.parametrize("material", MATERIALS)
def test_tangent_matches_the_axisymmetric_hand_tangent(material):
    n = 200
    Fs = path(n, 3, 2)
    st = PlasticState.virgin(n)
    r = stress_update(Fs[0], st.cp_inv, st.eps_p, material)
    st = PlasticState(r.cp_inv, r.eps_p)
    r2 = stress_update(Fs[2], st.cp_inv, st.eps_p, material)
    A2 = tangent(Fs[2], st, material, r2)  # (5, 5, n)
    cp3 = to3(np.stack([st.cp_inv[0], st.cp_inv[1], st.cp_inv[1], st.cp_inv[2], st.cp_inv[3]]))
    st3 = PlasticState3(cp3, st.eps_p)
    F3 = to3(Fs[2])
    r3 = stress_update3(F3, st3.cp_inv, st3.eps_p, material)
    A3 = tangent3(F3, st3, material, r3)
    idx = [3 * i + j for i, j in AX.values()]
    sub = A3[:, idx][:, :, idx].transpose(1, 2, 0)
    assert np.mean(r2.dgamma > 0) > 0.3
    assert np.max(np.abs(sub - A2)) < 1e-6 * material.E


def test_objective_and_consistent_in_general_3d():
    m = MATERIALS[1]
    rng = np.random.default_rng(3)
    n = 300
    F = np.eye(3) + rng.normal(scale=0.05, size=(n, 3, 3))
    st = PlasticState3.virgin(n)
    r = stress_update3(F, st.cp_inv, st.eps_p, m)
    # Q F gives Q P (the stored C_p⁻¹ is in the reference frame: unchanged)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    rq = stress_update3(Q @ F, st.cp_inv, st.eps_p, m)
    assert np.max(np.abs(rq.P - Q @ r.P)) < 1e-12 * m.E
    assert np.max(np.abs(rq.cp_inv - r.cp_inv)) < 1e-12
    # plastic points sit on the yield surface after the return
    s = r.tau - np.trace(r.tau, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    q = np.sqrt(1.5 * np.einsum("nij,nij->n", s, s))
    pl = r.dgamma > 0
    assert pl.sum() > 50
    assert np.max(np.abs(q[pl] - m.flow_stress(r.eps_p[pl]))) < 1e-9
    # det C_p⁻¹ = 1 (isochoric plastic flow)
    assert np.max(np.abs(np.linalg.det(r.cp_inv) - 1)) < 1e-12
