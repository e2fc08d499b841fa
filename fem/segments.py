"""Node-to-surface gap between a slave node and a smoothed master surface, with derivatives.

Frictionless contact of two deformable bodies (Wriggers, *Computational Contact
Mechanics*, 2nd ed. 2006, §4.1 and §9.2). The master surface between its nodes
P₁ and P₂ is the Catmull–Rom curve through the node sequence P₀ … P₃,

    x(t) = Σ_k N_k(t) P_k,   t ∈ [0, 1],
    N = ½ [−t + 2t² − t³,  2 − 5t² + 3t³,  t + 4t² − 3t³,  −t² + t³],

which interpolates every node and is C¹ across them (Padmanabhan & Laursen
2001 smooth the master for the same reason): with the plain C⁰ element edges
the normal jumps at each master node and Newton cycles whenever a slave node
sits on one, as it does for equal meshes pressed together. A slave node x_s is
projected by the closest-point condition (x_s − x(t))·x'(t) = 0 (Newton in t);
with the outward master normal n(t)

    g = (x_s − x(t))·n,      ∂g/∂x_s = n,      ∂g/∂P_k = −N_k(t) n

(the t-variation drops out at the projection). The second derivative, which
carries the curvature of the master and makes Newton quadratic, is the
complex-step derivative of that gradient (every operation here is analytic;
Squire & Trapp 1998), 10×10 per node. Coordinates are ordered
[x_s, P₀, P₁, P₂, P₃] × (r, z).
"""

from __future__ import annotations

import numpy as np

#: complex-step size
CSTEP = 1e-30
#: Newton iterations of the closest-point projection (quadratic: 1e-16 after ~4)
PROJECTION_ITERATIONS = 8


#: coordinates per pair: the slave node and four control points, (r, z) each
N_COORDS = 10


def _shape(t):
    """Catmull–Rom basis (4, n) and its first and second t-derivatives."""
    t2, t3 = t * t, t * t * t
    N = 0.5 * np.stack([-t + 2 * t2 - t3, 2 - 5 * t2 + 3 * t3, t + 4 * t2 - 3 * t3, -t2 + t3])
    dN = 0.5 * np.stack([-1 + 4 * t - 3 * t2, -10 * t + 9 * t2, 1 + 8 * t - 9 * t2, -2 * t + 3 * t2])
    ddN = 0.5 * np.stack([4 - 6 * t, -10 + 18 * t, 8 - 18 * t, -2 + 6 * t])
    return N, dN, ddN


def project(coords: np.ndarray, side: float):
    """Closest-point projection for a batch of (slave node, master interval) pairs.

    ``coords``: (10, n) real or complex [x_s, P_0, P_1, P_2, P_3]; ``side`` = ±1 picks
    the outward normal n = side · (−x'_z, x'_r)/|x'| of the master.
    Returns t (n,), g (n,), n (2, n) and N(t) (4, n).
    """
    xs = coords[0:2]
    P = coords[2:10].reshape(4, 2, -1).transpose(1, 0, 2)  # (2, 4, n)
    chord = P[:, 2] - P[:, 1]
    t = np.sum((xs - P[:, 1]) * chord, axis=0) / np.sum(chord * chord, axis=0)
    for _ in range(PROJECTION_ITERATIONS):
        N, dN, ddN = _shape(t)
        x = np.einsum("kn,ckn->cn", N, P)
        dx = np.einsum("kn,ckn->cn", dN, P)
        ddx = np.einsum("kn,ckn->cn", ddN, P)
        d = xs - x
        t = t + np.sum(d * dx, axis=0) / (np.sum(dx * dx, axis=0) - np.sum(d * ddx, axis=0))
    N, dN, _ = _shape(t)
    x = np.einsum("kn,ckn->cn", N, P)
    dx = np.einsum("kn,ckn->cn", dN, P)
    length = np.sqrt(dx[0] * dx[0] + dx[1] * dx[1])  # analytic (no abs): complex-step safe
    normal = side * np.stack([-dx[1], dx[0]]) / length
    gap = np.sum((xs - x) * normal, axis=0)
    return t, gap, normal, N


def gap_gradient(coords: np.ndarray, side: float):
    """g, ∂g/∂coords (10, n), t and n for a batch of pairs (see module docstring)."""
    t, gap, normal, N = project(coords, side)
    grad = np.concatenate([normal] + [-N[k] * normal for k in range(4)])
    return gap, grad, t, normal


def gap_hessian(coords: np.ndarray, side: float) -> np.ndarray:
    """∂²g/∂coords² (10, 10, n) by complex-step differentiation of :func:`gap_gradient`."""
    m, n = N_COORDS, coords.shape[1]
    pert = np.repeat(coords[:, None, :].astype(complex), m, axis=1)  # (coords, directions, n)
    pert[np.arange(m), np.arange(m), :] += 1j * CSTEP
    _, grad, _, _ = gap_gradient(pert.reshape(m, m * n), side)
    return grad.imag.reshape(m, m, n) / CSTEP
