"""Penalty contact (SolverOptions.penalty): consistent tangent, convergence to exact contact
as the stiffness grows, penetration ∝ 1/penalty, bad values named, and the symmetric
two-pass variant of two deformable bodies."""

import numpy as np
import pytest

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.io import run_indentation
from spherecontact.fem.solver import IndentationSolver, SolverOptions
from spherecontact.model import Material

PLASTIC = Material(E=200.0, nu=0.3, sigma_y=1.0)
H_MAX = 0.03


def _run(penalty):
    solver = IndentationSolver(PLASTIC, 1.0, RigidObstacle(), density=0.5,
                               options=SolverOptions(penalty=penalty))
    return solver, solver.run(H_MAX)


@pytest.fixture(scope="module")
def runs():
    return {p: _run(p) for p in (None, 1.0, 100.0)}


def test_penalty_tangent_matches_finite_differences():
    """∂(−f_c)/∂u of a rigid sphere obstacle against central differences of the contact force."""
    solver = IndentationSolver(PLASTIC, 1.0, RigidObstacle(2.0), density=0.5,
                               options=SolverOptions(penalty=3.0))
    rng = np.random.default_rng(1)
    u = np.zeros(solver.disc.n_dofs)
    u[1::2] = -0.01
    u += 1e-4 * rng.standard_normal(u.size)
    gap, normal, curv, pen, _, fc, points = solver._penalty_force(u)
    assert pen.sum() >= 3 and points is None
    data = solver._penalty_tangent(np.zeros(solver.disc.n_entries), gap, normal, curv, pen)
    K = solver.disc.matrix(data).toarray()
    dofs = np.concatenate([2 * solver.surface[pen], 2 * solver.surface[pen] + 1])
    eps = 1e-7
    for j in dofs:
        e = np.zeros(u.size)
        e[j] = eps
        fd = -(solver._penalty_force(u + e)[5] - solver._penalty_force(u - e)[5]) / (2 * eps)
        assert np.allclose(K[:, j], fd, rtol=1e-5, atol=1e-6 * np.abs(K).max())


def test_penalty_converges_to_exact_contact(runs):
    """The work of the contact force, ∫F dh to h/R = 0.03, approaches the exact contact's as the
    penalty stiffness grows (measured: −0.63 % at 1, −0.08 % at 100). The work is compared, not
    F pointwise: on this coarse mesh F(h) steps by ±2 % as single nodes close, in both methods."""
    exact = runs[None][1]
    err = {}
    for p in (1.0, 100.0):
        r = runs[p][1]
        assert r.status == "converged"
        err[p] = abs(r.curves["work_external"][-1] / exact.curves["work_external"][-1] - 1)
    assert err[100.0] < 0.002
    assert err[1.0] > 3 * err[100.0]


def test_penetration_scales_as_one_over_penalty(runs):
    """Largest penetration ≈ p ℓ/(penalty E): a hundredfold stiffness, about a hundredth of it."""
    depth = {}
    for p in (1.0, 100.0):
        _, r = runs[p]
        depth[p] = -r.profile_g[-1].min()
    assert 50 < depth[1.0] / depth[100.0] < 200


@pytest.mark.parametrize("bad", [0.0, -1.0, float("inf"), float("nan")])
def test_bad_penalty_is_named(bad):
    with pytest.raises(ValueError, match="penalty"):
        SolverOptions(penalty=bad).validate()


def test_two_pass_penalty_keeps_an_equal_pair_symmetric():
    """Two equal plastic spheres with the symmetric two-pass penalty contact: h₁ = h₂ to
    roundoff (the one-pass node-to-surface contact drifts by 1e-4–1e-2 here), and the same
    force as one sphere with penalty contact on a flat at the per-body approach. Newton is
    converged to 1e-8 here: at the default 1e-4 the first increment keeps 1.1e-9 of h₁/h₂ − 1."""
    opts = SolverOptions(penalty=100.0, tol=1e-8)
    pair = run_indentation(PLASTIC, 1.0, 0.012, radius2=1.0, material2=PLASTIC, scene="two_body",
                           density=0.5, options=opts)
    c = pair.curves
    assert pair.status == "converged"
    assert np.abs(c["h1"] / c["h2"] - 1).max() < 1e-9
    flat = run_indentation(PLASTIC, 1.0, 0.006, density=0.5, options=opts)
    F = np.interp(flat.h, c["h1"], c["F"])
    sel = flat.h > 0.002
    # as with the exact contact, the pair is 0.3–0.9 % stiffer than the flat scene on this coarse
    # mesh, with ±1 % from interpolating the nodal staircase between different increments
    assert np.abs(F[sel] / flat.F[sel] - 1).max() < 0.025
    W = np.trapezoid(c["F"], c["h1"])
    assert abs(W / np.trapezoid(flat.F, flat.h) - 1) < 0.01


