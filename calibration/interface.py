"""The two-body interface terms (``model/unified.py``), fitted on the two-body calibration runs.

The single-body fit sets every body law; the split h₁/h of two deformable spheres is then
set by the interface equation g(u) = ln p₁ − ln p₂ + C(a)(u − u_A(a)) = 0 (module docstring of
``unified``). With equal mean pressures alone (C = 0) the split of two bodies of equal yield
stress runs away once both are plastic (E ratio 3: h₁/h 0.99 at h/R = 0.3, the FE 0.55).

Fixed: the coupling λ = ``COUPLING`` (large enough that the anchor holds wherever the coupling
acts: λ = 3 and 10 gave the same split within 1 percentage point on the equal-yield pairs) and
the similarity width δ = ``SIMILARITY`` of the fully plastic pressures (at δ = 0.1 a yield
ratio of 1.5 weighs e^(−(ln 1.5/0.1)²) ≈ 1e-7 and the pairs of unequal yield keep the split and
F of C = 0; at δ = 0.2 its weight 0.016 took the validation pair E ratio 3, yield ratio 1.5 from
F 3.1 to 13 % at a far anchor). Fitted: the contact radius a_c/R* and exponent k where the
anchor moves from the Hertz partition to equal strains, by a deterministic grid search that
minimises the largest |h₁/h − FE| over the pairs (percentage points of h), at the FE's loading
increments with a ≥ ``A_MIN`` R and h/R ≤ ``H_MAX`` (R the smaller radius; the first
increments' transient, ``fem.io.reference_mask``, left out).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..fem.io import spheres_from_inputs
from ..model import Sphere, contact
from ..model.coefficients import Coefficients

__all__ = ["COUPLING", "SIMILARITY", "RADII", "EXPONENTS", "PairCurve", "InterfaceFit",
           "pair_curve", "load_pairs", "split_errors", "fit_interface"]

COUPLING = 10.0
SIMILARITY = 0.1
#: grid of the anchor's contact radius a_c/R* and exponent k
RADII = (0.4, 0.5, 0.6, 0.7, 0.8, 1.0, 1.2, 1.5)
EXPONENTS = (2.0, 3.0, 4.0, 6.0)
#: points compared: a ≥ A_MIN R and h/R ≤ H_MAX (as the validation's acceptance window)
A_MIN = 0.01
H_MAX = 0.3


@dataclass(frozen=True)
class PairCurve:
    """One two-body FE run: the spheres and its loading points (h, FE split h₁/h)."""

    name: str
    s1: Sphere
    s2: Sphere
    h: np.ndarray
    split: np.ndarray


@dataclass
class InterfaceFit:
    """The fitted interface terms and the largest split error per pair, with and without them."""

    coupling: float
    similarity: float
    radius: float
    exponent: float
    errors: dict[str, float]        # pair → max |split error| (fraction of h), fitted terms
    errors_none: dict[str, float]   # the same with equal pressures alone (C = 0)

    def section(self) -> dict:
        """The coefficient file's ``interface`` section."""
        return {"coupling": self.coupling, "similarity": self.similarity, "radius": self.radius,
                "exponent": self.exponent}


def pair_curve(name: str, run) -> PairCurve | None:
    """The loading points of a two-body run (``fem.io.Run``); None without usable points."""
    s1, s2 = spheres_from_inputs(run.inputs, "two_body")
    h, a, h1 = (np.asarray(v, dtype=float) for v in (run.h, run.a, run.curves["h1"]))
    keep = np.asarray(getattr(run, "reference", np.ones(h.size, bool)), dtype=bool)
    R = min(s1.radius, s2.radius)
    keep &= (h > 0.0) & (a >= A_MIN * R) & (h <= H_MAX * R * (1.0 + 1e-9))
    if np.count_nonzero(keep) < 2:
        return None
    return PairCurve(name, s1, s2, h[keep], h1[keep] / h[keep])


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


def split_errors(pairs, coeffs: Coefficients) -> dict[str, float]:
    """Largest |h₁/h model − FE| of each pair (fraction of h)."""
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # calibrated-range warnings: the fit covers these pairs
        for c in pairs:
            st = contact(c.s1, c.s2, c.h, coeffs)
            out[c.name] = float(np.max(np.abs(st.h1 / c.h - c.split)))
    return out


def _with(coeffs: Coefficients, radius: float, exponent: float, coupling: float = COUPLING) -> Coefficients:
    return dataclasses.replace(coeffs, interface_coupling=coupling, interface_similarity=SIMILARITY,
                               interface_radius=radius, interface_exponent=exponent)


def with_interface(coeffs: Coefficients, fitted: InterfaceFit | None) -> Coefficients:
    """``coeffs`` with the fitted interface terms (unchanged without a fit or when the terms were
    left out, coupling 0)."""
    if fitted is None or fitted.coupling <= 0.0:
        return coeffs
    return dataclasses.replace(coeffs, **{f"interface_{k}": v for k, v in fitted.section().items()})


def _grid_point(_ds, pairs, coeffs: Coefficients, radius: float, exponent: float) -> dict[str, float]:
    """:func:`split_errors` of ``pairs`` at one grid point (a task of ``calibration.workers``)."""
    return split_errors(pairs, _with(coeffs, radius, exponent))


def fit_interface(pairs, coeffs: Coefficients, pool=None) -> InterfaceFit | None:
    """Grid search of a_c/R* × k (module docstring); None without pairs. ``pool``: a
    ``workers.Workers`` the grid points are spread over (the same result in the same order).

    Score: the largest split error over the pairs, then (ties within 0.1 percentage point) the
    mean of the pairs' largest errors; further ties go to the first grid point. Pairs the
    coupling leaves unchanged (unequal fully plastic pressures) are scored once.
    """
    if not pairs:
        return None
    none = split_errors(pairs, _with(coeffs, 1.0, 4.0, coupling=0.0))
    probe = split_errors(pairs, _with(coeffs, RADII[0], EXPONENTS[0]))
    moved = [c for c in pairs if abs(probe[c.name] - none[c.name]) > 1e-9]
    fixed = {c.name: none[c.name] for c in pairs if c not in moved}
    grid = [(r, k) for r in RADII for k in EXPONENTS]
    tasks = [(moved, coeffs, r, k) for r, k in grid]
    done = pool.map(_grid_point, tasks) if pool is not None else [_grid_point(None, *t) for t in tasks]
    best = None
    for (r, k), moved_errors in zip(grid, done, strict=True):
        e = fixed | moved_errors
        score = (round(max(e.values()), 3), float(np.mean(list(e.values()))))
        if best is None or score < best[0]:
            best = (score, r, k, e)
    _, r, k, e = best
    e = {c.name: e[c.name] for c in pairs}
    if not math.isfinite(max(e.values())) or max(e.values()) >= max(none.values()):
        return InterfaceFit(0.0, SIMILARITY, r, k, none, none)  # the terms do not help: left out
    return InterfaceFit(COUPLING, SIMILARITY, r, k, e, none)
