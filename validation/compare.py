"""The model and the peer laws against one FE run: predictions on the run's grid and their errors.

For a case (:class:`.cases.Case`) the closed-form model is evaluated for the pair of
the FE scene at the FE approaches, ``contact(s1, s2, h)``; Λ of each body comes from
the model's state at its own contact radius (``contact_from_radius``), and the
level of a point is the highest level of the deformable bodies. Windows (h/R with R
the smaller deformable radius, :func:`.cases.reference_radius`):

* ``"to 0.3"``: from the first point past Level I to ``h_over_R_max`` (acceptance);
* ``"to 0.5"``: the same start to ``h_over_R_large_max``, only for runs that go beyond
  ``h_over_R_max``.

Points whose FE contact radius is below ``a_min_over_R`` (not resolved by the mesh) are
left out of every window and level. Quantities: F and a (relative errors); for two-body
runs also h_1 and h_2 (relative) and the split h_1/h (absolute error of the fraction).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..metrics import (
    EMPTY,
    LEVELS,
    Summary,
    level_labels,
    relative_error,
    summarise,
    trapezoid_weights,
)
from ..model import Coefficients, contact, contact_from_radius
from ..model.levels import level as model_level
from .cases import Case, classes, reference_radius, spheres
from .config import Thresholds
from .peer_scenes import PEERS, NotApplicable, predict_peers

__all__ = ["W_ACCEPT", "W_LARGE", "QUANTITIES", "MethodErrors", "Comparison", "compare_case",
           "model_curve_time", "own_range_mask"]

W_ACCEPT = "to 0.3"
W_LARGE = "to 0.5"
QUANTITIES = ("F", "a", "h1", "h2", "split")
MODEL = "model"


@dataclass
class MethodErrors:
    """One method (the model or a peer) on one case."""

    name: str
    applies: bool
    note: str = ""
    F: np.ndarray | None = None        # predictions at the FE points (None: not given)
    a: np.ndarray | None = None
    h1: np.ndarray | None = None
    h2: np.ndarray | None = None
    mask: np.ndarray | None = None     # points where the law is evaluated (None: all)
    in_range: np.ndarray | None = None  # points inside the law's stated range (None: all)
    errors: dict = field(default_factory=dict)   # quantity → error array
    windows: dict = field(default_factory=dict)  # window → quantity → Summary
    own_range: dict = field(default_factory=dict)  # quantity → Summary in the law's own range
    levels: dict = field(default_factory=dict)   # level label → quantity → Summary

    def summary(self, window: str, quantity: str) -> Summary:
        return self.windows.get(window, {}).get(quantity, EMPTY)

    def level_summary(self, label: str, quantity: str) -> Summary:
        return self.levels.get(label, {}).get(quantity, EMPTY)


@dataclass
class Comparison:
    """The model and every peer law on one FE run."""

    case: Case
    classes: tuple
    R_ref: float
    h_over_R: np.ndarray
    Lambda: np.ndarray        # Λ of the body that is furthest into plasticity, per point
    level: np.ndarray         # 1, 2, 3 per point
    labels: np.ndarray        # "I", "II", "III", "large" per point
    start: float              # h/R where Level I ends (inf: never)
    masks: dict               # window → bool mask
    resolved: np.ndarray      # FE contact radius resolved by the mesh (a/R ≥ a_min_over_R)
    model: MethodErrors
    peers: dict               # name → MethodErrors
    model_in_range: dict      # peer name → quantity → Summary of the model on the peer's range points
    model_time_s: float       # one evaluation of the model curve on the run's grid
    model_warnings: list

    @property
    def methods(self) -> dict:
        return {MODEL: self.model, **self.peers}


def _errors_and_summaries(m: MethodErrors, case: Case, masks: dict, labels: np.ndarray,
                          weights: np.ndarray, extra_mask=None) -> None:
    fe = {"F": case.F, "a": case.a, "h1": case.curve("h1"), "h2": case.curve("h2")}
    for q in ("F", "a", "h1", "h2"):
        pred = getattr(m, q)
        if pred is not None and fe[q] is not None:
            m.errors[q] = relative_error(pred, fe[q])
    if m.h1 is not None and fe["h1"] is not None:
        h = case.h
        with np.errstate(divide="ignore", invalid="ignore"):
            m.errors["split"] = np.where(h > 0, (m.h1 - fe["h1"]) / h, np.nan)
    base = np.ones(case.h.size, bool) if extra_mask is None else extra_mask
    for w, mask in masks.items():
        m.windows[w] = {q: summarise(e, mask & base, weights) for q, e in m.errors.items()}
    for lab in LEVELS:
        lm = (labels == lab) & base
        m.levels[lab] = {q: summarise(e, lm, weights) for q, e in m.errors.items()}


def model_curve_time(s1, s2, h, coeffs: Coefficients | None, repeats: int = 3) -> float:
    """Best-of-``repeats`` wall time of one model curve evaluation ``contact(s1, s2, h)``."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        contact(s1, s2, h, coeffs)
        best = min(best, time.perf_counter() - t0)
    return best


