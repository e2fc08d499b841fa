"""Segment-integrated penalty contact (fem/segment_penalty.py) and the surface band of the mesh."""

import math
import warnings

import numpy as np
import pytest
from _meshes import smallest_surface_element

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.mesh import EDGE_BAND_MIN, build_mesh
from spherecontact.fem.segment_penalty import SegmentPenalty
from spherecontact.fem.solver import SolverOptions
from spherecontact.metrics import interp_loglog


def _arc(n_edges: int = 6, radius: float = 1.0, span: float = 0.3):
    """Reference arc nodes of a sphere from the pole (corner/midside alternating)."""
    t = np.linspace(0.0, span, 2 * n_edges + 1)
    return np.stack([radius * np.sin(t), radius * (1 - np.cos(t))])


def test_uniform_penetration_of_a_flat_strip_gives_k_delta_area():
    """A flat disc of radius r pushed δ into a rigid flat carries k δ π r² (exact)."""
    X = np.stack([np.linspace(0.0, 0.4, 9), np.zeros(9)])
    seg = SegmentPenalty(X, k_n=50.0, n_points=4)
    _, _, _, _, force = seg.evaluate(X - np.array([[0.0], [1e-3]]), RigidObstacle())
    assert force[1].sum() == pytest.approx(50.0 * 1e-3 * np.pi * 0.4**2, rel=1e-12)
    assert np.allclose(force[0], 0.0)


@pytest.mark.parametrize("indenter", [np.inf, 0.8])
def test_tangent_blocks_are_the_derivative_of_the_force(indenter):
    X = _arc()
    seg = SegmentPenalty(X, k_n=30.0, n_points=6)
    obstacle = RigidObstacle(indenter)
    x = X.copy()
    x[1] -= 0.004 * np.cos(np.linspace(0, 1.5, X.shape[1]))  # part of the arc penetrates
    x[0] += 0.001 * np.sin(np.linspace(0, 3, X.shape[1]))
    gap, normal, curv, p, force = seg.evaluate(x, obstacle)
    assert 0 < np.count_nonzero(gap < 0) < gap.size
    blocks = seg.tangent_blocks(gap, normal, curv, p)  # ∂(−f)/∂x per edge
    K = np.zeros((x.shape[1], 2, x.shape[1], 2))
    for e, nodes in enumerate(seg.edges):
        for a in range(3):
            for b in range(3):
                K[nodes[a], :, nodes[b], :] += blocks[e, a, b]
    eps = 1e-7
    for node in range(x.shape[1]):
        for c in range(2):
            xp, xm = x.copy(), x.copy()
            xp[c, node] += eps
            xm[c, node] -= eps
            fd = -(seg.evaluate(xp, obstacle)[4] - seg.evaluate(xm, obstacle)[4]) / (2 * eps)
            assert np.allclose(K[:, :, node, c], fd.T, atol=1e-5 * np.abs(K).max())


def test_contact_radius_is_where_the_gap_of_the_points_crosses_zero():
    X = np.stack([np.linspace(0.0, 1.0, 11), np.zeros(11)])
    seg = SegmentPenalty(X, k_n=1.0, n_points=3)
    r = seg.R_q.ravel()
    gap = (r - 0.537).reshape(seg.R_q.shape)  # linear gap: crossing at 0.537
    assert seg.contact_radius(gap) == pytest.approx(0.537, rel=1e-12)
    assert seg.contact_radius(np.abs(gap) + 1.0) == 0.0


def test_bad_segment_inputs_are_named():
    with pytest.raises(ValueError, match="n_points"):
        SegmentPenalty(_arc(), 1.0, n_points=0)
    with pytest.raises(ValueError, match="penalty"):
        SolverOptions(segment_points=8).validate()
    with pytest.raises(ValueError, match="segment_points"):
        SolverOptions(penalty=10.0, segment_points=-1).validate()


