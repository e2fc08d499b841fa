"""Coefficient set of the level functions H̄(Λ), c²(Λ) (docs/design.md §2), stored as versioned JSON.

The default set is the calibrated file ``coefficients.json`` shipped inside this package
(``model/coefficients.json`` in the repository, read with :mod:`importlib.resources`, so a
wheel, an sdist and an editable install read the same file); ``make calibrate`` writes it
with ``"source": "calibration"``. The ``SPHERECONTACT_COEFFICIENTS`` environment variable
names another file. The built-in literature set :data:`LITERATURE` (schema 1) is used only
when asked for by name, ``load_coefficients("literature")``; a missing or unreadable default
file is an error, never a silent fallback. The JSON schema is documented in
``model/README.md``.

Functional forms fixed by the schema (symbols of docs/design.md §1–2):

* Level III, hardening exponent n:  q_III(n) = prefactor · exp(Σ_k exp_poly[k] n^(k+1))
  for q = H̄, c²;
* Level II, t = ln(Λ/Λ_I)/ln(Λ_III/Λ_I) ∈ [0, 1]:
  q(t) = q_I + (q_III − q_I) · [t + t(1 − t) Σ_k shape[k] t^k]  (continuous at both ends);
  with ``level_II.smooth`` (schema 2) instead the cubic Hermite that also matches the
  slopes at both ends, plus shape terms that keep them:
  s(t) = 3t² − 2t³ + m₀ (t − 2t² + t³) + t²(1 − t)² Σ_k shape[k] t^k, with
  m₀ = H̄_I ln(Λ_III/Λ_I)/(H̄_III − H̄_I) for H̄ (d ln H̄/d ln Λ = 1 of Hertz at Λ_I) and
  m₀ = 0 for c²; the slope is 0 at Λ_III. q and dq/dΛ are then continuous (F(h) is C¹);
* finite size, geometric ratio x (a/ρ_i or a/R_i):  q → q · (1 + Σ_k coeffs[k] x^(k+1)),
  which vanishes as x → 0; in schema 2 the coefficients move from their Level I values
  (``H_bar``, ``c2``) to their Level III values (``H_bar_plastic``, ``c2_plastic``) with
  the level weight s = 3t² − 2t³ (t of Level II clipped to [0, 1]), which is C¹;
* large-deformation collapse (schema 2, optional; same ratio x): the half-space values
  H̄_hs, c²_hs above are blended with limits of the whole body,
  L(x, n, z) = prefactor · x^(−exponent) · exp(Σ_k x_poly[k] x^(k+1) + Σ_k exp_poly[k] n^(k+1)
  + n Σ_k xn_poly[k] x^(k+1) + Σ_k z_poly[k] z^(k+1) + n Σ_k zn_poly[k] z^(k+1)),
  z = R/ρ_c − 1 with ρ_c the radius of the surface pressing the body (a constant of the pair:
  0 for equal spheres, R/R_i against a rigid sphere); ``xn_poly`` and ``zn_poly`` (optional,
  default none) let the x- and z-dependence vary with n,
  r = H̄_hs/H̄_c,  w = r^k/(1 + r^k)  (k = sharpness),
  w_c = (r e^s)^(k_c)/(1 + (r e^s)^(k_c))  (the c² weight: k_c = sharpness_c2 and
  s = offset_c2, both optional, default k and 0, so that w_c = w),
  H̄ = H̄_hs (1 + r^k)^(−1/k)   (smooth minimum of H̄_hs and H̄_c),
  c² = c²_hs^(1−w_c) · c²_c^(w_c);  H̄_c → ∞ as x → 0 (exponent > 0), so w, w_c → 0 and
  the correction vanishes. L depends on a only through x (n and z are constants of a
  body and a pair), so p_m keeps rising with 1/ρ and the κ root stays unique;
* counter surface (optional ``counter_surface``, needs the ratio a/R): the half-space
  H̄_hs and c²_hs are multiplied by exp(q · s(u)) with u = a/ρ − a/R, the contact radius
  over the radius of the surface pressing the body (a/R_i against a rigid sphere, 0 against
  a flat and between equal spheres), s(u) = max(u, 0)²/(1 + u²) (C¹, bounded by 1) and
  q = ``counter_surface.H_bar`` or ``.c2`` in [−2, 2]: the indenter's own curvature at
  a/R_i of order one, which the parabolic contact geometry of the half-space law leaves out.
  Optional ``H_bar_plastic``, ``c2_plastic``: the fully plastic (Level III) values q_III, and
  q = (1 − s_l) q + s_l q_III with the level weight s_l as for the finite-size factors
  (absent: q_III = q). Against a small rigid sphere c² rises with a/R_i while the body is
  elastic–plastic and falls once it is fully plastic (pile-up around the indenter).
  Optional ``H_bar_conformity``, ``c2_conformity`` (q_ζ, absent: 0): the Level III values
  change with the conformity ζ = z/(1 + z) = 1 − ρ_c/R of the pressing surface (0 against a
  flat, ½ against a rigid sphere of the body's radius, → 1 under a small one),
  q = (1 − s_l) q + s_l (q_III + q_ζ ζ): at the same a/R_i a fully plastic body is a half space
  under a small indenter and near collapse under one of its own size; q_III + q_ζ stays in
  [−2, 2] as well;
* counter cap (optional ``counter_cap``, absent: ``paraboloid``): ``exact`` adds to the gap a
  body closes the depth of a rigid (or much harder, by its weight w) partner's spherical cap
  beyond its paraboloid, h = (a²/(2ρ) + w e)/c² (``cap.py``); c² was calibrated with it;
* representative stress (optional ``strain_spread`` W ≥ 0, absent: 0): σ_rep is the flow
  curve averaged over a log-normal distribution of strains about ε_rep,
  σ_rep = ⅔ σ_f(ε_rep) + ⅙ σ_f(ε_rep e^(−√3W)) + ⅙ σ_f(ε_rep e^(√3W)) (three-point
  Gauss–Hermite), ``single.representative_stress``; W = 0 is σ_rep = σ_f(ε_rep);
* hardening exponent (``hardening_exponent``): ``secant_loglog``, one n per material, the secant
  of ln σ_rep against ln ε between ``eps_lo`` and ``eps_hi``; or ``local_secant`` (keys ``window``
  K and ``cap`` c as well), n read along the curve at each contact radius, the secant over
  [ε_rep/K, K ε_rep] softly capped, n/(1 + (n/c)⁴)^¼ (``single.local_exponent``): a curve that is
  not a power law (saturating, linear) has the exponent of the strains the contact holds. The
  calibrated range's exponent axis stays the per-material secant;
* unloading (optional ``unloading``; absent: Thornton 1997, Hertz from the peak): the
  elastic unloading branch below the largest approach reached, F = F_max ξ^m
  (``unloading.py`` gives the law; :class:`UnloadingCoefficients` the keys).

Schema 1 files (the literature set) are still read; they have no collapse block.

The input range the set was calibrated on is :attr:`Coefficients.calibrated_range`, read
from ``provenance["calibrated_range"]`` (``calibrated_range.py``; a default when absent).

Digits: calibration writes every fitted coefficient with 6 significant digits
(``calibration.fit.SIGNIFICANT``) and the statistics in ``provenance`` with 3
(``calibration.pipeline.STAT_SIGNIFICANT``); the values are used exactly as read, and the
residuals the file reports are those of the written set (``calibration/README.md``,
"Reproducibility").
"""

from __future__ import annotations

import copy
import json
import math
import os
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from .calibrated_range import CalibratedRange

__all__ = [
    "SCHEMA_VERSION",
    "SUPPORTED_VERSIONS",
    "CollapseLimit",
    "UnloadingCoefficients",
    "LITERATURE",
    "Coefficients",
    "default_path",
    "package_path",
    "load_coefficients",
    "default_coefficients",
]

