"""Total-Lagrangian axisymmetric assembly: internal force and tangent (hot loop).

Virtual work over the reference meridian section, dV₀ = 2π R dR dZ:

    f_int = ∫ Bᵀ P dV₀,      K = ∫ Bᵀ A B dV₀,      A = ∂P/∂F

with the deformation-gradient vector F = [F_rr, F_rz, F_zr, F_zz, F_θθ] =
[1 + ∂u_r/∂R, ∂u_r/∂Z, ∂u_z/∂R, 1 + ∂u_z/∂Z, 1 + u_r/R] (the hoop stretch
included). B is built once from scikit-fem's basis in the reference
configuration; each Newton iteration is two einsums and a bincount into a
fixed CSR pattern (about 10× faster than form assembly, see notes).
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.sparse as sp
import skfem

from .mesh import HemisphereMesh

#: Element kinds: quadratic serendipity with 2×2 (reduced) Gauss points — does
#: not lock in isochoric flow — and bilinear with 2×2 (full) Gauss points, which
#: locks (kept for the locking demonstration only).
ELEMENTS = {"q8r": (skfem.ElementQuadS2, 3), "q4": (skfem.ElementQuad1, 3)}


def positive_jacobian(F: np.ndarray) -> bool:
    """True when every point of the F vector (5, n) has det F_rz > 0 and F_θθ > 0."""
    return bool(np.all(F[0] * F[3] - F[1] * F[2] > 0) and np.all(F[4] > 0))


class Discretisation:
    """Element arrays of one hemisphere mesh: B, weights, dof maps, CSR pattern."""

    def __init__(self, hmesh: HemisphereMesh, element: str = "q8r"):
        if element not in ELEMENTS:
            raise ValueError(f"element must be one of {sorted(ELEMENTS)}, got {element!r}")
        cls, intorder = ELEMENTS[element]
        self.element = element
        self.hmesh = hmesh
        basis = skfem.Basis(hmesh.mesh, cls(), intorder=intorder)
        self.basis = basis
        nbf, nel = basis.Nbfun, basis.nelems
        nqp = basis.X.shape[1]
        self.n_nodes = int(basis.N)
        self.n_dofs = 2 * self.n_nodes
        self.n_elements, self.n_qp = nel, nqp
        xq = basis.mapping.F(basis.X)  # (2, nel, nqp) reference coordinates of the points
        self.R_qp = xq[0]
        self.weights = (2.0 * np.pi * xq[0] * basis.dx).reshape(-1)  # (nel*nqp,)
        phi = np.stack([np.asarray(basis.basis[i][0]) for i in range(nbf)])  # (nbf, nel, nqp)
        dphi = np.stack([basis.basis[i][0].grad for i in range(nbf)])  # (nbf, 2, nel, nqp)
        B = np.zeros((nel, nqp, 5, nbf, 2))
        B[:, :, 0, :, 0] = dphi[:, 0].transpose(1, 2, 0)  # ∂u_r/∂R
        B[:, :, 1, :, 0] = dphi[:, 1].transpose(1, 2, 0)  # ∂u_r/∂Z
        B[:, :, 2, :, 1] = dphi[:, 0].transpose(1, 2, 0)  # ∂u_z/∂R
        B[:, :, 3, :, 1] = dphi[:, 1].transpose(1, 2, 0)  # ∂u_z/∂Z
        B[:, :, 4, :, 0] = (phi / xq[0][None]).transpose(1, 2, 0)  # u_r/R
        self.B = B.reshape(nel * nqp, 5, 2 * nbf)
        nodes = basis.element_dofs  # (nbf, nel) node index = scalar dof index
        edofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1)  # (nbf, nel, 2)
        self.edofs = edofs.transpose(1, 0, 2).reshape(nel, 2 * nbf)
        self.qp_dofs = np.repeat(self.edofs, nqp, axis=0)  # (nel*nqp, 2nbf)
        self._pattern()

    def _pattern(self) -> None:
        nd = self.n_dofs
        rows = np.repeat(self.edofs[:, :, None], self.edofs.shape[1], axis=2).ravel()
        cols = np.repeat(self.edofs[:, None, :], self.edofs.shape[1], axis=1).ravel()
        keys = rows.astype(np.int64) * nd + cols
        uniq, slot = np.unique(keys, return_inverse=True)
        self._slot = slot
        self._nnz = uniq.size
        r, c = np.divmod(uniq, nd)
        self._indices = c.astype(np.int32)
        self._indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=nd))]).astype(np.int32)
        self._keys = uniq
        self._rows, self._cols = r, c

    @functools.cached_property
    def _siblings(self) -> np.ndarray:
        """For every stored entry (i, j): the slots of the four entries of its node pair's 2×2
        block (built on first use: only curved obstacles rotate blocks)."""
        I, J = self._rows // 2, self._cols // 2
        return self.node_block_slots(I, J)

    @property
    def csr_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        """(indptr, indices) of the fixed CSR pattern (sorted, whole diagonal stored)."""
        return self._indptr, self._indices

    @property
    def n_entries(self) -> int:
        """Number of stored entries of the fixed sparsity pattern."""
        return self._nnz

    def slots(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Positions in the CSR data array of entries (rows, cols) of the fixed pattern."""
        keys = np.asarray(rows, dtype=np.int64) * self.n_dofs + np.asarray(cols, dtype=np.int64)
        pos = np.searchsorted(self._keys, keys)
        if np.any(pos >= self._keys.size) or np.any(self._keys[np.minimum(pos, self._keys.size - 1)] != keys):
            raise ValueError("entry outside the sparsity pattern of the mesh")
        return pos

    def node_block_slots(self, nodes_i: np.ndarray, nodes_j: np.ndarray) -> np.ndarray:
        """(n, 2, 2) data positions of the 2×2 blocks coupling nodes_i[k] with nodes_j[k]."""
        rows = 2 * np.asarray(nodes_i)[:, None, None] + np.arange(2)[None, :, None]
        cols = 2 * np.asarray(nodes_j)[:, None, None] + np.arange(2)[None, None, :]
        return self.slots(*np.broadcast_arrays(rows, cols))

    def rotate_blocks(self, data: np.ndarray, nodes: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """Tangent data in nodal frames: K̃_IJ = Q_Iᵀ K_IJ Q_J, Q = ``frames[k]`` (2×2) at
        ``nodes[k]`` and the identity elsewhere. The pattern is unchanged, so the rotated
        matrix keeps the factorisation's symbolic analysis.
        """
        n_nodes = self.n_dofs // 2
        Q = np.broadcast_to(np.eye(2), (n_nodes, 2, 2)).copy()
        Q[nodes] = frames
        rotated = np.zeros(n_nodes, dtype=bool)
        rotated[nodes] = True
        r, c = self._rows, self._cols
        I, J = r // 2, c // 2
        k = np.flatnonzero(rotated[I] | rotated[J])
        qr = Q[I[k], :, r[k] % 2]  # (m, 2): column ci of Q_I
        qc = Q[J[k], :, c[k] % 2]
        out = data.copy()
        out[k] = np.einsum("ka,kab,kb->k", qr, data[self._siblings[k]], qc)
        return out

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """CSR matrix of the fixed pattern holding ``data``."""
        return sp.csr_matrix((data, self._indices, self._indptr), shape=(self.n_dofs,) * 2)

    # ------------------------------------------------------------------ kinematics
    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F vector (5, n_points) at the quadrature points for nodal displacements u."""
        ue = u[self.edofs]  # (nel, 2nbf)
        # one batched matrix-vector product per element (a 3-index einsum is ~1.7× slower)
        Be = self.B.reshape(self.n_elements, self.n_qp * 5, -1)
        grad = np.matmul(Be, ue[:, :, None]).reshape(self.n_elements, self.n_qp, 5)
        grad = grad.transpose(2, 0, 1).reshape(5, -1)
        grad[0] += 1.0
        grad[3] += 1.0
        grad[4] += 1.0
        return grad

    # ------------------------------------------------------------------ assembly
    def internal_force(self, P: np.ndarray) -> np.ndarray:
        """f_int = Σ_q w_q Bᵀ P (P: (5, n_points))."""
        fe = np.einsum("qkj,qk->qj", self.B, (P * self.weights).T)  # weights first: ~2× faster
        return np.bincount(self.qp_dofs.ravel(), weights=fe.ravel(), minlength=self.n_dofs)

    def tangent(self, A: np.ndarray) -> sp.csr_matrix:
        """K = Σ_q w_q Bᵀ A B (A: (5, 5, n_points)) on the fixed CSR pattern."""
        Aw = (A * self.weights).transpose(2, 0, 1)  # (q, 5, 5)
        AB = np.matmul(Aw, self.B)  # (q, 5, n)
        nel, nqp, nb = self.n_elements, self.n_qp, self.B.shape[2]
        # Σ_q B_qᵀ (A B)_q per element as one batched product over the stacked (q, k) index
        Bt = self.B.reshape(nel, nqp * 5, nb).transpose(0, 2, 1)
        Ke = np.matmul(Bt, AB.reshape(nel, nqp * 5, nb))
        data = np.bincount(self._slot, weights=Ke.ravel(), minlength=self._nnz)
        return self.matrix(data)

    def integrate(self, values: np.ndarray) -> float:
        """∫ values dV₀ over the body (values at the points)."""
        return float(np.dot(self.weights, values))
