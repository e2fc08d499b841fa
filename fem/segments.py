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
#: most Newton iterations of the closest-point projection
PROJECTION_ITERATIONS = 8
#: the projection stops once every Newton step in t is below this (real part) and below this
#: times the batch's largest |Im t| (imaginary part, the complex step): the error left is then
#: about its square, below round-off, for the gap, its gradient and the complex-step Hessian
#: alike; from the chord's point this takes 2–4 iterations in the pair runs
PROJECTION_TOL = 1e-10


#: coordinates per pair: the slave node and four control points, (r, z) each
N_COORDS = 10

#: Catmull–Rom basis as polynomials in t: N_k(t) = Σ_j CATMULL_ROM[k, j] t^j
CATMULL_ROM = 0.5 * np.array([[0.0, -1.0, 2.0, -1.0],
                              [2.0, 0.0, -5.0, 3.0],
                              [0.0, 1.0, 4.0, -3.0],
                              [0.0, 0.0, -1.0, 1.0]])


def _shape(t):
    """Catmull–Rom basis (4, n) at t."""
    t2, t3 = t * t, t * t * t
    return 0.5 * np.stack([-t + 2 * t2 - t3, 2 - 5 * t2 + 3 * t3, t + 4 * t2 - 3 * t3, -t2 + t3])


def project(coords: np.ndarray, side: float):
    """Closest-point projection for a batch of (slave node, master interval) pairs.

    ``coords``: (10, n) real or complex [x_s, P_0, P_1, P_2, P_3]; ``side`` = ±1 picks
    the outward normal n = side · (−x'_z, x'_r)/|x'| of the master.
    Returns t (n,), g (n,), n (2, n) and N(t) (4, n).

    Newton in t starts from the projection on the chord P₁P₂ and evaluates the curve as
    the cubic x(t) = Σ_j A_j t^j (A = the control points times :data:`CATMULL_ROM`, Horner).
    """
    xs = coords[0:2]
    P = coords[2:10].reshape(4, 2, -1).transpose(1, 0, 2)  # (2, 4, n)
    A0, A1, A2, A3 = (CATMULL_ROM.T @ P).swapaxes(0, 1)  # (2, n) each: coefficients of t^0 … t^3
    chord = P[:, 2] - P[:, 1]
    t = np.sum((xs - P[:, 1]) * chord, axis=0) / np.sum(chord * chord, axis=0)
    for _ in range(PROJECTION_ITERATIONS):
        dx = A1 + t * (2 * A2 + 3 * t * A3)
        ddx = 2 * A2 + 6 * t * A3
        d = xs - (A0 + t * (A1 + t * (A2 + t * A3)))
        step = (d[0] * dx[0] + d[1] * dx[1]) / (dx[0] * dx[0] + dx[1] * dx[1] - d[0] * ddx[0] - d[1] * ddx[1])
        t = t + step
        if (np.abs(step.real).max(initial=0.0) <= PROJECTION_TOL
                and np.abs(step.imag).max(initial=0.0) <= PROJECTION_TOL * np.abs(t.imag).max(initial=0.0)):
            break
    x = A0 + t * (A1 + t * (A2 + t * A3))
    dx = A1 + t * (2 * A2 + 3 * t * A3)
    length = np.sqrt(dx[0] * dx[0] + dx[1] * dx[1])  # analytic (no abs): complex-step safe
    normal = side * np.stack([-dx[1], dx[0]]) / length
    gap = np.sum((xs - x) * normal, axis=0)
    return t, gap, normal, _shape(t)


def gap_gradient(coords: np.ndarray, side: float):
    """g, ∂g/∂coords (10, n), t and n for a batch of pairs (see module docstring)."""
    t, gap, normal, N = project(coords, side)
    grad = np.concatenate([normal, (-N[:, None, :] * normal).reshape(8, -1)])
    return gap, grad, t, normal


def gap_hessian(coords: np.ndarray, side: float) -> np.ndarray:
    """∂²g/∂coords² (10, 10, n) by complex-step differentiation of :func:`gap_gradient`."""
    m, n = N_COORDS, coords.shape[1]
    pert = np.repeat(coords[:, None, :].astype(complex), m, axis=1)  # (coords, directions, n)
    pert[np.arange(m), np.arange(m), :] += 1j * CSTEP
    _, grad, _, _ = gap_gradient(pert.reshape(m, m * n), side)
    return grad.imag.reshape(m, m, n) / CSTEP