SCHEMA_VERSION = 2
#: schema versions this reader accepts (1: no ``collapse`` block)
SUPPORTED_VERSIONS = (1, 2)
ENV_VAR = "SPHERECONTACT_COEFFICIENTS"
SOURCES = ("literature", "calibration")
RATIOS = ("a_over_rho", "a_over_R")
#: variables of the collapse limits' z-polynomials (``collapse.z_variable``): z itself, or
#: ln(1 + max(z, 0)) = ln(R/ρ_c) (0 for z ≤ 0, where no calibration run lies)
Z_VARIABLES = ("z", "ln(1+z)")
EXPONENT_METHODS = ("secant_loglog", "local_secant")
#: shape of a rigid partner's surface in the gap a body closes (``counter_cap``, ``cap.py``)
COUNTER_CAPS = ("paraboloid", "exact")
#: contact pressure profile a less plastic body of a pair is loaded by (``profile.py``)
PRESSURE_PROFILES = ("hertz", "flattened")
#: allowed ranges of the ``local_secant`` exponent's window factor and cap
EXPONENT_WINDOW_RANGE = (1.5, 10.0)
EXPONENT_CAP_RANGE = (0.1, 2.0)

#: Built-in literature set (schema 1): the starting values of calibration, used by name only
#: (``load_coefficients("literature")``).
LITERATURE: dict = {
    "schema_version": 1,
    "source": "literature",
    "provenance": {
        "created": "2026-11-21",
        "method": "literature starting values, no fit to FE data",
        "fe_dataset": None,
        "notes": (
            "Level I is exact Hertz. Level III and beta from the Brinell similarity analyses; "
            "Level II is the straight line in ln(Lambda) joining Level I and Level III (no shape "
            "terms); no finite-size terms. These are starting values for calibration, not results."
        ),
    },
    "beta": 0.32,
    "Lambda_I": 3.0,
    "Lambda_III": 40.0,
    "H_bar_III": {"prefactor": 3.07, "exp_poly": []},
    "c2_III": {"prefactor": 1.43, "exp_poly": [-0.97]},
    "level_II": {"H_bar_shape": [], "c2_shape": []},
    "hardening_exponent": {"method": "secant_loglog", "eps_lo": 0.01, "eps_hi": 0.1},
    "finite_size": {"ratio": "a_over_rho", "H_bar": [], "c2": []},
    "references": {
        "beta": (
            "Biwa & Storakers (1995) J. Mech. Phys. Solids 43:1303, fully plastic Brinell "
            "similarity solution: H = 3.07 sigma(eps_rep = 0.32 a/R) (seed eq. 3). Tabor (1951) "
            "The Hardness of Metals: beta = 0.2 with H_bar = 2.8 (seed eq. 2)."
        ),
        "Lambda_I": (
            "Johnson (1985) Contact Mechanics, sec. 6.3-6.5; seed sec. 2: Level I (elastic) "
            "for Lambda < 3."
        ),
        "Lambda_III": (
            "Johnson (1985) Contact Mechanics, sec. 6.5: fully plastic indentation for "
            "E* a/(Y R) of about 40; the straight line in ln(Lambda) from (3, 4/pi) to "
            "(40, 3.07) has slope 0.69, close to the 2/3 of Johnson's cavity model."
        ),
        "H_bar_III": (
            "Biwa & Storakers (1995): H_bar = 3.07 with beta = 0.32, independent of the "
            "hardening exponent (seed eq. 3)."
        ),
        "c2_III": (
            "Storakers, Biwa & Larsson (1997) Int. J. Solids Struct. 34:3061, fit of the "
            "similarity solutions for sigma = sigma_0 eps^(1/m): c^2 = 1.43 exp(-0.97/m); "
            "written here with n = 1/m. Limits: n = 0 (perfectly plastic) 1.43; n = 1 gives "
            "0.54, near the Hertz value 1/2."
        ),
        "level_II": (
            "Seed sec. 2 and Fig. 2: H_bar and c^2 approximately linear in ln(Lambda) in "
            "Level II."
        ),
        "hardening_exponent": (
            "Mapping of a general flow curve to the power-law exponent n of the similarity "
            "solutions: secant slope of ln(sigma_f) against ln(eps_p) between eps_lo and eps_hi "
            "(the decade of eps_rep = beta a/rho met in Level III). Exact for sigma_f = K eps^n; "
            "0 for perfect plasticity."
        ),
        "finite_size": (
            "docs/design.md §2: finite-size and large-deformation terms vanish as a/rho -> 0; none "
            "in the literature set (pure half-space theory)."
        ),
    },
}


#: top-level keys a set may leave out (``to_dict`` writes them only when they are not the default)
#: largest log-width of the strain distribution of the representative stress (a factor e^(√3·2)
#: ≈ 32 between the outer quadrature strains and ε_rep)
SPREAD_MAX = 2.0

_OPTIONAL_TOP_KEYS = ("beta_growth", "strain_spread", "interface", "counter_surface", "counter_cap",
                      "pressure_profile", "unloading")

#: bound of the counter-surface coefficients: |q| ≤ 2 keeps d ln F/d ln a and d ln h/d ln a
#: above 2 − |q|/2 ≥ 1 from these terms (ds/d ln u ≤ ½)
COUNTER_BOUND = 2.0


@dataclass(frozen=True)
class UnloadingCoefficients:
    """Coefficients of the unloading law (``unloading.py``; JSON section ``unloading``).

    The defaults are Thornton (1997): Hertz from the peak state, i.e. the unloading
    stiffness 2E*a_max (``stiffness`` 1, no finite-size terms) and the exponent 3/2.
    """

    #: s₀: unloading stiffness over Sneddon's 2E*a (with the finite-size terms below)
    stiffness: float = 1.0
    #: g_a, g_h, g_ν: each body's stiffness grows by 1 + [g_a (a/R_i)² + g_h · 2h_i/R_i][1 + g_ν (ν_i − 0.3)]
    size_a: float = 0.0
    size_h: float = 0.0
    size_nu: float = 0.0
    #: exponent m of a plastic peak against a flat: m_p + m_c2 ln c² + m_depth z̄ + m_λ λ (z̄: the
    #: compliance-weighted 2h_i/R_i; m_λ: ``m_lambda``)
    m_plastic: float = 1.5
    m_c2: float = 0.0
    m_depth: float = 0.0
    #: ... against a curved counter-surface (u = a|κ| → ∞)
    m_counter: float = 1.5
    #: ... of an elastic peak: 3/2 + m_elastic_size ȳ²
    m_elastic_size: float = 0.0
    #: k of the elastic weight w = min(λ, 1)^k, λ = p_m over Hertz's at the same a
    elastic_weight: float = 1.0
    #: g_U: a curved counter-surface (U = u/(1 + u)) scales the size terms of g_i by (1 − g_U U)
    size_counter: float = 0.0
    #: s_c: the stiffness of a plastic peak grows by (c²)^q, q = s_c (1 − w) + s_U U + s_z z̄ + s_2 ln c²
    #: (pile-up stiffer, sink-in softer)
    stiffness_c2: float = 0.0
    #: m_λ: the plastic exponent grows by m_λ λ against a flat
    m_lambda: float = 0.0
    #: s_U, s_z, s_2 of the pile-up exponent q (curved counter-surface, depth, ln c² itself): the
    #: deepest cycles of perfectly plastic spheres under rigid spheres of R_i ≈ R keep c² > 1 while
    #: the body flattens to a/R ≈ 0.6, and s_c (1 − w) alone left them 11–14 % too stiff
    #: (model/README.md, "Unloading and reloading")
    stiffness_c2_counter: float = 0.0
    stiffness_c2_depth: float = 0.0
    stiffness_c2_c2: float = 0.0
    #: m_Uz: a deep dent under a curved counter-surface unloads with the exponent lowered by
    #: m_Uz U z̄² at the same elastic recovery δ_e (the term is left out of δ_e = m F C/s₀)
    m_counter_depth: float = 0.0

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in UNLOADING_RANGES}


