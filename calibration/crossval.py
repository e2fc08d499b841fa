"""Leave-one-material-out cross-validation of the candidate forms.

A fold holds out every run of one material (E/σY, ν, hardening; both scenes, flat and
rigid sphere), refits the form on the rest and predicts the held-out points. The fold
fit starts from the full fit (warm start) and is capped at ``FOLD_NFEV`` iterations:
dropping one material out of many moves the optimum little, and the cap keeps
``make calibrate`` fast. Each fold also records how far its coefficient set moved from
the full fit, as the change of the predicted H̄ and c² over all points (RMS and max):
the stability of the fit against dropping a material.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dataset import Dataset
from .fit import FitResult, errors, fit, rms
from .forms import predict

__all__ = ["FOLD_NFEV", "Fold", "CVResult", "cross_validate"]

#: iteration cap of a fold fit (warm-started from the full fit)
FOLD_NFEV = 8


@dataclass
class Fold:
    group: str
    n_points: int
    errors: dict[str, np.ndarray]   # held-out relative errors
    params: np.ndarray
    shift_rms: float = 0.0  # RMS and max change of the predicted H̄, c² over all points
    shift_max: float = 0.0  # (fold fit against the full fit): stability of the fit


@dataclass
class CVResult:
    form: str
    folds: list[Fold]

    def pooled(self) -> dict[str, dict[str, float]]:
        """RMS and max |error| over all held-out points, per quantity."""
        out = {}
        for q in ("H_bar", "c2"):
            e = np.concatenate([f.errors[q] for f in self.folds])
            out[q] = {"rms": rms(e), "max": float(np.max(np.abs(e)))}
        return out

    def worst_fold(self, q: str) -> tuple[str, float]:
        f = max(self.folds, key=lambda f: rms(f.errors[q]))
        return f.group, rms(f.errors[q])


def cross_validate(ds: Dataset, full: FitResult, nfev: int = FOLD_NFEV) -> CVResult:
    """Leave-one-material-out CV of ``full.form`` warm-started from ``full``."""
    folds = []
    groups = ds.groups
    if len(groups) < 2:
        raise ValueError("cross-validation needs at least two materials")
    p0, c0 = predict(ds, full.coeffs)
    for g in groups:
        train, test = ds.without_group(g), ds.only_group(g)
        r = fit(train, full.form, start=full.params, max_nfev=nfev)
        p1, c1 = predict(ds, r.coeffs)
        shift = np.concatenate([p1 / p0 - 1.0, c1 / c0 - 1.0])
        folds.append(Fold(group=g, n_points=test.size, errors=errors(test, r.coeffs), params=r.params,
                          shift_rms=rms(shift), shift_max=float(np.max(np.abs(shift)))))
    return CVResult(form=full.form.name, folds=folds)
