"""What a calibration produced (:class:`Calibration`) and its cross-validation score: the inputs
of the coefficient file (``pipeline.py``) and of the report (``report.py``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .check import MonotoneCheck, RunError
from .crossval import CVResult, FoldSolve, RegimeFold
from .dataset import Dataset
from .fit import FitResult
from .interface import InterfaceFit
from .unloading import UnloadingFit

__all__ = ["Calibration", "cv_score"]


def cv_score(cv: CVResult) -> float:
    """E_cv = sqrt((RMS_F² + RMS_a²)/2) of the pooled held-out errors of F(h) and a(h)."""
    p = cv.pooled()
    return math.sqrt(0.5 * (p["F"]["rms"] ** 2 + p["a"]["rms"] ** 2))


@dataclass
class Calibration:
    """Everything a calibration produced (inputs to the coefficient file and the report)."""

    dataset: Dataset
    fits: dict[str, FitResult]
    cv: dict[str, CVResult]
    chosen: str
    checks: list[MonotoneCheck]
    run_errors: list[RunError]
    alternatives: dict[str, FitResult] = field(default_factory=dict)  # large-deformation options
    alternative_checks: dict[str, bool] = field(default_factory=dict)
    form_checks: dict[str, bool] = field(default_factory=dict)  # monotone check per form tried
    source: dict = field(default_factory=dict)   # database path, hash, date, run keys, excluded
    timings: dict = field(default_factory=dict)
    noise: dict = field(default_factory=dict)      # scatter of the FE points (diagnostics.noise_floor)
    breakdown: dict = field(default_factory=dict)  # residuals of the chosen form by band
    regimes: list[RegimeFold] = field(default_factory=list)  # chosen form, one regime held out
    interface: InterfaceFit | None = None  # two-body interface terms (``interface.py``)
    unloading: UnloadingFit | None = None  # unloading law from the FE cycles (``unloading.py``)
    folds: FoldSolve = field(default_factory=FoldSolve)  # how far the fold fits were solved

    @property
    def best(self) -> FitResult:
        return self.fits[self.chosen]
