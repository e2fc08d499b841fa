"""FE building blocks: tensor functions, return mapping, tangent, assembly, mesh, contact."""


import subprocess
import sys

import numpy as np
import pytest

from spherecontact.fem.assembly import Discretisation
from spherecontact.fem.contact import RigidObstacle, contact_edge, smooth_contact_radius, surface_areas
from spherecontact.fem.mesh import build_mesh
from spherecontact.fem.plasticity import (
    PlasticState,
    exp_sym2,
    log_sym2,
    stress_and_tangent,
    stress_and_tangent_complex,
    stress_update,
)
from spherecontact.fem.solver import work_increment
from spherecontact.model import Material

MATERIALS = [
    Material(E=200.0, nu=0.3, sigma_y=1.0),
    Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3),
    Material.from_table(E=200.0, nu=0.3, eps_p=[0, 0.05, 1.0], sigma=[1.0, 1.4, 2.0]),
]


def random_F(n, scale, seed=0):
    rng = np.random.default_rng(seed)
    F = np.zeros((5, n))
    F[[0, 3, 4]] = 1.0
    return F + rng.normal(scale=scale, size=(5, n))


@pytest.mark.parametrize("b", [(2.0, 0.3, 0.7), (1.0, 0.0, 1.0), (1.3, 1e-9, 1.3), (5.0, -1.2, 0.4)])
def test_log_exp_inverse_and_eigenvalues(b):
    L = log_sym2(*b)
    assert np.allclose(exp_sym2(*L), b, rtol=1e-13, atol=1e-14)
    B = np.array([[b[0], b[1]], [b[1], b[2]]])
    w, V = np.linalg.eigh(B)
    ref = V @ np.diag(np.log(w)) @ V.T
    assert np.allclose([L[0], L[1], L[2]], [ref[0, 0], ref[0, 1], ref[1, 1]], atol=1e-13)


def test_log_is_analytic_at_equal_eigenvalues():
    """Complex step through ln B at B = I gives the exact derivative d ln B = dB."""
    h = 1e-30
    L = log_sym2(1.0 + 1j * h * 0.3, 0.0 + 1j * h * 0.7, 1.0 - 1j * h * 0.2)
    assert np.allclose(np.imag(L) / h, [0.3, 0.7, -0.2], rtol=1e-12)


def test_small_strain_tangent_is_isotropic_elasticity():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    _, A = stress_and_tangent(np.array([[1.0], [0], [0], [1], [1]]), PlasticState.virgin(1), m)
    lam = m.E * m.nu / ((1 + m.nu) * (1 - 2 * m.nu))
    mu = m.shear_modulus
    assert A[0, 0, 0] == pytest.approx(lam + 2 * mu, rel=1e-12)
    assert A[1, 1, 0] == pytest.approx(mu, rel=1e-12)
    assert A[0, 4, 0] == pytest.approx(lam, rel=1e-12)


@pytest.mark.parametrize("mat", MATERIALS)
def test_tangent_matches_finite_differences_and_is_symmetric(mat):
    F1 = random_F(40, 0.04, seed=1)
    first, _ = stress_and_tangent(F1, PlasticState.virgin(40), mat)
    state = PlasticState(first.cp_inv, first.eps_p)
    F2 = F1 + random_F(40, 0.01, seed=2) - random_F(40, 0.0, seed=2)
    upd, A = stress_and_tangent(F2, state, mat)
    assert np.mean(upd.dgamma > 0) > 0.5  # mostly plastic points
    e = 1e-6
    A_fd = np.empty_like(A)
    for k in range(5):
        Fp, Fm = F2.copy(), F2.copy()
        Fp[k] += e
        Fm[k] -= e
        A_fd[:, k] = (stress_update(Fp, state.cp_inv, state.eps_p, mat).P
                      - stress_update(Fm, state.cp_inv, state.eps_p, mat).P) / (2 * e)
    scale = np.abs(A).max()
    assert np.abs(A - A_fd).max() < 1e-6 * scale
    assert np.abs(A - A.transpose(1, 0, 2)).max() < 1e-12 * scale


