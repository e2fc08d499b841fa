"""Two deformable spheres: gap derivatives, scene choice, bad pairs, Hertz with E*, R*."""

import math
from pathlib import Path

import numpy as np
import pytest
from _meshes import smallest_surface_element

from spherecontact.fem import segments
from spherecontact.fem.io import choose_scene, read_run, run_indentation, write_run
from spherecontact.fem.segments import gap_gradient, gap_hessian
from spherecontact.model.material import Material

STEEL = Material(E=200.0, nu=0.3, sigma_y=1.0, K=0.0, n=1.0)


def _arc_pairs(n=6, seed=0):
    """Slave points near a unit circle (centre (0, −1)) and four control points on it."""
    rng = np.random.default_rng(seed)
    th = np.array([0.05, 0.1, 0.15, 0.2])
    P = np.stack([np.sin(th), np.cos(th) - 1.0])
    C = np.zeros((10, n))
    for k in range(4):
        C[2 + 2 * k:4 + 2 * k] = P[:, k:k + 1]
    C[0] = rng.uniform(0.1, 0.15, n)
    C[1] = np.cos(C[0]) - 1.0 + rng.uniform(-1e-2, 1e-2, n)
    return C


def test_gap_is_the_distance_to_a_circle_master():
    C = _arc_pairs()
    gap, _, t, normal = gap_gradient(C, side=1.0)
    exact = np.hypot(C[0], C[1] + 1.0) - 1.0
    assert np.all((t > 0) & (t < 1))
    np.testing.assert_allclose(gap, exact, atol=3e-7)  # Catmull–Rom vs the true arc
    np.testing.assert_allclose(np.hypot(*normal), 1.0, rtol=1e-14)


def test_gap_gradient_and_hessian_match_finite_differences():
    C = _arc_pairs()
    gap, grad, _, _ = gap_gradient(C, 1.0)
    H = gap_hessian(C, 1.0)
    eps = 1e-6
    for j in range(10):
        Cp, Cm = C.copy(), C.copy()
        Cp[j] += eps
        Cm[j] -= eps
        fd = (gap_gradient(Cp, 1.0)[0] - gap_gradient(Cm, 1.0)[0]) / (2 * eps)
        np.testing.assert_allclose(grad[j], fd, atol=1e-8)
        fdh = (gap_gradient(Cp, 1.0)[1] - gap_gradient(Cm, 1.0)[1]) / (2 * eps)
        np.testing.assert_allclose(H[:, j], fdh, atol=1e-6)
    np.testing.assert_allclose(H, H.transpose(1, 0, 2), atol=1e-12)


def test_smooth_edge_gap_derivatives_match_finite_differences():
    """The master's quadratic edge made C¹ (segments.SMOOTH_EDGE, 7 control points): the gap is the
    distance to the circle the nodes lie on, and its gradient and complex-step Hessian are the
    finite differences of the gap and the gradient."""
    from spherecontact.fem.segments import SMOOTH_EDGE

    rng = np.random.default_rng(2)
    n = 6
    th = 0.1 + 0.02 * np.array([-2, 0, 2, -1, 1, 3, 4])  # c₋, c₀, c₁, m₋, m, m₊, c₊ along the arc
    C = np.zeros((16, n))
    for k in range(7):
        C[2 + 2 * k] = np.sin(th[k])
        C[3 + 2 * k] = np.cos(th[k]) - 1.0
    C[0] = rng.uniform(0.1, 0.14, n)
    C[1] = np.cos(C[0]) - 1.0 + rng.uniform(-1e-3, 1e-3, n)
    gap, grad, t, _ = gap_gradient(C, 1.0, SMOOTH_EDGE)
    assert np.all((t > 0) & (t < 1))
    np.testing.assert_allclose(gap, np.hypot(C[0], C[1] + 1.0) - 1.0, atol=1e-7)
    H = gap_hessian(C, 1.0, SMOOTH_EDGE)
    eps = 1e-6
    for j in range(16):
        Cp, Cm = C.copy(), C.copy()
        Cp[j] += eps
        Cm[j] -= eps
        gp, gm = gap_gradient(Cp, 1.0, SMOOTH_EDGE), gap_gradient(Cm, 1.0, SMOOTH_EDGE)
        np.testing.assert_allclose(grad[j], (gp[0] - gm[0]) / (2 * eps), atol=1e-8)
        np.testing.assert_allclose(H[:, j], (gp[1] - gm[1]) / (2 * eps), atol=1e-5)
    np.testing.assert_allclose(H, H.transpose(1, 0, 2), atol=1e-10)


