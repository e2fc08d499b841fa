"""3D large-deformation FE of one sphere in a lattice cell: octant mesh, assembly, two-flat scene.

First scene (issue 62): a sphere of radius R squeezed between two rigid frictionless
plates, the axisymmetric flat scene in 3D and the 3D solver's own verification. With the
sphere centred at the origin, the planes x = 0, y = 0, z = 0 are symmetry planes; the octant
x, y, z ≥ 0 is meshed and the upper plate sits at z = R − h/2 (h: the change of the plates'
separation 2R − d). Each half of the sphere is then a hemisphere on a rigid flat with
approach h/2, so F(h) of this scene equals F_ax(h/2) of ``spherecontact fem run`` (flat
obstacle), the plate force F = 4 × the octant's reaction.

Kinematics: total Lagrangian, F = I + ∂u/∂X at the quadrature points; virtual work

    f_int = ∫ Bᵀ P dV₀,   K = ∫ Bᵀ A B dV₀,   A = ∂P/∂F                   (Wriggers 2008, §4.2)

with the constitutive update of :mod:`.constitutive3d` (shared with the axisymmetric solver).
Quadratic tetrahedra (10 nodes, isoparametric: midside nodes of the sphere's surface on the
sphere), 4-point Gauss rule.

Contact: exact, as in the axisymmetric solver (:mod:`.contact`): an active node has its
z displacement prescribed onto the plate (g = 0), an inactive one carries no force; the
active set is updated after each converged Newton loop (close on penetration, release on
a tensile reaction) until it no longer changes. No penalty number.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import skfem

from ..model.material import Material
from .constitutive3d import PlasticState3, stress_update3, tangent3
from .linsolve import SymmetricSolver
from .mesh import _gmsh_initialize

#: element sizes (units of R) at density 1: at the contact pole, far from it, and the growth
#: of the size with distance from the pole
SIZE_POLE = 0.03
SIZE_BULK = 0.25
SIZE_GROWTH = 0.6


@dataclass(frozen=True)
class OctantMesh:
    """Quadratic tetrahedral mesh of the sphere octant x, y, z ≥ 0, |X| ≤ R.

    Attributes
    ----------
    mesh : skfem.MeshTet2 (sphere-surface midside nodes on the sphere).
    X : (3, n_nodes) reference coordinates of the 10-node tetrahedra's nodes.
    sphere : node indices on the spherical surface.
    sphere_facets : (3, m) corner nodes of the boundary triangles on the sphere.
    """

    mesh: skfem.MeshTet2
    X: np.ndarray
    sphere: np.ndarray
    sphere_facets: np.ndarray
    radius: float
    density: float


def build_octant_mesh(radius: float = 1.0, density: float = 1.0) -> OctantMesh:
    """Octant of a sphere meshed by gmsh (OCC sphere ∩ box, Delaunay tetrahedra) under the size
    field s(X) = min(S_bulk, S_pole + g |X − R e_z|)/density: finest at the pole the plate
    touches. Made quadratic by skfem (``MeshTet2.from_mesh``) with the midside nodes of the
    sphere's surface edges projected onto the sphere (exact surface to second order)."""
    import gmsh

    _gmsh_initialize(gmsh)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("octant")
        occ = gmsh.model.occ
        ball = occ.addSphere(0, 0, 0, 1.0)
        box = occ.addBox(0, 0, 0, 1.0, 1.0, 1.0)
        occ.intersect([(3, ball)], [(3, box)])
        occ.synchronize()
        f = gmsh.model.mesh.field
        fid = f.add("MathEval")
        f.setString(fid, "F", f"Min({SIZE_BULK / density}, ({SIZE_POLE} + {SIZE_GROWTH}"
                              f"*Sqrt(x*x + y*y + (z - 1)*(z - 1)))/{density})")
        f.setAsBackgroundMesh(fid)
        for key in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints",
                    "Mesh.MeshSizeFromCurvature"):
            gmsh.option.setNumber(key, 0)
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
    finally:
        gmsh.finalize()
    order = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    order[tags.astype(np.int64)] = np.arange(tags.size)
    p = xyz.reshape(-1, 3).T
    t = order[np.asarray(conn[0], dtype=np.int64)].reshape(-1, 4).T
    used = np.unique(t)
    remap = np.full(p.shape[1], -1)
    remap[used] = np.arange(used.size)
    m1 = skfem.MeshTet1(p[:, used], remap[t])
    m2 = skfem.MeshTet2.from_mesh(m1)
    nv = m1.p.shape[1]
    onsphere = np.abs(np.linalg.norm(m1.p, axis=0) - 1.0) < 1e-8
    bf = m1.boundary_facets()
    sf = bf[np.all(onsphere[m1.facets[:, bf]], axis=0)]
    tri = m1.facets[:, sf]
    # midside dofs of the sphere's triangles: edge index of each corner pair, + nv
    ekeys = np.sort(m1.edges, axis=0)
    ekey = ekeys[0] * nv + ekeys[1]
    srt = np.argsort(ekey)
    pairs = np.sort(np.stack([tri[[0, 1, 2]], tri[[1, 2, 0]]]), axis=0)
    pk = (pairs[0] * nv + pairs[1]).ravel()
    eidx = srt[np.searchsorted(ekey[srt], pk)]
    mid = np.unique(eidx) + nv
    X = m2.doflocs.copy()
    X[:, mid] /= np.linalg.norm(X[:, mid], axis=0)
    sphere = np.concatenate([np.flatnonzero(onsphere), mid])
    from dataclasses import replace
    m2 = replace(m2, doflocs=X * radius)
    return OctantMesh(mesh=m2, X=X * radius, sphere=np.sort(sphere), sphere_facets=tri,
                      radius=float(radius), density=float(density))


