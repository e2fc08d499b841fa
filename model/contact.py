"""Public entry point: ``contact(s1, s2, h)`` — force, contact radius, split and stiffness.

h ≤ 0 means no contact: F = a = h1 = h2 = stiffness = 0 there (not an error). Approaches
beyond the model's domain (``UnifiedPair.domain``: a deformable sphere's own approach above
its radius, or a contact radius above a rigid sphere's radius) raise a ValueError naming h,
its value and the allowed range.
Inputs outside the calibrated range give a
:class:`~spherecontact.model.calibrated_range.CalibrationRangeWarning` per cause and call
(``range_check.py``); the values are still returned.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .coefficients import Coefficients, default_coefficients
from .range_check import emit, range_check
from .sphere import Sphere
from .unified import UnifiedState, pair

__all__ = ["ContactState", "contact", "contact_from_radius", "as_approach"]


class ContactState(NamedTuple):
    """Contact state, every field shaped like the approach h given to :func:`contact`."""

    F: np.ndarray          # contact force
    a: np.ndarray          # contact radius
    h1: np.ndarray         # approach taken by body 1
    h2: np.ndarray         # approach taken by body 2
    stiffness: np.ndarray  # dF/dh
    p_m: np.ndarray        # mean contact pressure F/(π a²)
    kappa: np.ndarray      # interface curvature κ
    rho1: np.ndarray       # relative radius seen by body 1
    rho2: np.ndarray


def as_approach(h) -> np.ndarray:
    """Validate an approach argument: real, finite numbers (any shape)."""
    try:
        arr = np.asarray(h)
    except Exception as err:  # ragged sequences and the like
        raise ValueError(f"h must be a real number or array of real numbers ({err})") from err
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.integer)
                                   or np.issubdtype(arr.dtype, np.floating)
                                   or arr.dtype == bool):
        raise ValueError(f"h must be a real number or a real array, got dtype {arr.dtype}")
    arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise ValueError("h must be finite (no NaN or inf)")
    return arr


def _shaped(x: np.ndarray):
    return x[()] if x.ndim == 0 else x


def contact(s1: Sphere, s2: Sphere, h, coeffs: Coefficients | None = None) -> ContactState:
    """Unified two-sphere contact law (DESIGN §3) evaluated at mutual approaches h.

    Parameters
    ----------
    s1, s2 : spheres (``radius=math.inf`` for a flat, ``Material.rigid()`` for a rigid body).
    h : approach of the two centres, float or array of any shape; h ≤ 0 is no contact.
    coeffs : coefficient set; default ``data/coefficients.json``.

    Returns
    -------
    ContactState with F, a, h1, h2, stiffness = dF/dh, p_m, κ, ρ_1, ρ_2 shaped like h
    (NumPy scalars for scalar h). Outside contact all fields are 0 except ρ_i (inf).

    Raises
    ------
    ValueError if an approach lies beyond the model's domain 0 < h ≤ h_max of the pair
    (``UnifiedPair.domain``); the message names h, its value and the allowed range.

    Warns
    -----
    CalibrationRangeWarning, once per cause and call, for materials, pairs, approaches
    (h/R), contact radii (a/R) or Λ outside the coefficient set's calibrated range.
    """
    hh = as_approach(h)
    co = default_coefficients() if coeffs is None else coeffs
    p = pair(s1, s2, co)
    chk = range_check(s1, s2, co)
    flat = hh.reshape(-1)
    on = flat > 0.0
    out = {k: np.zeros(flat.shape) for k in ContactState._fields}
    out["rho1"][:] = np.inf
    out["rho2"][:] = np.inf
    found = {}
    if np.any(on):
        st = p.state_from_h(flat[on])
        for k in ("F", "a", "h1", "h2", "stiffness", "p_m", "kappa", "rho1", "rho2"):
            out[k][on] = getattr(st, k)
        found = chk.check_state(st)
    emit([*chk.static.values(), *chk.messages(found)])
    return ContactState(**{k: _shaped(v.reshape(hh.shape)) for k, v in out.items()})


def contact_from_radius(s1: Sphere, s2: Sphere, a, coeffs: Coefficients | None = None
                        ) -> UnifiedState:
    """The unified model given the contact radius (DESIGN §3, forward direction).

    Returns the full :class:`~spherecontact.model.unified.UnifiedState` (κ, ρ_1, ρ_2,
    p_m, h_1, h_2, h, F, dF/dh, Λ_1, Λ_2) as 1-D arrays for contact radii 0 < a ≤ a_max
    (``UnifiedPair.domain``; beyond it a ValueError names a and the allowed range).
    Warns like :func:`contact`.
    """
    aa = as_approach(a).reshape(-1)
    if not np.all(aa > 0.0):
        raise ValueError("a (contact radius) must be > 0")
    co = default_coefficients() if coeffs is None else coeffs
    p = pair(s1, s2, co)
    p.check_radius(aa)
    st = p.state_at_a(aa)
    chk = range_check(s1, s2, co)
    emit([*chk.static.values(), *chk.messages(chk.check_state(st))])
    return st
