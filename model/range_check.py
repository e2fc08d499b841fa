"""Checks of one sphere pair and its approaches against the calibrated range.

What is checked (limits from :attr:`Coefficients.calibrated_range`, see
``calibrated_range.py``; "deformable" excludes rigid bodies, which are in range, as are
flats R = ∞ — they are the calibration scene):

* per deformable sphere i, once per pair: ν_i; for a body that yields (σ_Y finite),
  E_i/σ_Y,i, the hardening exponent n_i — the Ludwik n (0 when K = 0), or for a
  flow table its secant exponent, the n the model uses for H̄_III(n), c²_III(n)
  (``single.effective_exponent``) — and the hardening magnitude K_i/σ_Y,i (for a flow
  table the Ludwik fit of ``single.hardening_magnitude``);
* a deformable sphere (finite R) against a rigid body, once per pair: the radius ratio
  R_rigid/R of the calibration scenes (a rigid flat, R_rigid = ∞, or a rigid sphere),
  checked as the curvature ratio R/R_rigid against ``R_over_R_rigid``;
* pair of two deformable spheres, once per pair: R_max/R_min (both radii finite),
  E_max/E_min, and σ_Y,max/σ_Y,min (both bodies yield);
* per call, over all contacts together (NumPy reductions, no loop over points):
  h/R > ``h_over_R_max`` and a/R > ``a_over_R_max``. The approach is that of each
  deformable sphere over its own radius, max_i h_i/R_i: the calibration runs are one
  sphere on a rigid flat or sphere, where h_1 = h, so an equal pair at a total approach
  2h is as far in as its flat scene at h (if the only deformable body is a flat, the
  total h over the smallest finite radius is used). For a the radius is the smallest
  finite radius of either body (a contact radius reaching the radius of the sphere or
  of a rigid indenter); Λ_i above the largest calibrated Λ (when the
  range records Λ: small Λ is Level I, exact Hertz); for a flow table, the local
  log slope d ln σ_f/d ln ε_p at the representative strain ε_rep = β a/ρ_i above the
  largest calibrated n (a Ludwik curve σ_Y + K εⁿ never exceeds its n).

Each cause gives one :class:`CalibrationRangeWarning` per call, naming the parameter,
its value (the largest over the call for approach causes) and the calibrated range.
"""

from __future__ import annotations

import math
import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np

from .calibrated_range import CalibratedRange, CalibrationRangeWarning
from .coefficients import Coefficients
from .single import flow_log_slope, hardening_magnitude, representative_strain
from .sphere import Sphere

__all__ = ["RangeCheck", "range_check", "emit"]

_PKG_DIR = str(Path(__file__).resolve().parent)
_TAIL = "; the model extrapolates"


def _fmt(x: float) -> str:
    """4 significant digits; whole numbers below 1e7 written out (10000, not 1e+04)."""
    if math.isfinite(x) and x == round(x) and abs(x) < 1e7:
        return str(int(x))
    return f"{x:.4g}"


def _fmt_out(x: float, lo: float, hi: float) -> str:
    """x (outside [lo, hi]) with enough digits to read as outside (1.00002, not 1)."""
    text = _fmt(x)
    digits = 5
    while lo <= float(text) <= hi and digits <= 17:
        text = f"{x:.{digits}g}"
        digits += 1
    return text


def _interval(r: tuple[float, float]) -> str:
    return f"[{_fmt(r[0])}, {_fmt(r[1])}]"


def _outside(x: float, r: tuple[float, float]) -> bool:
    return not r[0] <= x <= r[1]


def _user_stacklevel() -> int:
    """stacklevel of the first frame outside this package (the user's call)."""
    import sys

    f = sys._getframe(1)  # the caller of warnings.warn
    level = 1
    while f is not None and f.f_code.co_filename.startswith(_PKG_DIR):
        f = f.f_back
        level += 1
    return level


def emit(messages) -> None:
    """Issue one :class:`CalibrationRangeWarning` per message, attributed to the user's code."""
    for msg in messages:
        warnings.warn(msg, CalibrationRangeWarning, stacklevel=_user_stacklevel())


#: relative slack of the approach limits: a run that ends at h/R = 0.3 up to roundoff
#: (0.30000000000000004) is inside h/R <= 0.3
SLACK = 1.0 + 1e-9