def test_early_stopped_projection_equals_the_fully_iterated_one(monkeypatch):
    """The projection stops at PROJECTION_TOL; gap, gradient and complex-step Hessian are those
    of Newton iterated far past convergence to round-off, also for t outside [0, 1]."""
    C = _arc_pairs(n=40, seed=3)
    C[0] = np.linspace(0.03, 0.22, C.shape[1])  # t from about −0.4 to 1.4
    C[1] = np.cos(C[0]) - 1.0 + np.linspace(-1e-2, 1e-2, C.shape[1])
    fast = gap_gradient(C, 1.0), gap_hessian(C, 1.0)
    monkeypatch.setattr(segments, "PROJECTION_TOL", 0.0)
    monkeypatch.setattr(segments, "PROJECTION_ITERATIONS", 30)
    full = gap_gradient(C, 1.0), gap_hessian(C, 1.0)
    assert np.ptp(full[0][2]) > 1.5
    for a, b in zip(fast[0] + (fast[1],), full[0] + (full[1],), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())
    monkeypatch.undo()
    # the Hessian's perturbed projections started from the real ones: the same to round-off
    H = gap_hessian(C, 1.0, t=fast[0][2])
    np.testing.assert_allclose(H, full[1], rtol=0, atol=1e-12 * np.abs(full[1]).max())


@pytest.mark.parametrize("kw, scene", [
    ({}, "rigid_flat"),
    ({"indenter_radius": 2.0}, "rigid_sphere"),
    ({"radius2": 2.0, "material2": Material.rigid()}, "rigid_sphere"),
    ({"radius2": math.inf, "material2": Material.rigid()}, "rigid_flat"),
    ({"radius2": 1.0, "material2": STEEL}, "equal_pair_symmetry"),
    ({"radius2": 2.0, "material2": STEEL}, "two_body"),
    ({"radius2": 1.0, "material2": Material(E=600.0, nu=0.3, sigma_y=1.0, K=0.0, n=1.0)}, "two_body"),
    ({"radius2": 1.0, "material2": STEEL, "scene": "two_body"}, "two_body"),
])
def test_cheapest_exact_scene(kw, scene):
    m2 = kw.get("material2")
    assert choose_scene(STEEL, 1.0, m2, kw.get("radius2"), kw.get("indenter_radius", math.inf),
                        kw.get("scene", "auto")) == scene


@pytest.mark.parametrize("kw, words", [
    ({"radius2": -0.5}, "overlap"),
    ({"radius2": -3.0}, "concave"),
    ({"material": Material.rigid(), "material2": Material.rigid()}, "both bodies are rigid"),
    ({"radius": math.inf, "radius2": math.inf}, "two flats"),
    ({"radius2": math.inf}, "deformable flat"),
    ({"radius2": 2.0, "indenter_radius": 2.0}, "not both"),
    ({"radius2": 0.5, "h_max": 0.45}, r"0.8 min\(radius, radius2\)"),
    ({"scene": "two_body", "material2": Material.rigid()}, "deformable body 2"),
])
def test_bad_pairs_are_named_before_any_work(kw, words):
    args = {"material": STEEL, "radius": 1.0, "h_max": 0.1, **kw}
    with pytest.raises(ValueError, match=words):
        run_indentation(**args)