#: allowed ranges of the ``unloading`` section's numbers (``UnloadingCoefficients``)
UNLOADING_RANGES = {"stiffness": (0.5, 2.0), "size_a": (0.0, 10.0), "size_h": (0.0, 10.0),
                    "size_nu": (-3.0, 3.0),
                    "m_plastic": (1.0, 2.0), "m_c2": (-1.0, 1.0), "m_depth": (-2.0, 2.0),
                    "m_counter": (1.0, 2.0),
                    "m_elastic_size": (-1.0, 3.0), "elastic_weight": (0.1, 20.0),
                    "size_counter": (0.0, 1.0), "stiffness_c2": (-0.5, 0.5), "m_lambda": (-1.0, 1.0),
                    "stiffness_c2_counter": (-2.0, 2.0), "stiffness_c2_depth": (-2.0, 2.0),
                    "stiffness_c2_c2": (-2.0, 2.0), "m_counter_depth": (-3.0, 3.0)}
#: keys of the ``unloading`` section an older file may leave out (absent: 0, the law without them)
UNLOADING_OPTIONAL = ("size_counter", "stiffness_c2", "m_lambda", "stiffness_c2_counter",
                      "stiffness_c2_depth", "stiffness_c2_c2", "m_counter_depth")

#: allowed ranges of the ``interface`` section's numbers
_INTERFACE_RANGES = {"coupling": (0.0, 1000.0), "similarity": (0.01, 10.0), "radius": (0.01, 100.0),
                     "exponent": (0.5, 20.0)}


def _counter(d: dict) -> dict:
    """The optional ``counter_surface`` section as ``Coefficients`` fields (absent: none)."""
    if "counter_surface" not in d:
        return {}
    sec = _section(d, "counter_surface")
    out = {}
    pairs = [("H_bar", "counter_H_bar"), ("c2", "counter_c2")]
    pairs += [(k, f) for k, f in (("H_bar_plastic", "counter_H_bar_plastic"),
                                  ("c2_plastic", "counter_c2_plastic")) if k in sec]
    for key, fld in pairs:
        q = _number(sec, key, "counter_surface.")
        if not -COUNTER_BOUND <= q <= COUNTER_BOUND:
            raise ValueError(f"coefficients: 'counter_surface.{key}' must lie in "
                             f"[{-COUNTER_BOUND:g}, {COUNTER_BOUND:g}], got {q!r}")
        out[fld] = q
    for key in ("H_bar_conformity", "c2_conformity"):  # bounded through q_III + q_ζ (below)
        if key in sec:
            out[f"counter_{key}"] = _number(sec, key, "counter_surface.")
    for which in ("H_bar", "c2"):  # the Level III value under a vanishing indenter, q_III + q_ζ
        q3 = out.get(f"counter_{which}_plastic", out.get(f"counter_{which}", 0.0))
        q31 = q3 + out.get(f"counter_{which}_conformity", 0.0)
        if not -COUNTER_BOUND <= q31 <= COUNTER_BOUND:
            raise ValueError(f"coefficients: 'counter_surface.{which}_plastic' (default '{which}') plus "
                             f"'{which}_conformity' must lie in [{-COUNTER_BOUND:g}, {COUNTER_BOUND:g}], "
                             f"got {q31!r}")
    fs = d.get("finite_size")
    if any(out.values()) and isinstance(fs, dict) \
            and fs.get("ratio") != "a_over_R":
        raise ValueError("coefficients: 'counter_surface' needs 'finite_size.ratio' = 'a_over_R' "
                         f"(u = a/rho - a/R), got {fs.get('ratio')!r}")
    return out


def _ranged(d: dict, name: str, ranges: dict, optional=()) -> dict | None:
    """The numbers of the optional section ``name``, each within its range (None if absent);
    keys in ``optional`` may be missing (left out of the result)."""
    if name not in d:
        return None
    sec = _section(d, name)
    out = {}
    for key, (lo, hi) in ranges.items():
        if key in optional and key not in sec:
            continue
        v = _number(sec, key, f"{name}.")
        if not lo <= v <= hi:
            raise ValueError(f"coefficients: '{name}.{key}' must lie in [{lo:g}, {hi:g}], got {v!r}")
        out[key] = v
    return out


def _unloading(d: dict) -> dict:
    """The optional ``unloading`` section as the ``Coefficients.unloading`` field (absent:
    Thornton's defaults; keys of ``UNLOADING_OPTIONAL`` absent: 0)."""
    values = _ranged(d, "unloading", UNLOADING_RANGES, UNLOADING_OPTIONAL)
    if values is None:
        return {}
    unknown = sorted(set(d["unloading"]) - set(UNLOADING_RANGES))
    if unknown:
        raise ValueError(f"coefficients: unknown key 'unloading.{unknown[0]}' "
                         f"(allowed: {', '.join(UNLOADING_RANGES)})")
    return {"unloading": UnloadingCoefficients(**values)}


def _interface(d: dict) -> dict:
    """The optional ``interface`` section as ``Coefficients`` fields (absent: no coupling)."""
    values = _ranged(d, "interface", _INTERFACE_RANGES, optional=("radius", "exponent"))
    return {} if values is None else {f"interface_{k}": v for k, v in values.items()}


def _number(d: dict, key: str, where: str) -> float:
    if key not in d:
        raise ValueError(f"coefficients: missing key '{where}{key}'")
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, int | float):
        raise ValueError(f"coefficients: '{where}{key}' must be a number, got {type(v).__name__}")
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"coefficients: '{where}{key}' must be finite, got {v!r}")
    return v


def _poly(d: dict, key: str, where: str) -> tuple[float, ...]:
    if key not in d:
        raise ValueError(f"coefficients: missing key '{where}{key}'")
    v = d[key]
    if not isinstance(v, list | tuple):
        raise ValueError(
            f"coefficients: '{where}{key}' must be a list of numbers (1-D), got {type(v).__name__}"
        )
    out = []
    for i, c in enumerate(v):
        if isinstance(c, bool) or not isinstance(c, int | float) or not math.isfinite(c):
            raise ValueError(
                f"coefficients: '{where}{key}[{i}]' must be a finite number, got {c!r}"
            )
        out.append(float(c))
    return tuple(out)


def _section(d: dict, key: str) -> dict:
    if key not in d:
        raise ValueError(f"coefficients: missing key '{key}'")
    v = d[key]
    if not isinstance(v, dict):
        raise ValueError(f"coefficients: '{key}' must be an object, got {type(v).__name__}")
    return v


def _choice(d: dict, key: str, where: str, allowed: tuple[str, ...], default: str | None = None) -> str:
    """``d[key]``, one of ``allowed``; ``default`` when the key is absent (None: required)."""
    if key not in d:
        if default is not None:
            return default
        raise ValueError(f"coefficients: missing key '{where}{key}'")
    v = d[key]
    if v not in allowed:
        raise ValueError(f"coefficients: '{where}{key}' must be one of {allowed}, got {v!r}")
    return v


