"""Calibration points from FE runs: ρ, σ_rep, Λ, H̄, c², a/R per increment (docs/design.md §2).

A run is one deformable hemisphere (radius R) pressed by a rigid surface of radius
R_i (``inf``: the flat that stands for an equal sphere by symmetry). The body sees the
relative radius

    ρ = R R_i/(R + R_i)        (ρ = R for the flat),

and, with h the approach taken by this body, the Brinell-type quantities are

    ε_rep = β a/ρ,  σ_rep = σ_f(ε_rep),  Λ = E' a/(σ_rep ρ),
    H̄ = p_m/σ_rep = F/(π a² σ_rep),   c² = a² G/(2 h ρ),

G = 1 + ρφ(a/R_i)/R_i the rigid sphere's exact cap over its paraboloid (``model.cap``; 1 on a
flat): c² is the gap the body closes over its approach, as the model's h reads it.

Only σ_rep (hence Λ and H̄) depends on the coefficient β; :func:`quantities` evaluates
them for any β, :class:`Dataset` holds what does not depend on it.

Curves, not increments, carry the information: the FE force has a small staircase at
large a/R (one step per surface node closing) and the increments are spaced unevenly.
Each run is therefore resampled on a fixed grid in ln h (``per_decade`` nodes per
decade, the same nodes for every run, plus the run's final approach) by a local linear
fit of ln F and ln a against ln h over the increments within one grid step of the node
(triangular weights).
This is exact for power laws (Hertz: F ∝ h^{3/2}, a ∝ h^{1/2}) and averages the
staircase over about two nodes of the surface mesh.

Resolution filter: the pole zone of the FE mesh has elements of 0.003 R/density.
The sub-element contact radius is within 0.5 % of Hertz (both p_m and c², elastic
run of the FE verification) from a ≈ 0.02 R on, i.e. about seven pole elements, and
off by 1–5 % below; points with a < ``A_MIN_ELEMENTS`` pole elements are dropped. Runs on
the surface-band mesh (``edge_band`` > 0, every run of campaign v2) have surface elements of
0.0005 R at the pole, 20 across a = 0.01 R: their points count from ``A_MIN_BAND_ELEMENTS``
pole elements (a ≥ 0.01 R at density 1), where the validation window starts
(``validation/thresholds.toml``). There, the stored start of the EPP E/σY 2500 validation run
is within 0.6 % in F of a re-run on the default mesh at twice its density (a/R 0.0106).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..model.cap import cap_gap_factor
from ..model.material import Material
from ..model.single import representative_strain, representative_stress

__all__ = [
    "A_MIN_ELEMENTS",
    "A_MIN_BAND_ELEMENTS",
    "POLE_ELEMENT",
    "PER_DECADE",
    "RunCurve",
    "Dataset",
    "relative_radius",
    "resample",
    "run_curve",
    "build_dataset",
    "quantities",
    "material_label",
]

#: size of the pole-zone elements of the FE mesh at density 1, in units of R
POLE_ELEMENT = 0.003
#: smallest usable contact radius, in pole elements (a ≥ 0.02 R at density 1)
A_MIN_ELEMENTS = 20.0 / 3.0
#: ... for runs on the surface-band mesh (a ≥ 0.01 R at density 1)
A_MIN_BAND_ELEMENTS = 10.0 / 3.0
#: grid nodes per decade of h
PER_DECADE = 16


def relative_radius(radius: float, indenter_radius: float) -> float:
    """ρ = R R_i/(R + R_i); ρ = R for a rigid flat (R_i = inf)."""
    if math.isinf(indenter_radius):
        return float(radius)
    return float(radius * indenter_radius / (radius + indenter_radius))


def material_label(m: Material) -> str:
    """Short label of a material: E/σY, ν and the Ludwik hardening (K/σY, n)."""
    if math.isinf(m.sigma_y):
        return f"elastic nu={m.nu:g}"
    s = f"E/sy={m.E / m.sigma_y:g} nu={m.nu:g}"
    hardening = m.flow.label()
    return f"{s} {hardening}" if hardening else s


def resample(h, F, a, lnh_grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """F and a at the grid approaches by local linear fits in ln–ln (module docstring).

    Parameters
    ----------
    h, F, a : FE curves (increasing h, positive values).
    lnh_grid : ln h of the grid nodes (uniform step Δ).

    Returns
    -------
    F_grid, a_grid : arrays like ``lnh_grid``.
    """
    x = np.log(np.asarray(h, dtype=float))
    Y = np.log(np.stack([np.asarray(F, dtype=float), np.asarray(a, dtype=float)]))
    step = float(lnh_grid[1] - lnh_grid[0]) if lnh_grid.size > 1 else 1.0
    out = np.empty((2, lnh_grid.size))
    for j, x0 in enumerate(lnh_grid):
        w = np.clip(1.0 - np.abs(x - x0) / step, 0.0, None)
        sel = w > 0.0
        if np.count_nonzero(sel) < 3:  # sparse increments: interpolate
            out[:, j] = [np.interp(x0, x, y) for y in Y]
            continue
        xs, ws = x[sel] - x0, w[sel]
        A = np.stack([np.ones_like(xs), xs], axis=1) * ws[:, None]
        coef, *_ = np.linalg.lstsq(A, (Y[:, sel] * ws).T, rcond=None)
        out[:, j] = coef[0]
    return np.exp(out[0]), np.exp(out[1])


@dataclass(frozen=True)
class RunCurve:
    """One FE run resampled on the ln h grid, with its geometry and material."""

    key: str
    material: Material
    group: str            # material label; the cross-validation folds group by it
    radius: float         # R of the deformable body
    indenter_radius: float  # R_i of the rigid surface (inf: flat)
    rho: float            # relative radius ρ
    h: np.ndarray
    F: np.ndarray
    a: np.ndarray
    h_fe: np.ndarray = field(repr=False)  # the FE increments (for the F(h), a(h) errors)
    F_fe: np.ndarray = field(repr=False)
    a_fe: np.ndarray = field(repr=False)
    a_min: float = 0.0    # resolution threshold used

    @property
    def scene(self) -> str:
        if math.isinf(self.indenter_radius):
            return "flat"
        return f"sphere R_i/R={self.indenter_radius / self.radius:g}"


def run_curve(key: str, run, per_decade: int = PER_DECADE,
              a_min_elements: float = A_MIN_ELEMENTS,
              a_min_band_elements: float = A_MIN_BAND_ELEMENTS) -> RunCurve | None:
    """Resample one run's loading curve (a ``spherecontact.fem.io.Run`` or anything with
    ``h, F, a, inputs, material()`` and optionally a ``loading`` mask); None if no
    increment is resolved (a < a_min: ``a_min_band_elements`` pole elements on the
    surface-band mesh, ``a_min_elements`` otherwise).
    """
    inp = run.inputs
    R = float(inp["radius"])
    Ri = float(inp.get("indenter_radius", math.inf))
    density = float(inp.get("mesh_density", 1.0))
    rho = relative_radius(R, Ri)
    h, F, a = (np.asarray(v, dtype=float) for v in (run.h, run.F, run.a))
    ok = (h > 0) & (F > 0) & (a > 0) & np.isfinite(h + F + a)
    # runs with unloading cycles: the loading curve only; without an oversized first step's
    # transient (``fem.io.reference_mask``)
    loading = getattr(run, "reference", getattr(run, "loading", None))
    if loading is not None:
        ok &= np.asarray(loading, dtype=bool)
    h, F, a = h[ok], F[ok], a[ok]
    order = np.argsort(h, kind="stable")
    h, F, a = h[order], F[order], a[order]
    band = float(inp.get("edge_band", 0.0) or 0.0) > 0.0
    a_min = (a_min_band_elements if band else a_min_elements) * POLE_ELEMENT * R / density
    use = a >= a_min
    if np.count_nonzero(use) < 2:
        return None
    lo, hi = np.log(h[use][0] / R), np.log(h[-1] / R)
    d = math.log(10.0) / per_decade
    k = np.arange(math.ceil(lo / d - 1e-9), math.floor(hi / d + 1e-9) + 1)
    lng = k * d + math.log(R)
    last = math.log(h[-1])
    if lng.size and last - lng[-1] > 0.25 * d:  # the final approach (h_max) as one more node
        lng = np.append(lng, last)
    if lng.size < 2:
        return None
    Fg, ag = resample(h, F, a, lng)
    mat = run.material()
    return RunCurve(key=key, material=mat, group=material_label(mat), radius=R, indenter_radius=Ri,
                    rho=rho, h=np.exp(lng), F=Fg, a=ag, h_fe=h, F_fe=F, a_fe=a, a_min=a_min)


@dataclass(frozen=True)
class Dataset:
    """Calibration points of many runs, concatenated (β-independent parts)."""

    curves: tuple[RunCurve, ...]
    run: np.ndarray    # index into ``curves`` per point
    h: np.ndarray
    F: np.ndarray
    a: np.ndarray
    rho: np.ndarray
    R: np.ndarray
    E_prime: np.ndarray
    p_m: np.ndarray    # F/(π a²)
    c2: np.ndarray     # a² G/(2 h ρ), G the rigid sphere's exact cap (``model.cap``; 1 on a flat)
    x_R: np.ndarray    # a/R
    x_rho: np.ndarray  # a/ρ
    h_R: np.ndarray    # h/R
    slope_F: np.ndarray  # d ln F/d ln h of the FE curve (errors at fixed h, ``fit.errors``)
    slope_a: np.ndarray  # d ln a/d ln h
    #: (h/R, F/Hertz) of the FE's elastic hemisphere, the fit's Level I anchor (``fit.level_I_anchor``;
    #: empty: none, e.g. synthetic data)
    elastic_sphere: tuple = ()
    cache: dict = field(default_factory=dict, repr=False, compare=False)  # derived per-point arrays

    @property
    def size(self) -> int:
        return int(self.h.size)

    @property
    def groups(self) -> list[str]:
        """Material labels, sorted (one fold each)."""
        return sorted({c.group for c in self.curves})

    def group_mask(self, group: str) -> np.ndarray:
        g = np.array([c.group == group for c in self.curves])
        return g[self.run]

    def subset(self, keep_runs: Sequence[int]) -> Dataset:
        """A dataset of the runs ``keep_runs`` (indices into ``curves``): the points of those
        runs taken from this one's arrays (the same numbers as building it from the curves)."""
        keep = list(keep_runs)
        if not keep:
            raise ValueError("no calibration points: no run has a resolved contact radius")
        starts = self.cache.get("run_starts")
        if starts is None:  # points of run i: starts[i]:starts[i + 1] (runs are contiguous)
            starts = self.cache["run_starts"] = np.searchsorted(self.run, np.arange(len(self.curves) + 1))
        idx = np.concatenate([np.arange(starts[i], starts[i + 1]) for i in keep])
        run = np.concatenate([np.full(starts[i + 1] - starts[i], j) for j, i in enumerate(keep)])
        return Dataset(curves=tuple(self.curves[i] for i in keep), run=run,
                       **{f: getattr(self, f)[idx] for f in _POINT_FIELDS},
                       elastic_sphere=self.elastic_sphere)

    def without_groups(self, *groups: str) -> Dataset:
        """The runs of every material but ``groups``."""
        return self.subset([i for i, c in enumerate(self.curves) if c.group not in groups])

    def only_groups(self, *groups: str) -> Dataset:
        """The runs of the materials ``groups``."""
        return self.subset([i for i, c in enumerate(self.curves) if c.group in groups])


