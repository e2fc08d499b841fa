"""FE unloading cycles as the unloading law sees them (``model/unloading.py``).

A run with cycles (``fem.io``: ``cycles/*``, ``curves/branch``) holds per unloading branch
its peak (h_max, F_max, a_max; the increments of the peak and of the end) and the branch
F(h) down to the residual approach h_res. :func:`run_cycles` turns each into an
:class:`UnloadingCurve`: the branch as F/F_max at the FE's approaches and the peak as the
law's ``PeakFeatures`` (``unloading.peak_features``, as the model reads its own peaks) — F, a,
each body's approach h_i and the curvature κ of the contact surface from the FE; only the
onset ramp comes from the model (the loading coefficients' Λ at the FE's a_max). Calibration
fits the law to these; validation scores it on them (:func:`branch_errors`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .model.coefficients import Coefficients, UnloadingCoefficients
from .model.run_inputs import spheres_from_inputs
from .model.unified import pair
from .model.unloading import PeakFeatures, peak_features, unloading_law

__all__ = ["UnloadingCurve", "run_cycles", "branch_errors", "law_branch", "law_residuals", "joined"]

#: FE scenes of the runs → the model's scene (``fem.io.spheres_from_inputs``)
_SCENES = {"rigid_flat": "flat", "rigid_sphere": "rigid_sphere", "two_body": "two_body",
           "equal_pair_symmetry": "flat"}


@dataclass(frozen=True)
class UnloadingCurve:
    """One FE unloading branch and its peak."""

    name: str               # run name and cycle number
    h: np.ndarray           # approaches of the branch, from h_max down to h_res
    f: np.ndarray           # F/F_max there
    h_max: float
    h_res: float            # the FE's residual approach
    R: float                # the smaller deformable radius (for h/R)
    peak: PeakFeatures = field(repr=False)  # one peak


def _peak_values(run, scene: str, i: int):
    """(h_i pair, |κ|) of the FE at increment ``i``."""
    c = run.curves
    h = float(c["h"][i])
    if scene == "two_body":
        return (float(c["h1"][i]), float(c["h2"][i])), abs(float(c["interface_curvature"][i]))
    if scene == "equal_pair_symmetry":
        return (0.5 * h, 0.5 * h), 0.0
    R_i = float(run.inputs.get("indenter_radius", math.inf)) if scene == "rigid_sphere" else math.inf
    return (h, 0.0), 1.0 / R_i


def run_cycles(name: str, run, coeffs: Coefficients) -> list[UnloadingCurve]:
    """The unloading branches of one FE run (``fem.io.Run``; none without cycles)."""
    cyc = getattr(run, "cycles", None) or {}
    if "h_max" not in cyc or len(cyc["h_max"]) == 0:
        return []
    scene = str(run.inputs.get("scene", "rigid_flat"))
    s1, s2 = spheres_from_inputs(run.inputs, _SCENES.get(scene, "flat"))
    if scene == "equal_pair_symmetry":
        s2 = s1
    p = pair(s1, s2, coeffs)
    R = min(s.radius for s in (s1, s2) if not s.is_rigid)
    h, F = np.asarray(run.curves["h"], dtype=float), np.asarray(run.curves["F"], dtype=float)
    peak, end = np.asarray(cyc["increment_peak"], dtype=int), np.asarray(cyc["increment_end"], dtype=int)
    h_max, F_max = np.asarray(cyc["h_max"], dtype=float), np.asarray(cyc["F_max"], dtype=float)
    h_i, kappa = zip(*(_peak_values(run, scene, i) for i in peak), strict=True)
    h_i = np.array(h_i)
    # the model's state at the FE's contact radii (its Λ: the onset ramp) carrying the FE's peak
    st = p.state_at_a(np.asarray(cyc["a_max"], dtype=float))._replace(
        h=h_max, F=F_max, h1=h_i[:, 0], h2=h_i[:, 1], kappa=np.array(kappa))
    peaks = peak_features(p, st)
    return [UnloadingCurve(name=f"{name} cycle {k + 1}", h=h[peak[k]:end[k] + 1],
                           f=F[peak[k]:end[k] + 1] / F_max[k], h_max=float(h_max[k]),
                           h_res=float(cyc["h_res"][k]), R=R,
                           peak=PeakFeatures(*(v[k:k + 1] for v in peaks)))
            for k in range(h_max.size)]


def joined(curves) -> tuple[PeakFeatures, np.ndarray]:
    """The peaks of ``curves`` as one batch, and the curve index of every branch point."""
    peaks = PeakFeatures(*(np.concatenate([getattr(c.peak, f) for c in curves])
                           for f in PeakFeatures._fields))
    idx = np.concatenate([np.full(c.h.size, i) for i, c in enumerate(curves)])
    return peaks, idx


def law_branch(law: UnloadingCoefficients, peaks: PeakFeatures, idx, h):
    """F/F_max of ``law`` at the approaches h of the branches ``idx`` of ``peaks``, and each
    peak's residual approach."""
    m, delta_e, h_res, _ = unloading_law(peaks, law)
    xi = np.clip((h - h_res[idx]) / delta_e[idx], 0.0, 1.0)
    return xi ** m[idx], h_res


def law_residuals(law: UnloadingCoefficients, peaks: PeakFeatures, idx, h, f):
    """:func:`law_branch` − the FE's F/F_max ``f``, and each peak's residual approach."""
    pred, h_res = law_branch(law, peaks, idx, h)
    return pred - f, h_res


def branch_errors(law: UnloadingCoefficients, curves) -> tuple[np.ndarray, np.ndarray]:
    """Per curve: the largest |F_law − F_FE|/F_max along the branch and |h_res,law − h_res,FE|/h_max."""
    if not curves:
        return np.zeros(0), np.zeros(0)
    peaks, idx = joined(curves)
    h = np.concatenate([c.h for c in curves])
    f = np.concatenate([c.f for c in curves])
    r, h_res = law_residuals(law, peaks, idx, h, f)
    worst = np.zeros(len(curves))
    np.maximum.at(worst, idx, np.abs(r))
    fe = np.array([c.h_res for c in curves])
    hm = np.array([c.h_max for c in curves])
    return worst, np.abs(h_res - fe) / hm


