"""Checks of a fitted coefficient set: F(h) continuous and monotone; model error per FE run.

Monotone and continuous F(h) (docs/design.md §3; the model inverts h(a)): along a dense grid
of contact radii a (step ``STEP`` in ln a, 1e-6 R … 0.95 R) the model state must have

* h(a) and F(a) strictly increasing (then F(h) is increasing and a(h) is unique),
* a positive stiffness dF/dh,
* no jump: the secant slopes Δln F/Δln a and Δln h/Δln a stay within ``MAX_SLOPE``
  (a jump of relative size δ between neighbours would show as a slope ≥ δ/STEP).

Then the same along a dense grid of approaches h (step ``STEP`` in ln h, 1e-5 R … 0.9 R),
with the state a user gets, ``contact(s1, s2, h)``: F(h) finite and strictly increasing. The
sweep in a cannot see everything: where the κ root of two plastic spheres of near-equal
hardness is not unique, ``contact_from_radius`` follows one root and the inversion h → a may
land on another (a pair E/σY 3·10⁴ against 150, R₂ = 2R₁, without interface terms: rising in a,
F(h) falling where the root jumps, d ln F/d ln h down to −19).

This is done for every calibration material (equal spheres and on a rigid flat) and
for a grid of other materials and pairs (``grid_pairs``). The check goes beyond the
calibrated range on purpose (a up to 0.95 R, E/σY 5…3·10⁴, strong hardening): the
model's warnings for leaving that range are silenced here.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..model import Material, Sphere, contact, contact_from_radius
from ..model.coefficients import Coefficients
from ..model.unified import pair
from .dataset import RunCurve

__all__ = ["STEP", "MAX_SLOPE", "MonotoneCheck", "check_pair", "grid_pairs", "two_body_pairs",
           "check_all",
           "RunError", "run_errors", "quiet_range_warnings"]

try:  # the model's warning for inputs outside the calibrated range (if it has one)
    from ..model.calibrated_range import CalibrationRangeWarning as _RangeWarning
except ImportError:  # pragma: no cover - model without a calibrated-range check
    _RangeWarning = None

STEP = 0.002
MAX_SLOPE = 6.0
WALL = Sphere(math.inf, Material.rigid())


class quiet_range_warnings(warnings.catch_warnings):
    """Silence the model's calibrated-range warnings (the checks leave the range on purpose)."""

    def __enter__(self):
        out = super().__enter__()
        if _RangeWarning is not None:
            warnings.simplefilter("ignore", _RangeWarning)
        return out


@dataclass
class MonotoneCheck:
    label: str
    ok: bool
    min_dlnF: float   # smallest secant slope d ln F/d ln a
    min_dlnh: float   # smallest secant slope d ln h/d ln a
    max_slope: float  # largest secant slope of either
    min_stiffness: float
    min_dlnF_h: float  # smallest secant slope d ln F/d ln h along h (−inf: no state there)


def check_pair(label: str, s1: Sphere, s2: Sphere, coeffs: Coefficients,
               a_range=(1e-6, 0.95), h_range=(1e-5, 0.9)) -> MonotoneCheck:
    """Monotonicity and continuity of the model for one pair (module docstring), over
    ``a_range`` (units of the smaller radius) cut at the end of the model's domain, then F(h)
    over ``h_range`` (the same units) cut there too. A pair whose state the model cannot
    give along h (a root solve that raises) fails."""
    R = min(s1.radius, s2.radius)
    with quiet_range_warnings():
        model = pair(s1, s2, coeffs)
        a_end = min(a_range[1] * R, model.domain.a_max)
        lna = np.arange(math.log(a_range[0] * R), math.log(a_end), STEP)
        st = contact_from_radius(s1, s2, np.exp(lna), coeffs=coeffs)
        h_end = min(h_range[1] * R, (1.0 - STEP) * model.domain.h_max)
        try:
            Fh = contact(s1, s2, np.exp(np.arange(math.log(h_range[0] * R), math.log(h_end), STEP)),
                         coeffs).F
            dF_h = float(np.min(np.diff(np.log(Fh)))) / STEP if np.all(np.isfinite(Fh)) else -math.inf
        except ValueError:
            dF_h = -math.inf
    h = st.h1 + st.h2
    dF = np.diff(np.log(st.F)) / STEP
    dh = np.diff(np.log(h)) / STEP
    ok = bool(np.all(np.isfinite(st.F)) and np.all(np.isfinite(h)) and dF.min() > 0 and dh.min() > 0
              and max(dF.max(), dh.max()) < MAX_SLOPE and st.stiffness.min() > 0 and dF_h > 0)
    return MonotoneCheck(label, ok, float(dF.min()), float(dh.min()), float(max(dF.max(), dh.max())),
                         float(np.min(st.stiffness / (st.F / h))), dF_h)