def test_elastic_dissimilar_pair_is_hertz_with_effective_modulus_and_radius(tmp_path):
    m1, m2 = Material.elastic(200.0, 0.3), Material.elastic(600.0, 0.2)
    res = run_indentation(m1, 1.0, 0.003, radius2=2.0, material2=m2, density=0.5)
    assert res.status == "converged" and res.inputs["scene"] == "two_body"
    c = res.curves
    Es = 1.0 / (1.0 / m1.E_prime + 1.0 / m2.E_prime)
    Rs = 2.0 / 3.0
    sel = c["a_ref"] >= 0.025  # three pole elements of the coarse mesh
    ratio = c["F"][sel] / (4 * Es * c["a_ref"][sel] ** 3 / (3 * Rs))
    assert np.abs(ratio - 1).max() < 0.025
    np.testing.assert_allclose(c["h1"] + c["h2"], c["h"], rtol=1e-10)
    target = m2.E_prime / m1.E_prime
    assert np.abs(c["h1"][sel] / c["h2"][sel] / target - 1).max() < 0.03
    # the interface bends towards the softer body 1: curvature between −1/R2 and +1/R1
    assert np.all((c["interface_curvature"][sel] < 1.0) & (c["interface_curvature"][sel] > -0.5))
    # Newton stays quadratic through the sliding interface: few iterations per increment
    assert c["iterations"].mean() < 5
    path = write_run(tmp_path / "pair.h5", res)
    run = read_run(path)
    assert run.scene == "two_body" and run.material2() == m2
    np.testing.assert_array_equal(run.h1, c["h1"])
    assert run.mesh["cells"].shape[0] == res.inputs["n_elements"]


def test_equal_pair_as_two_bodies_matches_the_symmetric_scene():
    two = run_indentation(STEEL, 1.0, 0.008, radius2=1.0, material2=STEEL, scene="two_body")
    sym = run_indentation(STEEL, 1.0, 0.008, radius2=1.0, material2=STEEL)
    assert sym.inputs["scene"] == "equal_pair_symmetry"
    np.testing.assert_allclose(two.curves["h1"], two.curves["h2"], rtol=2e-3)
    np.testing.assert_allclose(sym.curves["h1"], sym.curves["h"] / 2)
    h = two.h[two.h > 0.003]
    dF = np.interp(h, two.h, two.F) / np.interp(h, sym.h, sym.F) - 1
    # node-to-surface contact of two meshes is noisier than the symmetric scene
    assert np.sqrt(np.mean(dF**2)) < 0.01 and np.abs(dF).max() < 0.025


def test_database_pairs_table_and_the_required_pairs():
    """The pair report tabulates the v2 database's ten two-body runs with their contact and the
    largest approach reached (a run ends after its last unloading, below it): the designed pairs
    reach h/R_min 0.3, the three replaced ones their shortened h_max; the required pairs pass."""
    from fem_verification_pair import REQUIRED_PAIRS, _pairs_pass, database_pairs
    v2 = Path(__file__).resolve().parents[1] / "data" / "reference_v2.h5"
    rows = {r["case"]: r for r in database_pairs(v2)}
    assert len(rows) == 10 and all(r["status"] == "converged" and r["wall_s"] > 0 for r in rows.values())
    assert all(any(c.endswith(s) for c in rows) for s in REQUIRED_PAIRS)
    penalty = {c for c, r in rows.items() if r["contact"] != "exact one-pass"}
    assert penalty == {"two-pp-E300-nu0.3-vs-E900-f0.003", "two-pp-E300-nu0.3-vs-E99.9"}  # equal σY
    assert {rows[c]["contact"] for c in penalty} == {"two-pass penalty 3000, 3 Gauss points"}
    shortened = {"two-pp-E300-nu0.3-vs-sy2-h0.18-f0.0015": 0.18,
                 "two-pp-E200-nu0.3-vs-E600-sy1.5-h0.145-f0.0015": 0.145,
                 "two-pp-E200-nu0.3-vs-R0.333-sy2-h0.18-f0.003": 0.18}  # R_min = 0.333 for the last
    for case, r in rows.items():
        h_end = shortened.get(case, 0.3)
        # the penalty pairs' bodies sink into each other: up to 3e-5 beyond the approach asked for
        assert h_end - 1e-9 <= r["h_end_over_R_min"] <= h_end + (1e-4 if case in penalty else 1e-9), case
    assert _pairs_pass(list(rows.values()))
    assert not _pairs_pass([r for c, r in rows.items() if not c.endswith("vs-sy5")])  # one missing
    done = [{"case": f"two-x-{s}", "status": "converged", "h_end_over_R_min": 0.3} for s in REQUIRED_PAIRS]
    assert _pairs_pass(done)
    assert not _pairs_pass(done[:1])  # one required pair missing
    short = [dict(done[0]), {**done[1], "status": "stopped", "h_end_over_R_min": 0.073}, *done[2:]]
    assert not _pairs_pass(short)


