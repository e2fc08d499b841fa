"""Elastic–plastic materials: elastic constants and a monotone flow curve.

The flow curve σ_f(ε_p) is the uniaxial flow stress against equivalent plastic
strain (docs/design.md §1), any law of :mod:`spherecontact.model.flow` (Ludwik, Swift, Voce,
linear, tabulated). ``Material(E, nu, sigma_y, K, n)`` is Ludwik's σ_Y + K ε_p**n (K = 0:
elastic–perfectly plastic); ``Material.from_table`` a tabulated curve; ``Material.with_flow`` any
curve. A rigid material has E = ∞ (E' = ∞); it never yields; an elastic one has σ_Y = ∞.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .flow import FlowCurve, Ludwik, Table, flow_from_description
from .flow.ludwik import EPS_SLOPE_FLOOR  # noqa: F401 -- re-exported
from .flow.table import EPS_TABLE_MAX  # noqa: F401 -- re-exported

__all__ = ["Material"]

#: allowed E/σ_Y (and E over a flow table's first stress): outside it the two are almost surely
#: in different units (E in GPa and σ_Y in Pa gives 1e-9 of the true ratio, MPa against Pa 1e6 times)
E_OVER_SIGMA_Y_RANGE = (5.0, 1e6)


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


@dataclass(frozen=True, init=False)
class Material:
    """Isotropic elastic–plastic material: E, ν and a flow curve (``flow``).

    Parameters
    ----------
    E : Young's modulus, > 0 (``math.inf`` for a rigid body: use ``Material.rigid()``).
    nu : Poisson's ratio, in (-1, 0.5).
    sigma_y : initial yield stress σ_Y of a Ludwik curve, > 0, with E/σ_Y in
        ``E_OVER_SIGMA_Y_RANGE`` (an elastic body is ``Material.elastic(E, nu)``).
    K : Ludwik hardening modulus, >= 0 (0: perfectly plastic).
    n : Ludwik hardening exponent, > 0 when K > 0 (n = 0 would be a yield jump to σ_Y + K).
    flow : any flow curve instead of sigma_y, K, n (``Material.with_flow``).

    Raises
    ------
    ValueError
        naming the parameter, its value and the allowed range; for E/σ_Y outside
        ``E_OVER_SIGMA_Y_RANGE`` the likely cause (E and σ_Y in different units).
    """

    E: float
    nu: float
    flow: FlowCurve

    def __init__(self, E: float, nu: float, sigma_y: float | None = None, K: float = 0.0,
                 n: float = 1.0, *, flow: FlowCurve | None = None) -> None:
        Ef = float(E)
        if math.isnan(Ef) or Ef <= 0.0:
            raise ValueError(f"E (Young's modulus) must be > 0 (or inf for rigid), got {E!r}")
        nu_f = _check_finite("nu", nu)
        if not -1.0 < nu_f < 0.5:
            raise ValueError(f"nu (Poisson's ratio) must lie in (-1, 0.5), got {nu_f!r}")
        if flow is None:
            if sigma_y is None:
                raise TypeError("Material needs sigma_y (Ludwik: sigma_y, K, n) or flow=")
            flow = Ludwik(sigma_y, K, n)
        elif sigma_y is not None:
            raise TypeError("Material takes either sigma_y, K, n or flow=, not both")
        if not isinstance(flow, FlowCurve):
            raise TypeError(f"flow must be a FlowCurve (spherecontact.model.flow), got {flow!r}")
        object.__setattr__(self, "E", E)
        object.__setattr__(self, "nu", nu)
        object.__setattr__(self, "flow", flow)
        sy = float(flow.sigma_y)
        if math.isfinite(sy) and not math.isinf(Ef):
            name = "sigma[0] (the flow table's first stress)" if isinstance(flow, Table) else "sigma_y"
            check_stress_units(Ef, sy, name)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def with_flow(cls, E: float, nu: float, flow: FlowCurve) -> Material:
        """Material with the flow curve ``flow`` (any ``spherecontact.model.flow`` law)."""
        return cls(E, nu, flow=flow)

    @classmethod
    def from_table(cls, E: float, nu: float, eps_p, sigma) -> Material:
        """Material with a tabulated flow curve σ_f(ε_p) (``flow.Table``).

        ``eps_p`` must start at 0 and increase strictly; ``sigma`` must be positive
        and non-decreasing; at least two points.
        """
        return cls(E, nu, flow=Table(eps_p, sigma))

    @classmethod
    def from_description(cls, m: dict) -> Material:
        """Inverse of :meth:`describe`: E = inf is rigid; missing plastic keys are elastic."""
        E, nu = float(m["E"]), float(m.get("nu", 0.3))
        if math.isinf(E):
            return cls.rigid(nu)
        return cls(E, nu, flow=flow_from_description(m))

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
    def is_elastic(self) -> bool:
        """Never yields (rigid, or σ_Y = ∞)."""
        return math.isinf(self.E) or math.isinf(self.sigma_y)

    @property
    def sigma_y(self) -> float:
        """Initial yield stress σ_Y (inf: elastic)."""
        return self.flow.sigma_y

    # Ludwik and table fields, read through the flow curve (0, 1 and None for other laws)
    @property
    def K(self) -> float:
        return self.flow.K if isinstance(self.flow, Ludwik) else 0.0

    @property
    def n(self) -> float:
        return self.flow.n if isinstance(self.flow, Ludwik) else 1.0

    @property
    def is_tabulated(self) -> bool:
        return isinstance(self.flow, Table)

    @property
    def eps_table(self) -> tuple[float, ...] | None:
        return self.flow.eps_table if isinstance(self.flow, Table) else None

    @property
    def sigma_table(self) -> tuple[float, ...] | None:
        return self.flow.sigma_table if isinstance(self.flow, Table) else None

    @property
    def E_prime(self) -> float:
        """Plane-strain modulus E' = E/(1 − ν²) (docs/design.md §1)."""
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
    def flow_stress(self, eps_p):
        """Uniaxial flow stress σ_f(ε_p), vectorised; ε_p < 0 is treated as 0."""
        return self.flow.stress(eps_p)

    def flow_slope(self, eps_p):
        """Hardening slope dσ_f/dε_p, vectorised (right derivative at a table's nodes)."""
        return self.flow.slope(eps_p)

    def describe(self) -> dict:
        """Plain-dict description (for HDF5 attributes and JSON): E, nu and the flow curve's
        keys (Ludwik: sigma_y, K, n; a table: eps_table, sigma_table; any other law: "flow"
        with its name, sigma_y and its parameters)."""
        return {"E": self.E, "nu": self.nu, **self.flow.material_description()}
