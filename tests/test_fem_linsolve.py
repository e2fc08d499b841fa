"""Sparse symmetric solves (fem/linsolve.py) and the solver's fixed sparsity pattern."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.linsolve import (
    ConstrainedPattern,
    SupernodalCholesky,
    SymmetricSolver,
    shifted_diagonal,
)
from spherecontact.fem.solver import IndentationSolver, SolverOptions
from spherecontact.model import Material

NONE = {"cholesky_fresh": 0, "cholesky_update": 0, "not_definite": 0, "substitute": 0, "ldl_fresh": 0,
        "ldl_update": 0, "fallback": 0, "superlu": 0}


def _laplacian(n: int, shift: float = 0.1) -> sp.csr_matrix:
    """SPD 2-D Laplacian plus a shift (n² unknowns)."""
    T = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return (sp.kronsum(T, T) + shift * sp.eye(n * n)).tocsr()


def test_ldl_reuses_its_analysis_and_matches_superlu():
    K = _laplacian(20)
    b = np.random.default_rng(0).standard_normal(K.shape[0])
    s = SymmetricSolver("ldl")
    x1 = s.solve(K, b)
    x2 = s.solve(K * 2.0, b)  # same pattern, new values: numeric refactorisation only
    assert np.allclose(x1, spla.spsolve(K.tocsc(), b), rtol=1e-10, atol=1e-12)
    assert np.allclose(x2, 0.5 * x1, rtol=1e-10, atol=1e-12)
    assert s.stats == {**NONE, "ldl_fresh": 1, "ldl_update": 1}


def test_a_moving_pattern_settles_on_the_union_of_the_patterns_seen():
    """Contact couplings that come and go (two-body penalty contact): a matrix inside the stored
    pattern reuses its analysis, new entries trigger one fresh analysis of the union."""
    K = _laplacian(10)
    n = K.shape[0]
    b = np.ones(n)

    def coupled(i, j):
        E = sp.csr_matrix(([0.5, 0.5], ([i, j], [j, i])), shape=(n, n))
        return (K + E).tocsr()

    s = SymmetricSolver("ldl")
    for A in (coupled(3, 40), coupled(7, 60), coupled(3, 40), K, coupled(7, 60)):
        x = s.solve(A, b)
        assert np.abs(A @ x - b).max() < 1e-10
    assert s.stats["ldl_fresh"] == 2 and s.stats["ldl_update"] == 3 and s.stats["fallback"] == 0


def test_saddle_point_falls_back_to_superlu():
    """A zero pivot (Lagrange-multiplier block) defeats LDLᵀ without pivoting: SuperLU answers."""
    A = _laplacian(4)
    B = sp.csr_matrix(np.eye(16)[:, :3])
    K = sp.bmat([[A, B], [B.T, None]], format="csr")
    K = K + sp.csr_matrix((np.zeros(3), (np.arange(16, 19), np.arange(16, 19))), shape=K.shape)
    b = np.arange(19, dtype=float)
    s = SymmetricSolver("ldl")
    x = s.solve(K, b)
    assert np.abs(K @ x - b).max() < 1e-10 * np.abs(b).max()
    assert s.stats["fallback"] == 1


def _full(U, diag):
    return (U + U.T - sp.diags(diag)).toarray()


def test_constrained_pattern_keeps_the_pattern_and_the_reduced_solution():
    """The upper triangle taken by indexing the CSR data: symmetric, the fixed rows and
    columns zeroed with diag_value on their diagonal, and the reduced problem's solution."""
    K = _laplacian(6)
    K.sort_indices()
    n = K.shape[0]
    fixed = np.array([0, 7, 20])
    free = np.setdiff1d(np.arange(n), fixed)
    b = np.linspace(1.0, 2.0, n)
    pattern = ConstrainedPattern(K.indptr, K.indices)
    U, diag = pattern.upper(K.data, fixed, 3.0)
    assert U.nnz == (K.nnz + n) // 2  # explicit zeros kept: the pattern never changes
    Kc = _full(U, diag)
    expected = K.toarray()
    expected[fixed, :] = 0.0
    expected[:, fixed] = 0.0
    expected[fixed, fixed] = 3.0
    assert np.array_equal(Kc, expected)
    x_c = np.array([0.25, -0.5, 1.0])
    rhs = b - K[:, fixed] @ x_c
    rhs[fixed] = 3.0 * x_c
    x = SymmetricSolver("ldl").solve_upper(U, diag, rhs, pattern)
    assert np.allclose(x[fixed], x_c)
    reduced = spla.spsolve(K[free][:, free].tocsc(), b[free] - K[free][:, fixed] @ x_c)
    assert np.allclose(x[free], reduced, rtol=1e-12)