def test_a_pair_on_the_surface_band_takes_its_floor_on_both_bodies():
    """band_floor reaches both meshes, in units of the smaller radius, and is recorded."""
    from spherecontact.fem.twobody import TwoBodySolver
    soft, hard = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=200.0, nu=0.3, sigma_y=2.0)
    R_min = 0.5
    fine = TwoBodySolver(soft, 1.0, hard, R_min, edge_band=0.03)
    coarse = TwoBodySolver(soft, 1.0, hard, R_min, edge_band=0.03, band_floor=0.003)
    for solver, floor in ((fine, 0.0005), (coarse, 0.003)):
        for body in solver.bodies:
            m = body.disc.hmesh
            smallest = smallest_surface_element(m)
            assert m.band_floor == floor and 0.5 * floor * R_min < smallest < 1.6 * floor * R_min
    assert coarse.n_dofs < fine.n_dofs
    res = run_indentation(soft, 1.0, 0.002, radius2=0.5, material2=hard, edge_band=0.03,
                          band_floor=0.003, density=0.5)
    assert res.status == "converged" and res.inputs["band_floor"] == 0.003
    with pytest.raises(ValueError, match="band_floor"):
        run_indentation(soft, 1.0, 0.002, radius2=0.5, material2=hard, edge_band=0.03, band_floor=1.0)


def test_the_softer_sphere_is_the_slave_of_one_pass_contact():
    """One pass: the lower yield stress, then the lower E', then the smaller sphere, body 1 on
    a tie; two passes (penalty) keep the smaller sphere."""
    from spherecontact.fem.twobody import slave_index
    soft, hard = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=200.0, nu=0.3, sigma_y=2.0)
    assert slave_index(soft, 1.0, hard, 1 / 3) == 0  # the small hard sphere is the master
    assert slave_index(hard, 1 / 3, soft, 1.0) == 1
    assert slave_index(hard, 1.0, hard, 1 / 3) == 1  # same material: the smaller sphere
    assert slave_index(soft, 1.0, soft, 1.0) == 0
    stiff = Material(E=600.0, nu=0.3, sigma_y=1.0)
    assert slave_index(stiff, 1.0, soft, 2.0) == 1  # equal yield stress: the lower E'
    el1, el2 = Material.elastic(200.0, 0.3), Material.elastic(600.0, 0.2)
    assert slave_index(el2, 1.0, el1, 2.0) == 1
    assert slave_index(soft, 1.0, hard, 1 / 3, two_pass=True) == 1