def test_two_body_penalty_pair_starts_each_increment_from_the_last_tangent(monkeypatch):
    """Penalty contact of two bodies: the tangent predictor solves K Δu = 0 on the free dofs
    with body 1's equator moved by −dh, on the stored factors; the secant run ends within
    the path dependence of plasticity."""
    from spherecontact.fem.twobody import TwoBodySolver

    calls = []
    predictor = TwoBodySolver._tangent_predictor

    def recorded(self, u, dh):
        pred = predictor(self, u, dh)
        calls.append((u, dh, pred, self._tangent, self.free, self.bodies[0]))
        return pred

    monkeypatch.setattr(TwoBodySolver, "_tangent_predictor", recorded)
    # the tangent part alone: the springs of points entering contact are test_fem_pair_predictor's
    monkeypatch.setattr(TwoBodySolver, "_entering_contact", lambda self, u, u_pred: np.zeros_like(u))
    stiff = Material(E=600.0, nu=0.3, sigma_y=1.0)
    kw = dict(radius2=1.0, material2=stiff, density=0.5)
    res = run_indentation(PLASTIC, 1.0, 0.006, options=SolverOptions(penalty=100.0), **kw)
    assert res.status == "converged"
    assert sum(c[2] is not None for c in calls) >= res.timings["increments"] - 3
    u, dh, pred, K, free, body1 = calls[len(calls) // 2]
    du = pred - u
    assert np.abs((K @ du)[free]).max() <= 1e-9 * np.abs(K @ du).max()
    assert du[body1.offset + 2 * body1.hmesh.equator + 1] == pytest.approx(-dh)
    secant = run_indentation(PLASTIC, 1.0, 0.006, options=SolverOptions(penalty=100.0, predictor="secant"),
                             **kw)
    assert abs(secant.F[-1] / res.F[-1] - 1) < 5e-3


def test_two_body_penalty_tangent_keeps_one_pattern_per_zone():
    """The two-body penalty tangent on its fixed superset pattern: one symbolic analysis per
    contact zone (about a dozen per run, against one per new contact pair on the growing pattern),
    numeric updates otherwise, and the growing pattern's answers to round-off (both taking the
    LDLᵀ of a tangent Cholesky refuses: the growing pattern has no definite substitute)."""
    from spherecontact.fem.twobody import TwoBodySolver

    runs = {}
    for fixed in (True, False):
        solver = TwoBodySolver(PLASTIC, 1.0, Material(E=600.0, nu=0.3, sigma_y=1.0), 1.0, density=0.5,
                               options=SolverOptions(penalty=100.0))
        solver.fixed_pattern = fixed
        solver.curvature_substitute = False
        solver.contact_predictor = False  # the growing pattern has no stored factors to update
        runs[fixed] = (solver, solver.run(0.004))
    solver, res = runs[True]
    t, t_old = res.timings, runs[False][1].timings
    assert res.status == "converged" and t["linear_fallback"] == 0
    assert 1 <= solver.pattern_builds <= 12
    assert t["linear_cholesky_fresh"] == solver.pattern_builds
    assert t["linear_cholesky_update"] >= 10 * t["linear_cholesky_fresh"]
    assert t_old["linear_ldl_fresh"] >= 2 * t["linear_cholesky_fresh"]
    assert t["newton_iterations"] == t_old["newton_iterations"]
    for key in ("F", "a", "h1", "h2"):
        old = runs[False][1].curves[key]
        np.testing.assert_allclose(res.curves[key], old, rtol=0, atol=1e-9 * np.abs(old).max())


def test_two_body_penalty_definite_substitute_changes_the_steps_not_the_answers():
    """Where Cholesky refuses the pair's tangent, the tangent less its master-curvature part is
    solved instead (``curvature_substitute``): the run uses it, and every increment converges to
    the answers of the run that takes LDLᵀ of the full tangent there."""
    from spherecontact.fem.twobody import TwoBodySolver

    runs = {}
    for substitute in (True, False):
        solver = TwoBodySolver(PLASTIC, 1.0, Material(E=600.0, nu=0.3, sigma_y=1.0), 1.0, density=0.5,
                               options=SolverOptions(penalty=100.0))
        solver.curvature_substitute = substitute
        solver.contact_predictor = False  # with it this short run meets no tangent Cholesky refuses
        runs[substitute] = solver.run(0.004)
    new, old = runs[True], runs[False]
    assert new.timings["linear_substitute"] > 0 and old.timings["linear_substitute"] == 0
    assert old.timings["linear_ldl_update"] + old.timings["linear_ldl_fresh"] > 0
    assert new.h.size == old.h.size
    for key in ("F", "a", "h1", "h2"):
        np.testing.assert_allclose(new.curves[key], old.curves[key], rtol=0,
                                   atol=1e-8 * np.abs(old.curves[key]).max())
