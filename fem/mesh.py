"""Graded quadratic mesh of one hemisphere's meridian section (docs/design.md §4).

The section is the quarter disk r ≥ 0, z ≤ R, r² + (z − R)² ≤ R²: the contact
pole at the origin, the centre at (0, R), the equatorial plane z = R. gmsh
meshes it with quadrilaterals (Frontal-Delaunay for quads, full-quad blossom
recombination) under a background size field that is finest at the pole and
fine along the whole arc, so the contact stays resolved from Hertz (a/R ≈ 0.02)
to h/R = 0.5. Second order, incomplete (8-node serendipity quads): midside nodes
lie on the true arc, so the contact surface is exact to the element's order.

gmsh instead of a hand-written mapped mesh: the quarter disk with a point-graded
and arc-graded size field has no good single structured block, and gmsh gives
all-quad meshes with guaranteed minimum quality in ~0.05 s.
"""

from __future__ import annotations

import math
import signal
import threading
from dataclasses import dataclass

import numpy as np
import skfem

#: Allowed range of the mesh-density parameter (1 = default, 2 = 2× finer).
DENSITY_RANGE = (0.25, 4.0)

# Element sizes at density 1, in units of R.
SIZE_POLE = 0.003  # within _POLE_DIST of the contact pole
SIZE_ARC = 0.02  # along the whole arc
SIZE_BULK = 0.10  # far from the arc
_POLE_DIST = 0.07  # radius of the finest zone around the pole
#: the optional surface band of ``build_mesh(edge_band=...)``: smallest size (units of the
#: contact scale), growth of the size with depth below the arc, largest allowed ratio s/d
EDGE_BAND_MIN = 0.0005
#: allowed range of a chosen smallest band size (``build_mesh(band_floor=...)``), units of the
#: contact scale: up to the default mesh's pole size
BAND_FLOOR_RANGE = (0.0001, 0.003)
EDGE_BAND_GRADING = 0.3
EDGE_BAND_MAX = 0.2
#: node order that reverses a quad's orientation, by nodes per element (corners, then midsides)
REVERSED = {4: [0, 3, 2, 1], 8: [0, 3, 2, 1, 7, 6, 5, 4]}


@dataclass(frozen=True)
class HemisphereMesh:
    """Meridian mesh of a hemisphere of radius ``radius`` (pole at origin).

    Attributes
    ----------
    mesh : skfem.MeshQuad2 (quadratic geometry, curved arc edges).
    X : (2, n_nodes) reference nodal coordinates (r, z) of the serendipity nodes.
    surface : node indices on the arc, ordered from the pole outwards.
    axis, equator : node indices on r = 0 and on z = R.
    radius, density : the inputs.
    """

    mesh: skfem.MeshQuad2
    X: np.ndarray
    surface: np.ndarray
    axis: np.ndarray
    equator: np.ndarray
    radius: float
    density: float
    edge_band: float = 0.0
    band_floor: float = EDGE_BAND_MIN

    @property
    def n_nodes(self) -> int:
        return self.X.shape[1]

    @property
    def n_elements(self) -> int:
        return self.mesh.nelements


def check_density(density: float) -> float:
    d = float(density)
    lo, hi = DENSITY_RANGE
    if not np.isfinite(d) or not lo <= d <= hi:
        raise ValueError(f"mesh density must lie in [{lo}, {hi}], got {density!r}")
    return d


#: signals whose disposition gmsh's initialisation changes at the C level behind Python's back
_KEPT_SIGNALS = (signal.SIGINT, signal.SIGPIPE, signal.SIGTERM)


def _gmsh_initialize(gmsh) -> None:
    """``gmsh.initialize`` keeping this process's signal handlers.

    gmsh's C++ initialisation resets SIGPIPE and SIGTERM to their defaults (terminate) and
    takes SIGINT from Python. A process that later writes to a closed pipe (a dead worker, a reader
    that went away) would then die silently with status 141 instead of getting
    BrokenPipeError, and Ctrl-C would kill it without KeyboardInterrupt and the cleanup
    that goes with it. The Python handlers are put back (main thread only; elsewhere
    Python cannot set them).
    """
    kept = {s: signal.getsignal(s) for s in _KEPT_SIGNALS}
    gmsh.initialize(interruptible=False)
    if threading.current_thread() is threading.main_thread():
        for sig, handler in kept.items():
            if handler is not None:
                signal.signal(sig, handler)