@pytest.mark.parametrize("mat", MATERIALS + [Material.elastic(200.0, 0.45)])
@pytest.mark.parametrize("scale", [1e-7, 0.01, 0.1])
def test_hand_linearised_tangent_equals_the_complex_step_tangent(mat, scale):
    """Elastic and plastic points, near-equal principal stretches (scale 1e-7: the series
    branches), large strains, a prestrained state and Newton's frozen elastic points."""
    F1 = random_F(300, 0.05, seed=4)
    first, _ = stress_and_tangent_complex(F1, PlasticState.virgin(300), mat)
    state = PlasticState(first.cp_inv, first.eps_p)
    F2 = F1 + random_F(300, scale, seed=5) - random_F(300, 0.0, seed=5)
    frozen = np.arange(300) % 7 == 0
    for elastic in (None, frozen):
        upd, A = stress_and_tangent(F2, state, mat, elastic=elastic)
        _, A_ref = stress_and_tangent_complex(F2, state, mat, real=upd)
        assert np.abs(A - A_ref).max() < 1e-11 * np.abs(A_ref).max()
        if elastic is not None and np.isfinite(mat.sigma_y) and scale > 1e-3:
            assert np.any(upd.dgamma > 0) and np.all(upd.dgamma[frozen] == 0)  # both kinds of points


@pytest.mark.parametrize("mat", MATERIALS)
def test_return_mapping_lands_on_the_yield_surface(mat):
    virgin = PlasticState.virgin(200)
    upd = stress_update(random_F(200, 0.006, seed=3), virgin.cp_inv, virgin.eps_p, mat)
    t11, t12, t22, ttt = upd.tau
    p = (t11 + t22 + ttt) / 3
    q = np.sqrt(1.5 * ((t11 - p) ** 2 + (t22 - p) ** 2 + (ttt - p) ** 2 + 2 * t12**2))
    plastic = upd.dgamma > 0
    assert plastic.any() and (~plastic).any()
    assert np.allclose(q[plastic], mat.flow_stress(upd.eps_p[plastic]), rtol=1e-9)
    assert np.all(q[~plastic] <= mat.flow_stress(0.0) * (1 + 1e-12))


def test_isochoric_plastic_flow():
    """Plastic flow keeps det(C_p) = 1 (exponential map, deviatoric flow)."""
    m = MATERIALS[0]
    state = PlasticState.virgin(100)
    upd = stress_update(random_F(100, 0.1, seed=4), state.cp_inv, state.eps_p, m)
    c = upd.cp_inv
    det = (c[0] * c[2] - c[1] ** 2) * c[3]
    assert np.allclose(det, 1.0, atol=1e-12)


@pytest.fixture(scope="module")
def coarse():
    return Discretisation(build_mesh(1.0, density=0.5))


def test_mesh_geometry(coarse):
    hm = coarse.hmesh
    X = hm.X
    assert np.allclose(np.hypot(X[0, hm.surface], X[1, hm.surface] - 1.0), 1.0, atol=1e-12)
    assert np.all(np.diff(np.arctan2(X[0, hm.surface], 1.0 - X[1, hm.surface])) > 0)
    assert np.allclose(X[1, hm.equator], 1.0) and np.allclose(X[0, hm.axis], 0.0)
    # volume of the hemisphere from the quadrature weights: 2π/3 R³
    assert coarse.weights.sum() == pytest.approx(2 * np.pi / 3, rel=1e-6)