def _limit(d, where: str) -> CollapseLimit:
    """A collapse limit {prefactor, exponent, x_poly, exp_poly, z_poly[, xn_poly, zn_poly]}
    (module docstring); ``xn_poly`` and ``zn_poly`` are optional (absent: none)."""
    if not isinstance(d, dict):
        raise ValueError(f"coefficients: '{where}' must be an object, got {type(d).__name__}")
    pre = _number(d, "prefactor", where + ".")
    if pre <= 0.0:
        raise ValueError(f"coefficients: '{where}.prefactor' must be > 0, got {pre!r}")
    return CollapseLimit(prefactor=pre, exponent=_number(d, "exponent", where + "."),
                         x_poly=_poly(d, "x_poly", where + "."),
                         exp_poly=_poly(d, "exp_poly", where + "."),
                         z_poly=_poly(d, "z_poly", where + "."),
                         xn_poly=_poly(d, "xn_poly", where + ".") if "xn_poly" in d else (),
                         zn_poly=_poly(d, "zn_poly", where + ".") if "zn_poly" in d else ())


def exp_poly_log_and_slope(exp_poly, n):
    """Σ c_k n^(k+1) and its n-derivative Σ (k+1) c_k n^k (vectorised in n): the exponent of
    :func:`_exp_poly` and its slope, for the exponent read along the curve."""
    n = np.asarray(n, dtype=float)
    if not exp_poly:
        return np.zeros_like(n), np.zeros_like(n)
    k = len(exp_poly) - 1
    s, d = exp_poly[k] * n, np.full_like(n, (k + 1) * exp_poly[k])  # the first Horner step (n finite)
    for k in range(len(exp_poly) - 2, -1, -1):
        s = (s + exp_poly[k]) * n
        d = d * n + (k + 1) * exp_poly[k]
    return s, d


def _exp_poly(prefactor: float, exp_poly: tuple[float, ...], n):
    """prefactor · exp(Σ_k c_k n^(k+1)), vectorised in n."""
    n = np.asarray(n, dtype=float)
    s = np.zeros_like(n)
    for c in reversed(exp_poly):
        s = (s + c) * n
    return prefactor * np.exp(s)


def continue_beyond(x, x_max):
    """x_c = min(x, x_max) and u = x_c/x of the C¹ continuation beyond x_max (x > 0).

    A term g(x) fitted on x ≤ x_max (value g_c, log slope S_c = dg/d ln x at x_c) is used as

        g(x) = g_c + S_c (1 − u),   dg/d ln x = S_c u,        (u = x_max/x beyond x_max)

    continuous with its slope at x_max and tending to the constant g_c + S_c as x → ∞; for
    x ≤ x_max, u = 1 and g is the fitted term itself (bit for bit). ``x_max=None``: no
    continuation (x_c = x, u = 1).
    """
    x = np.asarray(x, dtype=float)
    if x_max is None:
        return x, np.ones_like(x)
    return np.minimum(x, x_max), x_max / np.maximum(x, x_max)   # u = 1.0 exactly up to x_max


def continued_log(x, x_max):
    """x_c, u of :func:`continue_beyond` and ln x_c (−inf at x = 0)."""
    xc, u = continue_beyond(np.asarray(x, dtype=float), x_max)
    with np.errstate(divide="ignore"):
        return xc, u, np.log(xc)


def poly_with_n(b, bn, n: float) -> tuple[float, ...]:
    """The coefficients b_k + n bn_k of a polynomial with per-n terms at one n (the shorter
    tuple padded with zeros)."""
    k = max(len(b), len(bn))
    return tuple(c + n * d for c, d in zip(tuple(b) + (0.0,) * (k - len(b)),
                                           tuple(bn) + (0.0,) * (k - len(bn)), strict=True))


def _poly_and_slope(x, poly: tuple[float, ...]):
    """Σ_k c_k x^(k+1) and its log slope x d/dx = Σ_k (k+1) c_k x^(k+1)."""
    if not poly:
        return np.zeros_like(x), np.zeros_like(x)
    k = len(poly) - 1
    s, ds = poly[k] * x, ((k + 1) * poly[k]) * x  # the first Horner step from s = ds = 0
    for k in range(len(poly) - 2, -1, -1):
        s = (s + poly[k]) * x
        ds = (ds + (k + 1) * poly[k]) * x
    return s, ds


def _z_terms(z, z_max: float | None, poly: tuple[float, ...]):
    """Σ poly[k] z^(k+1) and its z-derivative, continued beyond z_max in ln(1 + z)."""
    zc = z if z_max is None else np.minimum(z, z_max)
    sz = np.zeros_like(zc)  # Σ c_k z^(k+1)
    dz = np.zeros_like(zc)  # Σ (k+1) c_k z^k
    for k in range(len(poly) - 1, -1, -1):
        sz = (sz + poly[k]) * zc
        dz = dz * zc + (k + 1) * poly[k]
    if z_max is None or not poly or not np.any(z > z_max):
        return sz, dz
    S = (1.0 + zc) * dz  # d/d ln(1 + z) at z_c
    u = (1.0 + zc) / (1.0 + np.maximum(z, z_max))
    beyond = z > z_max
    return (np.where(beyond, sz + S * (1.0 - u), sz),
            np.where(beyond, S * u / (1.0 + np.maximum(z, z_max)), dz))


@dataclass(frozen=True)
class CollapseLimitAt:
    """A collapse limit at one n and one z (:meth:`CollapseLimit.at`): ln L = log_const
    − exponent ln x + Σ x_poly[k] x^(k+1), continued beyond x_max as
    :meth:`CollapseLimit.log_and_slope`; d ln L/d z is the constant dlnL_dz."""

    log_const: float
    exponent: float
    x_poly: tuple[float, ...]
    dlnL_dz: float

    def log_and_slope(self, x, x_max: float | None = None, cont=None):
        """ln L, d ln L/d ln x and d ln L/d z at x (vectorised, x > 0); ``cont``: the
        :func:`continued_log` of (x, x_max) if at hand."""
        xc, u, ln_xc = continued_log(x, x_max) if cont is None else cont
        s, ds = _poly_and_slope(xc, self.x_poly)
        if x_max is not None:
            s, ds = s + (ds - self.exponent) * (1.0 - u), ds * u + self.exponent * (1.0 - u)
        power = self.exponent * ln_xc if self.exponent else 0.0
        return self.log_const - power + s, ds - self.exponent, self.dlnL_dz


@dataclass(frozen=True)
class CollapseLimitAtZ:
    """A collapse limit at one z, for n per point (:meth:`CollapseLimit.at_z`; the exponent read
    along the curve): ln L = log_const − exponent ln x + Σ x_poly[k] x^(k+1) + E(n)
    + n (Σ xn_poly[k] x^(k+1) + zn_sum), E(n) = Σ exp_poly[k] n^(k+1), the x-terms continued
    beyond x_max as :meth:`CollapseLimit.log_and_slope`."""

    log_const: float
    exponent: float
    x_poly: tuple[float, ...]
    xn_poly: tuple[float, ...]
    exp_poly: tuple[float, ...]
    zn_sum: float

    def log_slope_and_dn(self, x, n, x_max: float | None = None):
        """ln L, d ln L/d ln x and ∂ln L/∂n at (x, n) (vectorised, x > 0)."""
        return self.with_n(self.x_terms(x, x_max), n)

    def x_terms(self, x, x_max: float | None = None) -> tuple[np.ndarray, ...]:
        """The terms of :meth:`log_slope_and_dn` that do not move with n, at x: log_const
        − exponent ln x + Σ x_poly[k] x^(k+1), its log slope, Σ xn_poly[k] x^(k+1) and its log
        slope (continued beyond x_max)."""
        xc, u, ln_xc = continued_log(np.asarray(x, dtype=float), x_max)
        s, ds = _poly_and_slope(xc, self.x_poly)
        sn, dsn = _poly_and_slope(xc, self.xn_poly)
        if x_max is not None:
            s, ds = s + (ds - self.exponent) * (1.0 - u), ds * u + self.exponent * (1.0 - u)
            sn, dsn = sn + dsn * (1.0 - u), dsn * u
        power = self.exponent * ln_xc if self.exponent else 0.0
        return self.log_const - power + s, ds - self.exponent, sn, dsn

    def with_n(self, terms: tuple[np.ndarray, ...], n):
        """ln L, d ln L/d ln x and ∂ln L/∂n from the x-terms (:meth:`x_terms`) and n:
        ln L = (x-terms) + E(n) + n (Σ xn_poly[k] x^(k+1) + zn_sum)."""
        base, slope, sn, dsn = terms
        n = np.asarray(n, dtype=float)
        e, de = exp_poly_log_and_slope(self.exp_poly, n)
        return base + e + n * (sn + self.zn_sum), slope + n * dsn, de + sn + self.zn_sum


