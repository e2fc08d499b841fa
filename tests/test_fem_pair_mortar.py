"""Penalty mortar contact of two bodies (twobody.MortarContactPass, ``segment_scheme`` "mortar")."""

import warnings

import numpy as np
import pytest

from spherecontact.fem.solver import SolverOptions
from spherecontact.fem.twobody import ContactPass, MortarContactPass, SegmentPairWarning, TwoBodySolver
from spherecontact.model.material import Material

SOFT, STIFF = Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=600.0, nu=0.3, sigma_y=1.0)


def _pressed(options: SolverOptions, h: float = 2e-3):
    """The pair E₂ = 3E₁, R₂ = 2R₁ and u: body 1 moved down by h, rigidly."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SegmentPairWarning)
        s = TwoBodySolver(SOFT, 1.0, STIFF, 2.0, options=options)
    b1 = s.bodies[0]
    u = np.zeros(s.n_dofs)
    u[b1.offset + 1:b1.offset + b1.n_dofs:2] = -h
    return s, u


def test_mortar_is_one_pass_of_the_softer_body_on_the_growing_pattern():
    """... and warns that it biases the split of near-equal bodies towards the master."""
    with pytest.warns(SegmentPairWarning, match="split"):
        TwoBodySolver(SOFT, 1.0, STIFF, 2.0, options=SolverOptions(penalty=100.0, segment_points=2,
                                                                  segment_scheme="mortar"))
    s, _ = _pressed(SolverOptions(penalty=100.0, segment_points=2, segment_scheme="mortar"))
    (p,) = s.passes
    assert isinstance(p, MortarContactPass) and p.weight == 1.0
    assert p.slave is s.bodies[0] and s.slave is s.bodies[0]  # body 1: the lower E'
    assert not s.fixed_pattern


def test_hat_weights_are_a_positive_partition_of_the_slave_area():
    """ψ_j ≥ 0, Σ_j A_j = the edges' area, every row of M sums to 1; the pole node's quadratic
    shape function would give it no area (∫ N₀ r dr = 0 on an edge from the axis), its hat does."""
    s, _ = _pressed(SolverOptions(penalty=100.0, segment_points=2, segment_scheme="mortar"))
    p = s.passes[0]
    assert p.mortar.data.min() > 0.0
    assert p.node_area.sum() == pytest.approx(p.area0.sum(), rel=1e-13)
    reached = p.node_area > 0
    assert reached[:-1].all() and not reached[-1]  # the equator edge is no candidate
    np.testing.assert_allclose(np.asarray(p.mortar.sum(axis=1)).ravel()[reached], 1.0, rtol=1e-13)
    r = p.slave.hmesh.X[0, p.candidates[:3]]
    L = r[2]  # first edge, from the axis: ∫ψ₀ 2πr dr over [0, L/2] = 2π (L/2)²/6
    assert p.node_area[0] == pytest.approx(2 * np.pi * (L / 2) ** 2 / 6, rel=0.05)


def test_mortar_tangent_is_the_derivative_of_its_force():
    """w k_N G̃ᵀ diag(A_j) G̃ − Σ_q Λ_q ∂²g_q is −∂(Gᵀλ)/∂u (central differences); leaving out the
    points of an active node's support that carry no own pressure (what the quadratic shape
    functions' negative weights did) breaks it."""
    s, u = _pressed(SolverOptions(penalty=100.0, segment_points=2, segment_scheme="mortar"))
    p = s.passes[0]
    rng = np.random.default_rng(1)
    near = np.zeros(s.n_dofs)
    for b in s.bodies:
        nodes = b.hmesh.surface[b.hmesh.X[0, b.hmesh.surface] < 0.1]
        near[b.offset + 2 * nodes] = near[b.offset + 2 * nodes + 1] = 1.0
    d = rng.standard_normal(s.n_dofs) * near * 1e-6
    kin = p.kinematics(u)
    pen, lam, _ = p.penalty_force(kin, s.k_penalty)
    assert (p.node_gap(kin) < 0).sum() >= 20 and lam.min() >= 0.0
    K = p.penalty_tangent(kin, s.k_penalty, pen, lam, p.constraints(kin, pen, lam)[0])
    eps = 1e-3
    up, down = (p.penalty_force(p.kinematics(u + sign * eps * d), s.k_penalty)[2] for sign in (1, -1))
    fd = (up - down) / (2 * eps)
    assert np.abs(fd + K @ d).max() <= 1e-6 * np.abs(K @ d).max()


