"""The flow-curve protocol: uniaxial flow stress σ_f(ε_p) against equivalent plastic strain.

Every law is a frozen dataclass whose first field is the initial yield stress ``sigma_y`` and whose
other fields are its parameters (validated once, in ``__post_init__``). A law implements
:meth:`FlowCurve._stress` and :meth:`FlowCurve._slope` at strains ε ≥ 0; everything the model and
the FE solver read from a flow curve (the log slope, the strain-averaged representative stress, the
secant exponent and hardening magnitude of the calibrated range, the return mapping's scalar
equation, smooth pieces) has a generic form here that any monotone curve satisfies; a law overrides
one where it has a closed form (``ludwik.py``).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import fields
from typing import ClassVar

import numpy as np

from .averages import spread_average

__all__ = ["FlowCurve", "check_parameter"]


def check_parameter(law: str, name: str, value, lo: float = -math.inf, hi: float = math.inf, *,
                    lo_open: bool = False, allow_inf: bool = False) -> float:
    """``value`` as a float if it lies in the range (``lo_open``: lo excluded), else ValueError
    naming the law, the parameter, its value and the allowed range."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{law}: {name} must be a number, got {value!r}") from None
    below = v <= lo if lo_open else v < lo
    if math.isnan(v) or (math.isinf(v) and not allow_inf) or below or v > hi:
        rng = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{']' if math.isfinite(hi) else ')'}"
        raise ValueError(f"{law}: {name} = {value!r} is outside the allowed range {rng}")
    return v