def compare_case(case: Case, coeffs: Coefficients | None, th: Thresholds, mdr=None) -> Comparison:
    """The model and the peers on one FE run (module docstring); ``mdr``: the stored LAMMPS
    mdr curves (:func:`.mdr.load_store`, None: not given)."""
    s1, s2 = spheres(case)
    h = case.h
    R = reference_radius(case)
    hR = h / R
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        st = contact(s1, s2, h, coeffs)
        on = st.a > 0
        lam = np.zeros_like(h)
        if np.any(on):
            us = contact_from_radius(s1, s2, st.a[on], coeffs)
            lam[on] = np.maximum(np.asarray(us.Lambda1), np.asarray(us.Lambda2))
    model_warnings = sorted({str(w.message) for w in caught})
    t_model = model_curve_time(s1, s2, h, coeffs)
    from ..model import default_coefficients

    cf = default_coefficients() if coeffs is None else coeffs
    lev = np.where(on, model_level(lam, cf), 1)
    labels = level_labels(lev, hR, th.large_deformation_from)
    past = np.nonzero(lev >= 2)[0]
    start = float(hR[past[0]]) if past.size else math.inf
    resolved = case.a / R >= th.a_min_over_R
    masks = {W_ACCEPT: (hR >= start) & (hR <= th.h_over_R_max * (1 + 1e-9)) & resolved}
    if hR.size and hR[-1] > th.h_over_R_max * (1 + 1e-3):
        masks[W_LARGE] = (hR >= start) & (hR <= th.h_over_R_large_max * (1 + 1e-9)) & resolved
    weights = trapezoid_weights(h)

    two = case.scene == "two_body"
    model = MethodErrors(MODEL, True, "", st.F, st.a, st.h1 if two else None,
                         st.h2 if two else None)
    _errors_and_summaries(model, case, masks, labels, weights, resolved)

    peer_results, model_in_range = {}, {}
    # a law's own range: resolved points up to the acceptance window's end, from h = 0 (an
    # elastic law's range ends before the window starts)
    upto = resolved & (hR <= th.h_over_R_max * (1 + 1e-9))
    for name, pred in predict_peers(case, mdr).items():
        if isinstance(pred, NotApplicable):
            peer_results[name] = MethodErrors(name, False, pred.reason)
            continue
        me = MethodErrors(name, True, pred.note, pred.F, pred.a, mask=pred.mask, in_range=pred.in_range)
        _errors_and_summaries(me, case, masks, labels, weights,
                              resolved if pred.mask is None else resolved & pred.mask)
        own = own_range_mask(me, upto)
        me.own_range = {q: summarise(e, own, weights) for q, e in me.errors.items()}
        model_in_range[name] = {q: summarise(e, own, weights) for q, e in model.errors.items()}
        peer_results[name] = me
    assert tuple(peer_results) == PEERS
    return Comparison(case, classes(case), R, hR, lam, lev, labels, start, masks, resolved, model,
                      peer_results, model_in_range, t_model, model_warnings)


def own_range_mask(m: MethodErrors, upto: np.ndarray) -> np.ndarray:
    """Points of ``upto`` where the peer ``m`` is evaluated and inside its own stated range."""
    own = upto.copy()
    for extra in (m.mask, m.in_range):
        if extra is not None:
            own &= extra
    return own