class RangeCheck:
    """Calibrated-range checks of one sphere pair under one coefficient set (module docstring).

    Attributes
    ----------
    range : the :class:`CalibratedRange` used.
    static : dict cause → message of the material and pair checks (empty when in range).
    limits : dict cause → upper limit of each approach-dependent check that applies.
    R_h, R_a : radii of the h/R and a/R checks.
    """

    def __init__(self, s1: Sphere, s2: Sphere, coeffs: Coefficients, rng: CalibratedRange) -> None:
        self.range = rng
        self.coeffs = coeffs
        self.static: dict[str, str] = {}
        bodies = ((1, s1), (2, s2))
        deform = [(i, s) for i, s in bodies if not s.is_rigid]
        for i, s in deform:
            self._material(i, s, coeffs)
        if len(deform) == 2:
            self._pair(s1, s2)
        else:
            self._rigid_partner(s1, s2)
        #: (i, R_i) of the deformable spheres whose own approach h_i/R_i is checked
        self.R_bodies = [(i, s.radius) for i, s in deform if not s.is_flat]
        finite_all = [s.radius for _, s in bodies if not s.is_flat]
        self.R_h = min(r for _, r in self.R_bodies) if self.R_bodies else min(finite_all)
        self.R_a = min(finite_all)
        self.limits: dict[str, float] = {"h_over_R": rng.h_over_R_max * SLACK,
                                         "a_over_R": rng.a_over_R_max * SLACK}
        self._tables = {}
        for i, s in deform:
            m = s.material
            if math.isinf(m.sigma_y):
                continue
            if rng.Lambda is not None:
                self.limits[f"Lambda_{i}"] = rng.Lambda[1] * SLACK
            if m.flow.checks_local_slope:
                self.limits[f"flow_slope_{i}"] = rng.hardening_n[1] * SLACK
                self._tables[i] = m

    # ------------------------------------------------------------------ once per pair
    def _flag(self, key: str, name: str, value: float, r: tuple[float, float], who: str) -> None:
        """Record ``key`` if value lies outside r; the message names the parameter and range."""
        if _outside(value, r):
            self.static[key] = (f"{name} = {_fmt_out(value, *r)} of {who} is outside the "
                                f"calibrated range {_interval(r)}{_TAIL}")

    def _material(self, i: int, s: Sphere, coeffs: Coefficients) -> None:
        m, rng, who = s.material, self.range, f"sphere {i}"
        self._flag(f"nu_{i}", "nu", m.nu, rng.nu, who)
        if math.isinf(m.sigma_y):
            return  # elastic: never leaves Level I
        self._flag(f"E_over_sigma_y_{i}", "E/sigma_y", m.E / m.sigma_y, rng.E_over_sigma_y, who)
        f = m.flow
        n = f.range_exponent(coeffs.eps_lo, coeffs.eps_hi, coeffs.strain_spread)
        self._flag(f"hardening_n_{i}", f.exponent_label.format(kind=f.kind), n, rng.hardening_n, who)
        name = f.magnitude_label.format(kind=f.kind)
        self._flag(f"K_over_sigma_y_{i}", name, hardening_magnitude(m, coeffs), rng.K_over_sigma_y, who)

    def _rigid_partner(self, s1: Sphere, s2: Sphere) -> None:
        """Radius ratio R_rigid/R of a deformable sphere against a rigid body (flat: ∞),
        checked as R/R_rigid ∈ ``R_over_R_rigid`` (the calibration scenes)."""
        (i, body), (j, rigid) = ((1, s1), (2, s2)) if s2.is_rigid else ((2, s2), (1, s1))
        if body.is_flat:
            return  # a half-space: the a/R → 0 limit of every calibration scene
        z = body.radius / rigid.radius  # 0 for a rigid flat
        r = self.range.R_over_R_rigid
        if _outside(z, r):
            inv = tuple(math.inf if v == 0.0 else 1.0 / v for v in (r[1], r[0]))
            self.static["R_rigid_over_R"] = (
                f"radius ratio R_rigid/R = {_fmt_out(rigid.radius / body.radius, *inv)} of rigid "
                f"sphere {j} over sphere {i} is outside the calibrated range {_interval(inv)} "
                f"(inf: a rigid flat){_TAIL}")

    def _pair(self, s1: Sphere, s2: Sphere) -> None:
        rng = self.range
        m1, m2 = s1.material, s2.material

        def ratio(x, y):
            return max(x, y) / min(x, y)

        if not (s1.is_flat or s2.is_flat):
            self._flag("radius_ratio", "radius ratio R_max/R_min", ratio(s1.radius, s2.radius),
                       (1.0, rng.radius_ratio_max), "the pair")
        self._flag("E_ratio", "Young's modulus ratio E_max/E_min", ratio(m1.E, m2.E),
                   (1.0, rng.E_ratio_max), "the pair")
        if math.isfinite(m1.sigma_y) and math.isfinite(m2.sigma_y):
            self._flag("yield_ratio", "yield-stress ratio sigma_y,max/sigma_y,min",
                       ratio(m1.sigma_y, m2.sigma_y), (1.0, rng.yield_ratio_max), "the pair")

    # ------------------------------------------------------------------ per call
    def approach_ratio(self, h, h1, h2) -> np.ndarray:
        """max_i h_i/R_i over the deformable spheres (h/R_h without any): the h/R check."""
        if not self.R_bodies:
            return h / self.R_h
        own = {1: h1, 2: h2}
        return np.maximum.reduce([own[i] / R for i, R in self.R_bodies] + [np.zeros_like(h)])

    def values(self, st) -> dict[str, np.ndarray]:
        """Per-point value of every approach-dependent check in :attr:`limits` (1-D arrays)
        for a :class:`~.unified.UnifiedState` ``st``."""
        out = {"h_over_R": self.approach_ratio(st.h, st.h1, st.h2), "a_over_R": st.a / self.R_a}
        lam = {1: st.Lambda1, 2: st.Lambda2}
        rho = {1: st.rho1, 2: st.rho2}
        a = st.a
        for key in self.limits:
            if key.startswith("Lambda_"):
                out[key] = lam[int(key[-1])]
            elif key.startswith("flow_slope_"):
                i = int(key[-1])
                eps = representative_strain(a / rho[i], self.coeffs.beta, self.coeffs.beta_growth)[0]
                out[key] = flow_log_slope(self._tables[i], eps)
        return out

    def exceeded(self, values: dict[str, np.ndarray]) -> dict[str, float]:
        """cause → largest value, for the causes above their limit."""
        out = {}
        for key, v in values.items():
            if v.size:
                top = float(np.max(v))
                if top > self.limits[key]:
                    out[key] = top
        return out

    def check_state(self, st) -> dict[str, float]:
        """Out-of-range approach causes of a :class:`~.unified.UnifiedState` (largest values)."""
        return self.exceeded(self.values(st))

    def message(self, key: str, value: float) -> str:
        """Warning text of an approach cause at its (largest) value."""
        rng = self.range
        v = _fmt_out(value, -math.inf, self.limits[key])
        if key == "h_over_R":
            what = ("largest approach of a sphere over its own radius" if self.R_bodies
                    else f"largest approach over R = {_fmt(self.R_h)}")
            return (f"h/R = {v} ({what}) is outside "
                    f"the calibrated range h/R <= {_fmt(rng.h_over_R_max)}{_TAIL}")
        if key == "a_over_R":
            return (f"a/R = {v} (largest contact radius over R = {_fmt(self.R_a)}) is "
                    f"outside the calibrated range a/R <= {_fmt(rng.a_over_R_max)}{_TAIL}")
        i = key[-1]
        if key.startswith("Lambda_"):
            return (f"Lambda = {v} (largest) of sphere {i} is outside the calibrated "
                    f"range {_interval(rng.Lambda)}{_TAIL}")
        return (f"hardening exponent d ln sigma_f/d ln eps_p = {v} of the flow table of "
                f"sphere {i} (largest at the representative strains reached) is outside the "
                f"calibrated range of n {_interval(rng.hardening_n)}{_TAIL}")

    def messages(self, found: dict[str, float]) -> list[str]:
        return [self.message(k, v) for k, v in found.items()]


@lru_cache(maxsize=256)
def _cached(s1: Sphere, s2: Sphere, coeffs: Coefficients, rng: CalibratedRange) -> RangeCheck:
    return RangeCheck(s1, s2, coeffs, rng)


def range_check(s1: Sphere, s2: Sphere, coeffs: Coefficients) -> RangeCheck:
    """Cached :class:`RangeCheck` of a pair (keyed by the range too: coefficient sets that
    differ only in provenance compare equal)."""
    return _cached(s1, s2, coeffs, coeffs.calibrated_range)
