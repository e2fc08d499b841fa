"""Least-squares fit of a candidate form to the FE points (scipy ``least_squares``, bounds).

Residuals are the log ratios model/FE of the two quantities at every point,

    r_H = ln(p_m,model/p_m,FE) = ln(H̄_model/H̄_FE),   r_c = ln(c²_model/c²_FE),

(p_m rather than H̄ so that β, which moves σ_rep, is fitted consistently). Every
point weighs the same; the points are uniform in ln h per run (``dataset``), so each
run counts by the decades of h it covers, not by its number of increments.

The fit is deterministic: fixed start values (the form's), a fixed list of restarts
in the level boundaries, trust-region reflective with the 2-point Jacobian. The
fitted parameters are rounded to ``SIGNIFICANT`` digits before the coefficient set is
built, and the residuals are those of the rounded set (what is written is what is
measured).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..model.coefficients import Coefficients
from .dataset import Dataset
from .forms import Form, predict

__all__ = ["SIGNIFICANT", "FitResult", "fit", "errors", "round_sig", "rms"]

#: significant digits of the written coefficients
SIGNIFICANT = 6
#: restarts of the main fit: start values of ln(Λ_III/Λ_I)
RESTARTS = (math.log(30.0), math.log(300.0))


def round_sig(x: float, digits: int = SIGNIFICANT) -> float:
    """``x`` rounded to ``digits`` significant digits (exactly representable text)."""
    return float(f"{x:.{digits}g}")


def _round_tree(v):
    if isinstance(v, float):
        return round_sig(v)
    if isinstance(v, dict):
        return {k: _round_tree(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_round_tree(x) for x in v]
    return v


def rms(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(np.sqrt(np.mean(x * x))) if x.size else math.nan


def errors(ds: Dataset, coeffs: Coefficients) -> dict[str, np.ndarray]:
    """Relative errors model/FE − 1 of H̄ (= of p_m) and c² at every point."""
    p, c = predict(ds, coeffs)
    return {"H_bar": p / ds.p_m - 1.0, "c2": c / ds.c2 - 1.0}


@dataclass
class FitResult:
    """A fitted form: parameters, the (rounded) coefficient set and its errors."""

    form: Form
    params: np.ndarray
    coeffs: Coefficients
    coeff_dict: dict
    errors: dict[str, np.ndarray]
    nfev: int
    status: int
    at_bounds: list[str] = field(default_factory=list)

    def summary(self) -> dict:
        """RMS and max |error| per quantity."""
        return {q: {"rms": rms(e), "max": float(np.max(np.abs(e)))} for q, e in self.errors.items()}


def _residuals(form: Form, ds: Dataset):
    bad = np.full(2 * ds.size, 10.0)

    def f(params):
        try:
            co = form.coefficients(params)
        except ValueError:  # e.g. Λ_I ≥ Λ_III cannot happen with the log parametrisation
            return bad
        p, c = predict(ds, co)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.concatenate([np.log(p / ds.p_m), np.log(c / ds.c2)])
        return np.where(np.isfinite(r), r, 10.0)

    return f


def _solve(form: Form, ds: Dataset, x0: np.ndarray, max_nfev: int | None):
    lo, hi = form.bounds()
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    return least_squares(_residuals(form, ds), x0, bounds=(lo, hi), x_scale="jac",
                         method="trf", max_nfev=max_nfev, ftol=1e-9, xtol=1e-9)


def fit(ds: Dataset, form: Form, start: np.ndarray | None = None,
        max_nfev: int | None = None) -> FitResult:
    """Fit ``form`` to ``ds``.

    Parameters
    ----------
    ds : calibration points.
    form : candidate form.
    start : start parameters (warm start, e.g. the full fit for a cross-validation fold);
        default: the form's start values with the restarts ``RESTARTS``.
    max_nfev : evaluation limit per solve (None: scipy's default).
    """
    if start is not None:
        best = _solve(form, ds, np.asarray(start, dtype=float), max_nfev)
        nfev = best.nfev
    else:
        best, nfev = None, 0
        i = form.names.index("ln_Lambda_III_over_I")
        for r in RESTARTS:
            x0 = form.start()
            x0[i] = r
            sol = _solve(form, ds, x0, max_nfev)
            nfev += sol.nfev
            if best is None or sol.cost < best.cost:
                best = sol
    d = _round_tree(form.to_dict(best.x))
    co = Coefficients.from_dict(d)
    lo, hi = form.bounds()
    tol = 1e-6 * (hi - lo)
    at = [n for n, x, a, b, t in zip(form.names, best.x, lo, hi, tol, strict=True)
          if x - a < t or b - x < t]
    return FitResult(form=form, params=best.x, coeffs=co, coeff_dict=d, errors=errors(ds, co),
                     nfev=nfev, status=int(best.status), at_bounds=at)
