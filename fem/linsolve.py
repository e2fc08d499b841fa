"""Sparse symmetric solves for Newton: supernodal Cholesky or LDLᵀ with a reused symbolic
analysis, SuperLU fallback.

One body's tangent is positive definite wherever Newton converges (on the standard run only
iterations of the two increments that failed were not; two bodies in penalty contact: about a
quarter), so :class:`SupernodalCholesky` (CHOLMOD through cvxopt) factors it first, about 2×
faster than the LDLᵀ below; a matrix it refuses goes to LDLᵀ.

The tangent of the total-Lagrangian problem is symmetric (exact tangent of a
potential; the contact constraints are eliminated symmetrically, see
:class:`ConstrainedPattern`). ``qdldl`` (Stellato, Banjac et al., the LDLᵀ of OSQP:
approximate minimum degree ordering, then an up-looking LDLᵀ without pivoting)
factors it about 3× faster than SuperLU, and ``Solver.update`` refactors a
matrix of the same sparsity pattern without redoing the ordering and the
elimination tree. Keeping the pattern fixed for a whole run is the caller's
job: constrained dofs keep their rows and columns as explicit zeros.

LDLᵀ without pivoting can fail on an indefinite matrix (a zero pivot) or lose
accuracy on a badly conditioned one (a tangent near a limit point). Every solution
is therefore checked by its residual ‖K x − b‖∞ ≤ ``rtol`` ‖b‖∞ and replaced by
SuperLU's (partial pivoting, MMD on Kᵀ + K) when the check fails; ``stats`` counts
both. The saddle-point systems of Lagrange multipliers (two-body contact) have a
zero block that defeats LDLᵀ without pivoting; :meth:`SymmetricSolver.solve_saddle`
factors them made quasi-definite by a tiny −δ on that block and refines the solution
on the exact system (3–5× faster than SuperLU on the two-body systems, the same
solution to 1e-14).
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

try:  # a wheel on every platform; the solver still works (SuperLU only) without it
    import qdldl
except ImportError:  # pragma: no cover - exercised only where the wheel is missing
    qdldl = None
try:  # CHOLMOD as cvxopt's wheels bundle it (with AMD and OpenBLAS); LDLᵀ without it
    from cvxopt import cholmod as _cholmod
    from cvxopt import matrix as _cvx_matrix
    from cvxopt import spmatrix as _cvx_spmatrix
except ImportError:  # pragma: no cover - exercised only where the wheel is missing
    _cholmod = None

#: the factorisations :class:`SymmetricSolver` offers
METHODS = ("cholesky", "ldl", "superlu")

#: relative residual above which an LDLᵀ solution is rejected for SuperLU's
RTOL = 1e-8
#: saddle-point systems: −δ on the multiplier block, δ this times the largest |diagonal| of K
REGULARISATION = 1e-10
#: ... and at most this many steps of iterative refinement on the unregularised system
REFINEMENTS = 3


def shifted_diagonal(U: sp.csc_matrix, diag: np.ndarray, shift: float) -> tuple[sp.csc_matrix, np.ndarray]:
    """(U', diag') of K + shift · |diag K| on U's pattern (upper triangle, sorted CSC, every
    diagonal entry stored, so the last of its column): a positive definite substitute for a
    tangent with a few small negative eigenvalues, whose Newton step is damped along them
    (modified Newton, Nocedal & Wright 2006, §3.4; Levenberg–Marquardt's scaled diagonal)."""
    last = U.indptr[1:] - 1
    if not np.array_equal(U.indices[last], np.arange(U.shape[0])):
        raise ValueError("U must store every diagonal entry (upper triangle, sorted CSC)")
    shifted = U.copy()
    shifted.data[last] += shift * np.abs(U.data[last])
    return shifted, diag + shift * np.abs(diag)


def superlu_factor(K: sp.spmatrix):
    """SuperLU factors of K (MMD on Kᵀ + K, symmetric mode: diagonal pivots preferred)."""
    return spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})


