"""Contact patch of a sphere node set against a rigid flat: contact radius, area, extent.

Nodal exact contact closes whole nodes, so the set of closed nodes jumps by an element as the
patch grows. The sub-element estimate of :func:`.contact.contact_edge` in 3D: near the edge of a
frictionless contact the gap opens as g ≈ C (ρ − a)^{3/2} (Johnson 1985, §4.2), ρ the current
distance of a surface node from the contact's axis. Per azimuthal sector of the patch, C and a
are fitted by least squares (C eliminated in closed form, a on a grid of
:data:`EDGE_GRID` values) to the gaps of the open surface nodes with ρ < ρ_c + ``EDGE_BAND`` s,
ρ_c the largest ρ of a closed node of the sector and s the length of the surface edges that
join a closed and an open node; a is searched in [ρ_c − s, ρ_c + s]. The patch's area is
A = Σ_sectors ½ a_s² Δθ_s × multiplicity, its extent min/max a_s, and a = √(A/π).
"""

from __future__ import annotations

import numpy as np

#: azimuthal sectors of the octant's part of a patch (a quarter or a half of it)
SECTORS = 6
#: open nodes within this many edge lengths beyond the closed ones enter the edge fit
EDGE_BAND = 3.0
EDGE_GRID = 201
#: exponents p of the gap's opening g ≈ C (ρ − a)^p the fit may take: 1 (a plastic edge, the
#: surface leaving the flat at an angle) to 2, as ``contact.EDGE_FITS["fitted"]``
EDGE_EXPONENTS = tuple(np.linspace(1.0, 2.0, 21))


def _edge_fit(rho: np.ndarray, gap: np.ndarray, sector: np.ndarray, lo: np.ndarray,
              hi: np.ndarray, exponents=None) -> np.ndarray:
    """Per sector s, the a in [lo_s, hi_s] (and p of ``exponents``) of the least-squares
    g ≈ C (ρ − a)^p over the points of that sector (arrays ``rho``, ``gap``, ``sector``)."""
    exponents = EDGE_EXPONENTS if exponents is None else exponents
    t = np.linspace(0.0, 1.0, EDGE_GRID)
    a = lo[:, None] + (hi - lo)[:, None] * t[None, :]  # (S, G)
    n_s = lo.size
    gg = np.bincount(sector, weights=gap * gap, minlength=n_s)
    best = np.full(n_s, np.inf)
    a_best = 0.5 * (lo + hi)
    d = np.maximum(rho[:, None] - a[sector], 0.0)  # (n, G)
    for p in exponents:  # a few exponents, once per increment
        f = d**p
        ff = np.zeros((n_s, EDGE_GRID))
        fg = np.zeros((n_s, EDGE_GRID))
        np.add.at(ff, sector, f * f)
        np.add.at(fg, sector, f * gap[:, None])
        miss = gg[:, None] - np.where(ff > 0, fg * fg / np.where(ff > 0, ff, 1.0), 0.0)
        j = np.argmin(miss, axis=1)
        m = miss[np.arange(n_s), j]
        better = m < best
        best = np.where(better, m, best)
        a_best = np.where(better, a[np.arange(n_s), j], a_best)
    return a_best


def patch_measures(x: np.ndarray, surface: np.ndarray, surface_edges: np.ndarray,
                   closed: np.ndarray, normal: np.ndarray, offset: float, multiplicity: float):
    """Contact radius, area and extent of one patch (module docstring).

    Parameters
    ----------
    x : (3, n_nodes) current positions.
    surface : indices of the sphere's surface nodes near the patch.
    surface_edges : (2, m) node pairs of the sphere's surface edges.
    closed : (n_nodes,) bool, the nodes closed on this flat.
    normal, offset : the flat n · x = offset.
    multiplicity : 2^(symmetry planes through the pole), the patch pieces the octant holds 1 of.

    Returns
    -------
    dict with a (√(A/π)), A, a_min, a_max (extent over the sectors), a_nodes (largest ρ of a
    closed node).
    """
    out = {"a": 0.0, "A": 0.0, "a_min": 0.0, "a_max": 0.0, "a_nodes": 0.0}
    if not np.any(closed[surface]):
        return out
    n = np.asarray(normal, dtype=float)
    xs = x[:, surface]
    inplane = xs - np.outer(n, n @ xs)
    rho = np.linalg.norm(inplane, axis=0)
    e1, e2 = plane_axes(n)
    theta = np.arctan2(e2 @ inplane, e1 @ inplane)  # in [0, 2π/multiplicity] in the octant
    c = closed[surface]
    width = 2 * np.pi / multiplicity / SECTORS
    sec = np.clip(np.floor((theta + 1e-12) / width), 0, SECTORS - 1)
    sec = sec.astype(np.int64)
    rho_c = np.zeros(SECTORS)
    np.maximum.at(rho_c, sec[c], rho[c])
    e_cl = closed[surface_edges]
    mixed = e_cl[0] != e_cl[1]
    s = (np.mean(np.linalg.norm(x[:, surface_edges[0, mixed]] - x[:, surface_edges[1, mixed]], axis=0))
         if np.any(mixed) else 0.0)
    a_nodes = float(rho[c].max())
    rho_c = np.where(rho_c > 0, rho_c, a_nodes)
    gap = offset - n @ xs
    use = (~c) & (rho < rho_c[sec] + EDGE_BAND * s)
    lo = np.maximum(rho_c - s, 0.0)
    hi = rho_c + s
    if s > 0 and np.any(use):
        a_s = _edge_fit(rho[use], np.maximum(gap[use], 0.0), sec[use], lo, hi)
        has = np.bincount(sec[use], minlength=SECTORS) >= 2
        a_s = np.where(has, a_s, rho_c)
    else:
        a_s = rho_c
    A = multiplicity * 0.5 * width * float(np.sum(a_s**2))
    out.update(a=float(np.sqrt(A / np.pi)), A=A, a_min=float(a_s.min()), a_max=float(a_s.max()),
               a_nodes=a_nodes)
    return out


def plane_axes(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two in-plane unit axes (e1, e2) of a flat whose normal ``n`` has a zero component j:
    e2 = e_j, e1 = e_j × n (n = e_m: e1 = e_{m+1}, e2 = e_{m+2}). The octant's piece of the
    patch then lies at azimuths atan2(x·e2, x·e1) in [0, 2π/multiplicity]."""
    zero = np.flatnonzero(np.abs(n) < 1e-12)
    nz = np.flatnonzero(np.abs(n) >= 1e-12)
    if nz.size == 1:
        m = int(nz[0])
        return np.eye(3)[(m + 1) % 3], np.eye(3)[(m + 2) % 3]
    e2 = np.eye(3)[zero[-1]]
    return np.cross(e2, n), e2