def _gmsh_quad8(radius: float, density: float, linear: bool, contact_scale: float,
                edge_band: float = 0.0, band_floor: float = EDGE_BAND_MIN) -> tuple[np.ndarray, np.ndarray]:
    """Run gmsh; return node coordinates (2, n) and quad connectivity (n_per_el, n_el)."""
    import gmsh

    R, L = radius, contact_scale
    _gmsh_initialize(gmsh)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("hemisphere")
        geo = gmsh.model.geo
        pole = geo.addPoint(0.0, 0.0, 0.0)
        centre = geo.addPoint(0.0, R, 0.0)
        edge = geo.addPoint(R, R, 0.0)
        axis = geo.addLine(pole, centre)
        equator = geo.addLine(centre, edge)
        arc = geo.addCircleArc(edge, centre, pole)
        geo.addPlaneSurface([geo.addCurveLoop([axis, equator, arc])])
        geo.synchronize()

        field = gmsh.model.mesh.field
        d_pole = field.add("Distance")
        field.setNumbers(d_pole, "PointsList", [pole])
        t_pole = field.add("Threshold")
        field.setNumber(t_pole, "InField", d_pole)
        for key, val in (("SizeMin", SIZE_POLE * L / density), ("SizeMax", SIZE_BULK * R / density),
                         ("DistMin", _POLE_DIST * L), ("DistMax", 0.6 * L)):
            field.setNumber(t_pole, key, val)
        d_arc = field.add("Distance")
        field.setNumbers(d_arc, "CurvesList", [arc])
        field.setNumber(d_arc, "Sampling", 500)
        t_arc = field.add("Threshold")
        field.setNumber(t_arc, "InField", d_arc)
        for key, val in (("SizeMin", SIZE_ARC * R / density), ("SizeMax", SIZE_BULK * R / density),
                         ("DistMin", 0.03 * R), ("DistMax", 0.4 * R)):
            field.setNumber(t_arc, key, val)
        fields = [t_pole, t_arc]
        if L < R:  # a larger partner: the arc band of the smaller sphere's size near the pole
            t_near = field.add("Threshold")
            field.setNumber(t_near, "InField", d_arc)
            for key, val in (("SizeMin", SIZE_ARC * L / density), ("SizeMax", SIZE_BULK * R / density),
                             ("DistMin", 0.03 * L), ("DistMax", 0.4 * L)):
                field.setNumber(t_near, key, val)
            t_zone = field.add("Threshold")
            field.setNumber(t_zone, "InField", d_pole)
            for key, val in (("SizeMin", 0.0), ("SizeMax", SIZE_BULK * R / density),
                             ("DistMin", 1.2 * L), ("DistMax", 2.0 * L)):
                field.setNumber(t_zone, key, val)
            near = field.add("Max")
            field.setNumbers(near, "FieldsList", [t_near, t_zone])
            fields.append(near)
        if edge_band > 0:  # surface size proportional to the distance from the pole
            band = field.add("MathEval")
            smallest, ratio = band_floor * L / density, edge_band / density
            expr = f"Max({smallest}, {ratio} * F{d_pole}) + {EDGE_BAND_GRADING} * F{d_arc}"
            field.setString(band, "F", expr)
            fields.append(band)
        both = field.add("Min")
        field.setNumbers(both, "FieldsList", fields)
        field.setAsBackgroundMesh(both)
        for key, val in (("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromPoints", 0),
                         ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.Algorithm", 8),
                         ("Mesh.RecombineAll", 1), ("Mesh.RecombinationAlgorithm", 2),
                         ("Mesh.SecondOrderIncomplete", 1), ("Mesh.Smoothing", 10),
                         ("General.NumThreads", 1), ("Mesh.RandomSeed", 1)):
            gmsh.option.setNumber(key, val)
        gmsh.model.mesh.generate(2)
        if not linear:
            gmsh.model.mesh.setOrder(2)
        types, _, conn = gmsh.model.mesh.getElements(2)
        names = [gmsh.model.mesh.getElementProperties(t)[0] for t in types]
        want = "Quadrilateral 4" if linear else "Quadrilateral 8"
        if names != [want]:
            raise RuntimeError(f"gmsh returned {names}, expected only {want!r}")
        tags, xyz, _ = gmsh.model.mesh.getNodes()
    finally:
        gmsh.finalize()
    index = np.empty(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(tags.size)
    X = xyz.reshape(-1, 3)[:, :2].T.copy()
    nper = 4 if linear else 8
    t = index[conn[0].astype(np.int64)].reshape(-1, nper).T
    # counter-clockwise corners (positive Jacobian)
    x, y = X[0, t[:4]], X[1, t[:4]]
    area = 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)
    flip = area < 0
    if np.any(flip):
        order = REVERSED[nper]
        t[:, flip] = t[order][:, flip]
    return X, t