class SupernodalCholesky:
    """K = LLᵀ of a symmetric positive definite K given by its upper triangle (sorted CSC), by
    CHOLMOD's supernodal factorisation (Chen, Davis, Hager & Rajamanickam 2008, ACM TOMS 35:22;
    through cvxopt): AMD ordering and symbolic analysis once per sparsity pattern, then one
    numeric factorisation per matrix, on dense BLAS blocks. On the standard run's tangent
    (7446 dofs) 8.7–12.6 ms against qdldl's 20–26 ms for the same refactorisation.

    :meth:`factor` raises ``ArithmeticError`` when K is not positive definite.
    """

    def __init__(self, U: sp.csc_matrix):
        n = U.shape[0]
        # CHOLMOD reads the lower triangle (column j, rows i ≥ j): the transpose of U, whose
        # column order is U's row order; ``_take`` maps U's data to it (explicit zeros kept)
        lower = sp.csc_matrix((np.arange(U.nnz, dtype=float), U.indices, U.indptr), shape=U.shape).T.tocsc()
        lower.sort_indices()
        self._take = lower.data.astype(np.int64)
        cols = np.repeat(np.arange(n), np.diff(lower.indptr))
        self._A = _cvx_spmatrix(U.data[self._take], lower.indices.astype(int), cols.astype(int), (n, n))
        _cholmod.options["supernodal"] = 2
        self._F = _cholmod.symbolic(self._A, uplo="L")

    def factor(self, U: sp.csc_matrix) -> None:
        """Numeric factorisation of the matrix with upper triangle U (the analysed pattern)."""
        self._A.V = _cvx_matrix(U.data[self._take])
        _cholmod.numeric(self._A, self._F)  # supernodal: the analysis chose it

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x with K x = b; b of shape (n,) or (n, k): k right-hand sides in one call (the
        supernodal solve works on all of them at once: 5 columns in 7.7 ms against 11.3 ms one by
        one on the 15k-dof pair)."""
        b = np.asarray(b, dtype=float)
        x = _cvx_matrix(np.asfortranarray(b))
        _cholmod.solve(self._F, x)
        return np.array(x).ravel() if b.ndim == 1 else np.array(x)


class SymmetricSolver:
    """Repeated solves K x = b for symmetric sparse K (CSR or CSC, both triangles stored).

    ``method``: ``"cholesky"`` (:class:`SupernodalCholesky` for the upper-triangle solves of
    :meth:`solve_upper`, LDLᵀ where K is not positive definite and for the other solves),
    ``"ldl"`` (qdldl, SuperLU fallback) or ``"superlu"`` (SuperLU only); a method whose package
    is missing falls back to the next. ``stats``: counts of ``cholesky_fresh`` (analysis and
    factorisation) and ``cholesky_update`` (numeric factorisation on the stored analysis), of
    them ``not_definite`` (refused: LDLᵀ took over, or the definite substitute of
    :meth:`solve_upper`, counted in ``substitute``), ``ldl_fresh``
    (ordering + factorisation), ``ldl_update`` (numeric refactorisation on the stored analysis)
    and ``fallback`` (SuperLU used because LDLᵀ failed or was inaccurate).
    """

    def __init__(self, method: str = "cholesky", rtol: float = RTOL):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}")
        if method == "cholesky" and _cholmod is None:
            method = "ldl"
        if method == "ldl" and qdldl is None:
            method = "superlu"
        self.method = method
        self.rtol = float(rtol)
        self._solver = None
        self._pattern = None
        self._keys, self._rows, self._indptr, self._n = None, None, None, 0
        self._last = None  # (indptr, indices, positions in the stored pattern) of the last matrix
        self._cholesky, self._cholesky_key = None, None  # SupernodalCholesky and its pattern's key
        self.stats = {"cholesky_fresh": 0, "cholesky_update": 0, "not_definite": 0, "substitute": 0,
                      "ldl_fresh": 0, "ldl_update": 0, "fallback": 0, "superlu": 0}
        self.times = {"factorisation": 0.0, "solve": 0.0}
        self._reuse = None  # solve() of the factors that gave the last accepted solution
        self._reuse_columns = False  # ... and whether it takes (n, k) right-hand sides in one call

    def resolve(self, b: np.ndarray) -> np.ndarray | None:
        """x with K x = b for the matrix of the last accepted solution, on its stored factors
        (no refactorisation, no check); b (n,) or (n, k), k right-hand sides; None when no
        solution has been accepted yet."""
        if self._reuse is None:
            return None
        t0 = time.perf_counter()
        b = np.asarray(b, dtype=float)
        if b.ndim == 1 or self._reuse_columns:
            x = self._reuse(b)
        else:
            x = np.column_stack([self._reuse(c) for c in b.T])
        self.times["solve"] += time.perf_counter() - t0
        return x

    def _factor(self, K: sp.csc_matrix):
        """Factor K by LDLᵀ and return the factors. The stored pattern only grows: a matrix whose
        entries lie inside it is refactored on the stored analysis (its missing entries as zeros);
        one with new entries gets a fresh analysis of the union, so a contact whose pairs move
        settles on one. A matrix with the pattern of the previous one reuses its positions
        without a search."""
        upper = sp.triu(K, format="csc")
        upper.sort_indices()
        n = upper.shape[0]
        last = self._last
        if (self._solver is not None and self._keys is not None and last is not None and n == self._n
                and np.array_equal(last[0], upper.indptr) and np.array_equal(last[1], upper.indices)):
            self._update_at(last[2], upper.data)
            return self._solver
        cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(upper.indptr))
        own = cols * n + upper.indices
        keys = own
        if self._solver is not None and self._keys is not None and n == self._n:
            pos = np.searchsorted(self._keys, own)
            inside = pos < self._keys.size
            inside[inside] = self._keys[pos[inside]] == own[inside]
            if inside.all():
                self._last = (upper.indptr.copy(), upper.indices.copy(), pos)
                self._update_at(pos, upper.data)
                return self._solver
            new = own[~inside]  # sorted, like the stored keys: merge by insertion
            keys = np.insert(self._keys, np.searchsorted(self._keys, new), new)
        self._keys = np.asarray(keys, dtype=np.int64)
        self._n = n
        cols_u, self._rows = np.divmod(self._keys, n)
        self._indptr = np.concatenate([[0], np.cumsum(np.bincount(cols_u, minlength=n))])
        data = np.zeros(self._keys.size)
        pos = np.searchsorted(self._keys, own)
        data[pos] = upper.data
        full = self._matrix(data)
        self._solver = qdldl.Solver(full, upper=True)
        self._pattern = None  # the stored pattern is ``_keys``
        self._last = (upper.indptr.copy(), upper.indices.copy(), pos)
        self.stats["ldl_fresh"] += 1
        return self._solver

    def _update_at(self, pos: np.ndarray, values: np.ndarray) -> None:
        """Refactor on the stored analysis the matrix with ``values`` at positions ``pos`` of
        the stored pattern (zeros elsewhere)."""
        data = np.zeros(self._keys.size)
        data[pos] = values
        self._solver.update(self._matrix(data), upper=True)
        self.stats["ldl_update"] += 1

    def _matrix(self, data: np.ndarray) -> sp.csc_matrix:
        """Upper-triangular CSC matrix of the stored pattern holding ``data``."""
        return sp.csc_matrix((data, self._rows, self._indptr), shape=(self._n, self._n))

    def solve_upper(self, U: sp.csc_matrix, diag: np.ndarray, b: np.ndarray, key: object,
                    definite=None) -> np.ndarray:
        """x with K x = b, K given by its upper triangle ``U`` (sorted CSC) and its diagonal
        ``diag``; ``key`` names U's pattern (a :class:`ConstrainedPattern`: the same key, the
        same pattern). The symbolic analysis is made once per key, so no conversion, triangle
        extraction or pattern comparison is paid per solve.

        ``definite``: None, or ``() -> (U', diag')`` on the same pattern, a positive definite
        approximation of K: where Cholesky refuses K, it factors K' instead (counted in
        ``substitute``) and x solves K' x = b, a quasi-Newton step, rather than taking K's
        LDLᵀ."""
        system = [U, diag]  # the matrix factored: K, or K' after a refusal

        def factor():
            if self.method == "cholesky":
                fresh = self._cholesky_key is not key
                if fresh:
                    self._cholesky, self._cholesky_key = SupernodalCholesky(U), key
                self.stats["cholesky_fresh" if fresh else "cholesky_update"] += 1
                try:
                    self._cholesky.factor(U)
                    return self._cholesky
                except ArithmeticError:  # not positive definite: K', else LDLᵀ, then SuperLU
                    self.stats["not_definite"] += 1
                if definite is not None:
                    system[:] = definite()
                    try:
                        self._cholesky.factor(system[0])
                        self.stats["substitute"] += 1
                        return self._cholesky
                    except ArithmeticError:
                        system[:] = [U, diag]
            if self._solver is not None and self._pattern is key:
                self._solver.update(U, upper=True)
                self.stats["ldl_update"] += 1
            else:
                self._solver = qdldl.Solver(U, upper=True)
                self._pattern, self._keys = key, None
                self.stats["ldl_fresh"] += 1
            return self._solver
        return self._checked(b, factor, lambda x: system[0] @ x + system[0].T @ x - system[1] * x,
                             lambda: system[0] + sp.triu(system[0], k=1).T)

    def solve(self, K: sp.spmatrix, b: np.ndarray) -> np.ndarray:
        """x with K x = b; LDLᵀ where it is accurate, SuperLU otherwise."""
        K = sp.csc_matrix(K)
        return self._checked(b, lambda: self._factor(K), lambda x: K @ x, lambda: K)

    def solve_saddle(self, A: sp.spmatrix, b: np.ndarray, n_constraints: int) -> np.ndarray:
        """x with A x = b for a symmetric saddle-point matrix A = [[K, Bᵀ], [B, 0]] whose last
        ``n_constraints`` rows are the constraints (K positive definite on the free dofs).

        LDLᵀ of the quasi-definite A − δ I on the multiplier block (δ = ``REGULARISATION`` ×
        max |diag K|), which has an LDLᵀ for every symmetric ordering (Vanderbei 1995, SIAM J.
        Optim. 5:100), then iterative refinement on A itself (up to ``REFINEMENTS`` steps, as
        OSQP does with qdldl): the regularisation changes the factor, not the solution. The
        result is checked on A like every other solve; SuperLU on A otherwise.
        """
        A = sp.csc_matrix(A)
        m = int(n_constraints)
        if m == 0 or self.method == "superlu":
            return self.solve(A, b)
        n = A.shape[0]
        d = A.diagonal()
        reg = np.zeros(n)
        reg[n - m:] = -REGULARISATION * max(float(np.abs(d[:n - m]).max(initial=0.0)), 1e-300)
        M = sp.csc_matrix(A + sp.diags(reg))
        return self._checked(b, lambda: self._factor(M), lambda x: A @ x, lambda: A,
                             refinements=REFINEMENTS)

    def _checked(self, b: np.ndarray, factor, matvec, full, refinements: int = 0) -> np.ndarray:
        """``factor()`` (which returns the factors) then their solution, improved by up to
        ``refinements`` steps of iterative refinement on ``matvec``, when its residual
        ‖matvec(x) − b‖∞ ≤ rtol ‖b‖∞; otherwise SuperLU's on ``full()`` (the whole matrix);
        times and counts recorded."""
        b = np.asarray(b, dtype=float)
        t0 = time.perf_counter()
        if self.method != "superlu":
            try:
                factors = factor()
                t1 = time.perf_counter()
                self.times["factorisation"] += t1 - t0
                x = factors.solve(b)
                scale = max(float(np.abs(b).max(initial=0.0)), 1e-300)
                for _ in range(refinements):
                    r = b - matvec(x)
                    if not np.all(np.isfinite(r)) or np.abs(r).max(initial=0.0) <= 1e-3 * self.rtol * scale:
                        break
                    x = x + factors.solve(r)
                ok = np.all(np.isfinite(x)) and np.abs(matvec(x) - b).max(initial=0.0) <= self.rtol * scale
                self.times["solve"] += time.perf_counter() - t1
                if ok:
                    self._reuse = factors.solve
                    self._reuse_columns = isinstance(factors, SupernodalCholesky)  # qdldl: one at a time
                    return x
            except (ValueError, RuntimeError):
                # not reused after a failure
                self._solver, self._pattern, self._keys, self._last = None, None, None, None
            self._reuse = None
            self.stats["fallback"] += 1
            t0 = time.perf_counter()
        else:
            self.stats["superlu"] += 1
        lu = superlu_factor(full())
        self.times["factorisation"] += time.perf_counter() - t0
        self._reuse, self._reuse_columns = lu.solve, True  # SuperLU solves (n, k) at once
        return lu.solve(b)


class ConstrainedPattern:
    """The upper triangle of a symmetric matrix stored on a fixed CSR pattern (both triangles,
    sorted indices), with the rows and columns of constrained dofs zeroed (kept as explicit zeros) and a
    value on their diagonal, built by indexing alone. With b[fixed] = diag_value · x_c and
    b[free] = b_f − K_fc x_c (the prescribed values moved to the right-hand side) the solution
    is x_c on the fixed dofs and the reduced solution on the free ones.

    The CSR arrays of the lower triangle (row j, columns i ≤ j) are the CSC arrays of the
    upper triangle (column j, rows i ≤ j), so the upper matrix is ``data[lower]`` on index
    arrays made once; its index arrays stay the same objects for every matrix, which lets
    :meth:`SymmetricSolver.solve_upper` reuse its analysis without comparing patterns.
    """

    def __init__(self, indptr: np.ndarray, indices: np.ndarray):
        n = indptr.size - 1
        rows = np.repeat(np.arange(n), np.diff(indptr))
        if np.any(np.diff(indices.astype(np.int64) + rows.astype(np.int64) * n) <= 0):
            raise ValueError("ConstrainedPattern: the CSR indices must be sorted and unique")
        self.n = n
        self.lower = np.flatnonzero(indices <= rows)
        self._row = indices[self.lower].astype(np.int64)  # row of the upper entry
        self._col = rows[self.lower]  # its column
        self._indptr = np.concatenate([[0], np.cumsum(np.bincount(self._col, minlength=n))]).astype(np.int32)
        self._indices = self._row.astype(np.int32)
        diag = np.flatnonzero(self._row == self._col)
        if diag.size != n:
            raise ValueError("ConstrainedPattern: the pattern must store every diagonal entry")
        self.diag = diag  # positions of the diagonal in the upper data (column order: dof order)
        self._fixed = None  # (fixed dofs, positions of their rows and columns in the upper data)

    def _fixed_entries(self, fixed: np.ndarray) -> np.ndarray:
        """Positions in the upper data of the rows and columns of ``fixed`` (kept for the last
        ``fixed`` seen: a run's constrained dofs do not change)."""
        if self._fixed is None or not np.array_equal(self._fixed[0], fixed):
            is_fixed = np.zeros(self.n, dtype=bool)
            is_fixed[fixed] = True
            self._fixed = (fixed.copy(), np.flatnonzero(is_fixed[self._row] | is_fixed[self._col]))
        return self._fixed[1]

    def upper(self, data: np.ndarray, fixed: np.ndarray, diag_value: float) -> tuple:
        """(U, diagonal) of the matrix holding CSR ``data`` with the rows and columns of
        ``fixed`` zeroed and ``diag_value`` on their diagonal (explicit zeros kept)."""
        u = data[self.lower]
        if fixed.size:
            u[self._fixed_entries(fixed)] = 0.0
            u[self.diag[fixed]] = diag_value
        U = sp.csc_matrix((u, self._indices, self._indptr), shape=(self.n, self.n))
        return U, u[self.diag]
