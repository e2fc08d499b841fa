"""The range of inputs the coefficient set was calibrated on, and the warning for leaving it.

A coefficient file written by calibration carries the range of its FE data set in
``provenance["calibrated_range"]``::

    "calibrated_range": {
        "E_over_sigma_y": [min, max],   # E/σ_Y of the calibration materials
        "nu": [min, max],               # Poisson's ratio
        "hardening_n": [min, max],      # hardening exponent n (0: perfectly plastic)
        "h_over_R_max": x,              # largest approach h/R of the calibration runs
        "a_over_R_max": y,              # largest contact radius a/R reached
        "Lambda": [min, max]            # Johnson's parameter Λ reached (null: not recorded)
    }

Two further axes the calibration samples are optional keys (files written before they
were recorded do not have them)::

        "K_over_sigma_y": [min, max],   # hardening magnitude K/σ_Y (Ludwik; 0: perfectly
                                        # plastic; a flow table: ``single.hardening_magnitude``)
        "R_over_R_rigid": [min, max],   # curvature ratio R/R_rigid of the sphere over its rigid
                                        # partner (0: a rigid flat; 1: a rigid sphere of radius R)

Absent (or ``null``), they take the documented values of the v1 calibration design,
:data:`DEFAULT_K_OVER_SIGMA_Y` = [0, 2] and :data:`DEFAULT_R_OVER_R_RIGID` = [0, 1] (the
``[[calibration]]`` entries of campaign v1, ``studies/campaign_v1.toml``: K/σ_Y 0 and 2; a
rigid flat or a rigid sphere of the body's radius), so these axes are checked for older files
too.

A ``null`` entry means the data set recorded none (e.g. no body that yields): ``Lambda``
is then not checked (small Λ is Level I, exact Hertz, and large Λ is bounded through
E/σ_Y and h/R anyway), every other key takes its value from :data:`DEFAULT_RANGE`.
Optional keys ``radius_ratio_max``, ``yield_ratio_max`` and ``E_ratio_max`` give the
largest ratios of two deformable spheres covered by the data; without them the
defaults below are used.

Files without the block (the built-in literature set, files written before calibration
recorded it) get :data:`DEFAULT_RANGE`: the calibration design of the FE campaign
(campaign v1, ``studies/campaign_v1.toml``, ``[[calibration]]`` entries: E/σ_Y 10–10000, ν 0.2–0.45,
Ludwik n 0–0.5 and K/σ_Y 0–2, a rigid flat or a rigid sphere of the body's radius,
approaches up to h/R = 0.3), a contact radius below the sphere
radius (a/R < 1) and no Λ limit. Pairs of two deformable spheres: the
``[[validation]]`` entries of the same campaign reach a radius ratio of 4, a
yield-stress ratio of 3 and a Young's-modulus ratio of 3
(:data:`DEFAULT_RADIUS_RATIO_MAX`, :data:`DEFAULT_YIELD_RATIO_MAX`,
:data:`DEFAULT_E_RATIO_MAX`).

Leaving the range is not an error: the model still returns values, but it
extrapolates, and says so with a :class:`CalibrationRangeWarning` (a ``UserWarning``,
filtered or escalated with the standard :mod:`warnings` machinery).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "CalibrationRangeWarning",
    "CalibratedRange",
    "DEFAULT_RANGE",
    "DEFAULT_RADIUS_RATIO_MAX",
    "DEFAULT_YIELD_RATIO_MAX",
    "DEFAULT_E_RATIO_MAX",
    "DEFAULT_K_OVER_SIGMA_Y",
    "DEFAULT_R_OVER_R_RIGID",
    "RANGE_KEYS",
    "OPTIONAL_INTERVAL_KEYS",
]


class CalibrationRangeWarning(UserWarning):
    """The model is evaluated outside the range its coefficients were calibrated on.

    The values returned are extrapolations. Silence with
    ``warnings.filterwarnings("ignore", category=CalibrationRangeWarning)`` or make it an
    error with ``warnings.filterwarnings("error", category=CalibrationRangeWarning)``.
    """


#: required keys of ``provenance["calibrated_range"]``
RANGE_KEYS = ("E_over_sigma_y", "nu", "hardening_n", "h_over_R_max", "a_over_R_max", "Lambda")
#: largest ratio R_max/R_min of two deformable spheres of the validation set
DEFAULT_RADIUS_RATIO_MAX = 4.0
#: largest yield-stress ratio of two deformable spheres of the validation set
DEFAULT_YIELD_RATIO_MAX = 3.0
#: largest Young's-modulus ratio of two deformable spheres of the validation set
DEFAULT_E_RATIO_MAX = 3.0
#: hardening magnitude K/σ_Y of the v1 calibration design (perfectly plastic and K/σ_Y = 2)
DEFAULT_K_OVER_SIGMA_Y = (0.0, 2.0)
#: curvature ratio R/R_rigid of the v1 calibration design (rigid flat 0, rigid sphere of radius R 1)
DEFAULT_R_OVER_R_RIGID = (0.0, 1.0)
#: optional interval keys of ``provenance["calibrated_range"]`` (absent or null: the default)
OPTIONAL_INTERVAL_KEYS = ("K_over_sigma_y", "R_over_R_rigid")


def _where(key: str) -> str:
    return f"provenance.calibrated_range.{key}"


def _number(v, key: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ValueError(f"coefficients: '{_where(key)}' must be a finite number, got {v!r}")
    return float(v)


def _interval(v, key: str) -> tuple[float, float]:
    if not isinstance(v, list | tuple) or len(v) != 2:
        raise ValueError(f"coefficients: '{_where(key)}' must be a list [min, max], got {v!r}")
    lo, hi = _number(v[0], key), _number(v[1], key)
    if lo > hi:
        raise ValueError(f"coefficients: '{_where(key)}' needs min <= max, got {v!r}")
    return lo, hi


def _non_negative_interval(v, key: str) -> tuple[float, float]:
    lo, hi = _interval(v, key)
    if lo < 0.0:
        raise ValueError(f"coefficients: '{_where(key)}' must lie in [0, inf), got {v!r}")
    return lo, hi


def _positive(v, key: str) -> float:
    x = _number(v, key)
    if x <= 0.0:
        raise ValueError(f"coefficients: '{_where(key)}' must be > 0, got {v!r}")
    return x


@dataclass(frozen=True)
class CalibratedRange:
    """Inputs covered by the calibration data (see the module docstring)."""

    E_over_sigma_y: tuple[float, float]
    nu: tuple[float, float]
    hardening_n: tuple[float, float]
    h_over_R_max: float
    a_over_R_max: float
    Lambda: tuple[float, float] | None = None
    radius_ratio_max: float = DEFAULT_RADIUS_RATIO_MAX
    yield_ratio_max: float = DEFAULT_YIELD_RATIO_MAX
    E_ratio_max: float = DEFAULT_E_RATIO_MAX
    K_over_sigma_y: tuple[float, float] = DEFAULT_K_OVER_SIGMA_Y
    R_over_R_rigid: tuple[float, float] = DEFAULT_R_OVER_R_RIGID
    source: str = "default"  # "provenance" (read from the coefficient set) or "default"

    @classmethod
    def from_provenance(cls, provenance: dict) -> CalibratedRange:
        """The range of ``provenance["calibrated_range"]``, :data:`DEFAULT_RANGE` if absent.

        A block that is present but malformed raises ValueError naming the key.
        """
        block = provenance.get("calibrated_range") if isinstance(provenance, dict) else None
        if block is None:
            return DEFAULT_RANGE
        if not isinstance(block, dict):
            raise ValueError("coefficients: 'provenance.calibrated_range' must be an object, got "
                             f"{type(block).__name__}")
        for key in RANGE_KEYS:
            if key not in block:
                raise ValueError(f"coefficients: missing key '{_where(key)}'")
        def get(key, parse, optional=False):
            v = block.get(key) if optional else block[key]
            return getattr(DEFAULT_RANGE, key) if v is None else parse(v, key)

        lam = block["Lambda"]
        return cls(
            E_over_sigma_y=get("E_over_sigma_y", _interval),
            nu=get("nu", _interval),
            hardening_n=get("hardening_n", _interval),
            h_over_R_max=get("h_over_R_max", _positive),
            a_over_R_max=get("a_over_R_max", _positive),
            Lambda=None if lam is None else _interval(lam, "Lambda"),
            radius_ratio_max=get("radius_ratio_max", _positive, optional=True),
            yield_ratio_max=get("yield_ratio_max", _positive, optional=True),
            E_ratio_max=get("E_ratio_max", _positive, optional=True),
            K_over_sigma_y=get("K_over_sigma_y", _non_negative_interval, optional=True),
            R_over_R_rigid=get("R_over_R_rigid", _non_negative_interval, optional=True),
            source="provenance",
        )

    def describe(self) -> str:
        """One line for reports: the ranges and where they come from."""
        lam = "" if self.Lambda is None else f", Λ {self.Lambda[0]:g}–{self.Lambda[1]:g}"
        where = ("the coefficient set's provenance" if self.source == "provenance"
                 else "default: the campaign's calibration design")
        return (f"E/σ_Y {self.E_over_sigma_y[0]:g}–{self.E_over_sigma_y[1]:g}, ν {self.nu[0]:g}–"
                f"{self.nu[1]:g}, hardening exponent n {self.hardening_n[0]:g}–{self.hardening_n[1]:g}, "
                f"K/σ_Y {self.K_over_sigma_y[0]:g}–{self.K_over_sigma_y[1]:g}, rigid partner "
                f"R/R_rigid {self.R_over_R_rigid[0]:g}–{self.R_over_R_rigid[1]:g} (0: flat), "
                f"h/R ≤ {self.h_over_R_max:g} (each sphere's own approach), a/R ≤ {self.a_over_R_max:g}"
                f"{lam}; pairs: radius ratio ≤ "
                f"{self.radius_ratio_max:g}, yield ratio ≤ {self.yield_ratio_max:g}, E ratio ≤ "
                f"{self.E_ratio_max:g} ({where})")

    def to_dict(self) -> dict:
        """The ``provenance["calibrated_range"]`` block of this range."""
        return {
            "E_over_sigma_y": list(self.E_over_sigma_y), "nu": list(self.nu),
            "hardening_n": list(self.hardening_n), "h_over_R_max": self.h_over_R_max,
            "a_over_R_max": self.a_over_R_max,
            "Lambda": None if self.Lambda is None else list(self.Lambda),
            "radius_ratio_max": self.radius_ratio_max, "yield_ratio_max": self.yield_ratio_max,
            "E_ratio_max": self.E_ratio_max,
            "K_over_sigma_y": list(self.K_over_sigma_y), "R_over_R_rigid": list(self.R_over_R_rigid),
        }


#: Range used when the coefficient set records none: the calibration design of the FE
#: campaign v1 (studies/campaign_v1.toml) — E/σ_Y 10–10000, ν 0.2–0.45, Ludwik n 0–0.5, K/σ_Y 0–2,
#: rigid flat or rigid sphere of radius R, h/R ≤ 0.3 —, a/R < 1 (the contact radius reaching
#: the sphere radius), no Λ limit, and
#: the pair ratios of the validation set (radius 4, yield stress 3, Young's modulus 3).
DEFAULT_RANGE = CalibratedRange(
    E_over_sigma_y=(10.0, 1e4),
    nu=(0.2, 0.45),
    hardening_n=(0.0, 0.5),
    h_over_R_max=0.3,
    a_over_R_max=1.0,
    Lambda=None,
)