#: the per-point arrays of a :class:`Dataset` besides ``run``
_POINT_FIELDS = ("h", "F", "a", "rho", "R", "E_prime", "p_m", "c2", "x_R", "x_rho", "h_R", "slope_F",
                 "slope_a")


def build_dataset_from_curves(curves: Iterable[RunCurve]) -> Dataset:
    curves = tuple(curves)
    if not curves:
        raise ValueError("no calibration points: no run has a resolved contact radius")
    run = np.concatenate([np.full(c.h.size, i) for i, c in enumerate(curves)])
    cat = lambda f: np.concatenate([f(c) for c in curves])  # noqa: E731
    h, F, a = cat(lambda c: c.h), cat(lambda c: c.F), cat(lambda c: c.a)
    rho = cat(lambda c: np.full(c.h.size, c.rho))
    R = cat(lambda c: np.full(c.h.size, c.radius))
    Ep = cat(lambda c: np.full(c.h.size, c.material.E_prime))
    cap = cat(lambda c: cap_gap_factor(c.a, 1.0 / c.rho, c.indenter_radius)[0])
    return Dataset(curves=curves, run=run, h=h, F=F, a=a, rho=rho, R=R, E_prime=Ep,
                   p_m=F / (math.pi * a * a), c2=a * a * cap / (2.0 * h * rho), x_R=a / R, x_rho=a / rho,
                   h_R=h / R, slope_F=cat(lambda c: _log_slope(c.h, c.F)),
                   slope_a=cat(lambda c: _log_slope(c.h, c.a)))


