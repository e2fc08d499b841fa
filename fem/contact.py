"""Frictionless node-to-rigid-surface contact: gaps, normals, pressure, contact edge.

Obstacles are rigid spheres of radius R₂ with centre (0, −R₂), touching the
undeformed pole at the origin; R₂ = ∞ is the flat z = 0. For a surface node at
current position x:

    g = |x − c| − R₂,   n = (x − c)/|x − c|,   curvature 1/|x − c|   (sphere)
    g = z,              n = e_z,               curvature 0            (flat)

Active nodes carry g = 0 exactly (the normal displacement is prescribed in a
nodal normal/tangential frame), inactive ones carry no force: a Lagrange
multiplier method without any penalty number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar


@dataclass(frozen=True)
class RigidObstacle:
    """Rigid sphere of radius ``radius`` below the body (``math.inf``: flat)."""

    radius: float = np.inf

    def __post_init__(self):
        if not (self.radius > 0):
            raise ValueError(f"indenter radius must be > 0 (inf for a flat), got {self.radius!r}")

    @property
    def is_flat(self) -> bool:
        return bool(np.isinf(self.radius))

    def gap_normal(self, x: np.ndarray):
        """Gap g (n,), outward normal of the obstacle n (2, n), curvature (n,) at points x (2, n)."""
        if self.is_flat:
            normal = np.zeros_like(x)
            normal[1] = 1.0
            return x[1].copy(), normal, np.zeros(x.shape[1])
        d = np.stack([x[0], x[1] + self.radius])
        dist = np.hypot(d[0], d[1])
        return dist - self.radius, d / dist, 1.0 / dist


def surface_areas(x_surf: np.ndarray) -> np.ndarray:
    """Lumped axisymmetric areas A_i = ∫ N_i 2π r ds of the surface nodes.

    ``x_surf``: (2, n) current positions of the arc nodes in order, corner and
    midside nodes alternating (3-node quadratic edges); 3-point Gauss per edge.
    """
    n = x_surf.shape[1]
    xi = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
    w = np.array([5 / 9, 8 / 9, 5 / 9])
    N = np.stack([xi * (xi - 1) / 2, 1 - xi**2, xi * (xi + 1) / 2])  # (3 nodes, 3 points)
    dN = np.stack([xi - 0.5, -2 * xi, xi + 0.5])
    idx = np.arange(0, n - 2, 2)[:, None] + np.arange(3)[None, :]  # (n_edges, 3)
    xe = x_surf[:, idx]  # (2, n_edges, 3)
    xq = np.einsum("cea,ap->cep", xe, N)
    dxq = np.einsum("cea,ap->cep", xe, dN)
    jac = np.hypot(dxq[0], dxq[1])
    contrib = np.einsum("ap,ep,p->ea", N, 2 * np.pi * xq[0] * jac, w)
    return np.bincount(idx.ravel(), weights=contrib.ravel(), minlength=n)


#: open nodes beyond the last closed one used in the contact-edge fit
EDGE_FIT_NODES = 6
#: the exponents p of the gap's opening g ≈ C (r − a)^p an edge fit may take: "hertz", 3/2 (an
#: elastic edge; the stored databases' contact radius); "fitted", chosen from 1 (a plastic edge,
#: where the surface leaves the counterface at an angle) through 3/2 to 2 (a conforming one)
EDGE_FITS = {"hertz": (1.5,), "fitted": tuple(np.linspace(1.0, 2.0, 41))}
#: contact radii tried per exponent across the node interval before the chosen one is polished
EDGE_GRID = 64


def _edge_misfit(rr: np.ndarray, gg: np.ndarray, a: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Least-squares misfit of g ≈ C (r − a)^p to the gaps gg at rr, C eliminated (closed form),
    for every a and p (broadcast against each other)."""
    f = np.maximum(rr - a[..., None], 0.0) ** p[..., None]
    ff = np.einsum("...k,...k->...", f, f)
    c = np.einsum("...k,k->...", f, gg) / np.where(ff > 0, ff, 1.0)
    res = c[..., None] * f - gg
    return np.einsum("...k,...k->...", res, res)


def _polished_edge(rr: np.ndarray, gg: np.ndarray, bounds: tuple[float, float], p: float, hi: float) -> float:
    """The a in ``bounds`` that minimises the misfit of C (r − a)^p (bounded Brent)."""
    def misfit(a):
        f = np.maximum(rr - a, 0.0) ** p
        c = np.dot(f, gg) / np.dot(f, f)
        return np.sum((c * f - gg) ** 2)

    return float(minimize_scalar(misfit, bounds=bounds, method="bounded", options={"xatol": 1e-10 * hi}).x)


