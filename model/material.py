"""Elastic–plastic materials: elastic constants and a monotone flow curve.

The flow curve σ_f(ε_p) is the uniaxial flow stress against equivalent plastic
strain (DESIGN §1). Two kinds:

* Ludwik, ``σ_f = σ_Y + K ε_p**n`` (K = 0: elastic–perfectly plastic,
  n = 1: linear hardening);
* tabulated, any monotone (non-decreasing) curve, interpolated linearly and
  continued beyond the last point with the last segment's slope.

A rigid material has E = ∞ (E' = ∞); it never yields.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

__all__ = ["Material"]

#: allowed E/σ_Y (and E over a flow table's first stress): outside it the two are almost surely
#: in different units (E in GPa and σ_Y in Pa gives 1e-9 of the true ratio, MPa against Pa 1e6 times)
E_OVER_SIGMA_Y_RANGE = (5.0, 1e6)
#: largest plastic strain a flow table may reach: beyond it the strains are likely in per cent
EPS_TABLE_MAX = 5.0

#: Ludwik slope K n ε^(n-1) is infinite at ε_p = 0 for n < 1; it is evaluated at
#: max(ε_p, EPS_SLOPE_FLOOR) so that Newton solvers get a large but finite slope.
EPS_SLOPE_FLOOR = 1e-12


def check_stress_units(E: float, stress: float, name: str) -> None:
    """Refuse E/stress outside ``E_OVER_SIGMA_Y_RANGE`` (a units slip), naming ``name``."""
    lo, hi = E_OVER_SIGMA_Y_RANGE
    if math.isfinite(E) and not lo <= E / stress <= hi:
        raise ValueError(
            f"E/{name.split(' ')[0]} = {E / stress:.4g} (E = {E:g}, {name} = {stress:g}) lies outside "
            f"[{lo:g}, {hi:g}]: E and the stress are likely in different units (e.g. E in GPa and "
            f"the stress in Pa); give both in the same unit")


def _check_finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return value


@dataclass(frozen=True)
class Material:
    """Isotropic elastic–plastic material.

    Parameters
    ----------
    E : Young's modulus, > 0 (``math.inf`` for a rigid body: use ``Material.rigid()``).
    nu : Poisson's ratio, in (-1, 0.5).
    sigma_y : initial yield stress σ_Y, > 0, with E/σ_Y in ``E_OVER_SIGMA_Y_RANGE`` (required:
        an elastic body is ``Material.elastic(E, nu)``).
    K : Ludwik hardening modulus, >= 0 (0: perfectly plastic).
    n : Ludwik hardening exponent, > 0 when K > 0 (n = 0 would be a yield jump to σ_Y + K).
    eps_table, sigma_table : tabulated flow curve (use ``Material.from_table``).

    Raises
    ------
    ValueError
        naming the parameter, its value and the allowed range; for E/σ_Y outside
        ``E_OVER_SIGMA_Y_RANGE`` the likely cause (E and σ_Y in different units).
    """

    E: float
    nu: float
    sigma_y: float
    K: float = 0.0
    n: float = 1.0
    eps_table: tuple[float, ...] | None = field(default=None, repr=False)
    sigma_table: tuple[float, ...] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        E = float(self.E)
        if math.isnan(E) or E <= 0.0:
            raise ValueError(f"E (Young's modulus) must be > 0 (or inf for rigid), got {self.E!r}")
        nu = _check_finite("nu", self.nu)
        if not -1.0 < nu < 0.5:
            raise ValueError(f"nu (Poisson's ratio) must lie in (-1, 0.5), got {nu!r}")
        if math.isinf(E):
            return  # rigid: plastic parameters are irrelevant
        sy = float(self.sigma_y)
        if math.isnan(sy) or sy <= 0.0:
            raise ValueError(
                f"sigma_y (yield stress) must be > 0 (inf: elastic), got {self.sigma_y!r}"
            )
        if self.eps_table is None:
            K = _check_finite("K", self.K)
            n = _check_finite("n", self.n)
            if K < 0.0:
                raise ValueError(f"K (Ludwik hardening modulus) must be >= 0, got {K!r}")
            if n < 0.0:
                raise ValueError(f"n (Ludwik hardening exponent) must be >= 0, got {n!r}")
            if n == 0.0 and K > 0.0:
                raise ValueError(
                    f"n = 0 with K = {K!r} > 0 makes the flow stress jump from sigma_y = {sy!r} to "
                    f"sigma_y + K = {sy + K!r} at the first plastic strain; for a perfectly plastic "
                    f"material write sigma_y = {sy + K!r}, K = 0 (or give n > 0 for hardening)")
        if math.isfinite(sy):
            check_stress_units(E, sy, "sigma_y")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_table(cls, E: float, nu: float, eps_p, sigma) -> Material:
        """Material with a tabulated flow curve σ_f(ε_p).

        ``eps_p`` must start at 0 and increase strictly; ``sigma`` must be positive
        and non-decreasing; at least two points.
        """
        eps = np.asarray(eps_p, dtype=float)
        sig = np.asarray(sigma, dtype=float)
        if eps.ndim != 1 or sig.ndim != 1 or eps.shape != sig.shape:
            raise ValueError(
                "eps_p and sigma must be 1-D arrays of equal length, "
                f"got shapes {eps.shape} and {sig.shape}"
            )
        if eps.size < 2:
            raise ValueError(f"flow table needs at least 2 points, got {eps.size}")
        if not (np.all(np.isfinite(eps)) and np.all(np.isfinite(sig))):
            raise ValueError("eps_p and sigma must be finite (no NaN/inf)")
        if eps[0] != 0.0:
            raise ValueError(f"eps_p must start at 0, got eps_p[0] = {eps[0]!r}")
        if np.any(np.diff(eps) <= 0.0):
            raise ValueError("eps_p must be strictly increasing")
        if sig[0] <= 0.0:
            raise ValueError(f"sigma must be > 0, got sigma[0] = {sig[0]!r}")
        if np.any(np.diff(sig) < 0.0):
            raise ValueError("sigma must be non-decreasing (a monotone flow curve)")
        if eps[-1] > EPS_TABLE_MAX:
            raise ValueError(
                f"eps_p reaches {eps[-1]:g}, above {EPS_TABLE_MAX:g}: plastic strains look like per "
                f"cent; give them as fractions (e.g. 0.2, not 20)")
        check_stress_units(float(E), float(sig[0]), "sigma[0] (the flow table's first stress)")
        return cls(
            E=E, nu=nu, sigma_y=float(sig[0]), K=0.0, n=1.0,
            eps_table=tuple(eps.tolist()), sigma_table=tuple(sig.tolist()),
        )

    @classmethod
    def rigid(cls, nu: float = 0.3) -> Material:
        """A rigid body: E = ∞, E' = ∞."""
        return cls(E=math.inf, nu=nu, sigma_y=math.inf)

    @classmethod
    def elastic(cls, E: float, nu: float) -> Material:
        """A purely elastic body (σ_Y = ∞)."""
        return cls(E=E, nu=nu, sigma_y=math.inf)

    # ------------------------------------------------------------------ elastic constants
    @property
    def is_rigid(self) -> bool:
        return math.isinf(self.E)

    @property
    def is_tabulated(self) -> bool:
        return self.eps_table is not None

    @property
    def E_prime(self) -> float:
        """Plane-strain modulus E' = E/(1 − ν²) (DESIGN §1)."""
        return self.E / (1.0 - self.nu**2)

    @property
    def shear_modulus(self) -> float:
        """G = E / (2(1 + ν))."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def bulk_modulus(self) -> float:
        """κ = E / (3(1 − 2ν))."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    # ------------------------------------------------------------------ flow curve
    @cached_property
    def _table(self):
        """(ε, σ, segment slopes, last slope) of a tabulated flow curve as arrays (made once)."""
        et, st = np.asarray(self.eps_table), np.asarray(self.sigma_table)
        return et, st, np.diff(st) / np.diff(et), (st[-1] - st[-2]) / (et[-1] - et[-2])

    def flow_stress(self, eps_p):
        """Uniaxial flow stress σ_f(ε_p), vectorised; ε_p < 0 is treated as 0."""
        e = np.maximum(np.asarray(eps_p, dtype=float), 0.0)
        if self.eps_table is not None:
            et, st, _, slope_end = self._table
            return np.where(e <= et[-1], np.interp(e, et, st), st[-1] + slope_end * (e - et[-1]))
        if self.K == 0.0:
            return np.full_like(e, self.sigma_y)
        return self.sigma_y + self.K * e**self.n

    def flow_slope(self, eps_p):
        """Hardening slope dσ_f/dε_p, vectorised (right derivative on tables)."""
        e = np.maximum(np.asarray(eps_p, dtype=float), 0.0)
        if self.eps_table is not None:
            et, _, slopes, _ = self._table
            idx = np.clip(np.searchsorted(et, e, side="right") - 1, 0, slopes.size - 1)
            return slopes[idx]
        if self.K == 0.0 or self.n == 0.0:
            return np.zeros_like(e)
        return self.K * self.n * np.maximum(e, EPS_SLOPE_FLOOR) ** (self.n - 1.0)

    def describe(self) -> dict:
        """Plain-dict description (for HDF5 attributes and JSON)."""
        d = {"E": self.E, "nu": self.nu, "sigma_y": self.sigma_y, "K": self.K, "n": self.n}
        if self.eps_table is not None:
            d = {"E": self.E, "nu": self.nu, "eps_table": list(self.eps_table),
                 "sigma_table": list(self.sigma_table)}
        return d