def test_edge_band_keeps_the_surface_size_proportional_to_the_distance_from_the_pole():
    band = 0.03
    m = build_mesh(1.0, 1.0, edge_band=band)
    X = m.X[:, m.surface]
    ds = np.hypot(*np.diff(X, axis=1))
    d = np.concatenate([[0.0], np.cumsum(ds)])
    size = 2 * ds  # a quadratic edge spans two node gaps
    mid = 0.5 * (d[1:] + d[:-1])
    sel = (mid > 0.05) & (mid < 0.5)
    assert np.all(size[sel] / mid[sel] < 1.6 * band)
    assert np.all(size[sel] / mid[sel] > 0.5 * band)
    plain = build_mesh(1.0, 1.0)
    assert m.surface.size > 1.5 * plain.surface.size
    with pytest.raises(ValueError, match="edge_band"):
        build_mesh(1.0, 1.0, edge_band=-0.1)


def test_band_floor_sets_the_smallest_surface_element_in_units_of_the_contact_scale():
    default = build_mesh(1.0, 1.0, edge_band=0.03)
    assert default.band_floor == EDGE_BAND_MIN
    assert smallest_surface_element(default) < 2.0 * EDGE_BAND_MIN
    coarse = build_mesh(1.0, 1.0, edge_band=0.03, band_floor=0.003)
    assert 0.5 * 0.003 < smallest_surface_element(coarse) < 1.6 * 0.003
    # a smaller partner sets the contact scale: the floor scales with it
    small = build_mesh(1.0, 1.0, contact_scale=0.5, edge_band=0.03, band_floor=0.003)
    assert 0.5 * 0.0015 < smallest_surface_element(small) < 1.6 * 0.0015
    assert coarse.surface.size < default.surface.size


@pytest.mark.parametrize("floor, edge_band, message", [
    (0.01, 0.03, r"band_floor must lie in \[0.0001, 0.003\]"),
    (0.0, 0.03, "band_floor must lie in"),
    (float("nan"), 0.03, "band_floor must lie in"),
    ("thin", 0.03, "band_floor must lie in"),
    (0.002, 0.0, "needs a surface band: set edge_band > 0"),
])
def test_bad_band_floor_is_named_with_its_range(floor, edge_band, message):
    with pytest.raises(ValueError, match=message):
        build_mesh(1.0, 1.0, edge_band=edge_band, band_floor=floor)


# --------------------------------------------------------------- penalty scaled with the approach
def _flat_run(E: float, h_max: float, **options):
    from spherecontact.fem.solver import IndentationSolver
    from spherecontact.model.material import Material

    solver = IndentationSolver(Material(E=E, nu=0.3, sigma_y=1.0), 1.0, RigidObstacle(),
                               options=SolverOptions(**options))
    return solver.run(h_max)


def test_approach_scaled_penalty_presses_in_about_h_over_P_and_h_is_the_body_shortening():
    """k_N = P p_m / h: the obstacle presses into the body by about h/P at every approach; the
    stored h is the equator-to-pole shortening (h_applied − pole penetration), and F(h) stays on
    the exact contact's curve."""
    P = 300.0
    soft = _flat_run(1000.0, 2e-3, penalty=P, segment_points=8, penalty_scale="approach")
    exact = _flat_run(1000.0, 2e-3)
    c = soft.curves
    assert soft.status == "converged" and np.all(np.diff(c["h"]) > 0)
    sunk = c["h_applied"] - c["h"]  # the pole's penetration
    late = c["h_applied"] > 5e-4
    assert np.all(sunk[late] > 0.2 * c["h_applied"][late] / P)
    assert np.all(c["penetration"][late] < 3.0 * c["h_applied"][late] / P)
    F_exact = np.interp(c["h"][-1], exact.h, exact.F)
    assert c["F"][-1] == pytest.approx(F_exact, rel=0.015)  # within the exact run's node steps


