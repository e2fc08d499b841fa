"""The two-body interface terms (``model/unified.py``), fitted on the two-body calibration runs.

The single-body fit sets every body law; the split h₁/h of two deformable spheres is then
set by the interface equation g(u) = ln p₁ − ln p₂ + C(a)(u − u_H) = 0 (module docstring of
``unified``). Two plastic spheres of equal yield stress and unequal moduli leave the
equal-pressure equation (C = 0) nearly neutral. The FE with smooth frictionless contact
surfaces (campaign v2's E/σY 300 against 900 and 99.9, Gauss-point contact since
2026-11-28) moves the split from the Hertz partition towards the softer sphere, 0.75 → 0.96
at h/R = 0.3, converged under mesh refinement; equal pressures alone overshoot early (6 points
at h/R 0.06) and leave the κ root of extreme pairs not unique (E/σY 3·10⁴ against 150,
R₂ = 2R₁: F(h) falls where the root jumps, d ln F/d ln h −19; ``check.py``).

Fixed: the anchor, the Hertz partition u_H = ln(E'₂/E'₁) at every contact radius (a weak
pull, not a course to follow), and the similarity width δ = ``SIMILARITY`` of the fully
plastic pressures (at δ = 0.1 a yield ratio of 1.5 weighs e^(−(ln 1.5/0.1)²) ≈ 1e-7 and the
pairs of unequal yield keep the split and F of C = 0). Fitted: the coupling λ, on the grid
``COUPLINGS`` (0 included). The coupling moves F and a too (the contact pressure is √(p₁p₂)
once the pressures differ: λ = 0.07, the best for the split alone, 4.1 points, left F 9.1 %
off on the E-ratio-3 pair), so the score is the largest error over its target, split / 5
points and F, a / 3 % (:func:`target_ratio`), at the FE's loading increments with
a ≥ ``A_MIN`` R and h/R ≤ ``H_MAX`` (R the smaller radius; the first increments' transient,
``fem.io.reference_mask``, left out), among the couplings whose model passes the two-body pairs
of the monotonicity check (``check.two_body_pairs``).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..model import Sphere, contact
from ..model.coefficients import Coefficients
from ..model.run_inputs import spheres_from_inputs

__all__ = ["COUPLINGS", "SIMILARITY", "SPLIT_TARGET", "FA_TARGET", "PairCurve", "InterfaceFit",
           "pair_errors", "target_ratio",
           "pair_curve", "load_pairs", "split_errors", "fit_interface"]

#: couplings λ tried (0: equal mean pressures alone)
COUPLINGS = (0.0, 0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.2, 0.5, 1.0, 3.0, 10.0)
SIMILARITY = 0.1
#: the targets the score divides by: the split (fraction of h), F and a (relative)
SPLIT_TARGET = 0.05
FA_TARGET = 0.03
#: points compared: a ≥ A_MIN R and h/R ≤ H_MAX (as the validation's acceptance window)
A_MIN = 0.01
H_MAX = 0.3


@dataclass(frozen=True)
class PairCurve:
    """One two-body FE run: the spheres and its loading points (h, FE split h₁/h, and F, a when
    known; without them only the split is scored)."""

    name: str
    s1: Sphere
    s2: Sphere
    h: np.ndarray
    split: np.ndarray
    F: np.ndarray | None = None
    a: np.ndarray | None = None


@dataclass
class InterfaceFit:
    """The fitted coupling and the largest split error per pair, with it and without (C = 0)."""

    coupling: float
    similarity: float
    errors: dict[str, float]        # pair → max |split error| (fraction of h), fitted coupling
    errors_none: dict[str, float]   # the same with equal pressures alone (C = 0)
    #: pair → max relative |F error|, |a error| with the fitted coupling (nan: not known)
    F_errors: dict[str, float] = field(default_factory=dict)
    a_errors: dict[str, float] = field(default_factory=dict)
    #: couplings in the order of their score: (λ, score, whether their model passed the check;
    #: None: not checked, a better one passed)
    tried: list[tuple[float, float, bool | None]] = field(default_factory=list)

    def section(self) -> dict:
        """The coefficient file's ``interface`` section (the anchor: the Hertz partition)."""
        return {"coupling": self.coupling, "similarity": self.similarity}


def pair_curve(name: str, run) -> PairCurve | None:
    """The loading points of a two-body run (``fem.io.Run``); None without usable points."""
    s1, s2 = spheres_from_inputs(run.inputs, "two_body")
    h, a, h1 = (np.asarray(v, dtype=float) for v in (run.h, run.a, run.curves["h1"]))
    keep = np.asarray(getattr(run, "reference", np.ones(h.size, bool)), dtype=bool)
    R = min(s1.radius, s2.radius)
    keep &= (h > 0.0) & (a >= A_MIN * R) & (h <= H_MAX * R * (1.0 + 1e-9))
    if np.count_nonzero(keep) < 2:
        return None
    F = np.asarray(run.F, dtype=float)
    return PairCurve(name, s1, s2, h[keep], h1[keep] / h[keep], F[keep], a[keep])


def two_body_runs(db) -> list:
    """(record, run) of the converged two-body runs of set "calibration" of ``db``."""
    two_body = lambda rec: rec.inputs.get("scene") == "two_body"  # noqa: E731
    return db.runs(set="calibration", status="converged", where=two_body)