def test_constrained_pattern_refuses_a_pattern_without_its_diagonal():
    K = sp.csr_matrix(np.array([[0.0, 1.0], [1.0, 2.0]]))
    K.eliminate_zeros()
    with pytest.raises(ValueError, match="diagonal"):
        ConstrainedPattern(K.indptr, K.indices)


def test_solve_upper_reuses_its_analysis_per_key_and_falls_back_on_a_zero_pivot():
    K = _laplacian(8)
    K.sort_indices()
    pattern = ConstrainedPattern(K.indptr, K.indices)
    b = np.ones(K.shape[0])
    s = SymmetricSolver("ldl")
    none = np.zeros(0, dtype=int)
    x1 = s.solve_upper(*pattern.upper(K.data, none, 1.0), b, pattern)
    x2 = s.solve_upper(*pattern.upper(2.0 * K.data, none, 1.0), b, pattern)
    assert np.allclose(x2, 0.5 * x1, rtol=1e-10)
    assert s.stats == {**NONE, "ldl_fresh": 1, "ldl_update": 1}
    # a zero diagonal entry first (LDLᵀ without pivoting breaks down): SuperLU answers
    A = K.copy()
    A.data[(np.repeat(np.arange(A.shape[0]), np.diff(A.indptr)) == A.indices) & (A.indices == 0)] = 0.0
    U, diag = pattern.upper(A.data, none, 1.0)
    s = SymmetricSolver("ldl")
    x = s.solve_upper(U, diag, b, pattern)
    assert np.abs(A @ x - b).max() < 1e-10
    assert s.stats["fallback"] == 1


def test_cholesky_reuses_its_analysis_keeps_explicit_zeros_and_gives_way_to_ldl():
    """The supernodal Cholesky on the constrained pattern: the reduced solution (the fixed rows
    and columns held as explicit zeros), a second matrix on the same analysis, and a matrix that
    is not positive definite refused and solved by LDLᵀ instead, counted."""
    K = _laplacian(8)
    K.sort_indices()
    n = K.shape[0]
    pattern = ConstrainedPattern(K.indptr, K.indices)
    fixed = np.array([0, 9, 30])
    U, diag = pattern.upper(K.data, fixed, 2.0)
    chol = SupernodalCholesky(U)
    chol.factor(U)
    b = np.linspace(-1.0, 1.0, n)
    assert np.abs(_full(U, diag) @ chol.solve(b) - b).max() < 1e-12
    s = SymmetricSolver("cholesky")
    x1 = s.solve_upper(U, diag, b, pattern)
    x2 = s.solve_upper(*pattern.upper(3.0 * K.data, fixed, 6.0), b, pattern)
    assert np.allclose(x2, x1 / 3.0, rtol=1e-12)
    assert np.allclose(s.resolve(b), x2, rtol=1e-12)  # the tangent predictor's solve, no refactorisation
    B = np.column_stack([b, b**2, -b])  # several right-hand sides in one supernodal solve
    X = s.resolve(B)
    assert X.shape == B.shape
    assert np.allclose(X, np.column_stack([s.resolve(c) for c in B.T]), rtol=0, atol=1e-14)
    assert s.stats == {**NONE, "cholesky_fresh": 1, "cholesky_update": 1}
    shifted = K - 0.5 * sp.eye(n, format="csr")  # the Laplacian's lowest eigenvalue is ~0.24
    shifted.sort_indices()
    U, diag = pattern.upper(shifted.data, fixed, 1.0)
    x = s.solve_upper(U, diag, b, pattern)
    assert np.abs(_full(U, diag) @ x - b).max() < 1e-9
    assert s.stats["not_definite"] == 1 and s.stats["ldl_fresh"] == 1 and s.stats["fallback"] == 0


