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

import math
from typing import NamedTuple

import numpy as np

from .coefficients import Coefficients, default_coefficients
from .range_check import emit, range_check
from .sphere import Sphere
from .unified import UnifiedPair, UnifiedState, pair
from .unloading import Peak, branch, peak_parameters

__all__ = ["ContactState", "contact", "contact_from_radius", "as_approach", "as_history",
           "residual_approach"]


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


def _real_array(x, what: str, allow_bool: bool) -> np.ndarray:
    """``x`` as a float array (no copy of a float array: read only here) of real, finite
    numbers; ValueError naming ``what`` otherwise."""
    try:
        arr = np.asarray(x)
    except Exception as err:  # ragged sequences and the like
        raise ValueError(f"{what} must be a real number or array of real numbers ({err})") from err
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.integer)
                                   or np.issubdtype(arr.dtype, np.floating)
                                   or (allow_bool and arr.dtype == bool)):
        raise ValueError(f"{what} must be a real number or a real array, got dtype {arr.dtype}")
    arr = arr.astype(float, copy=False)
    if not np.isfinite(arr).all():
        raise ValueError(f"{what} must be finite (no NaN or inf)")
    return arr


def as_approach(h) -> np.ndarray:
    """Validate an approach argument: real, finite numbers (any shape)."""
    return _real_array(h, "h", allow_bool=True)


def as_history(h_max, shape: tuple[int, ...], name: str = "h_max") -> np.ndarray:
    """Validate the largest approach reached: real, finite, ≥ 0, a scalar or shaped like the
    approaches (``shape``); returned with that shape."""
    what = f"{name} (largest approach reached)"
    arr = _real_array(h_max, what, allow_bool=False)
    if arr.ndim and arr.shape != tuple(shape):
        raise ValueError(f"{what} must be a scalar or shaped like h {tuple(shape)}, got shape {arr.shape}")
    if arr.size and arr.min() < 0.0:
        raise ValueError(f"{what} must be >= 0, got min {float(arr.min())!r}")
    return arr if arr.shape == tuple(shape) else np.broadcast_to(arr, shape)


def _peaks(p: UnifiedPair, h_max: np.ndarray) -> tuple[Peak, UnifiedState]:
    """Unloading parameters of the loaded states at the largest approaches h_max (1-D, > 0)."""
    p.check_approach(h_max, "h_max")
    st = p.state_from_h(h_max)
    return peak_parameters(p, st), st


def residual_approach(s1: Sphere, s2: Sphere, h_max, coeffs: Coefficients | None = None):
    """Residual approach h_res after unloading from the largest approach h_max (any shape;
    h_max = 0: 0): where the unloading force returns to zero (``unloading.py``)."""
    hm = as_history(h_max, np.shape(h_max))
    co = default_coefficients() if coeffs is None else coeffs
    p = pair(s1, s2, co)
    chk = range_check(s1, s2, co)
    flat = hm.reshape(-1)
    out = np.zeros(flat.shape)
    on = flat > 0.0
    found = {}
    if np.any(on):
        pk, st = _peaks(p, flat[on])
        out[on] = pk.h_res
        found = chk.check_state(st)
    emit([*chk.static.values(), *chk.messages(found)])
    return _shaped(out.reshape(hm.shape))


def _shaped(x: np.ndarray):
    return x[()] if x.ndim == 0 else x


def contact(s1: Sphere, s2: Sphere, h, coeffs: Coefficients | None = None,
            h_max=None) -> ContactState:
    """Unified two-sphere contact law (docs/design.md §3) evaluated at mutual approaches h.

    Parameters
    ----------
    s1, s2 : spheres (``radius=math.inf`` for a flat, ``Material.rigid()`` for a rigid body).
    h : approach of the two centres, float or array of any shape; h ≤ 0 is no contact.
    coeffs : coefficient set; default ``model/coefficients.json``.
    h_max : largest approach reached before (scalar or shaped like h, ≥ 0); default h itself
        (monotone loading). Where h ≥ h_max the state is on the loading curve (loading past
        the previous maximum); below it on the elastic unloading/reloading branch of the
        peak at h_max (``unloading.py``), with F = a = h1 = h2 = 0 at and below the residual
        approach (:func:`residual_approach`). κ and ρ_i on the branch are the peak's.

    Returns
    -------
    ContactState with F, a, h1, h2, stiffness = dF/dh, p_m, κ, ρ_1, ρ_2 shaped like h
    (NumPy scalars for scalar h). Outside contact all fields are 0 except ρ_i (inf).

    Raises
    ------
    ValueError if an approach lies beyond the model's domain 0 < h ≤ h_max of the pair
    (``UnifiedPair.domain``); the message names h, its value and the allowed range. Also
    for an invalid ``h_max`` (negative, NaN, wrong shape; the message names it).

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
    below = np.zeros(flat.shape, dtype=bool)
    if h_max is not None:
        hm = as_history(h_max, hh.shape).reshape(-1)
        below = flat < hm
        if np.any(below):
            found = _unload(p, chk, flat, hm, below, out)
    load = on & ~below
    if np.any(load):
        st = p.state_from_h(flat[load])
        for k in _STATE_FIELDS:
            out[k][load] = getattr(st, k)
        for key, v in chk.check_state(st).items():
            found[key] = max(v, found.get(key, -math.inf))
    emit([*chk.static.values(), *chk.messages(found)])
    return ContactState(**{k: _shaped(v.reshape(hh.shape)) for k, v in out.items()})


_STATE_FIELDS = ("F", "a", "h1", "h2", "stiffness", "p_m", "kappa", "rho1", "rho2")


def _unload(p: UnifiedPair, chk, h: np.ndarray, hm: np.ndarray, below: np.ndarray, out: dict) -> dict:
    """Fill ``out`` where h < h_max: the unloading branch of the peak at h_max, or the loading
    curve where that peak is elastic (no hysteresis). Returns the range causes of the peaks."""
    idx = np.flatnonzero(below)
    pk, st = _peaks(p, hm[idx])
    found = chk.check_state(st)
    br = branch(h[idx], pk)
    vals = {"F": br.F, "a": br.a, "h1": br.h1, "h2": br.h2, "stiffness": br.stiffness,
            "kappa": st.kappa, "rho1": st.rho1, "rho2": st.rho2}
    contact_ = br.F > 0.0
    for k, v in vals.items():
        out[k][idx] = np.where(contact_, v, 0.0 if k not in ("rho1", "rho2") else np.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        out["p_m"][idx] = np.where(contact_, br.F / (math.pi * br.a * br.a), 0.0)
    elastic = ~pk.plastic & (h[idx] > 0.0)
    if np.any(elastic):  # an elastic peak: back along the loading curve
        j = idx[elastic]
        se = p.state_from_h(h[j])
        for k in _STATE_FIELDS:
            out[k][j] = getattr(se, k)
    return found


def contact_from_radius(s1: Sphere, s2: Sphere, a, coeffs: Coefficients | None = None
                        ) -> UnifiedState:
    """The unified model given the contact radius (docs/design.md §3, forward direction).

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
