"""Ludwik hardening σ_f = σ_Y + K ε_p^n (K = 0: elastic–perfectly plastic; n = 1: linear).

σ_Y = ∞ is an elastic body (it never yields). Ludwik's slope K n ε^(n−1) is infinite at ε_p = 0
for n < 1; it is evaluated at max(ε_p, ``EPS_SLOPE_FLOOR``) so that Newton solvers get a large but
finite slope, and the return mapping solves such curves in y = ε_p^n instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .averages import ludwik_representative_stress
from .base import FlowCurve

__all__ = ["Ludwik", "EPS_SLOPE_FLOOR"]

#: floor of ε_p in the slope K n ε^(n−1) (n < 1)
EPS_SLOPE_FLOOR = 1e-12


def _finite(name: str, value) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return value


@dataclass(frozen=True)
class Ludwik(FlowCurve):
    """σ_f = σ_Y + K ε_p^n.

    Parameters
    ----------
    sigma_y : initial yield stress σ_Y, > 0 (inf: elastic).
    K : hardening modulus, >= 0 (0: perfectly plastic).
    n : hardening exponent, >= 0, and > 0 when K > 0 (n = 0 would be a yield jump to σ_Y + K).
    """

    name = "ludwik"
    kind = "Ludwik"
    checks_local_slope = False
    exponent_label = "hardening exponent n"
    magnitude_label = "hardening magnitude K/sigma_y"

    sigma_y: float
    K: float = 0.0
    n: float = 1.0

    def __post_init__(self) -> None:
        sy = float(self.sigma_y)
        if math.isnan(sy) or sy <= 0.0:
            raise ValueError(f"sigma_y (yield stress) must be > 0 (inf: elastic), got {self.sigma_y!r}")
        K = _finite("K", self.K)
        n = _finite("n", self.n)
        if K < 0.0:
            raise ValueError(f"K (Ludwik hardening modulus) must be >= 0, got {K!r}")
        if n < 0.0:
            raise ValueError(f"n (Ludwik hardening exponent) must be >= 0, got {n!r}")
        if n == 0.0 and K > 0.0:
            raise ValueError(
                f"n = 0 with K = {K!r} > 0 makes the flow stress jump from sigma_y = {sy!r} to "
                f"sigma_y + K = {sy + K!r} at the first plastic strain; for a perfectly plastic "
                f"material write sigma_y = {sy + K!r}, K = 0 (or give n > 0 for hardening)")

    def _stress(self, e):
        if self.K == 0.0:
            return np.full_like(e, self.sigma_y)
        return self.sigma_y + self.K * e**self.n

    def _slope(self, e):
        if self.K == 0.0 or self.n == 0.0:
            return np.zeros_like(e)
        return self.K * self.n * np.maximum(e, EPS_SLOPE_FLOOR) ** (self.n - 1.0)

    def log_slope(self, eps):
        """m = n K εⁿ/(σ_Y + K εⁿ) (0 for perfect plasticity and elastic bodies)."""
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        if self.K == 0.0 or self.n == 0.0 or math.isinf(self.sigma_y):
            return np.zeros_like(e)
        t = self.K * e**self.n
        return self.n * t / (self.sigma_y + t)

    def representative(self, eps, spread: float = 0.0):
        """Closed form of the strain average (``averages.ludwik_representative_stress``)."""
        if spread == 0.0:
            return self.stress(eps), self.log_slope(eps)
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        return ludwik_representative_stress(self.sigma_y, self.K, self.n, e, spread)

    def hardens(self) -> bool:
        return self.K > 0.0

    def range_exponent(self, eps_lo: float, eps_hi: float, spread: float = 0.0) -> float:
        """n itself (0 for perfect plasticity): the calibrated-range axis is Ludwik's n."""
        return self.n if self.K > 0.0 else 0.0

    def hardening_magnitude(self, eps_lo: float, eps_hi: float) -> float:
        """K/σ_Y."""
        return self.K / self.sigma_y

    def plastic_multiplier(self, q_tr, eps_p_n, mu: float, tol: float = 1e-12, maxit: int = 100):
        """Perfect plasticity in closed form, n < 1 in y = ε_p^n (:meth:`_multiplier_power`),
        else the generic bracketed Newton."""
        q_tr = np.asarray(q_tr, dtype=float)
        if self.K == 0.0:
            return (q_tr - self.sigma_y) / (3.0 * mu)
        if 0.0 < self.n < 1.0:
            return self._multiplier_power(q_tr, np.asarray(eps_p_n, dtype=float), mu, tol, maxit)
        return super().plastic_multiplier(q_tr, eps_p_n, mu, tol, maxit)

    def _multiplier_power(self, q_tr, eps_p_n, mu: float, tol: float, maxit: int):
        """The root of q_tr − 3μΔγ − σ_f = 0 in y = (ε_p,n + Δγ)^n for n < 1.

        dσ_f/dε_p is unbounded at ε_p → 0, but in y the residual
        q_tr − 3μ (y^(1/n) − ε_p,n) − σ_Y − K y is smooth with slope −3μ y^(1/n−1)/n − K,
        so bracketed Newton converges at the onset of yield too. A point is converged where
        |residual| ≤ tol σ_Y or its bracket has shrunk to the roundoff of y.
        """
        n, K, sy = self.n, self.K, self.sigma_y
        lo = eps_p_n**n
        hi = (eps_p_n + q_tr / (3.0 * mu)) ** n
        y = lo.copy()
        for _ in range(maxit):
            r = q_tr - 3.0 * mu * (y ** (1.0 / n) - eps_p_n) - sy - K * y
            # converged, or the bracket has shrunk to the roundoff of y (3μ y^(1/n) cancels
            # ε_p,n: at E/σY = 1e4 and ε_p ~ 1 its roundoff alone is ~1e-12 σY)
            done = (np.abs(r) <= tol * sy) | (hi - lo <= 4e-16 * y + 1e-300)
            if np.all(done):
                break
            lo = np.where(r > 0, y, lo)
            hi = np.where(r < 0, y, hi)
            slope = 3.0 * mu * y ** (1.0 / n - 1.0) / n + K
            y_new = y + r / slope
            bisect = (y_new <= lo) | (y_new >= hi)
            y = np.where(done, y, np.where(bisect, 0.5 * (lo + hi), y_new))
        else:
            raise RuntimeError("return mapping: plastic multiplier did not converge")
        return np.maximum(y ** (1.0 / n) - eps_p_n, 0.0)

    def material_description(self) -> dict:
        """``{"sigma_y", "K", "n"}`` as given (no "flow" key: the stored runs' form)."""
        return {"sigma_y": self.sigma_y, "K": self.K, "n": self.n}

    def text(self) -> str:
        return f"sigma_y = {self.sigma_y:.6g}, K = {self.K:.6g}, n = {self.n:.6g}"

    def label(self, sy: str = "sy") -> str:
        """``K/sy=… n=…``; empty for perfect plasticity."""
        return f"K/{sy}={self.K / self.sigma_y:g} n={self.n:g}" if self.K > 0.0 else ""