def load_pairs(db_path, db=None, runs=None) -> list[PairCurve]:
    """The converged two-body runs of set "calibration" of the database at ``db_path`` (``db``:
    that database already opened, ``spherecontact.data.Database``; ``runs``: those runs
    already read, :func:`two_body_runs`)."""
    from spherecontact.data import Database

    if runs is None:
        runs = two_body_runs(Database(db_path) if db is None else db)
    out = []
    for rec, run in runs:
        c = pair_curve(f"{rec.case} [{rec.key}]", run)
        if c is not None:
            out.append(c)
    return sorted(out, key=lambda c: c.name)


def pair_errors(pairs, coeffs: Coefficients) -> dict[str, tuple[float, float, float]]:
    """Largest |h₁/h model − FE| (fraction of h) and largest relative |F|, |a| errors of each pair
    (nan where the pair has no F, a)."""
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # calibrated-range warnings: the fit covers these pairs
        for c in pairs:
            try:
                st = contact(c.s1, c.s2, c.h, coeffs)
            except ValueError:  # no state along h: the worst score
                out[c.name] = (math.inf, math.inf, math.inf)
                continue
            rel = lambda m, fe: math.nan if fe is None else float(np.max(np.abs(m / fe - 1.0)))  # noqa: E731
            out[c.name] = (float(np.max(np.abs(st.h1 / c.h - c.split))), rel(st.F, c.F), rel(st.a, c.a))
    return out


def split_errors(pairs, coeffs: Coefficients) -> dict[str, float]:
    """Largest |h₁/h model − FE| of each pair (fraction of h)."""
    return {k: v[0] for k, v in pair_errors(pairs, coeffs).items()}


def target_ratio(err: tuple[float, float, float]) -> float:
    """The largest of a pair's errors over its target: split / ``SPLIT_TARGET``, F and a /
    ``FA_TARGET`` (F, a left out where unknown)."""
    split, F, a = err
    return max([split / SPLIT_TARGET, *(e / FA_TARGET for e in (F, a) if not math.isnan(e))])


def _with(coeffs: Coefficients, coupling: float) -> Coefficients:
    return dataclasses.replace(coeffs, interface_coupling=coupling, interface_similarity=SIMILARITY,
                               interface_radius=math.inf)


def with_interface(coeffs: Coefficients, fitted: InterfaceFit | None) -> Coefficients:
    """``coeffs`` with the fitted interface terms (unchanged without a fit or when the terms were
    left out, coupling 0)."""
    if fitted is None or fitted.coupling <= 0.0:
        return coeffs
    return _with(coeffs, fitted.coupling)


def _grid_point(_ds, pairs, coeffs: Coefficients, coupling: float) -> dict:
    """:func:`pair_errors` of ``pairs`` at one coupling (a task of ``calibration.workers``)."""
    return pair_errors(pairs, _with(coeffs, coupling))


def passes_check(coeffs: Coefficients) -> bool:
    """The two-body pairs of the monotonicity check (``check.two_body_pairs``) all pass."""
    from .check import check_pair, two_body_pairs

    return all(check_pair(label, s1, s2, coeffs).ok for label, s1, s2 in two_body_pairs())


def fit_interface(pairs, coeffs: Coefficients, pool=None, check=passes_check) -> InterfaceFit | None:
    """The coupling of ``COUPLINGS`` (module docstring); None without pairs. ``pool``: a
    ``workers.Workers`` the grid points are spread over (the same result in the same order);
    ``check``: whether a coefficient set may ship (None: no check).

    Score: over the pairs, the largest error relative to its target (:func:`target_ratio`:
    split / 5 points, F and a / 3 %; the coupling moves F through the contact pressure √(p₁p₂)),
    then (ties within 0.001) the mean of the pairs' ratios, then the smaller coupling. The
    best-scored coupling whose model passes ``check`` is taken; if none does, the best-scored one
    (the form's own check then fails). Pairs the coupling leaves unchanged (unequal fully plastic
    pressures) are scored once.
    """
    if not pairs:
        return None
    none = pair_errors(pairs, _with(coeffs, 0.0))
    strongest = pair_errors(pairs, _with(coeffs, COUPLINGS[-1]))  # also the probe of which pairs move
    moved = [c for c in pairs if strongest[c.name] != none[c.name]]
    fixed = {c.name: none[c.name] for c in pairs if c not in moved}
    lams = [lam for lam in COUPLINGS if 0.0 < lam < COUPLINGS[-1]]
    tasks = [(moved, coeffs, lam) for lam in lams]
    done = pool.map(_grid_point, tasks) if pool is not None else [_grid_point(None, *t) for t in tasks]
    scored = []
    for lam, e in zip([0.0, *lams, COUPLINGS[-1]], [none, *(fixed | d for d in done), strongest],
                      strict=True):
        e = {c.name: e[c.name] for c in pairs}
        ratios = [target_ratio(v) for v in e.values()]
        worst = max(ratios)
        key = (round(worst, 3) if math.isfinite(worst) else math.inf, float(np.mean(ratios)), lam)
        scored.append((key, lam, e))
    scored.sort(key=lambda s: s[0])
    tried, chosen = [], None
    for key, lam, e in scored:
        ok = None if chosen is not None or check is None else bool(check(_with(coeffs, lam)))
        tried.append((lam, key[0], ok))
        if chosen is None and (check is None or ok):
            chosen = (lam, e)
    lam, e = chosen if chosen is not None else scored[0][1:]
    pick = lambda d, i: {k: v[i] for k, v in d.items()}  # noqa: E731
    return InterfaceFit(lam, SIMILARITY, pick(e, 0), pick(none, 0), pick(e, 1), pick(e, 2), tried)
