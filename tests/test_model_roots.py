"""The vectorised safeguarded root solver (model/roots.py)."""

import warnings

import numpy as np
import pytest

from spherecontact.model import Material, Sphere
from spherecontact.model import unified as U
from spherecontact.model.fast import ContactLaw
from spherecontact.model.roots import solve_increasing

ROOTS = np.linspace(-3.0, 3.0, 41)


@pytest.mark.parametrize("shape", ["cbrt", "kink", "tanh"])
def test_roots_of_hard_increasing_functions(shape):
    """Newton oscillates on cbrt (infinite slope at the root), overshoots a kink and stalls
    on tanh far from the root: the bracket steps must still close on every root."""
    def f(x, idx):
        d = x - ROOTS[idx]
        if shape == "cbrt":
            return np.cbrt(d), 1.0 / (3.0 * np.maximum(np.abs(d), 1e-300) ** (2.0 / 3.0))
        if shape == "kink":
            return np.where(d < 0, d, 50.0 * d), np.where(d < 0, 1.0, 50.0)
        return np.tanh(5.0 * d), 5.0 / np.cosh(5.0 * d) ** 2
    x = solve_increasing(f, np.zeros_like(ROOTS), tol=1e-14)
    assert np.abs(x - ROOTS).max() < 1e-12


def test_non_convergence_is_reported():
    with pytest.raises(ValueError, match=r"did not converge for \d+ of 41 elements"):
        solve_increasing(lambda x, idx: (np.cbrt(x - ROOTS[idx]), np.ones_like(x)),
                         np.zeros_like(ROOTS), maxiter=3)


def test_non_convergence_leaves_nan_when_not_strict():
    """strict=False: the elements still open after maxiter are NaN, the converged ones exact."""
    def f(x, idx):  # element 0 converges at once (linear), the others cannot in 3 iterations
        lin = idx == 0
        return np.where(lin, x - ROOTS[idx], np.cbrt(x - ROOTS[idx])), np.ones_like(x)
    x = solve_increasing(f, np.zeros_like(ROOTS), maxiter=3, strict=False)
    assert x[0] == pytest.approx(ROOTS[0], abs=1e-14)
    assert np.isnan(x[1:]).sum() >= 1 and np.all(np.isnan(x) | (np.abs(x - ROOTS) < 1e-12))


def test_table_of_a_dissimilar_pair_needs_few_kappa_iterations(monkeypatch):
    """The interface-curvature solve over the ~600 table nodes of a steel-aluminium pair: the
    false-position closing step keeps the slowest node under 15 iterations (bisection
    alone took 35), which is most of the table's setup cost."""
    counts = []

    def counted(f, x0, **kw):
        n = [0]

        def g(x, idx):
            n[0] += 1
            return f(x, idx)
        out = solve_increasing(g, x0, **kw)
        counts.append((np.size(x0), n[0]))
        return out

    monkeypatch.setattr(U, "solve_increasing", counted)
    steel = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
    alu = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ContactLaw(Sphere(1e-3, steel), Sphere(2e-3, alu))
    evaluations = max(n for size, n in counts if size > 500)
    assert 3 <= evaluations <= 15


def _counting(f):
    """f wrapped to count its calls (one call evaluates all active elements)."""
    calls = [0]

    def g(x, idx):
        calls[0] += 1
        return f(x, idx)
    return g, calls


def test_newton_step_below_tol_on_a_bracket_end_converges():
    """An inversion-like equation, ln h(t) − ln h* with ln h ≈ 2t + 7.3 ≈ −30: rounding of
    ln h is about an ulp of t, so once Newton has landed on the root the next Newton step can
    round to t itself, a bracket end. It converges there (it used to be rejected, reopening
    the bracket: 44 calls instead of 2, and residuals up to 3e-13)."""
    rng = np.random.default_rng(3)
    target = rng.uniform(-32.0, -28.0, 400)

    def lnh(x, idx):
        e = 1e-8 * np.exp(x)
        return 2.0 * x + np.log1p(e) + 7.3 - target[idx], 2.0 + e / (1.0 + e)
    f, calls = _counting(lnh)
    x = solve_increasing(f, 0.5 * (target - 7.3) + 0.3, step=0.5, tol=1e-14)
    assert np.abs(lnh(x, np.arange(target.size))[0]).max() <= 1e-14
    assert calls[0] <= 3


def test_far_root_is_approached_by_clipped_newton_steps():
    """While the bracket is open the Newton step, clipped to max_step, sets the expansion
    when it is longer than the doubling step (1, 2, 4, ... from ``step``)."""
    roots = np.array([5.0, 7.5, 11.0])
    f, calls = _counting(lambda x, idx: (x - roots[idx], np.ones_like(x)))
    x = solve_increasing(f, np.zeros(3), step=1.0, max_step=4.0, tol=1e-14)
    assert np.array_equal(x, roots)
    assert calls[0] <= 4  # doubling steps alone: 0, 1, 3, 7, then Newton (5 calls)