@dataclass(frozen=True)
class CollapseLimit:
    """L(x, n, z) = prefactor · x^(−exponent)
    · exp(Σ x_poly[k] x^(k+1) + Σ exp_poly[k] n^(k+1) + n Σ xn_poly[k] x^(k+1)
    + Σ z_poly[k] z^(k+1) + n Σ zn_poly[k] z^(k+1)).

    x: finite-size ratio, n: effective hardening exponent, z = R/ρ_c − 1: curvature of the
    surface pressing the body relative to the body's own (0 for equal spheres; R/R_i against
    a rigid sphere of radius R_i; ``unified.harder_partner_weight``).
    """

    prefactor: float
    exponent: float
    x_poly: tuple[float, ...] = ()
    exp_poly: tuple[float, ...] = ()
    z_poly: tuple[float, ...] = ()
    xn_poly: tuple[float, ...] = ()
    zn_poly: tuple[float, ...] = ()

    def log_and_slope(self, x, n=0.0, z=0.0, x_max: float | None = None,
                      z_max: float | None = None):
        """ln L, d ln L/d ln x = −exponent + Σ (k+1) x_poly[k] x^(k+1)
        + n Σ (k+1) xn_poly[k] x^(k+1) and d ln L/d z, vectorised (x > 0).

        Beyond the fitted ranges the terms are continued C¹ to constants
        (:func:`continue_beyond`): the x-dependence g(x) = −exponent ln x + Σ … beyond
        ``x_max`` in ln x, the z-dependence Σ z_poly[k] z^(k+1) (and n Σ zn_poly[k] z^(k+1))
        beyond ``z_max`` (≥ 0) in ln(1 + z) = ln(R/ρ_c)."""
        x = np.asarray(x, dtype=float)
        z = np.asarray(z, dtype=float)
        xc, u = continue_beyond(x, x_max)
        s, ds = _poly_and_slope(xc, self.x_poly)
        if self.xn_poly:
            sn, dsn = _poly_and_slope(xc, self.xn_poly)
            n_ = np.asarray(n, dtype=float)
            s, ds = s + n_ * sn, ds + n_ * dsn
        if x_max is not None:
            s, ds = s + (ds - self.exponent) * (1.0 - u), ds * u + self.exponent * (1.0 - u)
        sz, dz = _z_terms(z, z_max, self.z_poly)
        if self.zn_poly:
            szn, dzn = _z_terms(z, z_max, self.zn_poly)
            n_ = np.asarray(n, dtype=float)
            sz, dz = sz + n_ * szn, dz + n_ * dzn
        with np.errstate(divide="ignore"):  # x = 0 (a flat body): ln L = +inf, or finite if exponent 0
            power = self.exponent * np.log(xc) if self.exponent else 0.0
            lnL = math.log(self.prefactor) - power + s + sz + np.log(_exp_poly(1.0, self.exp_poly, n))
        return lnL, ds - self.exponent, dz

    def dlog_dn(self, x, n=0.0, z=0.0, x_max: float | None = None, z_max: float | None = None):
        """∂ln L/∂n at x, n, z (vectorised; the same continuations as :meth:`log_and_slope`):
        Σ (k+1) exp_poly[k] n^k + Σ xn_poly[k] x^(k+1) + Σ zn_poly[k] z^(k+1)."""
        x = np.asarray(x, dtype=float)
        d = exp_poly_log_and_slope(self.exp_poly, n)[1] + np.zeros(np.broadcast_shapes(
            x.shape, np.shape(n), np.shape(z)))
        if self.xn_poly:
            xc, u = continue_beyond(x, x_max)
            sn, dsn = _poly_and_slope(xc, self.xn_poly)
            d = d + (sn + dsn * (1.0 - u) if x_max is not None else sn)
        if self.zn_poly:
            d = d + _z_terms(np.asarray(z, dtype=float), z_max, self.zn_poly)[0]
        return d

    def __call__(self, x, n=0.0, z=0.0):
        return np.exp(self.log_and_slope(x, n, z)[0])

    @lru_cache(maxsize=64)  # noqa: B019 -- frozen and hashable; a body law asks for one (n, z)
    def at(self, n: float, z: float, z_max: float | None = None) -> CollapseLimitAt:
        """The limit at one hardening exponent n and one z (floats): the n- and z-terms of
        :meth:`log_and_slope` summed once, for a body law that reads them at every x."""
        sz, dz = _z_terms(z, z_max, self.z_poly)
        if self.zn_poly:
            szn, dzn = _z_terms(z, z_max, self.zn_poly)
            sz, dz = sz + n * szn, dz + n * dzn
        const = math.log(self.prefactor) + float(sz) + math.log(float(_exp_poly(1.0, self.exp_poly, n)))
        return CollapseLimitAt(log_const=const, exponent=self.exponent,
                               x_poly=poly_with_n(self.x_poly, self.xn_poly, n), dlnL_dz=float(dz))

    @lru_cache(maxsize=64)  # noqa: B019 -- frozen and hashable; a body law asks for one z
    def at_z(self, z: float, z_max: float | None = None) -> CollapseLimitAtZ:
        """The limit at one z (float) with n left free: the z-terms of :meth:`log_and_slope`
        summed once, for a body law whose exponent is read along the curve."""
        sz = float(_z_terms(z, z_max, self.z_poly)[0])
        szn = float(_z_terms(z, z_max, self.zn_poly)[0]) if self.zn_poly else 0.0
        return CollapseLimitAtZ(log_const=math.log(self.prefactor) + sz, exponent=self.exponent,
                                x_poly=tuple(self.x_poly), xn_poly=tuple(self.xn_poly),
                                exp_poly=tuple(self.exp_poly), zn_sum=szn)

    def to_dict(self) -> dict:
        return {"prefactor": self.prefactor, "exponent": self.exponent,
                "x_poly": list(self.x_poly), "exp_poly": list(self.exp_poly),
                "z_poly": list(self.z_poly), "xn_poly": list(self.xn_poly),
                **({"zn_poly": list(self.zn_poly)} if self.zn_poly else {})}


