"""Cross-validation of the candidate forms by held-out materials (``FOLDS`` folds).

The materials (E/σY, ν, hardening; both scenes, flat and rigid sphere, of a material go
together) are dealt in turn, by their sorted labels, into ``FOLDS`` folds; a fold holds out
every run of its materials, refits the form on the rest and predicts the held-out points.
The fold fit starts from the full fit (warm start, solved in the shift from it:
``fit._solve``) and is solved to ``FOLD_TOL`` with at most ``FOLD_NFEV`` iterations.

A fold must move away from the full fit: the full fit has seen the held-out points, and a
fold that stays at it scores the form's fit, not its prediction. Leaving one material out
(90 folds of one material each, the scheme until 2026-11-27) did not: the fit's cost valley is
so flat that removing one material of 90 moved its minimum by 3e-4 of the cost, trf stopped
at the start in 24 of the first 40 folds of the chosen form and after one or two steps in the
rest, and the held-out errors were the fit's own (E_cv 1.19 against the in-sample 1.16 %; the
report's 'shift' column read 0.00 %). Solved (200 evaluations, 1e-10) such a fold took 10 s and
moved the held-out F error by up to +11 % of itself (0.90 → 0.99 % RMS): 360 folds were out of
reach. Five folds of 18 materials move every fit (parameters by 0.3–1.5 in ‖Δx‖) in ≤ 30
iterations; ten folds gave the same choice (``calibration/README.md``, "Cross-validation").
Each fold also records how far its coefficient set moved from the full fit, as the change of
the predicted H̄ and c² over all points (RMS and max): the stability of the fit against
dropping a fifth of the materials. The folds of all forms are independent tasks (``workers``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.coefficients import Coefficients
from .dataset import Dataset
from .fit import FitResult, errors, fit, rms
from .forms import Form, predict
from .workers import Workers

__all__ = ["FOLDS", "FOLD_NFEV", "FOLD_TOL", "FoldSolve", "DEFAULT_FOLDS", "Fold", "CVResult",
           "material_folds", "fold_fit", "fold_tasks", "cross_validate",
           "cross_validate_many", "REGIMES", "regime_of", "RegimeFold", "regime_fold_fit",
           "regime_tasks", "cross_validate_regimes"]

#: folds of the materials (fewer when the dataset has fewer materials)
FOLDS = 5
#: iteration cap of a fold fit (warm-started from the full fit)
FOLD_NFEV = 30
#: stopping tolerance of a fold fit (relative change of cost and parameters)
FOLD_TOL = 1e-5


@dataclass(frozen=True)
class FoldSolve:
    """How far each fold fit is solved: at most ``nfev`` evaluations, tolerance ``tol``.

    The default (30, 1e-5) keeps ``make calibrate`` within about a minute; some folds stop at
    the cap, before their minimum, and a fold that stays nearer the full fit flatters the form
    (module docstring; ``calibration/README.md``, "Cross-validation", has the figures against
    solved folds). ``--fold-nfev``/``--fold-tol`` of the command line set it."""

    nfev: int = FOLD_NFEV
    tol: float = FOLD_TOL

    def __post_init__(self) -> None:
        if not (isinstance(self.nfev, int) and 1 <= self.nfev <= 10_000):
            raise ValueError(f"fold nfev must be an integer in [1, 10000], got {self.nfev!r}")
        if not (isinstance(self.tol, float | int) and 1e-15 <= self.tol <= 1e-2):
            raise ValueError(f"fold tol must lie in [1e-15, 1e-2], got {self.tol!r}")


#: the fold solve of ``make calibrate``
DEFAULT_FOLDS = FoldSolve()


@dataclass
class Fold:
    group: str                  # the fold's label ("fold k/K")
    n_points: int
    errors: dict[str, np.ndarray]   # held-out relative errors
    params: np.ndarray
    shift_rms: float = 0.0  # RMS and max change of the predicted H̄, c² over all points
    shift_max: float = 0.0  # (fold fit against the full fit): stability of the fit
    materials: tuple[str, ...] = ()  # the held-out materials


@dataclass
class CVResult:
    form: str
    folds: list[Fold]

    def pooled(self) -> dict[str, dict[str, float]]:
        """RMS and max |error| over all held-out points, per quantity."""
        out = {}
        for q in ("H_bar", "c2", "F", "a"):
            e = np.concatenate([f.errors[q] for f in self.folds])
            out[q] = {"rms": rms(e), "max": float(np.max(np.abs(e)))}
        return out

    def worst_fold(self, q: str) -> tuple[str, float]:
        f = max(self.folds, key=lambda f: rms(f.errors[q]))
        return f.group, rms(f.errors[q])


def material_folds(groups: list[str], folds: int = FOLDS) -> list[tuple[str, ...]]:
    """The materials ``groups`` (sorted labels) dealt in turn into ``folds`` folds (at most one
    per material)."""
    k = min(folds, len(groups))
    return [tuple(groups[i::k]) for i in range(k)]


def fold_fit(ds: Dataset, form: Form, params: np.ndarray, coeff_dict: dict, materials: tuple[str, ...],
             nfev: int = FOLD_NFEV, tol: float = FOLD_TOL, label: str = "") -> Fold:
    """One fold: refit ``form`` without the runs of ``materials`` (warm start ``params``), predict
    them. ``coeff_dict`` is the full fit's (rounded) coefficient set, against which the shift of
    the predictions over all points is measured."""
    if isinstance(materials, str):
        raise TypeError(f"materials must be a tuple of material labels, got the string {materials!r}")
    full = Coefficients.from_dict(coeff_dict)
    train, test = ds.without_groups(*materials), ds.only_groups(*materials)
    r = fit(train, form, start=params, max_nfev=nfev, tol=tol)
    p0, c0 = predict(ds, full)
    p1, c1 = predict(ds, r.coeffs)
    shift = np.concatenate([p1 / p0 - 1.0, c1 / c0 - 1.0])
    return Fold(group=label or ", ".join(materials), n_points=test.size, errors=errors(test, r.coeffs),
                params=r.params, shift_rms=rms(shift), shift_max=float(np.max(np.abs(shift))),
                materials=tuple(materials))


def cross_validate(ds: Dataset, full: FitResult, nfev: int = FOLD_NFEV,
                   workers: Workers | None = None) -> CVResult:
    """Cross-validation of ``full.form`` by held-out materials, warm-started from ``full``
    (folds on ``workers`` if given, else in this process)."""
    return cross_validate_many(ds, [full], nfev, workers)[0]


def cross_validate_many(ds: Dataset, fulls: list[FitResult], nfev: int = FOLD_NFEV,
                        workers: Workers | None = None) -> list[CVResult]:
    """:func:`cross_validate` of several fits, all their folds as one batch of tasks."""
    folds = _run(ds, [t for f in fulls for t in fold_tasks(ds, f, nfev)], workers)
    n = len(material_folds(ds.groups))
    return [CVResult(form=f.form.name, folds=folds[i * n:(i + 1) * n]) for i, f in enumerate(fulls)]


def _run(ds: Dataset, tasks, workers: Workers | None) -> list:
    """The ``(fn, args)`` tasks on ``workers``, or in this process (``Workers`` with one worker)."""
    return (workers if workers is not None else Workers(ds, 1)).run(tasks)


def fold_tasks(ds: Dataset, full: FitResult, nfev: int = FOLD_NFEV, tol: float = FOLD_TOL) -> list[tuple]:
    """The folds of ``full`` as ``(fold_fit, args)`` tasks (``Workers.run``, :func:`material_folds`)."""
    groups = ds.groups
    if len(groups) < 2:
        raise ValueError("cross-validation needs at least two materials")
    sets = material_folds(groups)
    return [(fold_fit, (full.form, full.params, full.coeff_dict, m, nfev, tol, f"fold {i + 1}/{len(sets)}"))
            for i, m in enumerate(sets)]


# ------------------------------------------------------------------ held-out regimes
#: regime families and how a run is labelled in each: an E/σY decade, a hardening magnitude
#: band, a partner (flat or rigid-sphere radius band). A fold holds out every run of one label.
REGIMES = ("E/σY decade", "K/σY", "partner")


def regime_of(curve, family: str) -> str:
    """Label of a calibration run (``dataset.RunCurve``) in a regime family of ``REGIMES``."""
    m = curve.material
    if family == "E/σY decade":
        if math.isinf(m.sigma_y):
            return "elastic"
        k = math.floor(math.log10(m.E / m.sigma_y) + 1e-9)
        return f"1e{k}–1e{k + 1}"
    if family == "K/σY":
        if m.is_tabulated:
            return "tabulated curve"
        K = 0.0 if math.isinf(m.sigma_y) else m.K / m.sigma_y
        if K == 0.0:
            return "0"
        return "0–2" if K <= 2.0 else ("2–5" if K <= 5.0 else "> 5")
    if family == "partner":
        if math.isinf(curve.indenter_radius):
            return "flat"
        r = curve.indenter_radius / curve.radius
        return "R_i/R < 0.5" if r < 0.5 else ("R_i/R 0.5–1.5" if r <= 1.5 else "R_i/R > 1.5")
    raise ValueError(f"regime family must be one of {REGIMES}, got {family!r}")


@dataclass
class RegimeFold:
    family: str
    label: str
    runs: int
    errors: dict[str, np.ndarray]   # held-out relative errors (``fit.errors``)


def regime_fold_fit(ds: Dataset, form: Form, params: np.ndarray, family: str, label: str,
                    nfev: int = FOLD_NFEV, tol: float = FOLD_TOL) -> RegimeFold:
    """Refit ``form`` without the runs of ``label`` in ``family`` (warm start ``params``) and
    predict them."""
    held = [i for i, c in enumerate(ds.curves) if regime_of(c, family) == label]
    keep = [i for i, c in enumerate(ds.curves) if regime_of(c, family) != label]
    r = fit(ds.subset(keep), form, start=params, max_nfev=nfev, tol=tol)
    return RegimeFold(family, label, len(held), errors(ds.subset(held), r.coeffs))


def cross_validate_regimes(ds: Dataset, full: FitResult, nfev: int = FOLD_NFEV,
                           workers: Workers | None = None) -> list[RegimeFold]:
    """Hold out one regime at a time (every label of every family of ``REGIMES`` that leaves
    runs to fit), refit ``full.form`` and predict the held-out runs: how the form extrapolates
    to a decade of E/σY, a hardening band or a partner it was not fitted on."""
    return _run(ds, regime_tasks(ds, full, nfev), workers)


def regime_tasks(ds: Dataset, full: FitResult, nfev: int = FOLD_NFEV, tol: float = FOLD_TOL) -> list[tuple]:
    """The regime folds of :func:`cross_validate_regimes` as ``(regime_fold_fit, args)`` tasks."""
    tasks = []
    for family in REGIMES:
        labels = sorted({regime_of(c, family) for c in ds.curves})
        if len(labels) < 2:
            continue
        tasks += [(regime_fold_fit, (full.form, full.params, family, lab, nfev, tol)) for lab in labels]
    return tasks
