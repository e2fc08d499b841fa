"""Depth of a spherical cap beyond its paraboloid: the exact shape of a (nearly) rigid partner.

A sphere of radius R_o is R_o − √(R_o² − a²) deep at radius a, not a²/(2R_o):

    R_o − √(R_o² − a²) = a²/(2R_o) (1 + φ(t)),
    φ(t) = (1 − s)/(1 + s) = t²/(1 + s)²,   s = √(1 − t²),   t = a/R_o,

φ ≈ t²/4 for small t, 0.09 at t = 0.55, 0.39 at t = 0.9. A body pressed by a rigid sphere shortens
by the gap it closes, a²/(2ρ) + e with the excess e = a²φ(t)/(2R_o), over its c² (``unified.py``):

    h = (a²/(2ρ) + w e)/c²,

w the weight of the rigid-partner geometry (1 for a rigid partner, ``unified.harder_partner_weight``
for a deformable one, 0 for the softer body or a flat). At t ≥ 1 the body would wrap the sphere;
φ is continued beyond t_c = 0.9 along its tangent, so h(a) stays finite and increasing there
(``range_check.py`` warns beyond the calibrated a/R_i).
"""

from __future__ import annotations

import math

import numpy as np

#: t = a/R_o beyond which φ is continued linearly (its slope is 2.0 there and → ∞ at t = 1)
T_CONTINUE = 0.9
_S_C = math.sqrt(1.0 - T_CONTINUE ** 2)
_PHI_C = T_CONTINUE ** 2 / (1.0 + _S_C) ** 2
_DPHI_C = 2.0 * T_CONTINUE / (_S_C * (1.0 + _S_C) ** 2)


def cap_excess_factor(t) -> tuple[np.ndarray, np.ndarray]:
    """φ(t) and dφ/dt (module docstring), t = a/R_o ≥ 0."""
    t = np.asarray(t, dtype=float)
    tc = np.minimum(t, T_CONTINUE)
    s = np.sqrt(1.0 - tc * tc)
    phi = tc * tc / (1.0 + s) ** 2  # (1 − s)/(1 + s) without the cancellation at small t
    dphi = 2.0 * tc / (s * (1.0 + s) ** 2)
    beyond = t > T_CONTINUE
    return (np.where(beyond, _PHI_C + _DPHI_C * (t - T_CONTINUE), phi),
            np.where(beyond, _DPHI_C, dphi))


def cap_gap_factor(a, k, radius: float, weight: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """G = 1 + w φ(t)/(k R_o), the gap a body closes over its paraboloid part a²k/2 (k = 1/ρ):
    a²k/2 + w e = (a²k/2) G (module docstring), and ∂ln G/∂ln a at fixed k. (1, 0) for w = 0
    or a flat (R_o = inf), so the paraboloid model is unchanged to the bit."""
    a = np.asarray(a, dtype=float)
    if weight == 0.0 or math.isinf(radius):
        return np.ones_like(a), np.zeros_like(a)
    t = a / radius
    phi, dphi = cap_excess_factor(t)
    scale = weight / (np.asarray(k, dtype=float) * radius)
    G = 1.0 + scale * phi
    return G, scale * t * dphi / G
