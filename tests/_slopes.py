"""Finite-difference check of a body law's analytic log slopes (shared by the model tests)."""

import numpy as np


def assert_body_log_slopes(law, x, y, z, e: float = 1e-6, atol: float = 2e-5):
    """d ln p_m and d ln c² over d ln x and d ln y of ``law.response`` against forward differences;
    returns the response at (x, y, z)."""
    r = law.response(x, y, z)
    rx, ry = law.response(x * (1 + e), y, z), law.response(x, y * (1 + e), z)
    np.testing.assert_allclose(np.log(rx.p_m / r.p_m) / e, r.dlnp_dlnx, atol=atol)
    np.testing.assert_allclose(np.log(ry.p_m / r.p_m) / e, r.dlnp_dlny, atol=atol)
    np.testing.assert_allclose(np.log(rx.c2 / r.c2) / e, r.dlnc2_dlnx, atol=atol)
    np.testing.assert_allclose(np.log(ry.c2 / r.c2) / e, r.dlnc2_dlny, atol=atol)
    return r