class Discretisation3:
    """Element arrays of a quadratic tetrahedral mesh: B (∂u/∂X → F), weights, dofs, CSR pattern.

    F[3i+j] = δ_ij + Σ_a ∂N_a/∂X_j u_ai; dof 3a + i is node a's displacement along X_i.
    """

    def __init__(self, omesh: OctantMesh):
        self.omesh = omesh
        basis = skfem.Basis(omesh.mesh, skfem.ElementTetP2(), intorder=2)
        nbf, nel = basis.Nbfun, basis.nelems
        nqp = basis.X.shape[1]
        self.n_nodes, self.n_dofs = int(basis.N), 3 * int(basis.N)
        self.n_elements, self.n_qp = nel, nqp
        self.weights = np.asarray(basis.dx).reshape(-1)
        dphi = np.stack([basis.basis[i][0].grad for i in range(nbf)])  # (nbf, 3, nel, nqp)
        B = np.zeros((nel, nqp, 3, 3, nbf, 3))
        for i in range(3):  # components of u (3 fixed iterations, not over points)
            B[:, :, i, :, :, i] = dphi.transpose(2, 3, 1, 0)
        self.B = B.reshape(nel * nqp, 9, 3 * nbf)
        nodes = basis.element_dofs  # (nbf, nel)
        edofs = 3 * nodes[:, :, None] + np.arange(3)[None, None, :]
        self.edofs = edofs.transpose(1, 0, 2).reshape(nel, 3 * nbf)
        self.qp_dofs = np.repeat(self.edofs, nqp, axis=0)
        ne = self.edofs.shape[1]
        rows = np.repeat(self.edofs[:, :, None], ne, axis=2).ravel().astype(np.int64)
        cols = np.repeat(self.edofs[:, None, :], ne, axis=1).ravel().astype(np.int64)
        keys, self._slot = np.unique(rows * self.n_dofs + cols, return_inverse=True)
        self._rows, self._cols = np.divmod(keys, self.n_dofs)

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F (n_points, 3, 3) at the quadrature points for nodal displacements u (n_dofs,)."""
        grad = np.einsum("qkj,qj->qk", self.B, u[self.qp_dofs])
        return grad.reshape(-1, 3, 3) + np.eye(3)

    def internal_force(self, P: np.ndarray) -> np.ndarray:
        """f_int = Σ_q w_q Bᵀ P (P: (n_points, 3, 3))."""
        fe = np.einsum("qkj,qk->qj", self.B, P.reshape(-1, 9) * self.weights[:, None])
        return np.bincount(self.qp_dofs.ravel(), weights=fe.ravel(), minlength=self.n_dofs)

    def tangent(self, A: np.ndarray) -> sp.csr_matrix:
        """K = Σ_q w_q Bᵀ A B (A: (n_points, 9, 9)) on the fixed pattern."""
        AB = np.matmul(A * self.weights[:, None, None], self.B)
        nel, nqp, nb = self.n_elements, self.n_qp, self.B.shape[2]
        Bt = self.B.reshape(nel, nqp * 9, nb).transpose(0, 2, 1)
        Ke = np.matmul(Bt, AB.reshape(nel, nqp * 9, nb))
        data = np.bincount(self._slot, weights=Ke.ravel())
        return sp.csr_matrix((data, (self._rows, self._cols)), shape=(self.n_dofs,) * 2)

    def integrate(self, values: np.ndarray) -> float:
        return float(np.dot(self.weights, values))


@dataclass
class TwoFlatResult:
    """Curves of a two-plate run, per converged increment (full sphere: 8 × the octant)."""

    h: list = field(default_factory=list)  # plate approach 2R − d
    F: list = field(default_factory=list)  # plate force (4 × the octant's reaction)
    A: list = field(default_factory=list)  # contact area: closed sphere triangles, deformed
    a_nodes: list = field(default_factory=list)  # largest deformed radius of a closed node
    work: list = field(default_factory=list)  # external work ∫ F dh (trapezoid)
    stored: list = field(default_factory=list)  # elastic energy ∫ ψ dV
    dissipation: list = field(default_factory=list)  # plastic work Σ ∫ σ_f Δγ dV
    newton: list = field(default_factory=list)  # Newton iterations per increment
    wall_s: float = 0.0
    n_nodes: int = 0
    n_elements: int = 0


class IncrementFailed(RuntimeError):
    """Newton or the active-set loop did not converge."""


def _contact_area(x: np.ndarray, tri: np.ndarray, closed: np.ndarray) -> float:
    """Deformed area of the sphere triangles whose three corners are all closed (flat
    triangles on the corners; the closed ones lie in the plate)."""
    sel = tri[:, np.all(closed[tri], axis=0)]
    if sel.size == 0:
        return 0.0
    v1 = x[:, sel[1]] - x[:, sel[0]]
    v2 = x[:, sel[2]] - x[:, sel[0]]
    return float(0.5 * np.linalg.norm(np.cross(v1.T, v2.T), axis=1).sum())


def run_two_flats(material: Material, h_values, density: float = 1.0, radius: float = 1.0,
                  tol: float = 1e-4, max_iterations: int = 25, progress=None) -> TwoFlatResult:
    """Squeeze the sphere between two rigid frictionless plates through the approaches
    ``h_values`` (increasing, units of length; h = 2R − d), octant model (module docstring).

    Each increment: the displacement of the last one extrapolated (secant predictor), the
    active nodes moved onto the plate, then Newton on the free dofs (exact tangent up to the
    central-difference error of :func:`.constitutive3d.tangent3`) until
    ‖r_free‖∞ ≤ tol · max|reaction|, then the active set updated and Newton repeated until
    it is unchanged. Raises :class:`IncrementFailed` when Newton does not converge.
    """
    t0 = time.perf_counter()
    om = build_octant_mesh(radius, density)
    disc = Discretisation3(om)
    X = om.X
    nd = disc.n_dofs
    fixed_sym = np.concatenate([3 * np.flatnonzero(np.abs(X[0]) < 1e-12),
                                3 * np.flatnonzero(np.abs(X[1]) < 1e-12) + 1,
                                3 * np.flatnonzero(np.abs(X[2]) < 1e-12) + 2])
    cand = om.sphere[X[2, om.sphere] > 0.5 * radius]  # nodes that can meet the upper plate
    active = np.zeros(X.shape[1], dtype=bool)
    state = PlasticState3.virgin(disc.n_elements * disc.n_qp)
    u = np.zeros(nd)
    u_prev, h_prev = np.zeros(nd), 0.0
    res = TwoFlatResult(n_nodes=X.shape[1], n_elements=disc.n_elements)
    solver = SymmetricSolver("ldl")
    work, F_last = 0.0, 0.0
    for h in h_values:
        zp = radius - 0.5 * h
        if len(res.h) > 1:  # secant predictor through the last two converged increments
            u_conv = u.copy()
            u = u + (u - u_prev) * (h - h_prev) / (h_prev - res.h[-2])
            u_prev = u_conv
        else:
            u_prev = u.copy()
        # close every candidate the predicted (first increment: reference) surface puts
        # through the plate
        xz = X[2, cand] + u[3 * cand + 2]
        active[cand[xz > zp]] = True
        its = 0
        du, free = None, None
        for _it in range(3 * max_iterations):  # Newton with the active set updated in the loop
            cdofs = 3 * np.flatnonzero(active) + 2
            u[cdofs] = zp - X[2, active]
            u[fixed_sym] = 0.0
            fixed = np.zeros(nd, dtype=bool)
            fixed[fixed_sym] = True
            fixed[cdofs] = True
            Fq = disc.deformation_gradient(u)
            step = 1.0
            while np.any(np.linalg.det(Fq) <= 0):  # J > 0 guard: halve the Newton step
                if du is None or step < 1e-3:
                    raise IncrementFailed(f"inverted element at h = {h:g}")
                step *= 0.5
                u[free] -= step * du
                Fq = disc.deformation_gradient(u)
            free = np.flatnonzero(~fixed)
            upd = stress_update3(Fq, state.cp_inv, state.eps_p, material)
            r = disc.internal_force(upd.P)
            react = -r[cdofs]
            scale = max(np.max(np.abs(react)), 1e-300)
            its += 1
            if _it > 0:  # primal-dual active set: release tension, close penetration
                x = X + u.reshape(-1, 3).T
                pen = cand[(~active[cand]) & (x[2, cand] > zp + 1e-12 * radius)]
                tens = np.flatnonzero(active)[react < 0]
                if pen.size or tens.size:
                    active[pen] = True
                    active[tens] = False
                    du = None
                    continue
                if np.max(np.abs(r[free])) <= tol * scale:
                    break
            K = disc.tangent(tangent3(Fq, state, material, upd)).tocsc()
            du = solver.solve(K[free][:, free], -r[free])
            u[free] += du
        else:
            raise IncrementFailed(f"Newton did not converge at h = {h:g}")
        x = X + u.reshape(-1, 3).T
        F = 4.0 * float(np.sum(react))
        work += 0.5 * (F + F_last) * (h - h_prev)
        F_last = F
        dissip = (res.dissipation[-1] if res.dissipation else 0.0) + 8.0 * disc.integrate(
            material.flow_stress(upd.eps_p) * upd.dgamma if np.isfinite(material.sigma_y)
            else np.zeros_like(upd.dgamma))
        state = PlasticState3(upd.cp_inv, upd.eps_p)
        r_xy = np.hypot(x[0, active], x[1, active])
        res.h.append(float(h))
        res.F.append(F)
        res.A.append(4.0 * _contact_area(x, om.sphere_facets, active))
        res.a_nodes.append(float(r_xy.max()))
        res.work.append(work)
        res.stored.append(8.0 * disc.integrate(upd.psi))
        res.dissipation.append(dissip)
        res.newton.append(its)
        h_prev = h
        if progress is not None:
            progress(res)
    res.wall_s = time.perf_counter() - t0
    return res