def test_a_refused_matrix_is_replaced_by_its_definite_substitute_when_one_is_given():
    """solve_upper(..., definite): Cholesky refuses K and factors the substitute K' instead, so x
    solves K' x = b (a quasi-Newton step), counted; a substitute that is not definite either
    leaves K to LDLᵀ."""
    K = _laplacian(8)
    K.sort_indices()
    n = K.shape[0]
    pattern = ConstrainedPattern(K.indptr, K.indices)
    fixed = np.array([0, 9, 30])
    b = np.linspace(-1.0, 1.0, n)
    shifted = K - 0.5 * sp.eye(n, format="csr")
    shifted.sort_indices()
    U, diag = pattern.upper(shifted.data, fixed, 1.0)
    good = pattern.upper(K.data, fixed, 1.0)
    s = SymmetricSolver("cholesky")
    x = s.solve_upper(U, diag, b, pattern, lambda: good)
    assert np.abs(_full(*good) @ x - b).max() < 1e-12
    assert np.abs(_full(U, diag) @ x - b).max() > 0.1  # not K's solution
    assert s.stats == {**NONE, "cholesky_fresh": 1, "not_definite": 1, "substitute": 1}
    x = s.solve_upper(U, diag, b, pattern, lambda: pattern.upper(2.0 * shifted.data, fixed, 1.0))
    assert np.abs(_full(U, diag) @ x - b).max() < 1e-9
    assert s.stats["not_definite"] == 2 and s.stats["substitute"] == 1 and s.stats["ldl_fresh"] == 1


def test_the_shifted_diagonal_keeps_the_pattern_and_makes_a_slightly_indefinite_matrix_definite():
    """K + shift·|diag K| on U's own pattern: only the diagonal moves, a matrix with a small
    negative eigenvalue becomes one Cholesky accepts; a pattern without its diagonal is named."""
    K = _laplacian(8, shift=0.0)
    n = K.shape[0]
    lowest = spla.eigsh(K.tocsc(), k=1, sigma=0.0, return_eigenvectors=False)[0]
    K = (K - (lowest + 0.02) * sp.eye(n)).tocsr()  # one eigenvalue at -0.02
    K.sort_indices()
    pattern = ConstrainedPattern(K.indptr, K.indices)
    U, diag = pattern.upper(K.data, np.array([], dtype=int), 1.0)
    with pytest.raises(ArithmeticError):
        SupernodalCholesky(U).factor(U)
    U2, diag2 = shifted_diagonal(U, diag, 0.1)
    assert np.array_equal(U2.indices, U.indices) and np.array_equal(U2.indptr, U.indptr)
    assert np.allclose(diag2, 1.1 * np.abs(diag))
    assert np.abs(U2 - U).sum() == pytest.approx(0.1 * np.abs(diag).sum())  # the diagonal alone
    chol = SupernodalCholesky(U2)
    chol.factor(U2)
    b = np.linspace(-1.0, 1.0, n)
    assert np.abs(_full(U2, diag2) @ chol.solve(b) - b).max() < 1e-10
    with pytest.raises(ValueError, match="diagonal"):
        shifted_diagonal(sp.triu(U, k=1, format="csc"), diag, 0.1)


