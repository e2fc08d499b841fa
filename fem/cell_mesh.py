"""Octant mesh of a sphere refined at its contact poles, and its element arrays (issue 62).

The sphere (centre at the origin, radius R) is cut by the symmetry planes x = 0, y = 0, z = 0;
the octant x, y, z ≥ 0 is meshed by gmsh (OCC sphere ∩ box, Delaunay tetrahedra) under the
size field

    s(X) = min(S_bulk, max(S_pole, c · min(d, ρ)) + g · max(0, d − ρ)) / density,
    d = min_k |X − R n_k|

graded within a distance ρ of every contact pole R n_k, where the contact patch travels (size
c d: a patch edge at radius a always meets elements of size ≈ c a), growing with slope g beyond.
Made quadratic by skfem (``MeshTet2.from_mesh``) with the midside nodes of the sphere's surface
edges projected onto the sphere.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import skfem

from .mesh import _gmsh_initialize

#: element sizes (units of R) at density 1: the smallest, at the pole; far from the poles; the
#: growth of the size with distance beyond the pole region
SIZE_POLE = 0.012
SIZE_BULK = 0.25
SIZE_GROWTH = 0.6
#: size per unit distance from the pole inside the pole region (a patch edge at radius a meets
#: elements of size ≈ POLE_GRADE a: the patch spans ≈ 1/POLE_GRADE of them at every a)
POLE_GRADE = 0.18
#: radius of the pole region (units of R): beyond the contact radius at h/R 0.1 (a ≈ 0.32 R)
POLE_REGION = 0.4


@dataclass(frozen=True)
class OctantMesh:
    """Quadratic tetrahedral mesh of the sphere octant x, y, z ≥ 0, |X| ≤ R.

    Attributes
    ----------
    mesh : skfem.MeshTet2 (sphere-surface midside nodes on the sphere).
    X : (3, n_nodes) reference coordinates of the 10-node tetrahedra's nodes.
    sphere : node indices on the spherical surface.
    sphere_facets : (3, m) corner nodes of the boundary triangles on the sphere.
    poles : (k, 3) unit vectors of the refined contact poles.
    """

    mesh: skfem.MeshTet2
    X: np.ndarray
    sphere: np.ndarray
    sphere_facets: np.ndarray
    radius: float
    density: float
    poles: np.ndarray
    pole_size: float
    pole_region: float


def build_octant_mesh(radius: float = 1.0, density: float = 1.0, poles=((0.0, 0.0, 1.0),),
                      pole_size: float = SIZE_POLE, pole_region: float = POLE_REGION,
                      pole_grade: float = POLE_GRADE) -> OctantMesh:
    """Octant of a sphere, graded within ``pole_region`` (units of R) of each pole in ``poles``
    (unit vectors): sizes max(``pole_size``, ``pole_grade`` d) there (module docstring), all
    sizes ∝ 1/``density``."""
    import gmsh

    poles = np.atleast_2d(np.asarray(poles, dtype=float))
    poles = poles / np.linalg.norm(poles, axis=1, keepdims=True)
    dist = [f"Sqrt((x - {p[0]:.15f})*(x - {p[0]:.15f}) + (y - {p[1]:.15f})*(y - {p[1]:.15f})"
            f" + (z - {p[2]:.15f})*(z - {p[2]:.15f}))" for p in poles]
    dmin = dist[0]
    for d in dist[1:]:
        dmin = f"Min({dmin}, {d})"
    grade = pole_grade
    expr = (f"Min({SIZE_BULK / density}, Max({pole_size}, {grade}*Min({dmin}, {pole_region}))"
            f"/{density} + {SIZE_GROWTH}*Max(0, {dmin} - {pole_region})/{density})")
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
        f.setString(fid, "F", expr)
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
    m2 = replace(m2, doflocs=X * radius)
    return OctantMesh(mesh=m2, X=X * radius, sphere=np.sort(sphere), sphere_facets=tri,
                      radius=float(radius), density=float(density), poles=poles,
                      pole_size=float(pole_size), pole_region=float(pole_region))


class Discretisation3:
    """Element arrays of a quadratic tetrahedral mesh: B (∂u/∂X → F), weights, dofs, CSR pattern.

    F[3i+j] = δ_ij + Σ_a ∂N_a/∂X_j u_ai; dof 3a + i is node a's displacement along X_i.
    Total Lagrangian: f_int = ∫ Bᵀ P dV₀, K = ∫ Bᵀ A B dV₀, A = ∂P/∂F (Wriggers 2008, §4.2);
    4-point Gauss rule.
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