def _log_slope(h: np.ndarray, y: np.ndarray) -> np.ndarray:
    """d ln y/d ln h on a run's grid (second-order differences, one-sided at the ends)."""
    return np.gradient(np.log(y), np.log(h))


def build_dataset(runs: Iterable[tuple[str, object]], per_decade: int = PER_DECADE,
                  a_min_elements: float = A_MIN_ELEMENTS, elastic_sphere: tuple = (),
                  a_min_band_elements: float = A_MIN_BAND_ELEMENTS) -> Dataset:
    """Dataset of ``(key, run)`` pairs; runs without resolved points are skipped.
    ``elastic_sphere``: the Level I anchor points (``Dataset.elastic_sphere``)."""
    curves = []
    for key, run in runs:
        c = run_curve(key, run, per_decade, a_min_elements, a_min_band_elements)
        if c is not None:
            curves.append(c)
    return dataclasses.replace(build_dataset_from_curves(curves), elastic_sphere=tuple(elastic_sphere))


def quantities(ds: Dataset, beta: float, growth: float = 0.0, spread: float = 0.0) -> dict[str, np.ndarray]:
    """σ_rep, Λ and H̄ of every point for the representative strain ε_rep = β x (1 + γ x),
    x = a/ρ (β: ``beta``, γ: ``growth``; ``model.single.representative_strain``) and σ_rep of
    log-width W = ``spread`` (``model.single.representative_stress``).

    Returns
    -------
    dict with ``sigma_rep``, ``Lambda``, ``H_bar`` (NaN-free; elastic runs have
    σ_rep = inf, Λ = 0 and H̄ = 0) and ``eps_rep``.
    """
    eps = representative_strain(ds.x_rho, beta, growth)[0]
    sig = np.empty_like(eps)
    for i, c in enumerate(ds.curves):
        m = ds.run == i
        sig[m] = representative_stress(c.material, eps[m], spread)[0]
    Lam = ds.E_prime * ds.x_rho / sig
    with np.errstate(invalid="ignore"):
        H = np.where(np.isfinite(sig), ds.p_m / sig, 0.0)
    return {"eps_rep": eps, "sigma_rep": sig, "Lambda": Lam, "H_bar": H}