@dataclass(frozen=True)
class Coefficients:
    """A validated coefficient set (see module docstring for the functional forms)."""

    beta: float
    Lambda_I: float
    Lambda_III: float
    H_bar_III_prefactor: float
    H_bar_III_exp_poly: tuple[float, ...]
    c2_III_prefactor: float
    c2_III_exp_poly: tuple[float, ...]
    H_bar_shape: tuple[float, ...]
    c2_shape: tuple[float, ...]
    exponent_method: str
    eps_lo: float
    eps_hi: float
    finite_size_ratio: str
    finite_size_H_bar: tuple[float, ...]
    finite_size_c2: tuple[float, ...]
    finite_size_H_bar_plastic: tuple[float, ...] | None = None  # None: same as the above
    finite_size_c2_plastic: tuple[float, ...] | None = None
    collapse_H_bar: CollapseLimit | None = None
    collapse_c2: CollapseLimit | None = None
    collapse_sharpness: float = 0.0
    collapse_sharpness_c2: float | None = None  # None: the same as collapse_sharpness
    collapse_offset_c2: float | None = None     # None: 0
    collapse_z_variable: str = "z"              # one of Z_VARIABLES
    level_II_smooth: bool = False
    beta_growth: float = 0.0  # γ of ε_rep = β x (1 + γ x); 0: the linear ε_rep = β x
    #: W, log-width of the strains the representative stress averages the flow curve over
    #: (``single.representative_stress``); 0: σ_rep = σ_f(ε_rep)
    strain_spread: float = 0.0
    #: ``local_secant`` exponent: window factor K (the secant of σ_rep over [ε_rep/K, K ε_rep]) and
    #: cap c (n/(1 + (n/c)⁴)^¼); 0 for ``secant_loglog``
    exponent_window: float = 0.0
    exponent_cap: float = 0.0
    #: Level II shape terms per unit of the effective hardening exponent (``level_II.H_bar_shape_n``,
    #: ``c2_shape_n``; empty: none): P(t) = Σ (b_k + bn_k n) t^k
    H_bar_shape_n: tuple[float, ...] = ()
    c2_shape_n: tuple[float, ...] = ()
    #: counter-surface coefficients q of H̄_hs and c²_hs (module docstring; 0: none)
    counter_H_bar: float = 0.0
    counter_c2: float = 0.0
    #: their fully plastic (Level III) values, blended by the level weight (None: the same)
    counter_H_bar_plastic: float | None = None
    counter_c2_plastic: float | None = None
    #: the change of the Level III values with the conformity ζ = z/(1 + z) of the pressing
    #: surface (0: none)
    counter_H_bar_conformity: float = 0.0
    counter_c2_conformity: float = 0.0
    #: two-body interface equation (``unified.py``): coupling λ (0: equal mean pressures alone),
    #: similarity width δ of the fully plastic pressures; the anchor is the Hertz partition, or
    #: with a finite contact radius a_c/R* it moves from there to equal strains with exponent k
    interface_coupling: float = 0.0
    interface_similarity: float = 0.2
    interface_radius: float = math.inf
    interface_exponent: float = 4.0
    #: the rigid partner's cap in h: "paraboloid" (a²/(2ρ) alone) or "exact" (``cap.py``)
    counter_cap: str = "paraboloid"
    #: the pressure profile of a pair's less plastic body: "hertz" or "flattened" (``profile.py``)
    pressure_profile: str = "hertz"
    #: unloading law (``unloading.py``); the default is Thornton (1997)
    unloading: UnloadingCoefficients = field(default_factory=UnloadingCoefficients)
    source: str = "literature"
    schema_version: int = SCHEMA_VERSION
    provenance: dict = field(default_factory=dict, compare=False, hash=False, repr=False)
    references: dict = field(default_factory=dict, compare=False, hash=False, repr=False)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, d: dict) -> Coefficients:
        """Validate a schema-1 or schema-2 dictionary; ValueError names the offending key."""
        if not isinstance(d, dict):
            raise ValueError(f"coefficients: top level must be an object, got {type(d).__name__}")
        if "schema_version" not in d:
            raise ValueError("coefficients: missing key 'schema_version'")
        version = d["schema_version"]
        if isinstance(version, bool) or version not in SUPPORTED_VERSIONS:
            raise ValueError(
                f"coefficients: unknown 'schema_version' {version!r} "
                f"(this version reads schema_version in {SUPPORTED_VERSIONS})"
            )
        version = int(version)
        source = _choice(d, "source", "", SOURCES)
        provenance = _section(d, "provenance")
        CalibratedRange.from_provenance(provenance)  # a malformed range block raises here
        beta = _number(d, "beta", "")
        if beta <= 0.0:
            raise ValueError(f"coefficients: 'beta' must be > 0, got {beta!r}")
        growth = _number(d, "beta_growth", "") if "beta_growth" in d else 0.0
        if not 0.0 <= growth <= 100.0:
            raise ValueError(f"coefficients: 'beta_growth' must lie in [0, 100], got {growth!r}")
        spread = _number(d, "strain_spread", "") if "strain_spread" in d else 0.0
        if not 0.0 <= spread <= SPREAD_MAX:
            raise ValueError(f"coefficients: 'strain_spread' must lie in [0, {SPREAD_MAX:g}], "
                             f"got {spread!r}")
        interface = _interface(d)
        counter = _counter(d)
        counter_cap = _choice(d, "counter_cap", "", COUNTER_CAPS, default="paraboloid")
        profile = _choice(d, "pressure_profile", "", PRESSURE_PROFILES, default="hertz")
        unloading = _unloading(d)
        lam1 = _number(d, "Lambda_I", "")
        lam3 = _number(d, "Lambda_III", "")
        if not 0.0 < lam1 < lam3:
            raise ValueError(
                f"coefficients: need 0 < 'Lambda_I' < 'Lambda_III', got {lam1!r}, {lam3!r}"
            )
        H3 = _section(d, "H_bar_III")
        c3 = _section(d, "c2_III")
        H3p = _number(H3, "prefactor", "H_bar_III.")
        c3p = _number(c3, "prefactor", "c2_III.")
        if H3p <= 0.0:
            raise ValueError(f"coefficients: 'H_bar_III.prefactor' must be > 0, got {H3p!r}")
        if c3p <= 0.0:
            raise ValueError(f"coefficients: 'c2_III.prefactor' must be > 0, got {c3p!r}")
        lev2 = _section(d, "level_II")
        hexp = _section(d, "hardening_exponent")
        method = _choice(hexp, "method", "hardening_exponent.", EXPONENT_METHODS)
        eps_lo = _number(hexp, "eps_lo", "hardening_exponent.")
        eps_hi = _number(hexp, "eps_hi", "hardening_exponent.")
        if not 0.0 < eps_lo < eps_hi:
            raise ValueError(
                "coefficients: need 0 < 'hardening_exponent.eps_lo' < 'hardening_exponent.eps_hi',"
                f" got {eps_lo!r}, {eps_hi!r}"
            )
        window = cap = 0.0
        if method == "local_secant":
            window = _number(hexp, "window", "hardening_exponent.")
            cap = _number(hexp, "cap", "hardening_exponent.")
            for name, v, (lo, hi) in (("window", window, EXPONENT_WINDOW_RANGE),
                                      ("cap", cap, EXPONENT_CAP_RANGE)):
                if not lo <= v <= hi:
                    raise ValueError(f"coefficients: 'hardening_exponent.{name}' must lie in "
                                     f"[{lo:g}, {hi:g}], got {v!r}")
        fs = _section(d, "finite_size")
        refs = d.get("references", {})
        if not isinstance(refs, dict):
            raise ValueError("coefficients: 'references' must be an object")
        cH = cc = kc = sc = None
        zvar = "z"
        k = 0.0
        smooth = False
        fsHp = fscp = None
        if version >= 2:
            for key in ("H_bar_plastic", "c2_plastic"):
                if key not in fs:
                    raise ValueError(f"coefficients: missing key 'finite_size.{key}' (required by "
                                     "schema_version 2)")
            fsHp = _poly(fs, "H_bar_plastic", "finite_size.")
            fscp = _poly(fs, "c2_plastic", "finite_size.")
            if "smooth" not in lev2:
                raise ValueError("coefficients: missing key 'level_II.smooth' (required by "
                                 "schema_version 2)")
            smooth = lev2["smooth"]
            if not isinstance(smooth, bool):
                raise ValueError(f"coefficients: 'level_II.smooth' must be true or false, got {smooth!r}")
            if "collapse" not in d:
                raise ValueError("coefficients: missing key 'collapse' (required by schema_version 2; "
                                 "null for none)")
            col = d["collapse"]
            if col is not None:
                if not isinstance(col, dict):
                    raise ValueError(f"coefficients: 'collapse' must be an object or null, "
                                     f"got {type(col).__name__}")
                cH = _limit(_section(col, "H_bar"), "collapse.H_bar")
                cc = _limit(_section(col, "c2"), "collapse.c2")
                k = _number(col, "sharpness", "collapse.")
                if k <= 0.0:
                    raise ValueError(f"coefficients: 'collapse.sharpness' must be > 0, got {k!r}")
                if "sharpness_c2" in col:
                    kc = _number(col, "sharpness_c2", "collapse.")
                    if kc <= 0.0:
                        raise ValueError(f"coefficients: 'collapse.sharpness_c2' must be > 0, "
                                         f"got {kc!r}")
                if "offset_c2" in col:
                    sc = _number(col, "offset_c2", "collapse.")
                if "z_variable" in col:
                    zvar = _choice(col, "z_variable", "collapse.", Z_VARIABLES)
                if cH.exponent <= 0.0:
                    raise ValueError("coefficients: 'collapse.H_bar.exponent' must be > 0 (the limit "
                                     f"must vanish as the ratio -> 0), got {cH.exponent!r}")
                if cc.exponent < 0.0:
                    raise ValueError(f"coefficients: 'collapse.c2.exponent' must be >= 0, "
                                     f"got {cc.exponent!r}")
        elif "collapse" in d or "smooth" in lev2:
            raise ValueError("coefficients: keys 'collapse' and 'level_II.smooth' need schema_version 2")
        return cls(
            beta=beta,
            Lambda_I=lam1,
            Lambda_III=lam3,
            H_bar_III_prefactor=H3p,
            H_bar_III_exp_poly=_poly(H3, "exp_poly", "H_bar_III."),
            c2_III_prefactor=c3p,
            c2_III_exp_poly=_poly(c3, "exp_poly", "c2_III."),
            H_bar_shape=_poly(lev2, "H_bar_shape", "level_II."),
            c2_shape=_poly(lev2, "c2_shape", "level_II."),
            H_bar_shape_n=_poly(lev2, "H_bar_shape_n", "level_II.") if "H_bar_shape_n" in lev2 else (),
            c2_shape_n=_poly(lev2, "c2_shape_n", "level_II.") if "c2_shape_n" in lev2 else (),
            exponent_method=method,
            eps_lo=eps_lo,
            eps_hi=eps_hi,
            exponent_window=window,
            exponent_cap=cap,
            finite_size_ratio=_choice(fs, "ratio", "finite_size.", RATIOS),
            finite_size_H_bar=_poly(fs, "H_bar", "finite_size."),
            finite_size_c2=_poly(fs, "c2", "finite_size."),
            finite_size_H_bar_plastic=fsHp,
            finite_size_c2_plastic=fscp,
            collapse_H_bar=cH,
            collapse_c2=cc,
            collapse_sharpness=k,
            collapse_sharpness_c2=kc,
            collapse_offset_c2=sc,
            collapse_z_variable=zvar,
            level_II_smooth=smooth,
            beta_growth=growth, strain_spread=spread,
            **interface,
            **counter,
            counter_cap=counter_cap,
            pressure_profile=profile,
            **unloading,
            source=source,
            schema_version=version,
            provenance=copy.deepcopy(provenance),
            references=copy.deepcopy(refs),
        )

    def to_dict(self) -> dict:
        """The dictionary of this set's schema version (round-trips through :meth:`from_dict`)."""
        d = {
            "schema_version": self.schema_version,
            "source": self.source,
            "provenance": copy.deepcopy(self.provenance),
            "beta": self.beta,
            **({"beta_growth": self.beta_growth} if self.beta_growth else {}),
            **({"strain_spread": self.strain_spread} if self.strain_spread else {}),
            **({"interface": {"coupling": self.interface_coupling,
                              "similarity": self.interface_similarity,
                              **({"radius": self.interface_radius, "exponent": self.interface_exponent}
                                 if math.isfinite(self.interface_radius) else {})}}
               if self.interface_coupling else {}),
            **({"counter_surface": self._counter_section()} if self.has_counter_surface else {}),
            **({"counter_cap": self.counter_cap} if self.counter_cap != "paraboloid" else {}),
            **({"pressure_profile": self.pressure_profile} if self.pressure_profile != "hertz" else {}),
            **({"unloading": self.unloading.to_dict()}
               if self.unloading != UnloadingCoefficients() else {}),
            "Lambda_I": self.Lambda_I,
            "Lambda_III": self.Lambda_III,
            "H_bar_III": {"prefactor": self.H_bar_III_prefactor,
                          "exp_poly": list(self.H_bar_III_exp_poly)},
            "c2_III": {"prefactor": self.c2_III_prefactor, "exp_poly": list(self.c2_III_exp_poly)},
            "level_II": {"H_bar_shape": list(self.H_bar_shape), "c2_shape": list(self.c2_shape)},
            "hardening_exponent": {"method": self.exponent_method, "eps_lo": self.eps_lo,
                                   "eps_hi": self.eps_hi,
                                   **({"window": self.exponent_window, "cap": self.exponent_cap}
                                      if self.exponent_local else {})},
            "finite_size": {"ratio": self.finite_size_ratio, "H_bar": list(self.finite_size_H_bar),
                            "c2": list(self.finite_size_c2)},
        }
        if self.H_bar_shape_n or self.c2_shape_n:
            d["level_II"].update(H_bar_shape_n=list(self.H_bar_shape_n), c2_shape_n=list(self.c2_shape_n))
        if self.schema_version >= 2:
            d["level_II"]["smooth"] = self.level_II_smooth
            d["finite_size"]["H_bar_plastic"] = list(self.fs_H_bar_plastic)
            d["finite_size"]["c2_plastic"] = list(self.fs_c2_plastic)
            d["collapse"] = None if not self.has_collapse else {
                "H_bar": self.collapse_H_bar.to_dict(), "c2": self.collapse_c2.to_dict(),
                "sharpness": self.collapse_sharpness}
            if self.has_collapse and self.collapse_sharpness_c2 is not None:
                d["collapse"]["sharpness_c2"] = self.collapse_sharpness_c2
            if self.has_collapse and self.collapse_offset_c2 is not None:
                d["collapse"]["offset_c2"] = self.collapse_offset_c2
            if self.has_collapse and self.collapse_z_variable != "z":
                d["collapse"]["z_variable"] = self.collapse_z_variable
        d["references"] = copy.deepcopy(self.references)
        return d

    def replace(self, **changes) -> Coefficients:
        """A validated copy with some schema keys changed (``replace(beta=0.2)``).

        Keys are top-level schema keys; nested sections are given as whole dicts,
        e.g. ``replace(finite_size={"ratio": "a_over_rho", "H_bar": [0.5], "c2": []})``.
        """
        d = self.to_dict()
        for k, v in changes.items():
            if k not in d and k not in _OPTIONAL_TOP_KEYS:
                raise ValueError(f"coefficients: unknown key {k!r}")
            d[k] = v
        return Coefficients.from_dict(d)

    @cached_property
    def calibrated_range(self) -> CalibratedRange:
        """Inputs the set was calibrated on: ``provenance["calibrated_range"]``, or
        :data:`~spherecontact.model.calibrated_range.DEFAULT_RANGE` (the calibration design
        of the FE campaign) when the provenance records none."""
        return CalibratedRange.from_provenance(self.provenance)

    @property
    def x_fit_max(self) -> float:
        """Largest finite-size ratio the x-dependent terms (finite-size factors, collapse
        limits) were fitted on: ``calibrated_range.a_over_R_max`` (default 1, a/R < 1).
        Beyond it they are continued C¹ to constants (``levels.continue_beyond``), so F(h)
        and a(h) stay finite and increasing however far the approach goes."""
        return self.calibrated_range.a_over_R_max

    def collapse_z(self, z):
        """The variable of the collapse limits' z-polynomials at curvature ratio z
        (``collapse_z_variable``): z, or ln(1 + max(z, 0)) (vectorised)."""
        if self.collapse_z_variable == "z":
            return z
        return np.log1p(np.maximum(np.asarray(z, dtype=float), 0.0))

    def collapse_z_slope(self, z):
        """d :meth:`collapse_z`/dz: 1, or 1/(1 + z) for z > 0 and 0 below (vectorised)."""
        z = np.asarray(z, dtype=float)
        if self.collapse_z_variable == "z":
            return np.ones_like(z)
        return np.where(z > 0.0, 1.0 / (1.0 + np.maximum(z, 0.0)), 0.0)

    @property
    def z_fit_max(self) -> float:
        """Largest curvature ratio z = R/ρ_H − 1 the collapse limits' z-terms were fitted on:
        the largest R/R_rigid of the calibration scenes (``calibrated_range.R_over_R_rigid``,
        default 1: a rigid sphere of the body's radius). Beyond it the z-terms are continued C¹
        to constants, so a small rigid indenter does not drive the limits to 0 or ∞."""
        return self.calibrated_range.R_over_R_rigid[1]

    # ------------------------------------------------------------------ Level I and III values
    @property
    def H_bar_I(self) -> float:
        """H̄ at the end of Level I: 4Λ_I/(3π) (Hertz)."""
        return 4.0 * self.Lambda_I / (3.0 * math.pi)

    @property
    def exponent_local(self) -> bool:
        """True when the hardening exponent is read along the flow curve (``local_secant``,
        ``single.local_exponent``) instead of once per material (``secant_loglog``)."""
        return self.exponent_method == "local_secant"

    def H_bar_III(self, n):
        """Level III normalised hardness H̄_III(n), n = effective hardening exponent."""
        return _exp_poly(self.H_bar_III_prefactor, self.H_bar_III_exp_poly, n)

    def c2_III(self, n):
        """Level III contact-area parameter c²_III(n) (Storåkers et al. 1997 form)."""
        return _exp_poly(self.c2_III_prefactor, self.c2_III_exp_poly, n)

    @property
    def has_finite_size(self) -> bool:
        return (any(self.finite_size_H_bar) or any(self.finite_size_c2) or any(self.fs_H_bar_plastic)
                or any(self.fs_c2_plastic) or self.has_collapse)

    @property
    def fs_H_bar_plastic(self) -> tuple[float, ...]:
        """Finite-size coefficients of H̄ in Level III (schema 1: the same as in Level I)."""
        p = self.finite_size_H_bar_plastic
        return self.finite_size_H_bar if p is None else p

    @property
    def fs_c2_plastic(self) -> tuple[float, ...]:
        p = self.finite_size_c2_plastic
        return self.finite_size_c2 if p is None else p

    @property
    def finite_size_by_level(self) -> bool:
        """True when the finite-size coefficients differ between Level I and Level III."""
        return (self.fs_H_bar_plastic != self.finite_size_H_bar
                or self.fs_c2_plastic != self.finite_size_c2)

    @property
    def has_counter_surface(self) -> bool:
        return bool(self.counter_H_bar or self.counter_c2 or self.counter_H_bar_plastic
                    or self.counter_c2_plastic or self.counter_H_bar_conformity
                    or self.counter_c2_conformity)

    def counter_by_level(self, s_l, z=0.0):
        """Counter-surface coefficients (q_H, q_c) at level weight ``s_l`` and curvature ratio ``z``
        of the pressing surface: (1 − s_l) q + s_l (q_III + q_ζ ζ), ζ = z/(1 + z) (module docstring;
        q_III defaults to q, q_ζ to 0), and their derivatives in s_l."""
        z = np.asarray(z, dtype=float)
        zeta = z / (1.0 + z)
        out = []
        for q, q3, qz in ((self.counter_H_bar, self.counter_H_bar_plastic, self.counter_H_bar_conformity),
                          (self.counter_c2, self.counter_c2_plastic, self.counter_c2_conformity)):
            d = 0.0 if q3 is None else q3 - q
            out.append((q + d * s_l + qz * zeta * s_l, d + qz * zeta))
        return out

    def _counter_section(self) -> dict:
        sec = {"H_bar": self.counter_H_bar, "c2": self.counter_c2}
        for key, v in (("H_bar_plastic", self.counter_H_bar_plastic),
                       ("c2_plastic", self.counter_c2_plastic),
                       ("H_bar_conformity", self.counter_H_bar_conformity or None),
                       ("c2_conformity", self.counter_c2_conformity or None)):
            if v is not None:
                sec[key] = v
        return sec

    @property
    def has_collapse(self) -> bool:
        return self.collapse_H_bar is not None

    @property
    def c2_sharpness(self) -> float:
        """Sharpness k_c of the c² collapse weight: ``collapse_sharpness_c2``, else k."""
        kc = self.collapse_sharpness_c2
        return self.collapse_sharpness if kc is None else kc


