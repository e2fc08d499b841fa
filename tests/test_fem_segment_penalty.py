"""Segment-integrated penalty contact (fem/segment_penalty.py) and the surface band of the mesh."""

import numpy as np
import pytest

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.mesh import build_mesh
from spherecontact.fem.segment_penalty import SegmentPenalty
from spherecontact.fem.solver import SolverOptions


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
