"""Voce saturation σ_f = σ_Y + Q σ_Y (1 − e^(−b ε_p)) (Voce 1948, J. Inst. Metals 74, 537–562),
with the saturation stress written relative to σ_Y as the FE campaign writes it
(``Q_over_sigma_y``, ``b``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import FlowCurve, check_parameter

__all__ = ["Voce"]


@dataclass(frozen=True)
class Voce(FlowCurve):
    """σ_f = σ_Y + Q σ_Y (1 − e^(−b ε_p)); dσ_f/dε_p = Q σ_Y b e^(−b ε_p).

    Parameters
    ----------
    sigma_y : initial yield stress σ_Y, in (0, inf).
    Q : saturation increase over σ_Y, relative to σ_Y, in [0, 1e4] (0: perfectly plastic).
    b : saturation rate, in (0, 1e5] (the stress saturates over ε_p ~ 1/b).
    """

    name = "voce"
    kind = "Voce curve"

    sigma_y: float
    Q: float
    b: float

    def __post_init__(self) -> None:
        check_parameter(self.name, "sigma_y", self.sigma_y, 0.0, lo_open=True)
        check_parameter(self.name, "Q", self.Q, 0.0, 1e4)
        check_parameter(self.name, "b", self.b, 0.0, 1e5, lo_open=True)

    def saturation(self, eps_p):
        """The saturating term Q σ_Y (1 − e^(−b ε_p)) alone (ε_p < 0 treated as 0); the
        campaign adds it to a Ludwik curve."""
        e = np.maximum(np.asarray(eps_p, dtype=float), 0.0)
        return self.Q * self.sigma_y * -np.expm1(-self.b * e)

    def _stress(self, e):
        return self.sigma_y + self.Q * self.sigma_y * -np.expm1(-self.b * e)

    def _slope(self, e):
        return self.Q * self.sigma_y * self.b * np.exp(-self.b * e)

    def hardens(self) -> bool:
        return self.Q > 0.0