def _load_ratio(force, body, n=5):
    """Midside over neighbouring corner load per unit circumference, first ``n`` midside nodes."""
    arc = body.hmesh.surface
    q = np.abs(force[body.offset + 2 * arc + 1])[1:2 * n + 2] / body.hmesh.X[0, arc][1:2 * n + 2]
    return q[0::2][:n] / q[1::2][:n]


def _node_shares(basis, nodes_of):
    """∫ N dt per node of a long straight master (corner, midside, … alternating), summed over the
    intervals: ``nodes_of(j)`` gives interval j's control nodes in the basis' order."""
    P = np.polynomial.polynomial
    share = np.zeros(40)
    for j in range(5, 15):
        for node, row in zip(nodes_of(j), basis, strict=True):
            share[node] += P.polyval(1.0, P.polyint(row))
    return share


def test_smooth_edges_keep_the_consistent_shares_where_catmull_rom_evens_them_out():
    """Where the sawtooth of a master comes from, and its remedy. Node by node, the Catmull–Rom
    curve through all surface nodes (intervals node to node) gives every node the same share of
    a uniform pressure; the quadratic edge's consistent shares are 1/6, 2/3, 1/6 of an edge (a
    corner, shared by two edges, 1/3, a midside 2/3). SMOOTH_EDGE keeps those and is C¹."""
    from spherecontact.fem.segments import CATMULL_ROM, SMOOTH_EDGE, _shape

    cr = _node_shares(CATMULL_ROM, lambda j: (j - 1, j, j + 1, j + 2))  # interval = half an edge
    np.testing.assert_allclose(cr[8:14], 1.0, atol=1e-12)  # every node one interval's worth
    smooth = _node_shares(SMOOTH_EDGE, lambda j: (2 * j - 2, 2 * j, 2 * j + 2, 2 * j - 1, 2 * j + 1,
                                                  2 * j + 3, 2 * j + 4))  # interval = an edge
    np.testing.assert_allclose(smooth[14:22:2], 1.0 / 3.0, atol=1e-12)  # corners
    np.testing.assert_allclose(smooth[15:22:2], 2.0 / 3.0, atol=1e-12)  # midsides
    # through the edge's nodes at t = 0, ½, 1, and the same tangent on both sides of a corner
    np.testing.assert_allclose(_shape(np.array([0.0, 0.5, 1.0]), SMOOTH_EDGE)[[1, 4, 2]], np.eye(3),
                               atol=1e-12)
    nodes = np.random.default_rng(0).standard_normal((11, 2))
    D = np.array([np.polynomial.polynomial.polyder(r) for r in SMOOTH_EDGE])

    def tangent(e, t):
        idx = [2 * e - 2, 2 * e, 2 * e + 2, 2 * e - 1, 2 * e + 1, 2 * e + 3, 2 * e + 4]
        return (D @ t ** np.arange(D.shape[1])) @ nodes[idx]
    np.testing.assert_allclose(tangent(2, 1.0), tangent(3, 0.0), atol=1e-12)


@pytest.mark.parametrize("smooth, ratio", [(False, 1.0), (True, 1.8)])
def test_the_master_takes_the_loads_its_curve_gives(smooth, ratio):
    """On the pressed pair the slave's quadratic edges take their consistent loads (midside twice a
    corner's share per unit circumference), the master what its curve gives: the same share per
    node on the Catmull–Rom curve, near the consistent ones on SMOOTH_EDGE (1.8: the pressure
    falls off towards the edge)."""
    s, u = _pressed(SolverOptions(penalty=100.0, segment_points=2, segment_scheme="mortar"))
    p = MortarContactPass(s.bodies[0], s.bodies[1], s.n_dofs, 1.0, 2, smooth_edges=smooth)
    force = p.penalty_force(p.kinematics(u), s.k_penalty)[2]
    np.testing.assert_allclose(_load_ratio(force, p.slave), 2.0, atol=0.05)
    np.testing.assert_allclose(_load_ratio(force, p.master)[1:], ratio, atol=0.05)