def build_mesh(radius: float = 1.0, density: float = 1.0, linear: bool = False,
               contact_scale: float | None = None, edge_band: float = 0.0,
               band_floor: float | None = None) -> HemisphereMesh:
    """Graded all-quad meshing of the hemisphere's meridian section.

    Parameters
    ----------
    radius : sphere radius R > 0.
    density : mesh-density factor in ``DENSITY_RANGE``; element sizes scale as 1/density.
    linear : 4-node quads (straight edges) instead of 8-node serendipity quads;
        only for the locking demonstration.
    contact_scale : length that sets the pole zone (default R). A sphere pressed
        by a smaller partner of radius R₁ < R gets R₁ here: its contact zone is
        as small as the partner's, so it gets the partner's pole and arc sizes
        within about 1.2 R₁ of the pole, and its own coarser ones beyond.
    edge_band : surface element size per unit distance from the pole, s = edge_band · d
        (at least ``EDGE_BAND_MIN`` · contact_scale, growing by ``EDGE_BAND_GRADING`` per
        unit depth below the arc); 0 (default) leaves the band out. Where the contact edge
        travels, a node closing adds a ring of nearly full plastic pressure, a step of about
        2 Δs/a in F: a constant s/d keeps that step the same fraction of F at every a.
    band_floor : the band's smallest size in units of contact_scale (default
        ``EDGE_BAND_MIN``; range ``BAND_FLOOR_RANGE``). Two deformable bodies take a larger
        one: the partner's nodes crush pole elements far below the pole size (campaign v2).
    """
    radius = float(radius)
    if not np.isfinite(radius) or radius <= 0:
        raise ValueError(f"radius must be a finite number > 0, got {radius!r}")
    density = check_density(density)
    scale = radius if contact_scale is None else min(float(contact_scale), radius)
    edge_band = check_edge_band(edge_band)
    floor = check_band_floor(band_floor, edge_band)
    Xg, tg = _gmsh_quad8(radius, density, linear, scale, float(edge_band), floor)
    if linear:
        mesh = skfem.MeshQuad1(Xg, tg)
        basis_mesh = mesh
    else:
        centre = (-(Xg[:, tg[0]] + Xg[:, tg[1]] + Xg[:, tg[2]] + Xg[:, tg[3]])
                  + 2.0 * (Xg[:, tg[4]] + Xg[:, tg[5]] + Xg[:, tg[6]] + Xg[:, tg[7]])) / 4.0
        ncen = centre.shape[1]
        doflocs = np.hstack([Xg, centre])
        t9 = np.vstack([tg, Xg.shape[1] + np.arange(ncen)[None, :]])
        # drop gmsh nodes not used by any element (the geometry's points are all used)
        mesh = skfem.MeshQuad2(doflocs, t9)
        basis_mesh = mesh
    element = skfem.ElementQuad1() if linear else skfem.ElementQuadS2()
    dofs = skfem.Basis(basis_mesh, element, intorder=1)
    X = dofs.doflocs
    tol = 1e-9 * radius
    dist = np.hypot(X[0], X[1] - radius)
    on_arc = np.abs(dist - radius) < 1e-7 * radius
    surface = np.flatnonzero(on_arc)
    angle = np.arctan2(X[0, surface], radius - X[1, surface])
    surface = surface[np.argsort(angle)]
    axis = np.flatnonzero(np.abs(X[0]) < tol)
    equator = np.flatnonzero(np.abs(X[1] - radius) < tol)
    return HemisphereMesh(mesh=mesh, X=X, surface=surface, axis=axis, equator=equator,
                          radius=radius, density=density, edge_band=float(edge_band),
                          band_floor=floor)


def check_edge_band(edge_band) -> float:
    """The surface band's ratio of element size to distance from the pole, checked against
    [0, ``EDGE_BAND_MAX``] (0: no band, the default mesh)."""
    try:
        band = float(edge_band)
    except (TypeError, ValueError):
        band = math.nan
    if not (math.isfinite(band) and 0.0 <= band <= EDGE_BAND_MAX):
        raise ValueError(f"edge_band must lie in [0, {EDGE_BAND_MAX:g}] (0: no surface band), "
                         f"got {edge_band!r}")
    return band


def check_band_floor(band_floor, edge_band: float) -> float:
    """The surface band's smallest size (None: ``EDGE_BAND_MIN``), checked against
    ``BAND_FLOOR_RANGE``; a chosen floor needs a band (edge_band > 0)."""
    if band_floor is None:
        return EDGE_BAND_MIN
    lo, hi = BAND_FLOOR_RANGE
    try:
        floor = float(band_floor)
    except (TypeError, ValueError):
        floor = math.nan
    if not (np.isfinite(floor) and lo <= floor <= hi):
        raise ValueError(f"band_floor must lie in [{lo:g}, {hi:g}] (units of the contact scale), "
                         f"got {band_floor!r}")
    if not edge_band > 0 and floor != EDGE_BAND_MIN:
        raise ValueError(f"band_floor = {floor:g} needs a surface band: set edge_band > 0")
    return floor