def test_equal_pair_by_symmetry_doubles_the_applied_approach_and_the_penetration():
    """The equal pair runs as one hemisphere on the mid-plane: every approach of the pair is twice
    the hemisphere's, the penalty contact's h_applied and penetration included."""
    from spherecontact.fem.io import run_indentation
    from spherecontact.model.material import Material

    m = Material(E=1000.0, nu=0.3, sigma_y=1.0)
    res = run_indentation(m, 1.0, 2e-3, radius2=1.0, material2=m,
                          options=SolverOptions(penalty=300.0, segment_points=8, penalty_scale="approach"))
    c = res.curves
    assert res.inputs["scene"] == "equal_pair_symmetry" and res.status == "converged"
    assert c["h_applied"][-1] == pytest.approx(2e-3, rel=1e-12)
    late = c["h_applied"] > 1e-3
    sunk = (c["h_applied"] - c["h"])[late]  # at the pole, against the largest penetration
    assert np.allclose(sunk, c["penetration"][late], rtol=0.5, atol=0)
    assert np.all(c["penetration"][late] > 0.2 * 1e-3 / 300.0)


def test_penalty_scale_is_checked():
    with pytest.raises(ValueError, match="penalty_scale must be one of"):
        SolverOptions(penalty=1.0, penalty_scale="pressure").validate()
    with pytest.raises(ValueError, match="needs penalty contact"):
        SolverOptions(penalty_scale="approach").validate()


def test_two_bodies_take_the_approach_scaled_penalty():
    """Two deformable bodies, k_N = P p_m / h: they press into each other by about h/P, the stored
    h is h₁ + h₂ (the bodies' own shortening) and h_applied the equators' travel, and F(h) stays
    on the modulus-scaled penalty's curve (whose penetration is ~1e-4 of h)."""
    from spherecontact.fem.twobody import TwoBodySolver
    from spherecontact.model.material import Material

    P, h_max = 300.0, 3e-3
    m1, m2 = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=600.0, nu=0.3, sigma_y=1.0)
    approach = SolverOptions(penalty=P, penalty_scale="approach")
    soft = TwoBodySolver(m1, 1.0, m2, 2.0, options=approach).run(h_max)
    stiff = TwoBodySolver(m1, 1.0, m2, 2.0, options=SolverOptions(penalty=100.0)).run(h_max)
    c = soft.curves
    assert soft.status == "converged" and np.all(np.diff(c["h"]) > 0)
    assert np.allclose(c["h"], c["h1"] + c["h2"], rtol=0, atol=1e-15)
    late = c["h_applied"] > 1e-3
    assert np.all(c["penetration"][late] > 0.2 * c["h_applied"][late] / P)
    assert np.all(c["penetration"][late] < 3.0 * c["h_applied"][late] / P)
    assert "h_applied" not in stiff.curves  # the modulus-scaled penalty keeps h as applied
    F_stiff = np.interp(c["h"][-1], stiff.h, stiff.F)
    assert c["F"][-1] == pytest.approx(F_stiff, rel=0.015)


def test_two_bodies_sink_in_by_at_most_a_fraction_of_a_node_spacing():
    """The approach-scaled penalty of two bodies is bounded (twobody.APPROACH_DEPTH): with
    P = 1 (h/P = h, deeper than the pole's surface nodes are apart) the bodies still sink into
    each other by no more than about APPROACH_DEPTH × the smallest surface node spacing."""
    from spherecontact.fem import twobody
    from spherecontact.fem.twobody import TwoBodySolver
    from spherecontact.model.material import Material

    m1, m2 = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=600.0, nu=0.3, sigma_y=1.0)
    solver = TwoBodySolver(m1, 1.0, m2, 2.0, options=SolverOptions(penalty=1.0, penalty_scale="approach"))
    res = solver.run(2e-3)
    bound = twobody.APPROACH_DEPTH * solver._surface_spacing
    assert res.status == "converged" and res.curves["h_applied"][-1] > 5 * bound
    sunk = res.curves["penetration"][-1]  # at the poles, where the pressure is highest
    assert 0.5 * bound < sunk < 2.0 * bound


def test_loading_steps_keep_the_strain_increment_from_the_first_one_on():
    """dh ≤ strain_increment · a of the increment before, and the first step ≤ strain_increment² R
    (its own Hertz radius √(R dh) obeys the same bound): a step of dh_first = 2e-4 R alone crosses
    the elastic–plastic transition of E/σY = 1000 (first yield at h/R ≈ 5e-6)."""
    res = _flat_run(1000.0, 1e-3)
    c = res.curves
    eps = SolverOptions().strain_increment
    assert c["h"][0] <= eps**2 * (1 + 1e-9)
    dh = np.diff(c["h"])
    assert np.all(dh <= eps * c["a_nodes"][:-1] * (1 + 1e-9))


