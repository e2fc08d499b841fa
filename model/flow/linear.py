"""Linear hardening σ_f = σ_Y + H ε_p (H: the plastic modulus)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import FlowCurve, check_parameter

__all__ = ["Linear"]


@dataclass(frozen=True)
class Linear(FlowCurve):
    """σ_f = σ_Y + H ε_p; dσ_f/dε_p = H.

    Parameters
    ----------
    sigma_y : initial yield stress σ_Y, in (0, inf).
    H : plastic (hardening) modulus, in [0, inf) (0: perfectly plastic).
    """

    name = "linear"
    kind = "linear hardening"

    sigma_y: float
    H: float

    def __post_init__(self) -> None:
        check_parameter(self.name, "sigma_y", self.sigma_y, 0.0, lo_open=True)
        check_parameter(self.name, "H", self.H, 0.0)

    def _stress(self, e):
        return self.sigma_y + self.H * e

    def _slope(self, e):
        return np.full_like(e, float(self.H))

    def hardens(self) -> bool:
        return self.H > 0.0
