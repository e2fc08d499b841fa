"""Vectorised safeguarded Newton iteration for monotone increasing scalar equations f(x) = 0.

One root per array element, all solved together: no Python loop over elements,
only over iterations (each iteration evaluates f on the still-active elements).
Newton steps are accepted inside the current bracket; otherwise the bracket is
closed by a false-position step with the Illinois modification (Dowell & Jarratt
1971: the stored end value that is kept twice in a row is halved, which makes the
step superlinear also where f has a kink, e.g. at a level boundary), or — while one
side of the bracket is still unknown — expanded towards the root by the longer of a
doubling step and the Newton step clipped to ``max_step``.
Every evaluation tightens the bracket. An element has converged when its step is below
``tol``; a Newton step below ``tol`` counts even where rounding puts it on a bracket end
(f within rounding of 0), which would otherwise take an expansion or closing step away
from the root.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["solve_increasing"]


def solve_increasing(
    f: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    x0: np.ndarray,
    step: float = 1.0,
    tol: float = 1e-13,
    max_step: float = 4.0,
    maxiter: int = 200,
    describe: Callable[[np.ndarray], str] | None = None,
    strict: bool = True,
) -> np.ndarray:
    """Solve f(x) = 0 element-wise for f increasing in x.

    Parameters
    ----------
    f : ``f(x, idx) -> (value, derivative)`` evaluated at ``x`` for the elements ``idx``
        (indices into the full problem), both arrays shaped like ``x``.
    x0 : initial guesses (1-D).
    step : first bracket-expansion step; doubled on each expansion.
    tol : absolute convergence tolerance on x (x is a log variable in this package).
    max_step : largest Newton step accepted while the bracket is open on that side.
    maxiter : iteration limit; ValueError if some elements have not converged.
    describe : ``describe(idx) -> str`` names the inputs of the elements ``idx`` in the
        ValueError raised when they do not converge or f is NaN there.
    strict : False: elements that have not converged after ``maxiter`` iterations are NaN
        in the result instead of raising (a NaN f still raises).

    Returns
    -------
    x : roots, shaped like ``x0``.
    """
    x = np.array(x0, dtype=float)
    n = x.size
    lo = np.full(n, -np.inf)
    hi = np.full(n, np.inf)
    f_lo = np.full(n, np.nan)  # f at the bracket ends (Illinois-scaled)
    f_hi = np.full(n, np.nan)
    side = np.zeros(n, dtype=np.int8)  # end moved last: +1 hi, -1 lo
    width = np.full(n, step)
    idx = np.arange(n)
    fx, dx = f(x, idx)
    for it in range(maxiter):
        if idx.size == 0:
            return x
        xi = x[idx]
        _check_defined(fx, xi, idx, n, describe)
        done = fx == 0.0
        pos = fx > 0.0
        neg = ~pos & ~done
        l = np.where(neg, xi, lo[idx])
        h = np.where(pos, xi, hi[idx])
        lo[idx], hi[idx] = l, h
        s_old = side[idx]
        fl, fh = f_lo[idx], f_hi[idx]
        fl = np.where(neg, fx, np.where(pos & (s_old == 1), 0.5 * fl, fl))
        fh = np.where(pos, fx, np.where(neg & (s_old == -1), 0.5 * fh, fh))
        f_lo[idx], f_hi[idx] = fl, fh
        side[idx] = np.where(pos, 1, np.where(neg, -1, s_old))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            newton = xi - fx / dx
        expand_down, expand_up = ~np.isfinite(l), ~np.isfinite(h)
        bracketed = ~(expand_down | expand_up)
        usable = np.isfinite(newton) & (dx > 0.0)
        step_n = np.abs(newton - xi)  # the Newton step's length
        small = tol * np.maximum(1.0, np.abs(xi))  # convergence threshold
        ok = usable & (newton > l) & (newton < h)
        ok &= step_n <= np.where(bracketed, np.inf, max_step)
        if it % 8 == 7:  # guard against slow Newton progress near kinks
            ok &= ~bracketed
        # a Newton step below tol converges even where rounding puts it on a bracket end
        ok |= usable & (step_n <= small)
        w = width[idx]
        # expansion towards the root: the doubling width, or the rejected Newton step up to max_step
        with np.errstate(invalid="ignore"):
            reach = np.maximum(w, np.where(usable, np.minimum(step_n, max_step), 0.0))
        with np.errstate(invalid="ignore", divide="ignore"):
            regula = l - fl * (h - l) / (fh - fl)
            inside = np.isfinite(regula) & (regula > l) & (regula < h)
            closing = np.where(inside, regula, 0.5 * (l + h))
        xn = np.where(ok, newton, np.where(expand_down, xi - reach, np.where(expand_up, xi + reach, closing)))
        width[idx] = np.where(~ok & ~bracketed, 2.0 * w, w)
        conv = done | (np.abs(xn - xi) <= small)
        x[idx] = np.where(done, xi, xn)
        keep = ~conv
        idx = idx[keep]
        if idx.size == 0:
            return x
        fx, dx = f(x[idx], idx)
    if not strict:
        x[idx] = np.nan
        return x
    raise ValueError(_failure(f"root solve did not converge for {idx.size} of {n} elements", idx,
                              describe))


def _failure(text: str, idx: np.ndarray, describe) -> str:
    """The error text, with the inputs of the failing elements if ``describe`` is given."""
    return text if describe is None else f"{text}: {describe(idx)}"


def _check_defined(fx, xi, idx, n: int, describe) -> None:
    """ValueError naming the inputs where f is NaN (no sign, so no bracket can be kept)."""
    bad = np.isnan(fx)
    if np.any(bad):
        raise ValueError(_failure(f"root solve: the equation is undefined (NaN) for {int(bad.sum())} of "
                                  f"{n} elements (e.g. at x = {xi[bad][0]:.6g})", idx[bad], describe))