def grid_pairs(calibration: list[Material]) -> list[tuple[str, Sphere, Sphere]]:
    """Pairs to check: every calibration material (rigid flat, equal spheres) and a grid of
    other materials (E/σY 5…3e4, ν 0.2–0.45, perfectly plastic to strongly hardening)
    on a rigid flat, against a rigid sphere, and dissimilar pairs."""
    out = []
    for m in calibration:
        lab = f"E/sy={m.E / m.sigma_y:g} nu={m.nu:g} K/sy={m.K / m.sigma_y:g} n={m.n:g}"
        out.append((lab + " | flat", Sphere(1.0, m), WALL))
        out.append((lab + " | equal spheres", Sphere(1.0, m), Sphere(1.0, m)))
    grid = _material_grid()
    for m in grid:
        lab = f"E/sy={m.E:g} nu={m.nu:g} K/sy={m.K:g} n={m.n:g}"
        out.append((lab + " | flat", Sphere(1.0, m), WALL))
        out.append((lab + " | rigid sphere R_i=0.5R", Sphere(1.0, m), Sphere(0.5, Material.rigid())))
    out += two_body_pairs(grid)
    table = Material.from_table(E=200.0, nu=0.3, eps_p=[0.0, 0.02, 0.1, 0.5],
                                sigma=[1.0, 1.3, 1.6, 2.0])
    out.append(("tabulated E/sy=200 | flat", Sphere(1.0, table), WALL))
    return out


def _material_grid() -> list[Material]:
    """E/σY 5…3·10⁴ × ν 0.2, 0.45 × five hardening laws (perfectly plastic to K/σY 10)."""
    hard = [(0.0, 1.0), (2.0, 0.15), (2.0, 0.5), (10.0, 0.3), (1.0, 1.0)]
    return [Material(E=E, nu=nu, sigma_y=1.0, K=K, n=n)
            for E in (5.0, 20.0, 150.0, 700.0, 5000.0, 3e4) for nu in (0.2, 0.45) for K, n in hard]


def two_body_pairs(grid: list[Material] | None = None) -> list[tuple[str, Sphere, Sphere]]:
    """The dissimilar pairs of :func:`grid_pairs`: every fifth grid material (R₁ = 1) against
    another (R₂ = 2), three of them perfectly plastic of equal yield stress, E ratios 6.7, 7.1
    and 200 (the two-body interface's ill-conditioned case)."""
    grid = _material_grid() if grid is None else grid
    out = []
    for i, m in enumerate(grid[::5]):
        other = grid[(7 * i + 3) % len(grid)]
        out.append((f"E/sy={m.E:g} vs E/sy={other.E:g} K/sy={other.K:g} | R2=2R1",
                    Sphere(1.0, m), Sphere(2.0, other)))
    return out


#: pairs per task when :func:`check_all` runs on worker processes
CHUNK = 24


def check_all(coeffs: Coefficients, calibration: list[Material], pool=None) -> list[MonotoneCheck]:
    """:func:`check_pair` of every pair of :func:`grid_pairs`, in order; on the worker
    processes of ``pool`` (``workers.Workers``) in chunks of ``CHUNK`` pairs when given."""
    pairs = grid_pairs(calibration)
    if pool is None:
        return _check_chunk(None, coeffs, pairs)
    chunks = [(coeffs, pairs[i:i + CHUNK]) for i in range(0, len(pairs), CHUNK)]
    return [c for done in pool.map(_check_chunk, chunks) for c in done]


def _check_chunk(_ds, coeffs: Coefficients, pairs) -> list[MonotoneCheck]:
    """:func:`check_pair` of ``pairs`` (a worker task; the dataset argument is not used)."""
    return [check_pair(lab, s1, s2, coeffs) for lab, s1, s2 in pairs]


@dataclass
class RunError:
    """Model against one FE run over its resolved range (a ≥ a_min): relative errors.

    ``F_*``, ``a_*``: against the FE curve as resampled for the fit (local linear fit in
    ln–ln over ±1 grid step, which removes the force staircase of the surface mesh);
    ``F_rms_inc``, ``a_rms_inc``: against every FE increment (staircase included).
    """

    key: str
    group: str
    scene: str
    h_range: tuple[float, float]
    F_rms: float
    F_max: float
    a_rms: float
    a_max: float
    F_rms_inc: float
    a_rms_inc: float
    F_err: np.ndarray    # per grid point of the resampled curve
    a_err: np.ndarray
    h: np.ndarray


def _model_Fa(curve: RunCurve, h: np.ndarray, coeffs: Coefficients):
    partner = WALL if math.isinf(curve.indenter_radius) else Sphere(curve.indenter_radius,
                                                                    Material.rigid())
    with quiet_range_warnings():  # a set being fitted records no range yet
        st = contact(Sphere(curve.radius, curve.material), partner, h, coeffs=coeffs)
    return np.asarray(st.F), np.asarray(st.a)


def run_errors(curve: RunCurve, coeffs: Coefficients) -> RunError:
    """F(h) and a(h) of the model (the FE scene: the body on a rigid flat or sphere) against
    the FE run, relative, over a ≥ a_min (class docstring)."""
    r = lambda e: float(np.sqrt(np.mean(e * e)))  # noqa: E731
    F, a = _model_Fa(curve, curve.h, coeffs)
    eF, ea = F / curve.F - 1.0, a / curve.a - 1.0
    sel = curve.a_fe >= curve.a_min
    Fi, ai = _model_Fa(curve, curve.h_fe[sel], coeffs)
    eFi, eai = Fi / curve.F_fe[sel] - 1.0, ai / curve.a_fe[sel] - 1.0
    return RunError(curve.key, curve.group, curve.scene, (float(curve.h[0]), float(curve.h[-1])),
                    r(eF), float(np.abs(eF).max()), r(ea), float(np.abs(ea).max()), r(eFi), r(eai),
                    eF, ea, curve.h)
