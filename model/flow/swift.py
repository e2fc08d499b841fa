"""Swift hardening σ_f = σ_Y (1 + ε_p/ε₀)^n, i.e. K (ε₀ + ε_p)^n with K = σ_Y ε₀^(−n)
(Swift 1952, J. Mech. Phys. Solids 1, 1–18)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import FlowCurve, check_parameter

__all__ = ["Swift"]


@dataclass(frozen=True)
class Swift(FlowCurve):
    """σ_f = σ_Y (1 + ε_p/ε₀)^n; dσ_f/dε_p = σ_Y (n/ε₀) (1 + ε_p/ε₀)^(n−1);
    d ln σ_f/d ln ε_p = n ε_p/(ε₀ + ε_p).

    Parameters
    ----------
    sigma_y : initial yield stress σ_Y, in (0, inf).
    eps0 : strain offset ε₀, in (0, 5] (a fraction, not per cent).
    n : hardening exponent, in [0, 1] (0: perfectly plastic).
    """

    name = "swift"
    kind = "Swift curve"

    sigma_y: float
    eps0: float
    n: float

    def __post_init__(self) -> None:
        check_parameter(self.name, "sigma_y", self.sigma_y, 0.0, lo_open=True)
        check_parameter(self.name, "eps0", self.eps0, 0.0, 5.0, lo_open=True)
        check_parameter(self.name, "n", self.n, 0.0, 1.0)

    def _stress(self, e):
        return self.sigma_y * (1.0 + e / self.eps0) ** self.n

    def _slope(self, e):
        return self.sigma_y * self.n / self.eps0 * (1.0 + e / self.eps0) ** (self.n - 1.0)

    def log_slope(self, eps):
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        return self.n * e / (self.eps0 + e)

    def hardens(self) -> bool:
        return self.n > 0.0