def test_hertz_check_figures_of_an_exact_and_a_perturbed_hertz_pair():
    """The Hertz check reads F(a_ref) against Hertz with E*, R* and h₁/h₂ against E'₂/E'₁:
    zero for the half-space solution itself, and the perturbation when F is 2 % high."""
    from fem_verification_pair import HERTZ_PAIR, hertz_figures
    m1, m2 = HERTZ_PAIR["material"], HERTZ_PAIR["material2"]
    Es = 1.0 / (1.0 / m1.E_prime + 1.0 / m2.E_prime)
    Rs = 1.0 / (1.0 / HERTZ_PAIR["radius"] + 1.0 / HERTZ_PAIR["radius2"])
    a = np.linspace(0.005, 0.06, 40)
    h = a**2 / Rs
    ratio = m2.E_prime / m1.E_prime  # h₁/h₂ of two half-spaces
    curves = {"a": a, "a_ref": a, "F": 4 * Es * a**3 / (3 * Rs), "h1": h * ratio / (1 + ratio),
              "h2": h / (1 + ratio)}
    run = {"curves": curves, "wall_s": 1.0, "n_dofs": 10}
    exact = hertz_figures(run)
    assert exact["F_vs_a_max_pct"] < 1e-10 and exact["h1_over_h2_dev_pct_all"] < 1e-10
    high = hertz_figures({**run, "curves": {**curves, "F": 1.02 * curves["F"]}})
    assert abs(high["F_vs_a_max_pct"] - 2.0) < 1e-9 and abs(high["F_vs_a_mean_pct"] - 2.0) < 1e-9


def test_penalty_pairs_converge_to_the_tighter_pair_tolerance():
    """Two-body penalty contact stops Newton at twobody.PENALTY_PAIR_TOL (1e-8) even when the
    options allow 1e-4: at 1e-4 the campaign's E₂ = 3E₁ pair stopped at h/R 0.17."""
    from spherecontact.fem.solver import SolverOptions
    from spherecontact.fem.twobody import PENALTY_PAIR_TOL, TwoBodySolver

    plastic = Material(E=200.0, nu=0.3, sigma_y=1.0)
    s = TwoBodySolver(plastic, 1.0, Material(E=600.0, nu=0.3, sigma_y=1.0), 1.0,
                      options=SolverOptions(penalty=100.0, tol=1e-4))
    r = s.run(0.002)
    assert r.status == "converged"
    assert r.inputs["options"]["tol"] == PENALTY_PAIR_TOL  # the run records the tolerance it used
    finals = [res[-1] for res in r.residuals if res]
    # the first increments stop at the roundoff floor of their tiny reactions (above 1e-8)
    assert len(finals) >= 10 and max(finals[5:]) <= PENALTY_PAIR_TOL < 1e-4


def test_pair_tolerance_follows_the_contact_scheme():
    """Newton's tolerance for two bodies: 1e-8 under the modulus-scaled penalty, 1e-5 under the
    approach-scaled one at the nodes or with the mortar, the one-body 1e-4 under the Gauss points;
    a tighter tolerance in the options is kept (the run records the one it used)."""
    from spherecontact.fem.solver import NEWTON_TOL, SolverOptions
    from spherecontact.fem.twobody import (
        APPROACH_PAIR_TOL,
        PENALTY_PAIR_TOL,
        POINTS_PAIR_TOL,
        TwoBodySolver,
        pair_tolerance,
    )

    approach = dict(penalty=3000.0, penalty_scale="approach")
    assert pair_tolerance(SolverOptions(penalty=100.0)) == PENALTY_PAIR_TOL == 1e-8
    assert pair_tolerance(SolverOptions(**approach)) == APPROACH_PAIR_TOL == 1e-5
    assert pair_tolerance(SolverOptions(**approach, segment_points=3, segment_scheme="mortar")) == 1e-5
    assert pair_tolerance(SolverOptions(**approach, segment_points=3)) == POINTS_PAIR_TOL == NEWTON_TOL
    plastic = Material(E=200.0, nu=0.3, sigma_y=1.0)
    for tol, used in ((1e-3, POINTS_PAIR_TOL), (1e-6, 1e-6)):
        s = TwoBodySolver(plastic, 1.0, plastic, 1.0, density=0.5,
                          options=SolverOptions(**approach, segment_points=3, tol=tol))
        assert s.options.tol == used