class FlowCurve(ABC):
    """A monotone (non-decreasing) flow curve σ_f(ε_p), σ_f(0) = σ_Y = ``sigma_y``.

    Subclasses are frozen dataclasses with ``sigma_y`` first; ``name`` is the registry name
    (``registry.REGISTRY``), ``kind`` a few words for messages.
    """

    name: ClassVar[str] = ""
    kind: ClassVar[str] = ""
    #: the calibrated-range check reads the local log slope along the curve (Ludwik: its n)
    checks_local_slope: ClassVar[bool] = True
    #: smooth pieces of the curve (a table: its segments)
    segments: ClassVar[int] = 1

    sigma_y: float

    # ------------------------------------------------------------------ the law
    @abstractmethod
    def _stress(self, e: np.ndarray) -> np.ndarray:
        """σ_f at strains e ≥ 0 (an array)."""

    @abstractmethod
    def _slope(self, e: np.ndarray) -> np.ndarray:
        """dσ_f/dε_p at strains e ≥ 0 (an array; the right derivative at a kink)."""

    @classmethod
    def parameter_names(cls) -> tuple[str, ...]:
        """The law's parameters besides ``sigma_y`` (its dataclass fields), in order."""
        return tuple(f.name for f in fields(cls) if f.name != "sigma_y")

    def parameters(self) -> dict:
        """The law's parameters besides ``sigma_y``, as given."""
        return {k: getattr(self, k) for k in self.parameter_names()}

    # ------------------------------------------------------------------ evaluation
    def stress(self, eps_p):
        """σ_f(ε_p), vectorised; ε_p < 0 is treated as 0."""
        return self._stress(np.maximum(np.asarray(eps_p, dtype=float), 0.0))

    def slope(self, eps_p):
        """dσ_f/dε_p, vectorised; ε_p < 0 is treated as 0."""
        return self._slope(np.maximum(np.asarray(eps_p, dtype=float), 0.0))

    def log_slope(self, eps):
        """m = d ln σ_f/d ln ε = ε σ_f'(ε)/σ_f(ε), vectorised (0 at ε = 0)."""
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        return e * self.slope(e) / self.stress(e)

    def representative(self, eps, spread: float = 0.0):
        """σ_rep and m = d ln σ_rep/d ln ε at ``eps``: σ_f and :meth:`log_slope` for W =
        ``spread`` = 0, else the Gauss–Hermite strain average (``averages.spread_average``)."""
        if spread == 0.0:
            return self.stress(eps), self.log_slope(eps)
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        return spread_average(lambda x: (self.stress(x), self.slope(x)), e, spread)

    def hardens(self) -> bool:
        """Whether σ_f rises anywhere (False: perfectly plastic)."""
        return bool(self.stress(1.0) > self.sigma_y)

    # ------------------------------------------------------------------ the model's averages
    def secant_exponent(self, eps_lo: float, eps_hi: float, spread: float = 0.0) -> float:
        """n = ln(σ_rep(ε_hi)/σ_rep(ε_lo))/ln(ε_hi/ε_lo): exact for σ_f = K εⁿ, 0 for perfect
        plasticity."""
        s_lo, s_hi = self.representative(np.array([eps_lo, eps_hi]), spread)[0]
        return float(math.log(s_hi / s_lo) / math.log(eps_hi / eps_lo))

    def range_exponent(self, eps_lo: float, eps_hi: float, spread: float = 0.0) -> float:
        """The hardening exponent on the calibrated-range axis: the secant exponent."""
        return self.secant_exponent(eps_lo, eps_hi, spread)

    def hardening_magnitude(self, eps_lo: float, eps_hi: float) -> float:
        """K/σ_Y of the Ludwik curve through σ_f at ε = 0, ε_lo and ε_hi: with Δσ = σ_f(ε) −
        σ_f(0), n_L = ln(Δσ(ε_hi)/Δσ(ε_lo))/ln(ε_hi/ε_lo) clipped to [0, 1], K = Δσ(ε_hi)/ε_hi^n_L
        (exact for a Ludwik curve with n ≤ 1)."""
        s0, s_lo, s_hi = self.stress(np.array([0.0, eps_lo, eps_hi]))
        d_lo, d_hi = s_lo - s0, s_hi - s0
        if d_hi <= 0.0:
            return 0.0
        n_l = 1.0 if d_lo <= 0.0 else math.log(d_hi / d_lo) / math.log(eps_hi / eps_lo)
        return float(d_hi / eps_hi ** min(max(n_l, 0.0), 1.0) / s0)

    def segment(self, eps) -> np.ndarray:
        """Index of the smooth piece containing each ε (0 .. ``segments`` − 1)."""
        return np.zeros(np.shape(eps), dtype=np.int64)

    # ------------------------------------------------------------------ the FE return mapping
    def plastic_multiplier(self, q_tr, eps_p_n, mu: float, tol: float = 1e-12, maxit: int = 100):
        """Δγ ≥ 0 with q_tr − 3μΔγ − σ_f(ε_p,n + Δγ) = 0, vectorised (radial return, bracketed
        Newton).

        The residual is strictly decreasing in Δγ; the root lies in [0, q_tr/(3μ)]. Newton falls
        back to bisection when it leaves the bracket or stalls (a slope floored at tiny ε_p or
        one-sided at a kink); a point is converged where |residual| ≤ tol σ_Y or its bracket has
        shrunk to the roundoff of ε_p.
        """
        q_tr = np.asarray(q_tr, dtype=float)
        lo = np.zeros_like(q_tr)
        hi = q_tr / (3.0 * mu)
        x = np.zeros_like(q_tr)
        scale = self.sigma_y
        r_prev = np.full_like(q_tr, np.inf)
        for _ in range(maxit):
            r = q_tr - 3.0 * mu * x - self.stress(eps_p_n + x)
            done = (np.abs(r) <= tol * scale) | (hi - lo <= 4e-16 * (eps_p_n + x) + 1e-30)
            if np.all(done):
                break
            lo = np.where(r > 0, x, lo)
            hi = np.where(r < 0, x, hi)
            slope = 3.0 * mu + self.slope(eps_p_n + x)
            x_new = x + r / slope
            bisect = (x_new <= lo) | (x_new >= hi) | (np.abs(r) > 0.5 * np.abs(r_prev))
            r_prev = r
            x = np.where(done, x, np.where(bisect, 0.5 * (lo + hi), x_new))
        else:
            raise RuntimeError("return mapping: plastic multiplier did not converge")
        return x

    # ------------------------------------------------------------------ descriptions
    def describe(self) -> dict:
        """Plain JSON-able description: ``{"flow": name, "sigma_y": …, <parameters>}``
        (``registry.flow_from_description`` inverts it)."""
        return {"flow": self.name, "sigma_y": self.sigma_y, **self.parameters()}

    def material_description(self) -> dict:
        """The flow part of ``Material.describe()``."""
        return self.describe()

    def spec(self) -> str:
        """The ``--flow`` form, ``name:P=V,…`` (σ_Y apart: ``--sigma-y``)."""
        return f"{self.name}:" + ",".join(f"{k}={v:g}" for k, v in self.parameters().items())

    def text(self) -> str:
        """The curve for messages: ``sigma_y = …, <parameters>``."""
        items = {"sigma_y": self.sigma_y, **self.parameters()}
        return f"{self.kind}, " + ", ".join(f"{k} = {v:.6g}" for k, v in items.items())

    def label(self, sy: str = "sy") -> str:
        """Short label of the hardening for report rows (``sy``: how σ_Y is written)."""
        return f"{self.name} " + " ".join(f"{k}={v:g}" for k, v in self.parameters().items())

    #: names of the calibrated-range checks (exponent, magnitude) of this law
    exponent_label: ClassVar[str] = "hardening exponent n (secant, {kind})"
    magnitude_label: ClassVar[str] = "hardening magnitude K/sigma_y (Ludwik fit, {kind})"