#: file name of the calibrated set inside the package (``model/coefficients.json``)
PACKAGE_FILE = "coefficients.json"
#: name that selects :data:`LITERATURE` in :func:`load_coefficients` and ``--coefficients``
LITERATURE_NAME = "literature"


def package_path() -> Path:
    """The calibrated coefficient file shipped inside the package (``model/coefficients.json``)."""
    return Path(str(resources.files(__package__).joinpath(PACKAGE_FILE)))


def default_path() -> Path:
    """``$SPHERECONTACT_COEFFICIENTS`` if set, else the packaged file (:func:`package_path`)."""
    env = os.environ.get(ENV_VAR)
    return Path(env) if env else package_path()


def load_coefficients(path: str | os.PathLike | None = None) -> Coefficients:
    """Load and validate a coefficient set.

    Parameters
    ----------
    path : a coefficient JSON file; ``"literature"`` for the built-in literature set
        :data:`LITERATURE`; ``None`` for the default (:func:`default_path`: the calibrated file
        shipped with the package, or ``$SPHERECONTACT_COEFFICIENTS``).

    Raises
    ------
    ValueError
        The file is missing, is not JSON or fails validation; for the default file the
        message says how to restore it.
    """
    if path is not None and str(path) == LITERATURE_NAME:
        return Coefficients.from_dict(LITERATURE)
    p = Path(path) if path is not None else default_path()
    try:
        text = p.read_text()
    except OSError as err:
        raise ValueError(_unreadable(p, path, err.strerror or str(err))) from None
    try:
        d = json.loads(text)
    except json.JSONDecodeError as err:
        raise ValueError(_unreadable(p, path, f"not valid JSON: {err}")) from None
    return Coefficients.from_dict(d)


def _unreadable(p: Path, path, why: str) -> str:
    """Message for a coefficient file that cannot be read; the default one says how to restore it."""
    if path is not None:
        return f"coefficients: cannot read {p}: {why}"
    if os.environ.get(ENV_VAR):
        return (f"coefficients: cannot read {p} named by ${ENV_VAR}: {why}; unset {ENV_VAR} to use "
                "the calibrated set shipped with the package")
    return (f"coefficients: the calibrated set shipped with the package, {p}, cannot be read: {why}. "
            "Reinstall spherecontact (pip install --force-reinstall spherecontact), or in a "
            "checkout restore it with `git checkout model/coefficients.json` or `make calibrate`; "
            "load_coefficients(\"literature\") gives the uncalibrated literature set by name")


@lru_cache(maxsize=4)
def _cached_default(path_key: str, mtime: float) -> Coefficients:
    return load_coefficients(None)


def default_coefficients() -> Coefficients:
    """The default coefficient set, re-read when the file or the env override changes."""
    p = default_path()
    try:
        mtime = p.stat().st_mtime
    except OSError:
        mtime = -1.0  # load_coefficients raises the error that says how to restore it
    return _cached_default(str(p), mtime)