def test_elastic_mortar_pair_is_hertz_and_splits_as_hertz_with_either_body_as_slave():
    """The elastic pair E₂ = 3E₁, R₂ = 2R₁ (approach-scaled penalty, default mesh) to h = 2e-3:
    with the solver's slave (the softer body) F against the contact radius is Hertz's with E*, R*
    within 1.5 %; with either body as slave the split is the elastic E₂'/(E₁' + E₂') within 1
    point (0.55 at most, nodal contact 0.3). F(h) with the stiffer body as slave lies up to 1.3 %
    below (contact 3–6 surface nodes wide: its master, the soft body, takes the Catmull–Rom loads
    of the test above)."""
    m1, m2 = Material.elastic(E=200.0, nu=0.3), Material.elastic(E=600.0, nu=0.2)
    opts = SolverOptions(penalty=3000.0, penalty_scale="approach", segment_points=2, segment_scheme="mortar")
    runs = []
    for which in (0, 1):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SegmentPairWarning)
            s = TwoBodySolver(m1, 1.0, m2, 2.0, options=opts)
        if which == 1:  # the stiffer body's weighted gaps
            s.slave, s.master = s.bodies[1], s.bodies[0]
            s.passes = [MortarContactPass(s.slave, s.master, s.n_dofs, 1.0, 2)]
            s.contact = ContactPass(s.slave, s.master, s.n_dofs, 1.0)
            s.candidates = s.contact.candidates
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            runs.append(s.run(2e-3))
    run, other = runs
    assert run.status == other.status == "converged"
    Es = 1.0 / (1.0 / m1.E_prime + 1.0 / m2.E_prime)
    a = run.curves["a_ref"]
    sel = a >= 0.02
    assert sel.sum() >= 5
    assert np.abs(run.F[sel] / (4 * Es * a[sel] ** 3 / (3 * 2.0 / 3.0)) - 1).max() < 0.015
    elastic = m2.E_prime / (m1.E_prime + m2.E_prime)
    for r in runs:
        late = r.h > 5e-4
        assert np.abs(r.curves["h1"][late] / r.h[late] - elastic).max() < 0.01
    late = run.h > 5e-4
    assert np.abs(np.interp(run.h[late], other.h, other.F) / run.F[late] - 1).max() < 0.015


@pytest.mark.parametrize("kw, words", [
    ({"penalty": 100.0, "segment_points": 2, "segment_scheme": "dual"}, "segment_scheme"),
    ({"penalty": 100.0, "segment_scheme": "mortar"}, "segment_points"),
])
def test_bad_segment_schemes_are_named(kw, words):
    with pytest.raises(ValueError, match=words):
        SolverOptions(**kw).validate()


def test_a_rigid_obstacle_refuses_the_mortar_scheme():
    from spherecontact.fem.solver import IndentationSolver

    with pytest.raises(ValueError, match="segment_scheme 'mortar' is for two deformable bodies"):
        IndentationSolver(SOFT, options=SolverOptions(penalty=100.0, segment_points=2,
                                                      segment_scheme="mortar"))


def test_pair_contacts_builds_the_five_discretisations_and_reads_the_split():
    """``fem.pair_contacts``: the passes of each contact, and one short run's figures."""
    from fem_pair_contacts import CONTACTS, Scene, pair_solver, run_one

    from spherecontact.fem.segments import CATMULL_ROM, SMOOTH_EDGE
    from spherecontact.fem.twobody import SegmentContactPass

    scene = Scene("near-equal", 210.0, 1.0, 0.0, 0.011)
    kinds = {}
    for c in CONTACTS:
        s = pair_solver(scene, c)
        kinds[c] = ([type(p) for p in s.passes], s.passes[0].slave is s.bodies[0],
                    s.slave is s.passes[0].slave)
    assert kinds["nodal"][0] == [ContactPass, ContactPass]
    assert kinds["points"][0] == [SegmentContactPass, SegmentContactPass]
    assert kinds["mortar"][0] == [MortarContactPass] and kinds["mortar"][1]  # body 1: the lower E'
    assert kinds["mortar, other slave"][0] == [MortarContactPass] and not kinds["mortar, other slave"][1]
    assert kinds["mortar, Catmull-Rom master"][0] == [MortarContactPass]
    assert pair_solver(scene, "mortar, Catmull-Rom master").passes[0].basis is CATMULL_ROM
    assert pair_solver(scene, "mortar").passes[0].basis is SMOOTH_EDGE
    assert all(k[2] for k in kinds.values())  # the records read the first pass's slave
    row = run_one(scene, "mortar, other slave")
    assert row["status"] == "converged" and row["slave"] == 2 and row["approaches"] == [0.01]
    assert abs(row["split"][0] - 0.512) < 0.005  # elastic–plastic start: near E2'/(E1' + E2') = 0.512
    assert row["surfaces"]["mesh_matches"] and row["surfaces"]["body1"]["nodes"] >= 10
