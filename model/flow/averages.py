"""The strain average the model's representative stress takes of a flow curve (docs/design.md §2).

σ_rep = Σ_j w_j σ_f(ε e^(W t_j)) with the three-point Gauss–Hermite rule of a standard normal
variable (nodes t_j = 0, ±√3, weights ⅔, ⅙, ⅙) and W the strain spread; m = d ln σ_rep/d ln ε.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["spread_factors", "spread_average", "ludwik_representative_stress"]

#: three-point Gauss–Hermite rule of a standard normal variable t: nodes t_j, weights w_j
_GH_NODES = (0.0, -math.sqrt(3.0), math.sqrt(3.0))
_GH_WEIGHTS = (2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0)


def spread_factors(spread: float) -> tuple[tuple[float, float], ...]:
    """(e^(W t_j), w_j) of the representative stress's strain distribution, W = ``spread``
    (one factor 1 with weight 1 for W = 0)."""
    if spread == 0.0:
        return ((1.0, 1.0),)
    return tuple((math.exp(spread * t), w) for t, w in zip(_GH_NODES, _GH_WEIGHTS, strict=True))


def spread_average(flow, e, spread: float):
    """σ_rep and m (W = ``spread`` > 0) of a flow curve given by ``flow(ε)`` → (σ_f, σ_f') at the
    strains ``e`` ≥ 0 (one curve, or one per point as ``calibration.flowtables`` evaluates them)."""
    sig = np.zeros_like(e)
    dsig = np.zeros_like(e)  # Σ w_j ε_j σ_f'(ε_j) = ε dσ_rep/dε
    for f, w in spread_factors(spread):
        ef = f * e
        s, slope = flow(ef)
        sig = sig + w * s
        # the log slope times σ_f, σ_f(ε_f) not evaluated twice; the product is kept in this
        # order: ε σ_f' alone differs in the last bit, which moves the fitted coefficients
        dsig = dsig + w * (ef * slope / s) * s
    with np.errstate(invalid="ignore", divide="ignore"):
        return sig, np.where(sig > 0.0, dsig / sig, 0.0)


def ludwik_representative_stress(sigma_y, K, n, eps, spread: float):
    """σ_rep and m of Ludwik curves σ_Y + K εⁿ (ε σ_f' = n K εⁿ); the parameters may be arrays
    shaped like ``eps`` (one curve per point, as the calibration has)."""
    sig = dsig = 0.0
    for f, w in spread_factors(spread):
        t = K * (f * eps) ** n
        sig, dsig = sig + w * (sigma_y + t), dsig + w * n * t
    return sig, dsig / sig
