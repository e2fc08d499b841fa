"""Unloading law from the FE cycles of the calibration runs (``model/unloading.py``).

Every unloading branch of a calibration run (campaign v2 unloads at h/R = 0.01, 0.03, 0.1,
0.3 and reloads; the reloading retraces the unloading) gives a peak and the branch F/F_max at
the FE's approaches (``spherecontact.cycles``). The law reads the peak through
``unloading.features`` exactly as the model does from its own loaded state.

Residuals: F_law/F_max − F_FE/F_max at every branch point (the validation's measure: the
error relative to F_max along the branch) and, per branch, H_RES_WEIGHT · (h_res,law −
h_res,FE)/h_max (the validation's other measure), both with heavier tails (``TAIL``). Trust-region
reflective within ``UNLOADING_RANGES``, from a fixed start: deterministic. Thornton (1997) — the defaults,
Hertz from the peak — is scored beside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..cycles import UnloadingCurve, branch_errors, joined, law_residuals
from ..model.coefficients import UNLOADING_RANGES, UnloadingCoefficients
from .fit import round_sig

__all__ = ["UnloadingFit", "fit_unloading", "START", "TAIL", "H_RES_WEIGHT"]

#: residuals r enter as r·√(1 + (r/TAIL)²): least squares below TAIL, ~r²/TAIL above, so the
#: worst branches weigh more (the acceptance is a per-branch maximum). With plain least squares
#: the validation's worst branch was 7.3 % of F_max and 8 branches exceeded 3 %; with 0.03,
#: 5.4 % and 7 (0.015: 4.9 % and 7, but h_res worse)
TAIL = 0.03

#: weight of each branch's residual-approach error (one residual per branch beside its ~20 force
#: residuals). Without it the h_res of nearly elastic deep peaks (λ ≈ 1, h/R = 0.3), where the
#: FE branch has a soft tail a power law cannot follow, was left 4–5 % of h_max off. Calibration
#: branches above 3 % (F and h_res counted apart, 355 branches): 23 / 22 / 20 / 18 for weights
#: 1.0 / 1.25 / 1.5 / 2.0; validation's worst F / h_res: 2.86 / 3.23, 2.86 / 3.04, 2.85 / 2.89,
#: 3.02 / 2.68 % (2026-11-26, the loading law of that day)
H_RES_WEIGHT = 1.5

#: start of the fit (Thornton's exponent and stiffness, moderate terms elsewhere)
START = UnloadingCoefficients(stiffness=1.0, size_a=1.0, size_h=1.0, size_nu=0.0, m_plastic=1.3,
                              m_c2=0.0, m_depth=0.0,
                              m_counter=1.5, m_elastic_size=0.0, elastic_weight=1.0,
                              size_counter=0.0, stiffness_c2=0.0, m_lambda=0.0)
@dataclass
class UnloadingFit:
    law: UnloadingCoefficients
    curves: list[UnloadingCurve]
    errors: np.ndarray           # per curve, the fitted law (branch_errors)
    h_res_errors: np.ndarray
    thornton: np.ndarray         # the same for Thornton (1997)
    thornton_h_res: np.ndarray
    nfev: int

    def section(self) -> dict:
        return self.law.to_dict()

    def summary(self) -> dict:
        def stats(e):
            return {"median": float(np.median(e)), "p95": float(np.percentile(e, 95)),
                    "max": float(np.max(e)), "above_3pct": int(np.count_nonzero(e > 0.03))}
        return {"branches": len(self.curves), "F_branch": stats(self.errors),
                "h_res": stats(self.h_res_errors), "thornton_F_branch": stats(self.thornton),
                "thornton_h_res": stats(self.thornton_h_res)}


def fit_unloading(curves) -> UnloadingFit | None:
    """Least-squares fit of the unloading coefficients to the branches ``curves`` (module
    docstring); None without any. The coefficients are rounded like the loading ones."""
    if not curves:
        return None
    names = list(UNLOADING_RANGES)
    lo = np.array([UNLOADING_RANGES[n][0] for n in names])
    hi = np.array([UNLOADING_RANGES[n][1] for n in names])
    peaks, idx = joined(curves)
    h = np.concatenate([c.h for c in curves])
    f = np.concatenate([c.f for c in curves])
    h_res = np.array([c.h_res for c in curves])
    h_max = np.array([c.h_max for c in curves])

    def res(x):
        r, h_res_law = law_residuals(UnloadingCoefficients(**dict(zip(names, x, strict=True))),
                                     peaks, idx, h, f)
        r = np.concatenate([r, H_RES_WEIGHT * (h_res_law - h_res) / h_max])
        return r * np.sqrt(1.0 + (r / TAIL) ** 2)

    x0 = np.clip([getattr(START, n) for n in names], lo, hi)
    sol = least_squares(res, x0, bounds=(lo, hi), method="trf", x_scale=0.1, ftol=1e-10, xtol=1e-10)
    law = UnloadingCoefficients(**{n: round_sig(float(v)) for n, v in zip(names, sol.x, strict=True)})
    err, herr = branch_errors(law, curves)
    th, thh = branch_errors(UnloadingCoefficients(), curves)
    return UnloadingFit(law=law, curves=list(curves), errors=err, h_res_errors=herr,
                        thornton=th, thornton_h_res=thh, nfev=int(sol.nfev))