def contact_edge(r_ref: np.ndarray, r_cur: np.ndarray, gap: np.ndarray, active: np.ndarray,
                 fit: str = "hertz"):
    """Contact radius: node-based and sub-element estimates.

    Near the edge of a frictionless contact the gap opens as g ≈ C (r − a)^p: p = 3/2 at an
    elastic edge (Hertz; Johnson 1985, §4.2), p → 1 where the material at the edge flows
    plastically and the free surface leaves the counterface at an angle. The sub-element
    estimate fits C and a (and, with ``fit`` "fitted", p from :data:`EDGE_FITS`) by least
    squares to the gaps of the first ``EDGE_FIT_NODES`` open nodes, with a bounded between the
    last closed and the first open node, in the reference coordinates of the surface nodes (for
    an elastic sphere 0.2 % scatter in a at a/R = 0.02–0.06 on the default mesh). The deformed
    radius is interpolated at the same fraction.

    With p held at 3/2 ("hertz", the default and the stored databases' estimate) a plastic
    edge's fit spans a length that halves with the mesh and pulls a back towards the last
    closed node: the standard run's a at h/R 0.05 lay 0.85 % below the 2× mesh's on the same
    approaches. With p fitted (1.1 there, 1.5 on an elastic sphere) 0.19 %, and a reads 0.4–0.6 %
    higher than the "hertz" fit on the campaigns' surface-band mesh (fem/README.md, "Contact
    radius").

    Returns (a_nodes, a, a_ref): deformed radius of the outermost closed node,
    the deformed sub-element radius and its reference-configuration radius
    (the linear-theory contact radius, comparable with Hertz).
    """
    if fit not in EDGE_FITS:
        raise ValueError(f"fit must be one of {', '.join(map(repr, EDGE_FITS))}, got {fit!r}")
    idx = np.flatnonzero(active)
    if idx.size == 0:
        return 0.0, 0.0, 0.0
    k = idx.max()
    a_nodes = float(r_cur[k])
    stop = min(k + 1 + EDGE_FIT_NODES, r_ref.size)
    if stop - (k + 1) < 2:
        return a_nodes, a_nodes, float(r_ref[k])
    rr = r_ref[k + 1:stop]
    gg = np.maximum(gap[k + 1:stop], 0.0)
    lo, hi = float(r_ref[k]), float(r_ref[k + 1])
    top = hi * (1 - 1e-12) + lo * 1e-12
    exponents = EDGE_FITS[fit]
    if len(exponents) == 1:
        a_ref = _polished_edge(rr, gg, (lo, top), exponents[0], hi)
    else:  # the best (p, a) of a grid, then a polished at that p between the grid's neighbours
        grid = np.linspace(lo, top, EDGE_GRID)
        miss = _edge_misfit(rr, gg, grid[None, :], np.asarray(exponents)[:, None])
        ip, ia = np.unravel_index(np.argmin(miss), miss.shape)
        a_ref = _polished_edge(rr, gg, (grid[max(ia - 1, 0)], grid[min(ia + 1, EDGE_GRID - 1)]),
                               exponents[ip], hi)
    frac = (a_ref - lo) / (hi - lo)
    a_cur = float(r_cur[k] + frac * (r_cur[k + 1] - r_cur[k]))
    return a_nodes, a_cur, a_ref


def smooth_contact_radius(h: np.ndarray, a_raw: np.ndarray, half_window: int = 3) -> np.ndarray:
    """Contact radius smoothed over neighbouring increments.

    Nodal contact on quadratic edges makes the per-increment sub-element
    estimate alternate with the parity (corner/midside) of the outermost
    closed node: ±0.2 % rms scatter in a for an elastic sphere, while F(h) is
    smooth to 0.02 %. Under monotone loading a(h) is smooth and locally a power
    law (a ∝ h^½ in Hertz and in the self-similar plastic regime), so each a is
    replaced by the value at its own h of a local straight-line least-squares
    fit of ln a against ln h over ``2 half_window + 1`` increments (one-sided at
    the ends). Increments with a = 0 are neither used nor changed.
    """
    h = np.asarray(h, dtype=float)
    a_raw = np.asarray(a_raw, dtype=float)
    out = a_raw.copy()
    idx = np.flatnonzero((a_raw > 0) & (h > 0))
    n = idx.size
    if n < 3:
        return out
    x, y = np.log(h[idx]), np.log(a_raw[idx])
    for j in range(n):
        lo = max(0, min(j - half_window, n - 2 * half_window - 1))
        hi = min(n, lo + 2 * half_window + 1)
        slope, icpt = np.polyfit(x[lo:hi] - x[j], y[lo:hi], 1)
        out[idx[j]] = np.exp(icpt)
    return out
