"""Measures of a generated hemisphere mesh (shared by the FE tests)."""

import numpy as np


def smallest_surface_element(m) -> float:
    """Length of the shortest surface edge of a ``HemisphereMesh``: a quadratic edge spans two
    gaps between the arc's nodes."""
    X = m.X[:, m.surface]
    return float(2 * np.hypot(*np.diff(X, axis=1)).min())
