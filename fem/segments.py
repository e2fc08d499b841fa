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

The Catmull–Rom basis gives every master node the same share of a uniform pressure; the
quadratic edge's consistent shares are 1/6, 2/3, 1/6 of an edge, so a master loaded through
it has its corner nodes pressed in and grows a corner/midside sawtooth. :data:`SMOOTH_EDGE`
is the alternative the mortar contact uses: one master edge (two corners, a midside) per
interval, made C¹ through its corners with the neighbouring edges' nodes, seven control points,
the consistent shares kept. Any basis of polynomials in t works the same way (``basis``).
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


#: Catmull–Rom basis as polynomials in t: N_k(t) = Σ_j CATMULL_ROM[k, j] t^j
CATMULL_ROM = 0.5 * np.array([[0.0, -1.0, 2.0, -1.0],
                              [2.0, 0.0, -5.0, 3.0],
                              [0.0, 1.0, 4.0, -3.0],
                              [0.0, 0.0, -1.0, 1.0]])


def _smooth_edge_basis() -> np.ndarray:
    """:data:`SMOOTH_EDGE`: the quadratic edge plus two quintic-times-t terms that set both corner
    tangents to the mean of the two adjacent edges' (so the curve is C¹ through the corners)
    and integrate to zero over the edge (so a uniform pressure keeps the edge's consistent loads).
    """
    P = np.polynomial.polynomial
    t = np.array([0.0, 1.0])
    L0, L1, L2 = np.array([1.0, -3.0, 2.0]), np.array([0.0, 4.0, -4.0]), np.array([0.0, -1.0, 2.0])
    # α(t) = t (1 − 2t)(1 − t)² (1 + 7t²): zero at t = 0, ½, 1; α'(0) = 1, α'(1) = 0, ∫α = 0
    alpha = P.polymul(P.polymul(P.polymul(t, [1.0, -2.0]), [1.0, -2.0, 1.0]), [1.0, 0.0, 7.0])
    beta = -_reflect(alpha)  # β(t) = −α(1 − t): β'(0) = 0, β'(1) = 1, ∫β = 0
    rows = [0.5 * alpha,                                  # corner before (c₋)
            P.polyadd(P.polyadd(L0, 3 * alpha), -0.5 * beta),   # corner 0
            P.polyadd(P.polyadd(L2, 0.5 * alpha), -3 * beta),   # corner 1
            -2 * alpha,                                   # midside before (m₋)
            P.polyadd(P.polyadd(L1, -2 * alpha), 2 * beta),     # midside
            2 * beta,                                     # midside after (m₊)
            -0.5 * beta]                                  # corner after (c₊)
    out = np.zeros((7, 7))
    for k, r in enumerate(rows):
        out[k, :len(r)] = r
    return out


def _reflect(c: np.ndarray) -> np.ndarray:
    """Coefficients of p(1 − t) from those of p(t)."""
    P = np.polynomial.polynomial
    out = np.zeros(1)
    for j, cj in enumerate(c):
        out = P.polyadd(out, cj * P.polypow([1.0, -1.0], j))
    return out


#: the master's quadratic edge made C¹ (:func:`_smooth_edge_basis`), control points [c₋, c₀, c₁,
#: m₋, m, m₊, c₊] (the edge's corners c₀, c₁ and midside m, the neighbouring edges' midsides m₋, m₊
#: and far corners c₋, c₊): x(t) passes through c₀, m, c₁ at t = 0, ½, 1; N_k(t) = Σ_j B[k, j] t^j
#: with ∫N dt = 1/6, 2/3, 1/6 for c₀, m, c₁ and 0 for the others, the quadratic edge's consistent
#: shares. The Catmull–Rom curve gives every node the same share instead
SMOOTH_EDGE = _smooth_edge_basis()


def _shape(t, basis=CATMULL_ROM):
    """The basis (k, n) at t."""
    return basis @ np.stack([t**j for j in range(basis.shape[1])])