def test_relative_step_bounds_the_loading_increments_by_the_approach():
    """``relative_step`` r: dh ≤ r · h once in contact, on top of the strain bound (which lets a
    stiff sphere's increments reach dh ≈ 0.6 h where its contact is small); bad values are named.
    The force converges as r falls: the strain bound alone leaves F at h/R = 1e-3 (E/σY 1000)
    2.3 % below the run with r = 0.01, r = 0.1 0.5 % and r = 0.03 0.05 % (the path of the plastic
    increments across the elastic–plastic transition)."""
    for bad in (0.0, -0.1, math.inf, 11.0):
        with pytest.raises(ValueError, match="relative_step"):
            SolverOptions(relative_step=bad).validate()
    runs = {r: _flat_run(1000.0, 1e-3, **({} if r is None else {"relative_step": r})).curves
            for r in (None, 0.1, 0.03)}
    h = runs[0.1]["h"]
    assert np.all(np.diff(h)[1:] <= 0.1 * h[1:-1] * (1 + 1e-9))
    free = runs[None]["h"]
    assert np.max(np.diff(free)[1:] / free[1:-1]) > 0.3  # the bound acts
    F_end = {r: c["F"][-1] for r, c in runs.items()}
    assert abs(F_end[0.03] / F_end[0.1] - 1) < 0.3 * abs(F_end[0.1] / F_end[None] - 1)
    assert F_end[None] < F_end[0.1] < F_end[0.03]  # the coarse path is low


def test_increment_check_reports_the_largest_deviation_per_decade():
    from spherecontact.fem.increments import by_decade

    h_new = np.geomspace(1e-6, 1e-2, 200)
    F_new = h_new**1.3
    h_old = np.array([2e-6, 5e-6, 2e-5, 5e-5, 3e-4, 2e-3])
    off = np.array([-0.01, -0.03, -0.02, 0.01, 0.004, -0.001])
    d = by_decade(h_old, h_old**1.3 * np.exp(off), h_new, F_new, 1.0)
    assert set(d) == {"1e-6", "1e-5", "1e-4", "1e-3", "largest", "mean"}
    assert d["1e-6"] == pytest.approx(-0.03, abs=1e-9) and d["1e-5"] == pytest.approx(-0.02, abs=1e-9)
    assert d["1e-4"] == pytest.approx(0.004, abs=1e-9) and d["largest"] == pytest.approx(-0.03, abs=1e-9)
    # each decade's mean beside its largest: a systematic shift, not one closing node
    assert d["mean"]["1e-6"] == pytest.approx(-0.02, abs=1e-9)
    assert d["mean"]["1e-5"] == pytest.approx(-0.005, abs=1e-9)


@pytest.mark.parametrize(("flag", "value"), [("--h-end", "0.9"), ("--relative-step", "-1")])
def test_increment_check_names_a_bad_window_or_step(flag, value, capsys):
    """The re-run's end and step bound are checked before any database is read or run made."""
    from spherecontact.cli import main

    assert main(["campaign", "increments", "--db", "missing.h5", "--cases", "none", flag, value]) == 2
    assert f"{flag} must lie in" in capsys.readouterr().err


def _pressed_pair(segment_points: int, h: float = 2e-3):
    """A pair E₂ = 3E₁, R₂ = 2R₁ with penalty contact and u: body 1 moved down by h, rigidly; the
    two-pass Gauss points are the reference contact of such pairs: no SegmentPairWarning."""
    from spherecontact.fem.twobody import SegmentPairWarning, TwoBodySolver
    from spherecontact.model.material import Material

    m1, m2 = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=600.0, nu=0.3, sigma_y=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SegmentPairWarning)
        s = TwoBodySolver(m1, 1.0, m2, 2.0,
                          options=SolverOptions(penalty=100.0, segment_points=segment_points))
    b1 = s.bodies[0]
    u = np.zeros(s.n_dofs)
    u[b1.offset + 1:b1.offset + b1.n_dofs:2] = -h
    return s, u


