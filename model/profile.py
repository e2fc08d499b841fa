"""The contact pressure profile a pair's less plastic body is loaded by (``pressure_profile``).

A body law gives p_m at x = a/ρ for the profile of its own contact on a rigid surface: Hertz's
elliptical one while elastic, flatter as it yields. In a pair the pressure is common to both
bodies and its profile is set by the more plastic one, so the less plastic body is loaded by a
profile flatter than its own. An elastic half space under a uniform pressure of mean p_m on a
circle of radius a sinks 2 p_m a/E' at its centre, under Hertz's (3π/4) p_m a/E': the factor
Φ = 8/(3π) (Johnson 1985, §3.4 and §4.2). With ``"flattened"`` the body's pressure law is read as

    p_m = p_m,law/φ,  φ = 1 − (1 − Φ) w,  w = d²/(d + δ) for d = s_o − s > 0 (else 0),

s and s_o the level weights (``levels.level_weight``) of the body and its partner, read at a/ρ_c
of each (``unified``: functions of a alone, so the κ root stays unique), δ = ``SMOOTHING``: an
elastic body under a fully plastic partner takes 8/(3π) of the Hertz approach at the same p_m, a
body under a partner no more plastic than itself (equal spheres, a rigid partner) is unchanged.
On campaign v2's pairs of unequal yield the harder body's approach at the FE's contact radius was
7–18 % above the FE's with the Hertz profile (``calibration/README.md``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["UNIFORM_OVER_HERTZ", "SMOOTHING", "profile_factor"]

#: centre displacement under a uniform pressure over that under Hertz's, at one mean pressure
UNIFORM_OVER_HERTZ = 8.0 / (3.0 * math.pi)
#: width δ of the C¹ start of the weight w = d²/(d + δ)
SMOOTHING = 0.05


def profile_factor(s, ds, s_o, ds_o):
    """ln(1/φ) and its derivative d/d ln a (module docstring), given the level weights s, s_o
    of the body and its partner and their derivatives ds, ds_o in ln a."""
    d = np.maximum(np.asarray(s_o, dtype=float) - np.asarray(s, dtype=float), 0.0)
    w = d * d / (d + SMOOTHING)
    dw_dd = d * (d + 2.0 * SMOOTHING) / (d + SMOOTHING) ** 2
    phi = 1.0 - (1.0 - UNIFORM_OVER_HERTZ) * w
    return -np.log(phi), (1.0 - UNIFORM_OVER_HERTZ) * dw_dd * (np.asarray(ds_o) - np.asarray(ds)) / phi