def _polynomial(A, t):
    """x(t), x'(t), x''(t) of the curve Σ_j A_j t^j (A: (degree + 1, 2, n)), by Horner."""
    x, dx, ddx = A[-1], 0.0 * A[-1], 0.0 * A[-1]
    for a in A[-2::-1]:
        ddx = ddx * t + 2 * dx
        dx = dx * t + x
        x = x * t + a
    return x, dx, ddx


def project(coords: np.ndarray, side: float, basis: np.ndarray = CATMULL_ROM, t0: np.ndarray | None = None):
    """Closest-point projection for a batch of (slave node, master interval) pairs.

    ``coords``: (2 + 2k, n) real or complex [x_s, P_0 … P_{k−1}]; ``side`` = ±1 picks
    the outward normal n = side · (−x'_z, x'_r)/|x'| of the master; ``basis`` (k, degree + 1):
    :data:`CATMULL_ROM` (k = 4) or :data:`SMOOTH_EDGE` (k = 7).
    Returns t (n,), g (n,), n (2, n) and N(t) (k, n).

    Newton in t starts from ``t0`` if given (the projection already made at the real
    coordinates, for the complex-step Hessian: two iterations instead of four to six), else
    from the projection on the chord P₁P₂, and evaluates the curve as x(t) = Σ_j A_j t^j (A =
    the control points times the basis, Horner).
    """
    k = basis.shape[0]
    xs = coords[0:2]
    P = coords[2:2 + 2 * k].reshape(k, 2, -1).transpose(1, 0, 2)  # (2, k, n)
    A = np.einsum("kj,ckn->jcn", basis, P)  # (degree + 1, 2, n): coefficients of t^j
    if t0 is None:
        chord = P[:, 2] - P[:, 1]
        t = np.sum((xs - P[:, 1]) * chord, axis=0) / np.sum(chord * chord, axis=0)
    else:
        t = np.asarray(t0, dtype=coords.dtype)
    for _ in range(PROJECTION_ITERATIONS):
        x, dx, ddx = _polynomial(A, t)
        d = xs - x
        step = (d[0] * dx[0] + d[1] * dx[1]) / (dx[0] * dx[0] + dx[1] * dx[1] - d[0] * ddx[0] - d[1] * ddx[1])
        t = t + step
        if (np.abs(step.real).max(initial=0.0) <= PROJECTION_TOL
                and np.abs(step.imag).max(initial=0.0) <= PROJECTION_TOL * np.abs(t.imag).max(initial=0.0)):
            break
    x, dx, _ = _polynomial(A, t)
    length = np.sqrt(dx[0] * dx[0] + dx[1] * dx[1])  # analytic (no abs): complex-step safe
    normal = side * np.stack([-dx[1], dx[0]]) / length
    gap = np.sum((xs - x) * normal, axis=0)
    return t, gap, normal, _shape(t, basis)


def gap_gradient(coords: np.ndarray, side: float, basis: np.ndarray = CATMULL_ROM,
                 t0: np.ndarray | None = None):
    """g, ∂g/∂coords (2 + 2k, n), t and n for a batch of pairs (see module docstring);
    ``t0``: :func:`project`'s start."""
    t, gap, normal, N = project(coords, side, basis, t0)
    grad = np.concatenate([normal, (-N[:, None, :] * normal).reshape(2 * N.shape[0], -1)])
    return gap, grad, t, normal


def gap_hessian(coords: np.ndarray, side: float, basis: np.ndarray = CATMULL_ROM,
                t: np.ndarray | None = None) -> np.ndarray:
    """∂²g/∂coords² (2 + 2k, 2 + 2k, n) by complex-step differentiation of :func:`gap_gradient`;
    ``t``: the pairs' projections at ``coords``, where the perturbed projections start."""
    m, n = coords.shape
    pert = np.repeat(coords[:, None, :].astype(complex), m, axis=1)  # (coords, directions, n)
    pert[np.arange(m), np.arange(m), :] += 1j * CSTEP
    _, grad, _, _ = gap_gradient(pert.reshape(m, m * n), side, basis, None if t is None else np.tile(t, m))
    return grad.imag.reshape(m, m, n) / CSTEP