def test_meshing_keeps_the_process_signal_handlers():
    """gmsh's initialisation resets SIGPIPE to terminate: a process that wrote to a closed
    pipe afterwards died with status 141 instead of getting BrokenPipeError."""
    script = ("import os\n"
              "from spherecontact.fem.mesh import build_mesh\n"
              "build_mesh(1.0, density=0.25)\n"
              "r, w = os.pipe()\n"
              "os.close(r)\n"
              "try:\n"
              "    os.write(w, b'x')\n"
              "except BrokenPipeError:\n"
              "    print('BrokenPipeError')\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "BrokenPipeError", (proc.returncode, proc.stderr)


@pytest.mark.parametrize("density", [0.1, 5.0, float("nan")])
def test_mesh_density_out_of_range(density):
    with pytest.raises(ValueError, match="mesh density"):
        build_mesh(1.0, density=density)


def test_patch_test_homogeneous_deformation(coarse):
    """u = (ε_r R, ε_z Z): uniform stress, interior nodal forces vanish (B and 2πR weights).

    Exact on straight-sided elements; on the curved elements along the arc 2×2 Gauss
    points integrate the rational isoparametric integrand only approximately (~1e-5).
    """
    X = coarse.hmesh.X
    u = np.zeros(coarse.n_dofs)
    u[0::2] = 0.003 * X[0]
    u[1::2] = -0.002 * X[1]
    Fv = coarse.deformation_gradient(u)
    assert np.allclose(Fv, np.array([[1.003], [0], [0], [0.998], [1.003]]), atol=1e-12)
    upd, _ = stress_and_tangent(Fv, PlasticState.virgin(Fv.shape[1]), Material.elastic(200.0, 0.3))
    f = coarse.internal_force(upd.P)
    hm = coarse.hmesh
    boundary = np.unique(np.concatenate([hm.surface, hm.axis, hm.equator]))
    interior = np.setdiff1d(np.arange(coarse.n_nodes), boundary)
    assert np.abs(f[2 * interior]).max() < 1e-4 * np.abs(f).max()
    assert np.abs(f[2 * interior + 1]).max() < 1e-4 * np.abs(f).max()
    straight = X[0, interior] ** 2 + (X[1, interior] - 1.0) ** 2 < 0.6**2  # far from the arc
    assert np.abs(f[2 * interior[straight]]).max() < 1e-10 * np.abs(f).max()
    # resultant on the equator equals σ_zz times the equatorial area π R²
    Fz = f[2 * hm.equator + 1].sum()
    assert Fz == pytest.approx(upd.P[3, 0] * np.pi, rel=1e-6)


def test_tangent_is_derivative_of_internal_force(coarse):
    X = coarse.hmesh.X
    r = np.hypot(X[0], X[1])
    u = np.zeros(coarse.n_dofs)
    u[1::2] = -0.002 * np.exp(-((r / 0.2) ** 2))
    m = Material.elastic(200.0, 0.3)
    state = PlasticState.virgin(coarse.n_elements * coarse.n_qp)
    upd, A = stress_and_tangent(coarse.deformation_gradient(u), state, m)
    K = coarse.tangent(A)
    v = np.random.default_rng(5).normal(size=coarse.n_dofs) * 1e-3
    e = 1e-5

    def fint(w):
        return coarse.internal_force(stress_and_tangent(coarse.deformation_gradient(w), state, m)[0].P)

    fd = (fint(u + e * v) - fint(u - e * v)) / (2 * e)
    assert np.abs(fd - K @ v).max() < 1e-7 * np.abs(K @ v).max()


def test_obstacles_gap_and_normal():
    x = np.array([[0.0, 0.3], [0.1, -0.05]])
    g, n, k = RigidObstacle().gap_normal(x)
    assert np.allclose(g, [0.1, -0.05]) and np.allclose(n, [[0, 0], [1, 1]]) and np.all(k == 0)
    g, n, k = RigidObstacle(2.0).gap_normal(np.array([[0.0], [0.1]]))
    assert g[0] == pytest.approx(0.1) and np.allclose(n[:, 0], [0, 1]) and k[0] == pytest.approx(1 / 2.1)
    with pytest.raises(ValueError, match="indenter radius"):
        RigidObstacle(-1.0)


def test_surface_areas_sum_to_hemisphere_area():
    hm = build_mesh(1.0, density=0.5)
    A = surface_areas(hm.X[:, hm.surface])
    assert A.sum() == pytest.approx(2 * np.pi, rel=1e-6)
    assert np.all(A[1:] > 0)


def hertz_gap(r, a, R=1.0):
    """Hertz separation outside the contact (Johnson 1985, eq. 4.25), r > a."""
    rho = np.maximum(r / a, 1.0)
    return a**2 / (np.pi * R) * (np.sqrt(rho**2 - 1) - (2 - rho**2) * np.arccos(1 / rho))


@pytest.mark.parametrize("a", [0.0203, 0.0311, 0.0437])
def test_contact_edge_recovers_hertz_radius(a):
    r = np.arange(0, 0.08, 0.0015)
    active = r <= a
    gap = np.where(active, 0.0, hertz_gap(r, a))
    a_nodes, a_cur, a_ref = contact_edge(r, r, gap, active)
    assert a_nodes <= a < a_nodes + 0.0015
    assert abs(a_ref - a) < 0.1 * 0.0015  # a tenth of the node spacing
    assert a_cur == pytest.approx(a_ref)


@pytest.mark.parametrize("p", [1.0, 1.2])
def test_contact_edge_follows_a_plastic_edge_that_the_hertz_exponent_misplaces(p):
    """A plastic edge opens as g ∝ (r − a)^p with p near 1 (the surface leaves the counterface at
    an angle): the fitted exponent places a within a twentieth of the node spacing; the fit with
    Hertz's 3/2 pulls a back towards the last closed node (the low, mesh-dependent bias it has)."""
    s, a = 0.01, 0.2537
    r = np.arange(0.0, 0.4, s / 2)  # quadratic edges: corner and midside nodes
    active = r <= a
    gap = np.where(active, 0.0, 0.05 * np.maximum(r - a, 0.0) ** p)
    assert abs(contact_edge(r, r, gap, active, fit="fitted")[2] - a) < 0.05 * s / 2
    assert a - contact_edge(r, r, gap, active)[2] > 0.5 * s / 2


@pytest.mark.parametrize("a", [0.0203, 0.0311, 0.0437])
def test_the_fitted_exponent_keeps_hertz_radius_on_an_elastic_edge(a):
    r = np.arange(0, 0.08, 0.0015)
    active = r <= a
    gap = np.where(active, 0.0, hertz_gap(r, a))
    assert abs(contact_edge(r, r, gap, active, fit="fitted")[2] - a) < 0.1 * 0.0015


def test_an_unknown_edge_fit_is_named():
    with pytest.raises(ValueError, match="fit must be one of 'hertz', 'fitted'"):
        contact_edge(np.arange(5.0), np.arange(5.0), np.zeros(5), np.arange(5) < 2, fit="free")


def test_smoothing_removes_alternating_scatter_only():
    h = np.linspace(1e-4, 4e-3, 40)
    a_true = np.sqrt(h)
    noisy = a_true * (1 + 0.003 * (-1) ** np.arange(h.size))
    sm = smooth_contact_radius(h, noisy)
    assert np.abs(sm / a_true - 1)[3:-3].max() < 0.001  # interior: scatter averaged out
    assert np.abs(sm / a_true - 1).max() < 0.003  # ends: no worse than the raw scatter
    assert np.abs(smooth_contact_radius(h, a_true) / a_true - 1).max() < 1e-3


def test_work_increment_exact_for_power_laws():
    for p in (1.0, 1.5, 0.5):
        F = lambda h, p=p: 3.0 * h**p  # noqa: E731
        exact = 3.0 * (0.2 ** (p + 1) - 0.1 ** (p + 1)) / (p + 1)
        assert work_increment(0.1, 0.2, F(0.1), F(0.2)) == pytest.approx(exact, rel=1e-12)
    assert work_increment(0.0, 0.1, 0.0, 2.0) == pytest.approx(2.0 * 0.1 / 2.5)


def test_power_law_multiplier_converges_at_the_roundoff_floor():
    """Ludwik n = 0.1 at E/σY = 1e4 and ε_p ~ 1: 3μ y^(1/n) cancels ε_p,n, so the residual
    cannot fall below ~1e-12 σY; the bracket's collapse ends the iteration (it used to raise
    "plastic multiplier did not converge" and stop the run)."""
    from spherecontact.fem.plasticity import solve_plastic_multiplier

    mat = Material(E=1e4, nu=0.3, sigma_y=1.0, K=0.5, n=0.1)
    mu = mat.shear_modulus
    eps_n = np.array([0.3, 0.8, 1.5, 2.5])
    dg = np.array([1e-6, 1e-4, 1e-3, 3e-3])
    q_tr = mat.flow_stress(eps_n + dg) + 3.0 * mu * dg
    got = solve_plastic_multiplier(q_tr, eps_n, mat, mu)
    np.testing.assert_allclose(got, dg, rtol=1e-6, atol=1e-14)


def test_the_edge_fit_changes_the_contact_radius_alone():
    """``edge_fit`` "fitted" reads the same converged states: F to the bit, the contact radius
    higher where the edge is plastic (the Hertz exponent's fit pulls it back towards the last
    closed node), and the choice is recorded with the run."""
    from spherecontact.fem.io import run_indentation
    from spherecontact.fem.solver import SolverOptions
    from spherecontact.model import Material

    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    runs = {fit: run_indentation(m, 1.0, 0.05, density=0.7, options=SolverOptions(edge_fit=fit))
            for fit in ("hertz", "fitted")}
    hertz, fitted = (runs[k].curves for k in ("hertz", "fitted"))
    np.testing.assert_array_equal(hertz["F"], fitted["F"])
    plastic = np.asarray(hertz["h"]) > 0.01
    ratio = np.asarray(fitted["a"])[plastic] / np.asarray(hertz["a"])[plastic]
    assert 0.002 < np.mean(ratio - 1) < 0.03
    assert runs["fitted"].inputs["options"]["edge_fit"] == "fitted"
    with pytest.raises(ValueError, match="edge_fit must be one of 'hertz', 'fitted'"):
        SolverOptions(edge_fit="free").validate()