def test_a_refused_one_body_tangent_is_shifted_not_left_to_ldl():
    """E/σY 10⁴ on a flat, fully plastic: Cholesky refuses some tangents. With ``definite_shift``
    each is factored shifted (no LDLᵀ at all); with 0 they go to LDLᵀ. Over the same increments
    both converge to the same curve: the shift changes Newton's path, not its answer."""
    mat = Material(E=1e4, nu=0.3, sigma_y=1.0)
    exact = IndentationSolver(mat, 1.0, density=0.5, options=SolverOptions(definite_shift=0.0))
    a = exact.run(0.02)
    shifted = IndentationSolver(mat, 1.0, density=0.5, options=SolverOptions(definite_shift=0.1))
    b = shifted.run(0.02, schedule=a.h[a.h > 0])
    assert a.status == b.status == "converged"
    assert exact.linear.stats["not_definite"] > 0 and exact.linear.stats["ldl_update"] > 0
    stats = shifted.linear.stats
    assert stats["substitute"] == stats["not_definite"] > 0
    assert stats["ldl_fresh"] == stats["ldl_update"] == stats["fallback"] == 0
    assert np.array_equal(a.h, b.h) and np.abs(b.F / a.F - 1)[a.F > 0].max() < 1e-3
    with pytest.raises(ValueError, match=r"definite_shift must be a number in \[0, 10\]"):
        SolverOptions(definite_shift=-0.1).validate()


def test_bad_method_is_named():
    with pytest.raises(ValueError, match="'cholesky', 'ldl', 'superlu'"):
        SymmetricSolver("cholmod")
    with pytest.raises(ValueError, match="linear_solver"):
        SolverOptions(linear_solver="pardiso").validate()


@pytest.mark.parametrize("indenter", [np.inf, 1.5])
def test_cholesky_ldl_and_superlu_give_the_same_run(indenter):
    """Flat (constrained z dofs) and rigid sphere (nodal frames rotated in place): the Cholesky
    and LDLᵀ paths keep one symbolic analysis each for the whole run and reproduce SuperLU's
    answer."""
    runs = {}
    for method in ("cholesky", "ldl", "superlu"):
        s = IndentationSolver(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, RigidObstacle(indenter),
                              density=0.5, options=SolverOptions(linear_solver=method))
        runs[method] = s.run(0.004)
    a, b = runs["ldl"], runs["superlu"]
    assert a.status == b.status == "converged"
    assert np.array_equal(a.curves["iterations"], b.curves["iterations"])
    assert np.allclose(a.F, b.F, rtol=1e-9)
    assert a.timings["linear_ldl_fresh"] == 1
    # every later factorisation (rejected increments' included) reuses the first analysis
    assert a.timings["linear_ldl_update"] >= a.timings["newton_iterations"] - 1
    assert a.timings["linear_fallback"] == 0 and b.timings["linear_superlu"] >= b.timings["newton_iterations"]
    c = runs["cholesky"]
    assert np.array_equal(c.curves["iterations"], b.curves["iterations"])
    assert np.allclose(c.F, b.F, rtol=1e-9)
    assert c.timings["linear_cholesky_fresh"] == 1
    assert c.timings["linear_cholesky_update"] >= c.timings["newton_iterations"] - 1
    assert c.timings["linear_fallback"] == 0


def _saddle(n: int = 6, m: int = 3, seed: int = 0):
    """[[K, Bᵀ], [B, 0]] with K an SPD Laplacian (n² dofs) and m constraint rows."""
    K = _laplacian(n)
    rng = np.random.default_rng(seed)
    B = sp.csr_matrix(rng.standard_normal((m, K.shape[0])) * (rng.random((m, K.shape[0])) < 0.2))
    A = sp.bmat([[K, B.T], [B, sp.csr_matrix((m, m))]], format="csc")
    return A, rng.standard_normal(A.shape[0])