def test_segment_contact_tangent_is_the_derivative_of_its_force():
    """Gauss points on the slave's edges (twobody.SegmentContactPass): the blocks k A ∂g ∂gᵀ − λ ∂²g,
    with ∂g/∂x_a = N_a ∂g/∂x_s, are −∂(Gᵀλ)/∂u (central differences, both passes)."""
    s, u = _pressed_pair(3)
    rng = np.random.default_rng(1)
    near = np.zeros(s.n_dofs)
    for b in s.bodies:  # a random direction on the surface nodes near the poles
        nodes = b.hmesh.surface[b.hmesh.X[0, b.hmesh.surface] < 0.1]
        near[b.offset + 2 * nodes] = near[b.offset + 2 * nodes + 1] = 1.0
    d = rng.standard_normal(s.n_dofs) * near * 1e-6
    for p in s.passes:
        kin = p.kinematics(u)
        pen, lam, _ = p.penalty_force(kin, s.k_penalty)
        assert pen.sum() >= 20 and p.point_nodes.shape[0] == 3
        dofs, normal, curvature = p.penalty_blocks(kin, s.k_penalty, pen, lam)
        Kd = np.zeros(s.n_dofs)
        np.add.at(Kd, dofs[:, None, :].repeat(dofs.shape[0], axis=1),
                  (normal + curvature) * d[dofs][None, :, :])
        eps = 1e-3

        up, down = (p.penalty_force(p.kinematics(u + sign * eps * d), s.k_penalty)[2] for sign in (1, -1))
        fd = (up - down) / (2 * eps)
        assert np.abs(fd + Kd).max() <= 1e-5 * np.abs(Kd).max()


def test_segment_contact_carries_the_load_of_nodal_contact_and_keeps_hertz():
    """The E₂ = 3E₁, R₂ = 2R₁ elastic pair with the approach-scaled penalty: the force over 3 Gauss
    points per edge is the nodal contact's within 0.5 %, F against the contact radius is Hertz's
    with E*, R* within 1.5 % (default mesh)."""
    from spherecontact.fem.twobody import SegmentPairWarning, TwoBodySolver
    from spherecontact.model.material import Material

    m1, m2 = Material.elastic(E=200.0, nu=0.3), Material.elastic(E=600.0, nu=0.2)
    runs = {}
    for n in (0, 3):
        opts = SolverOptions(penalty=3000.0, penalty_scale="approach", segment_points=n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SegmentPairWarning)
            runs[n] = TwoBodySolver(m1, 1.0, m2, 2.0, options=opts).run(2e-3)
    nodal, seg = runs[0], runs[3]
    assert seg.status == "converged"
    # the runs step differently (segment contact's step reads each body's share): compare in
    # ln F against ln h, where Hertz's F ∝ h^1.5 is straight
    F_nodal = interp_loglog(seg.h, nodal.h, nodal.F)  # NaN beyond the nodal run's last approach
    late = (seg.h > 5e-4) & np.isfinite(F_nodal)
    assert late.sum() >= 5
    assert np.abs(seg.F[late] / F_nodal[late] - 1).max() < 5e-3
    Es = 1.0 / (1.0 / m1.E_prime + 1.0 / m2.E_prime)
    a = seg.curves["a_ref"]
    sel = a >= 0.02
    assert sel.sum() >= 5
    assert np.abs(seg.F[sel] / (4 * Es * a[sel] ** 3 / (3 * 2.0 / 3.0)) - 1).max() < 0.015


def test_pair_dofs_of_no_points_are_empty_blocks():
    """No penetrating point (a pair opening on unloading): empty dof and sign blocks of the right
    height, for nodal and for Gauss-point passes."""
    from spherecontact.fem.twobody import TwoBodySolver
    from spherecontact.model.material import Material

    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    nodal = TwoBodySolver(m, 1.0, m, 2.0, options=SolverOptions(penalty=100.0))
    gauss, _ = _pressed_pair(3)
    none = np.array([], dtype=int)
    for p in nodal.passes + gauss.passes:
        dofs, signs = p._pair_dofs(none, none)
        assert dofs.shape == signs.shape == (2 * (p.point_nodes.shape[0] + 4), 0)