def test_the_saddle_point_system_the_plain_ldl_cannot_factor_is_solved_by_regularised_ldl():
    """The multiplier block that defeats LDLᵀ without pivoting (test above) is factored as the
    quasi-definite A − δI: no SuperLU, the refinement on A brings the residual to rounding, and a
    second matrix of the same pattern reuses the analysis."""
    A, b = _saddle()
    s = SymmetricSolver("ldl")
    x = s.solve_saddle(A, b, 3)
    assert np.abs(A @ x - b).max() < 1e-12 * np.abs(b).max()
    assert np.allclose(x, spla.spsolve(A, b), rtol=1e-10, atol=1e-12)
    x2 = s.solve_saddle(2.0 * A, b, 3)
    assert np.allclose(x2, 0.5 * x, rtol=1e-10, atol=1e-12)
    assert s.stats == {**NONE, "ldl_fresh": 1, "ldl_update": 1}


def test_the_regularisation_is_refined_away(monkeypatch):
    """With a large δ the first LDLᵀ solution misses the rtol of the check; the refinement steps
    on A recover the exact solution without SuperLU."""
    import spherecontact.fem.linsolve as ls

    monkeypatch.setattr(ls, "REGULARISATION", 1e-4)
    A, b = _saddle()
    s = SymmetricSolver("ldl")
    x = s.solve_saddle(A, b, 3)
    first = s._solver.solve(b)  # the regularised solution alone
    assert np.abs(A @ first - b).max() > ls.RTOL * np.abs(b).max()
    assert np.abs(A @ x - b).max() <= ls.RTOL * np.abs(b).max()
    assert s.stats["fallback"] == 0


def test_a_saddle_point_system_beyond_the_refinement_falls_back_to_superlu(monkeypatch):
    """A δ so large that three refinement steps cannot reach rtol: SuperLU answers, counted."""
    import spherecontact.fem.linsolve as ls

    monkeypatch.setattr(ls, "REGULARISATION", 10.0)
    A, b = _saddle()
    s = SymmetricSolver("ldl")
    x = s.solve_saddle(A, b, 3)
    assert np.abs(A @ x - b).max() < 1e-10 * np.abs(b).max()
    assert s.stats["fallback"] == 1


def test_saddle_and_plain_solves_share_one_solver():
    """A two-body run alternates systems without constraints (plain LDLᵀ on the union pattern)
    and with them (regularised LDLᵀ on the exact pattern): each path keeps to its own analysis."""
    A, b = _saddle()
    K = _laplacian(6)
    s = SymmetricSolver("ldl")
    for sys_, m in ((K, 0), (A, 3), (K, 0), (K, 0), (A, 3)):
        rhs = b[:sys_.shape[0]]
        x = s.solve_saddle(sys_, rhs, m)
        assert np.abs(sys_ @ x - rhs).max() < 1e-10 * np.abs(rhs).max()
    assert s.stats["fallback"] == 0 and s.stats["ldl_fresh"] == 4 and s.stats["ldl_update"] == 1


@pytest.mark.parametrize("method", ["cholesky", "ldl", "superlu"])
def test_resolve_reuses_the_factors_of_the_last_accepted_solution(method):
    K = _laplacian(12)
    rng = np.random.default_rng(1)
    s = SymmetricSolver(method)
    assert s.resolve(np.ones(K.shape[0])) is None  # nothing factored yet
    s.solve(K, rng.standard_normal(K.shape[0]))
    b = rng.standard_normal(K.shape[0])
    counts = dict(s.stats)
    assert np.allclose(K @ s.resolve(b), b, rtol=0, atol=1e-10)
    B = rng.standard_normal((K.shape[0], 3))  # several right-hand sides: columns of the result
    assert np.allclose(K @ s.resolve(B), B, rtol=0, atol=1e-10)
    assert s.stats == counts  # no factorisation


def test_resolve_after_a_fallback_uses_superlus_factors():
    K = _laplacian(8).tolil()
    K[0, 0] = 0.0  # zero first pivot: LDLᵀ without pivoting breaks down
    K = K.tocsr()
    s = SymmetricSolver("ldl")
    s.solve(K, np.ones(K.shape[0]))
    assert s.stats["fallback"] == 1
    b = np.arange(K.shape[0], dtype=float)
    assert np.allclose(K @ s.resolve(b), b, rtol=0, atol=1e-9)
