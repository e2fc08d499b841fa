"""Candidate functional forms: a parameter vector ↔ a schema-2 coefficient set.

Every candidate is a restriction of the model's coefficient schema
(``model/README.md``), so whatever is fitted is evaluated by the model's own code
(:func:`predict` calls ``spherecontact.model.single.BodyLaw``) and can be written to
``model/coefficients.json`` as it is.

Free parameters of a form (bounds in :func:`Form.parameters`):

* β (ε_rep = β a/ρ), ln Λ_I and ln(Λ_III/Λ_I);
* Level III: H̄_III(n) = P exp(Σ g_k n^(k+1)), c²_III(n) likewise (``n_III`` terms each);
* Level II shape terms b_k (``n_shape``), straight (seed), polynomial or smooth (C¹ Hermite);
* finite-size factor 1 + Σ f_k x^(k+1) on H̄ and c² (``n_finite``);
* optional collapse blend (``collapse``): ln H̄_c prefactor, exponent, x-polynomial,
  n-polynomial, ln c²_c prefactor, x-polynomial, n-polynomial, z-polynomials, ln of the
  sharpness k; optionally x·n terms of both limits (``n_collapse_xnH``, ``n_collapse_xnc``)
  and a separate sharpness k_c and offset s of the c² weight (``c2_sharpness``, ``c2_offset``);
  optionally z·n terms of both limits (``n_collapse_znH``, ``n_collapse_znc``);
* counter-surface terms q (``counter``), with Level III values q_III (``counter_by_level``) and
  those under a vanishing indenter, q_III + q_ζ (``counter_conformity``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from ..model import levels
from ..model.coefficients import COUNTER_BOUND, LITERATURE, SCHEMA_VERSION, Coefficients, CollapseLimit
from ..model.flow import Ludwik, Table
from ..model.single import (
    BodyLaw,
    capped_exponent,
    curvature_ratio,
    effective_exponent,
    ludwik_representative_stress,
    representative_strain,
    spread_average,
)
from .dataset import Dataset
from .flowtables import FlowTables

#: collapse c²_c is parametrised by its value and slopes at this a/R
X_C2 = 0.5

__all__ = ["Form", "FORMS", "CANDIDATES", "predict", "predict_exact", "point_inputs", "hertz_start"]


@dataclass(frozen=True)
class Form:
    """A candidate functional form (see module docstring)."""

    name: str
    description: str
    smooth: bool = False        # Level II: cubic Hermite (C¹) instead of polynomial in t
    n_shape_H: int = 0          # Level II shape terms of H̄
    n_shape_c: int = 0          # ... of c²
    n_III_H: int = 1            # exp_poly terms of H̄_III(n)
    n_III_c: int = 1            # ... of c²_III(n)
    n_finite_H: int = 1         # finite-size polynomial terms of H̄
    n_finite_c: int = 1         # ... of c²
    finite_by_level: bool = True  # separate Level I and Level III finite-size coefficients
    collapse: bool = True       # large-deformation collapse blend
    n_collapse_H: int = 1       # x_poly terms of H̄_c
    n_collapse_c: int = 1       # x_poly terms of c²_c
    n_collapse_nH: int = 1      # exp_poly (hardening) terms of H̄_c
    n_collapse_nc: int = 1      # ... of c²_c
    n_collapse_zH: int = 1      # z_poly (curvature of the pressing surface) terms of H̄_c
    n_collapse_zc: int = 1      # ... of c²_c
    n_collapse_xnH: int = 0     # xn_poly (x·n) terms of H̄_c
    n_collapse_xnc: int = 0     # ... of c²_c
    n_collapse_znH: int = 0     # zn_poly (z·n) terms of H̄_c
    n_collapse_znc: int = 0     # ... of c²_c
    z_log: bool = False         # the z-polynomials in ln(1 + z) (``collapse.z_variable``) instead of z
    c2_sharpness: bool = False  # separate sharpness k_c of the c² weight
    c2_offset: bool = False     # offset s of the c² weight, w_c = (r e^s)^k_c/(1 + (r e^s)^k_c)
    ratio: str = "a_over_R"     # finite-size ratio
    eps_lo: float = 0.01        # secant of the effective hardening exponent
    eps_hi: float = 0.1
    strain_growth: bool = False  # ε_rep = β x (1 + γ x) with γ fitted (else γ = 0)
    counter: bool = False       # counter-surface terms exp(q s(a/ρ − a/R)) of H̄_hs, c²_hs (ratio a/R)
    counter_by_level: bool = False  # ... with Level III values q_III, q = (1 − s_l) q + s_l q_III
    counter_conformity: str = ""  # ... their Level III values changing with the conformity
    #                               ζ = z/(1 + z) of the pressing surface: "H" (H̄'s alone) or "both"
    strain_spread: float = 0.0  # W of the representative stress (``single.representative_stress``)
    n_shape_n: int = 0          # Level II shape terms per unit of the hardening exponent (each)
    exponent_window: float = 0.0  # > 0: the exponent read along the curve (``local_secant``), window K
    exponent_cap: float = 0.5     # ... and its soft cap

    # ------------------------------------------------------------------ parameters
    def parameters(self) -> list[tuple[str, float, float, float]]:
        """(name, start, lower bound, upper bound) of every free parameter, in order."""
        p = [("beta", 0.32, 0.05, 1.0),
             ("ln_Lambda_I", math.log(3.0), math.log(1.0), math.log(10.0)),
             ("ln_Lambda_III_over_I", math.log(30.0), math.log(2.0), math.log(3000.0)),
             ("H_III", 2.9, 1.5, 4.5)]
        p += [(f"H_III_n{k}", 0.0, -5.0, 5.0) for k in range(self.n_III_H)]
        p += [("c2_III", 1.35, 0.6, 2.5)]
        p += [(f"c2_III_n{k}", -0.9, -5.0, 5.0) if k == 0 else (f"c2_III_n{k}", 0.0, -5.0, 5.0)
              for k in range(self.n_III_c)]
        p += [(f"H_shape{k}", 0.0, -8.0, 8.0) for k in range(self.n_shape_H)]
        p += [(f"c2_shape{k}", 0.0, -8.0, 8.0) for k in range(self.n_shape_c)]
        p += [(f"H_shape_n{k}", 0.0, -8.0, 8.0) for k in range(self.n_shape_n)]
        p += [(f"c2_shape_n{k}", 0.0, -8.0, 8.0) for k in range(self.n_shape_n)]
        # finite-size factors 1 + f x: positive for every x <= 1 (f > -0.9)
        p += [(f"fs_H{k}", 0.3 if k == 0 else 0.0, -0.9, 3.0) for k in range(self.n_finite_H)]
        p += [(f"fs_c2{k}", 0.1 if k == 0 else 0.0, -0.9, 3.0) for k in range(self.n_finite_c)]
        if self.finite_by_level:
            p += [(f"fsp_H{k}", 0.0, -0.9, 3.0) for k in range(self.n_finite_H)]
            p += [(f"fsp_c2{k}", 0.0, -0.9, 3.0) for k in range(self.n_finite_c)]
        if self.collapse:
            p += [("ln_Hc", math.log(1.2), math.log(0.2), math.log(10.0)),
                  ("Hc_exponent", 0.8, 0.05, 3.0)]
            p += [(f"Hc_x{k}", 0.0, -5.0, 5.0) for k in range(self.n_collapse_H)]
            p += [(f"Hc_n{k}", 0.0, -5.0, 5.0) for k in range(self.n_collapse_nH)]
            # c²_c in terms of its value and log slopes at x = X_C2 (well inside the data)
            p += [("ln_c2c", math.log(0.9), math.log(0.2), math.log(4.0))]
            p += [(f"c2c_x{k}", 0.0, -6.0, 6.0) for k in range(self.n_collapse_c)]
            p += [(f"c2c_n{k}", 0.0, -5.0, 5.0) for k in range(self.n_collapse_nc)]
            p += [(f"Hc_z{k}", 0.0, -3.0, 3.0) for k in range(self.n_collapse_zH)]
            p += [(f"c2c_z{k}", 0.0, -3.0, 3.0) for k in range(self.n_collapse_zc)]
            p += [("ln_sharpness", math.log(2.0), math.log(0.5), math.log(30.0))]
            p += [(f"Hc_xn{k}", 0.0, -5.0, 5.0) for k in range(self.n_collapse_xnH)]
            # like c²_c's x-polynomial: n Σ_k e_k (x − X_C2)^(k+1)
            p += [(f"c2c_xn{k}", 0.0, -6.0, 6.0) for k in range(self.n_collapse_xnc)]
            p += [(f"Hc_zn{k}", 0.0, -3.0, 3.0) for k in range(self.n_collapse_znH)]
            p += [(f"c2c_zn{k}", 0.0, -3.0, 3.0) for k in range(self.n_collapse_znc)]
            if self.c2_sharpness:
                p += [("ln_sharpness_c2", math.log(2.0), math.log(0.5), math.log(30.0))]
            if self.c2_offset:
                p += [("offset_c2", 0.0, -3.0, 3.0)]
        if self.strain_growth:
            p += [("beta_growth", 4.0, 0.0, 20.0)]
        if self.has_counter:
            p += [("counter_H", 0.0, -COUNTER_BOUND, COUNTER_BOUND),
                  ("counter_c2", 0.0, -COUNTER_BOUND, COUNTER_BOUND)]
            if self.counter_by_level:
                p += [("counter_H3", 0.0, -COUNTER_BOUND, COUNTER_BOUND),
                      ("counter_c23", 0.0, -COUNTER_BOUND, COUNTER_BOUND)]
            if self.counter_conformity:  # ... and under a vanishing indenter (ζ = 1): q_III + q_ζ
                p += [("counter_H31", 0.0, -COUNTER_BOUND, COUNTER_BOUND)]
                if self.counter_conformity == "both":
                    p += [("counter_c231", 0.0, -COUNTER_BOUND, COUNTER_BOUND)]
        return p

    def __post_init__(self) -> None:
        if self.counter_conformity not in ("", "H", "both"):
            raise ValueError(f"form {self.name}: counter_conformity must be '', 'H' or 'both', "
                             f"got {self.counter_conformity!r}")
        if self.counter_conformity and not self.counter_by_level:
            raise ValueError(f"form {self.name}: counter_conformity moves the Level III values "
                             "of the counter-surface terms: it needs counter_by_level")

    @property
    def has_counter(self) -> bool:
        """Counter-surface terms: asked for, and the finite-size ratio is a/R (u = a/ρ − a/R)."""
        return self.counter and self.ratio == "a_over_R"

    @functools.cached_property
    def names(self) -> list[str]:
        return [q[0] for q in self.parameters()]

    def start(self) -> np.ndarray:
        return np.array([q[1] for q in self.parameters()])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        ps = self.parameters()
        return np.array([q[2] for q in ps]), np.array([q[3] for q in ps])

    # ------------------------------------------------------------------ coefficient set
    def to_dict(self, params) -> dict:
        """Schema-2 coefficient dictionary of a parameter vector (source 'calibration')."""
        v = dict(zip(self.names, (float(x) for x in params), strict=True))
        seq = lambda prefix, n: [v[f"{prefix}{k}"] for k in range(n)]  # noqa: E731
        lam1 = math.exp(v["ln_Lambda_I"])
        d = {
            "schema_version": SCHEMA_VERSION,
            "source": "calibration",
            "provenance": {},
            "beta": v["beta"],
            **({"beta_growth": v["beta_growth"]} if self.strain_growth else {}),
            **({"strain_spread": self.strain_spread} if self.strain_spread else {}),
            # c² of the data is the gap over h with the rigid sphere's exact cap (``dataset``)
            "counter_cap": "exact",
            # a pair's less plastic body under its partner's flattened pressure (``model/profile.py``)
            "pressure_profile": "flattened",
            "Lambda_I": lam1,
            "Lambda_III": lam1 * math.exp(v["ln_Lambda_III_over_I"]),
            "H_bar_III": {"prefactor": v["H_III"], "exp_poly": seq("H_III_n", self.n_III_H)},
            "c2_III": {"prefactor": v["c2_III"], "exp_poly": seq("c2_III_n", self.n_III_c)},
            "level_II": {"H_bar_shape": seq("H_shape", self.n_shape_H),
                         "c2_shape": seq("c2_shape", self.n_shape_c), "smooth": self.smooth,
                         **({"H_bar_shape_n": seq("H_shape_n", self.n_shape_n),
                             "c2_shape_n": seq("c2_shape_n", self.n_shape_n)} if self.n_shape_n else {})},
            "hardening_exponent": (
                {"method": "local_secant", "eps_lo": self.eps_lo, "eps_hi": self.eps_hi,
                 "window": self.exponent_window, "cap": self.exponent_cap} if self.exponent_window
                else {"method": "secant_loglog", "eps_lo": self.eps_lo, "eps_hi": self.eps_hi}),
            "finite_size": {"ratio": self.ratio, "H_bar": seq("fs_H", self.n_finite_H),
                            "c2": seq("fs_c2", self.n_finite_c),
                            "H_bar_plastic": seq("fsp_H" if self.finite_by_level else "fs_H",
                                                 self.n_finite_H),
                            "c2_plastic": seq("fsp_c2" if self.finite_by_level else "fs_c2",
                                              self.n_finite_c)},
            "collapse": None,
            "references": {},
        }
        if self.has_counter:
            d["counter_surface"] = {"H_bar": v["counter_H"], "c2": v["counter_c2"]}
            if self.counter_by_level:
                d["counter_surface"].update(H_bar_plastic=v["counter_H3"], c2_plastic=v["counter_c23"])
            if self.counter_conformity:
                d["counter_surface"]["H_bar_conformity"] = v["counter_H31"] - v["counter_H3"]
            if self.counter_conformity == "both":
                d["counter_surface"]["c2_conformity"] = v["counter_c231"] - v["counter_c23"]
        if self.collapse:
            # ln c²_c = ln c0 + Σ_k d_k (x − X_C2)^(k+1) + n Σ_k e_k (x − X_C2)^(k+1) + ...,
            # expanded in powers of x for the schema (the n e(0) part joins exp_poly[0])
            shifted = _shift_powers(seq("c2c_x", self.n_collapse_c), X_C2)
            c_n = seq("c2c_n", self.n_collapse_nc)
            c_xn = []
            if self.n_collapse_xnc:
                sh = _shift_powers(seq("c2c_xn", self.n_collapse_xnc), X_C2)
                c_n = [c_n[0] + sh[0]] + c_n[1:] if c_n else [sh[0]]
                c_xn = [float(c) for c in sh[1:]]
            d["collapse"] = {
                "H_bar": {"prefactor": math.exp(v["ln_Hc"]), "exponent": v["Hc_exponent"],
                          "x_poly": seq("Hc_x", self.n_collapse_H),
                          "exp_poly": seq("Hc_n", self.n_collapse_nH),
                          "z_poly": seq("Hc_z", self.n_collapse_zH),
                          "xn_poly": seq("Hc_xn", self.n_collapse_xnH),
                          **({"zn_poly": seq("Hc_zn", self.n_collapse_znH)} if self.n_collapse_znH else {})},
                "c2": {"prefactor": math.exp(v["ln_c2c"] + shifted[0]), "exponent": 0.0,
                       "x_poly": [float(c) for c in shifted[1:]],
                       "exp_poly": c_n,
                       "z_poly": seq("c2c_z", self.n_collapse_zc), "xn_poly": c_xn,
                       **({"zn_poly": seq("c2c_zn", self.n_collapse_znc)} if self.n_collapse_znc else {})},
                "sharpness": math.exp(v["ln_sharpness"]),
            }
            if self.c2_sharpness:
                d["collapse"]["sharpness_c2"] = math.exp(v["ln_sharpness_c2"])
            if self.c2_offset:
                d["collapse"]["offset_c2"] = v["offset_c2"]
            if self.z_log:
                d["collapse"]["z_variable"] = "ln(1+z)"
        return d

    def coefficients(self, params) -> Coefficients:
        return Coefficients.from_dict(self.to_dict(params))

    def coefficients_unchecked(self, params) -> Coefficients:
        """:meth:`coefficients` without the schema validation (equal sets; the fits' inner
        loop, where the parametrisation already keeps every value valid)."""
        return _unchecked(self.to_dict(params))

    @property
    def n_params(self) -> int:
        return len(self.parameters())


def _limit(d: dict) -> CollapseLimit:
    return CollapseLimit(prefactor=d["prefactor"], exponent=d["exponent"], x_poly=tuple(d["x_poly"]),
                         exp_poly=tuple(d["exp_poly"]), z_poly=tuple(d["z_poly"]),
                         xn_poly=tuple(d["xn_poly"]), zn_poly=tuple(d.get("zn_poly", ())))


def _unchecked(d: dict) -> Coefficients:
    """The :class:`Coefficients` of a dictionary made by :meth:`Form.to_dict`, built directly
    (what ``Coefficients.from_dict`` returns for it, without re-validating)."""
    fs, lev2, col = d["finite_size"], d["level_II"], d["collapse"]
    return Coefficients(
        beta=d["beta"], Lambda_I=d["Lambda_I"], Lambda_III=d["Lambda_III"],
        H_bar_III_prefactor=d["H_bar_III"]["prefactor"], H_bar_III_exp_poly=tuple(d["H_bar_III"]["exp_poly"]),
        c2_III_prefactor=d["c2_III"]["prefactor"], c2_III_exp_poly=tuple(d["c2_III"]["exp_poly"]),
        H_bar_shape=tuple(lev2["H_bar_shape"]), c2_shape=tuple(lev2["c2_shape"]),
        H_bar_shape_n=tuple(lev2.get("H_bar_shape_n", ())), c2_shape_n=tuple(lev2.get("c2_shape_n", ())),
        exponent_method=d["hardening_exponent"]["method"], eps_lo=d["hardening_exponent"]["eps_lo"],
        eps_hi=d["hardening_exponent"]["eps_hi"],
        exponent_window=d["hardening_exponent"].get("window", 0.0),
        exponent_cap=d["hardening_exponent"].get("cap", 0.0), finite_size_ratio=fs["ratio"],
        finite_size_H_bar=tuple(fs["H_bar"]), finite_size_c2=tuple(fs["c2"]),
        finite_size_H_bar_plastic=tuple(fs["H_bar_plastic"]), finite_size_c2_plastic=tuple(fs["c2_plastic"]),
        collapse_H_bar=None if col is None else _limit(col["H_bar"]),
        collapse_c2=None if col is None else _limit(col["c2"]),
        collapse_sharpness=0.0 if col is None else col["sharpness"],
        collapse_sharpness_c2=None if col is None else col.get("sharpness_c2"),
        collapse_offset_c2=None if col is None else col.get("offset_c2"),
        collapse_z_variable="z" if col is None else col.get("z_variable", "z"),
        level_II_smooth=lev2["smooth"], beta_growth=d.get("beta_growth", 0.0),
        strain_spread=d.get("strain_spread", 0.0),
        counter_H_bar=d.get("counter_surface", {}).get("H_bar", 0.0),
        counter_c2=d.get("counter_surface", {}).get("c2", 0.0),
        counter_H_bar_plastic=d.get("counter_surface", {}).get("H_bar_plastic"),
        counter_c2_plastic=d.get("counter_surface", {}).get("c2_plastic"),
        counter_H_bar_conformity=d.get("counter_surface", {}).get("H_bar_conformity", 0.0),
        counter_c2_conformity=d.get("counter_surface", {}).get("c2_conformity", 0.0),
        counter_cap=d.get("counter_cap", "paraboloid"),
        pressure_profile=d.get("pressure_profile", "hertz"), source=d["source"],
        schema_version=d["schema_version"])


def _shift_powers(d: list[float], x0: float) -> list[float]:
    """Coefficients e_j (j = 0..K) with Σ_k d_k (x − x0)^(k+1) = Σ_j e_j x^j (K = len(d))."""
    e = [0.0] * (len(d) + 1)
    for k, dk in enumerate(d):
        p = k + 1
        for j in range(p + 1):
            e[j] += dk * math.comb(p, j) * (-x0) ** (p - j)
    return e


def predict_exact(ds: Dataset, coeffs: Coefficients) -> tuple[np.ndarray, np.ndarray]:
    """Model p_m and c² at the points of ``ds``: the model's single-body law run by run."""
    p = np.empty(ds.size)
    c = np.empty(ds.size)
    ratio_R = coeffs.finite_size_ratio == "a_over_R"
    for i, curve in enumerate(ds.curves):
        m = ds.run == i
        law = BodyLaw(curve.material, coeffs)
        z = curvature_ratio(curve.radius, curve.rho)
        r = law.response(ds.x_rho[m], ds.x_R[m] if ratio_R else ds.x_rho[m], z)
        p[m] = r.p_m
        c[m] = r.c2
    return p, c


def _per_point(ds: Dataset, values) -> np.ndarray:
    return np.asarray(values, dtype=float)[ds.run]


def _memo(ds: Dataset, kind: str, key: tuple, make):
    """``make()`` memoised in ``ds.cache[kind]`` under ``key`` (at most 256 entries a kind)."""
    store = ds.cache.setdefault(kind, {})
    v = store.get(key)
    if v is None:
        if len(store) >= 256:
            store.clear()
        v = store[key] = make()
    return v


def point_inputs(ds: Dataset, co: Coefficients):
    """Per-point inputs of the level functions, memoised in ``ds.cache``: the effective
    hardening exponent n, σ_rep, Λ, the elastic mask, the finite-size ratio y (a/R or a/ρ)
    and z = R/ρ − 1 of the rigid partner (ρ: Hertz relative radius)."""
    if co.exponent_local:
        n_eff = _local_exponent(ds, co)[0]
    else:
        key = ("n_eff", co.eps_lo, co.eps_hi, co.strain_spread)
        n_eff = ds.cache.get(key)
        if n_eff is None:
            n_eff = ds.cache[key] = _per_point(
                ds, [0.0 if math.isinf(c.material.sigma_y) else effective_exponent(c.material, co)
                     for c in ds.curves])
    sig, Lam, elastic = _memo(ds, "sigma_rep", (co.beta, co.beta_growth, co.strain_spread),
                              lambda: _sigma_rep(ds, co.beta, co.beta_growth, co.strain_spread))
    y = ds.x_R if co.finite_size_ratio == "a_over_R" else ds.x_rho
    z = raw_curvature_ratio(ds)
    if co.collapse_z_variable != "z":  # the collapse limits' z variable
        key = ("z", co.collapse_z_variable)
        if key not in ds.cache:
            ds.cache[key] = co.collapse_z(z)
        z = ds.cache[key]
    return n_eff, sig, Lam, elastic, y, z


def raw_curvature_ratio(ds: Dataset) -> np.ndarray:
    """z = R/ρ − 1 of the rigid partner at every point (``single.curvature_ratio``), memoised."""
    z = ds.cache.get("z")
    if z is None:
        z = ds.cache["z"] = _per_point(ds, [curvature_ratio(c.radius, c.rho) for c in ds.curves])
    return z


def counter_surface_at(ds: Dataset, co: Coefficients) -> np.ndarray:
    """s(u) of the counter-surface terms at every point (``levels.counter_surface``; u = a/ρ − a/R,
    0 where the finite-size ratio is a/ρ), memoised."""
    def make():
        if co.finite_size_ratio != "a_over_R":
            return np.zeros(ds.size)
        return levels.counter_surface(ds.x_rho, ds.x_R)[0]
    return _memo(ds, "counter_s", (co.finite_size_ratio,), make)


def flow_log_slope_at(ds: Dataset, co: Coefficients) -> np.ndarray:
    """m = d ln σ_rep/d ln ε_rep at every point (0 for elastic bodies;
    ``single.representative_stress``), memoised by (β, γ, W)."""
    return _representative_stress(ds, co.beta, co.beta_growth, co.strain_spread)[1]


def predict(ds: Dataset, coeffs: Coefficients) -> tuple[np.ndarray, np.ndarray]:
    """Model p_m and c² at the points of ``ds``, all runs in one vectorised pass.

    The same equations as :func:`predict_exact` (the model's ``BodyLaw.response``),
    written with the model's level functions over all points at once (the collapse blend's
    few lines repeated in :func:`_blend`): the fits evaluate it thousands of times.
    Agreement is tested to rounding. The parts that depend on a few coefficients only
    (σ_rep and Λ; H̄ and c² of the half space with their finite-size factors; the collapse
    limits) are memoised in ``ds.cache`` by those coefficients: a finite-difference
    Jacobian moves one parameter at a time and leaves most of them unchanged.
    """
    co = coeffs
    n_eff, sig, Lam, elastic, y, z = point_inputs(ds, co)
    common = (co.beta, co.beta_growth, co.Lambda_I, co.Lambda_III, co.level_II_smooth, co.finite_size_ratio,
              co.eps_lo, co.eps_hi, co.exponent_window, co.exponent_cap)

    def half_space(level_fn, fs_elastic, fs_plastic):
        q, _ = level_fn(Lam, co, n_eff)
        s_l, ds_l = levels.level_weight(Lam, co)
        return q * levels.finite_size_by_level(y, s_l, ds_l, fs_elastic, fs_plastic)[0]

    H = _memo(ds, "H_hs", common + (co.H_bar_III_prefactor, co.H_bar_III_exp_poly, co.H_bar_shape,
                                    co.H_bar_shape_n, co.finite_size_H_bar, co.fs_H_bar_plastic),
              lambda: half_space(levels.H_bar_and_slope, co.finite_size_H_bar, co.fs_H_bar_plastic))
    c = _memo(ds, "c2_hs", common + (co.c2_III_prefactor, co.c2_III_exp_poly, co.c2_shape, co.c2_shape_n,
                                     co.finite_size_c2, co.fs_c2_plastic),
              lambda: half_space(levels.c2_and_slope, co.finite_size_c2, co.fs_c2_plastic))
    gH = 1.0
    if co.has_counter_surface:
        su = counter_surface_at(ds, co)
        (qH, _), (qc, _) = co.counter_by_level(levels.level_weight(Lam, co)[0], raw_curvature_ratio(ds))
        gH = np.exp(qH * su)
        H, c = H * gH, c * np.exp(qc * su)
    if co.has_collapse:
        where = (co.finite_size_ratio, co.eps_lo, co.eps_hi, co.collapse_z_variable, co.exponent_window,
                 co.exponent_cap) + ((co.beta, co.beta_growth, co.strain_spread) if co.exponent_local else ())
        lnHc = _memo(ds, "ln_Hc", (co.collapse_H_bar,) + where,
                     lambda: co.collapse_H_bar.log_and_slope(y, n_eff, z)[0])
        lncc = _memo(ds, "ln_c2c", (co.collapse_c2,) + where,
                     lambda: co.collapse_c2.log_and_slope(y, n_eff, z)[0])
        H, c = levels.blend_from_logs(H, c, lnHc, lncc, co.collapse_sharpness,
                                      co.collapse_sharpness_c2, co.collapse_offset_c2)[:2]
    p = H * np.where(elastic, 1.0, sig)
    if elastic.any():  # elastic bodies: Hertz p_m = 4E'x/(3π) with the finite-size factor
        hertz = 4.0 / (3.0 * math.pi) * ds.E_prime * ds.x_rho * levels.finite_size_factor(
            y, co.finite_size_H_bar)[0] * gH
        p = np.where(elastic, hertz, p)
    return p, c


def _representative_stress(ds: Dataset, beta: float, growth: float, spread: float):
    """σ_rep and m = d ln σ_rep/d ln ε_rep (``single.representative_stress``) at every point's
    ε_rep = β x (1 + γ x), x = a/ρ, memoised by (β, γ, W): the Ludwik runs all at once, the
    tabulated ones run by run."""
    return _memo(ds, "sigma_rep_m", (beta, growth, spread),
                 lambda: _stress_at(ds, representative_strain(ds.x_rho, beta, growth)[0], spread))


def _stress_at(ds: Dataset, eps, spread: float, copies: int = 1):
    """σ_rep and m of every point's flow curve at the strains ``eps`` (``copies`` stacked arrays of
    ds.size points each, evaluated in one pass): the Ludwik runs all at once, the tabulated ones
    stacked (``flowtables.FlowTables``), a run of any other law by its own
    ``FlowCurve.representative``."""
    mats = [c.material for c in ds.curves]
    run = np.tile(ds.run, copies)
    ludwik = [isinstance(m.flow, Ludwik) for m in mats]
    sy, K, n = (np.asarray(v, dtype=float)[run] for v in zip(
        *[(m.sigma_y, m.flow.K, m.flow.n) if lu else (1.0, 0.0, 1.0)
          for m, lu in zip(mats, ludwik, strict=True)], strict=True))
    with np.errstate(invalid="ignore"):
        sig, m = ludwik_representative_stress(sy, K, n, eps, spread)
    m = np.where(np.isfinite(sig), m, 0.0)  # 0 for elastic bodies (σ_Y = inf)
    if all(ludwik):
        return sig, m
    table_of_run, tables = _flow_tables(ds)
    sel = table_of_run[run] >= 0
    if tables is not None:
        rows, e = table_of_run[run[sel]], eps[sel]
        if spread == 0.0:  # representative_stress: σ_f and flow_log_slope
            s, slope = tables.flow(rows, e)
            sig[sel], m[sel] = s, np.maximum(e, 0.0) * slope / s
        else:
            sig[sel], m[sel] = spread_average(lambda x: tables.flow(rows, x), np.maximum(e, 0.0), spread)
    for i in np.flatnonzero(~np.asarray(ludwik) & (table_of_run < 0)):
        at = run == i
        sig[at], m[at] = mats[i].flow.representative(eps[at], spread)
    return sig, m


def _flow_tables(ds: Dataset) -> tuple[np.ndarray, FlowTables | None]:
    """Each run's row in the stacked tables of the tabulated runs (−1: any other run) and the
    tables (``flowtables.FlowTables``; None without tabulated runs), memoised."""
    def make():
        tab = [i for i, c in enumerate(ds.curves) if isinstance(c.material.flow, Table)]
        row = np.full(len(ds.curves), -1)
        row[tab] = np.arange(len(tab))
        return row, (FlowTables([ds.curves[i].material for i in tab]) if tab else None)
    return _memo(ds, "flow_tables", (), make)


def _local_exponent(ds: Dataset, co: Coefficients) -> tuple[np.ndarray, np.ndarray]:
    """n read along the flow curve at every point's ε_rep and dn/d ln ε_rep
    (``single.local_exponent``; 0 for elastic bodies), memoised by (β, γ, W, K, c)."""
    def make():
        eps = representative_strain(ds.x_rho, co.beta, co.beta_growth)[0]
        K, k = co.exponent_window, ds.size
        sig, m = _stress_at(ds, np.concatenate([eps / K, eps * K]), co.strain_spread, copies=2)
        span = 2.0 * math.log(K)
        with np.errstate(invalid="ignore"):
            n0 = np.log(sig[k:] / sig[:k]) / span
        elastic = ~np.isfinite(n0)
        n, dn_dn0 = capped_exponent(np.where(elastic, 0.0, n0), co.exponent_cap)
        return n, np.where(elastic, 0.0, dn_dn0 * (m[k:] - m[:k]) / span)
    return _memo(ds, "n_local", (co.beta, co.beta_growth, co.strain_spread, co.exponent_window,
                                 co.exponent_cap), make)


def exponent_slope_at(ds: Dataset, co: Coefficients) -> np.ndarray:
    """dn/d ln ε_rep at every point: 0 for one exponent per material, that of the exponent read
    along the curve otherwise (``local_secant``)."""
    return _local_exponent(ds, co)[1] if co.exponent_local else np.zeros(ds.size)


def _sigma_rep(ds: Dataset, beta: float, growth: float = 0.0, spread: float = 0.0):
    """σ_rep (``single.representative_stress``, log-width W = ``spread``) at ε_rep = β x (1 + γ x)
    with x = a/ρ, Λ = E' x/σ_rep (0 for elastic bodies) and the elastic mask."""
    sig = _representative_stress(ds, beta, growth, spread)[0]
    elastic = ~np.isfinite(sig)
    Lam = np.where(elastic, 0.0, ds.E_prime * ds.x_rho / np.where(elastic, 1.0, sig))
    return sig, Lam, elastic


def hertz_start() -> Coefficients:
    """The literature set (schema 1): the reference the calibration starts from."""
    return Coefficients.from_dict(LITERATURE)


#: The candidate forms, by name. ``seed``: Level II straight in ln Λ (seed §2);
#: ``poly``: polynomial Level II shape; ``smooth``: C¹ Hermite Level II with one shape
#: term. All share the Level III, finite-size and collapse terms, so the CV comparison
#: isolates the Level II form; ``smooth2_fs`` tests level-dependent finite-size terms.
FORMS: dict[str, Form] = {
    "seed": Form("seed", "Level II straight in ln Λ (seed §2); kinks at Λ_I and Λ_III"),
    "poly": Form("poly", "Level II cubic in t = ln(Λ/Λ_I)/ln(Λ_III/Λ_I) (2 shape terms each); "
                 "kinks at Λ_I and Λ_III", n_shape_H=2, n_shape_c=2),
    "smooth": Form("smooth", "Level II C¹ Hermite (Hertz slope at Λ_I, flat at Λ_III) + "
                   "1 shape term each; H̄, c², dF/dh continuous", smooth=True, n_shape_H=1,
                   n_shape_c=1),
    "smooth2": Form("smooth2", "as smooth, 2 shape terms each", smooth=True, n_shape_H=2,
                    n_shape_c=2),
    "smooth2_fs": Form("smooth2_fs", "as smooth2, one finite-size coefficient for all levels",
                       smooth=True, n_shape_H=2, n_shape_c=2, finite_by_level=False),
    "smooth2_fs2": Form("smooth2_fs2", "as smooth2, finite-size factors quadratic in a/R, "
                        "Level I and Level III coefficients", smooth=True, n_shape_H=2, n_shape_c=2,
                        n_finite_H=2, n_finite_c=2, finite_by_level=True),
    "smooth2_ld": Form("smooth2_ld", "as smooth2_fs2, collapse limits quadratic in a/R and H̄_c "
                       "quadratic in the hardening exponent", smooth=True, n_shape_H=2, n_shape_c=2,
                       n_finite_H=2, n_finite_c=2, finite_by_level=True, n_collapse_H=2,
                       n_collapse_c=2, n_collapse_nH=2),
    "smooth2_ld3": Form("smooth2_ld3", "as smooth2_ld, collapse limits cubic in a/R, hardening "
                        "exponent the secant between ε_p = 0.03 and 0.3", smooth=True, n_shape_H=2,
                        n_shape_c=2, n_finite_H=2, n_finite_c=2, finite_by_level=True,
                        n_collapse_H=3, n_collapse_c=3, n_collapse_nH=2, eps_lo=0.03, eps_hi=0.3),
    "smooth2_fs2_xn": Form("smooth2_fs2_xn", "as smooth2_fs2, both collapse limits with an "
                           "a/R·n term", smooth=True, n_shape_H=2, n_shape_c=2, n_finite_H=2,
                           n_finite_c=2, finite_by_level=True, n_collapse_xnH=1, n_collapse_xnc=1),
    "smooth2_fs2_xnw": Form("smooth2_fs2_xnw", "as smooth2_fs2_xn, c² collapse weight with its own "
                            "sharpness and offset", smooth=True, n_shape_H=2, n_shape_c=2, n_finite_H=2,
                            n_finite_c=2, finite_by_level=True, n_collapse_xnH=1, n_collapse_xnc=1,
                            c2_sharpness=True, c2_offset=True),
    "smooth2_fs2_g": Form("smooth2_fs2_g", "as smooth2_fs2, representative strain growing with "
                          "the depth of the contact, ε_rep = β x (1 + γ x)", smooth=True, n_shape_H=2,
                          n_shape_c=2, n_finite_H=2, n_finite_c=2, finite_by_level=True,
                          strain_growth=True),
    "smooth2_fs2_xn_g": Form("smooth2_fs2_xn_g", "as smooth2_fs2_xn, ε_rep = β x (1 + γ x)",
                             smooth=True, n_shape_H=2, n_shape_c=2, n_finite_H=2, n_finite_c=2,
                             finite_by_level=True, n_collapse_xnH=1, n_collapse_xnc=1,
                             strain_growth=True),
    "smooth2_fs2_xn2_g": Form("smooth2_fs2_xn2_g", "as smooth2_fs2_xn_g, x·n terms quadratic in "
                              "a/R in both collapse limits", smooth=True, n_shape_H=2, n_shape_c=2,
                              n_finite_H=2, n_finite_c=2, finite_by_level=True, n_collapse_xnH=2,
                              n_collapse_xnc=2, strain_growth=True),
    "smooth2_fs2_xn2n_g": Form("smooth2_fs2_xn2n_g", "as smooth2_fs2_xn2_g, H̄_c quadratic in the "
                               "hardening exponent", smooth=True, n_shape_H=2, n_shape_c=2,
                               n_finite_H=2, n_finite_c=2, finite_by_level=True, n_collapse_nH=2,
                               n_collapse_xnH=2, n_collapse_xnc=2, strain_growth=True),
    "smooth2_fs2_xn2n_x2_g": Form("smooth2_fs2_xn2n_x2_g", "as smooth2_fs2_xn2n_g, both collapse "
                                  "limits quadratic in a/R", smooth=True, n_shape_H=2, n_shape_c=2,
                                  n_finite_H=2, n_finite_c=2, finite_by_level=True, n_collapse_H=2,
                                  n_collapse_c=2, n_collapse_nH=2, n_collapse_xnH=2,
                                  n_collapse_xnc=2, strain_growth=True),
    "smooth2_fs2_xn2n_x3_g": Form("smooth2_fs2_xn2n_x3_g", "as smooth2_fs2_xn2n_g, both collapse "
                                  "limits cubic in a/R", smooth=True, n_shape_H=2, n_shape_c=2,
                                  n_finite_H=2, n_finite_c=2, finite_by_level=True, n_collapse_H=3,
                                  n_collapse_c=3, n_collapse_nH=2, n_collapse_xnH=2,
                                  n_collapse_xnc=2, strain_growth=True),
    "smooth2_fs2_xn2n_x2_g_cs": Form("smooth2_fs2_xn2n_x2_g_cs", "as smooth2_fs2_xn2n_x2_g, with "
                                     "the counter-surface terms of H̄ and c² (a/R_i of a rigid "
                                     "sphere)", smooth=True, n_shape_H=2, n_shape_c=2,
                                     n_finite_H=2, n_finite_c=2, finite_by_level=True,
                                     n_collapse_H=2, n_collapse_c=2, n_collapse_nH=2,
                                     n_collapse_xnH=2, n_collapse_xnc=2, strain_growth=True,
                                     counter=True),
    "smooth2_fs2_xn2n_x3_g_cs": Form("smooth2_fs2_xn2n_x3_g_cs", "as smooth2_fs2_xn2n_x2_g_cs, both "
                                     "collapse limits cubic in a/R", smooth=True, n_shape_H=2,
                                     n_shape_c=2, n_finite_H=2, n_finite_c=2, finite_by_level=True,
                                     n_collapse_H=3, n_collapse_c=3, n_collapse_nH=2,
                                     n_collapse_xnH=2, n_collapse_xnc=2, strain_growth=True,
                                     counter=True),
    # the two parts of the xnw weight alone (``--forms``)
    "smooth2_fs2_xnk": Form("smooth2_fs2_xnk", "as smooth2_fs2_xn, c² collapse weight with its own "
                            "sharpness", smooth=True, n_shape_H=2, n_shape_c=2, n_finite_H=2,
                            n_finite_c=2, finite_by_level=True, n_collapse_xnH=1, n_collapse_xnc=1,
                            c2_sharpness=True),
    "smooth2_fs2_xns": Form("smooth2_fs2_xns", "as smooth2_fs2_xn, c² collapse weight with its own "
                            "offset", smooth=True, n_shape_H=2, n_shape_c=2, n_finite_H=2,
                            n_finite_c=2, finite_by_level=True, n_collapse_xnH=1, n_collapse_xnc=1,
                            c2_offset=True),
}


def _derived(base: str, name: str, description: str, **changes) -> Form:
    """A form of :data:`FORMS` with some fields changed (the forms after ``…_cs`` are steps on it)."""
    return dataclasses.replace(FORMS[base], name=name, description=description, **changes)


FORMS["smooth2_fs2_xn2n_x2_g_csl"] = _derived(
    "smooth2_fs2_xn2n_x2_g_cs", "smooth2_fs2_xn2n_x2_g_csl", "as smooth2_fs2_xn2n_x2_g_cs, counter-surface "
    "terms with Level III values (blended by the level weight)", counter_by_level=True)
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl", "smooth2_fs2_xn2n_x2_g_csl_w1", "as smooth2_fs2_xn2n_x2_g_csl, σ_rep "
    "averaged over strains of log-width W = 1 about ε_rep", strain_spread=1.0)
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1", "smooth2_fs2_xn2n_x2_g_csl_w1_sn", "as smooth2_fs2_xn2n_x2_g_csl_w1, "
    "Level II shape terms changing with the hardening exponent", n_shape_n=2)
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn", "as "
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn, collapse limits with a z·n term (the pressing surface's "
    "curvature acting with the hardening exponent)", n_collapse_znH=1, n_collapse_znc=1)
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_z2"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_z2", "as "
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn, both collapse limits quadratic in z", n_collapse_zH=2,
    n_collapse_zc=2)
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_lz"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_lz", "as "
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn, the collapse limits' z-terms in ln(1 + z) = ln(R/ρ_c)",
    z_log=True)
for _base in ("smooth2_fs2_xn2n_x2_g_csl_w1_sn", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn",
              "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_lz"):  # each with the exponent along the curve
    FORMS[_base + "_nl"] = _derived(
        _base, _base + "_nl", f"as {_base}, the hardening exponent read along the curve (secant over "
        "[ε_rep/3, 3ε_rep], capped at 0.5)", exponent_window=3.0)
FORMS["smooth2_fs2_xn2n_x3_g_csl_w1"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1", "smooth2_fs2_xn2n_x3_g_csl_w1", "as smooth2_fs2_xn2n_x2_g_csl_w1, both "
    "collapse limits cubic in a/R", n_collapse_H=3, n_collapse_c=3)

FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz", "as "
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl, the counter-surface terms' Level III values changing "
    "with the conformity ζ = z/(1 + z) of the pressing surface", counter_conformity="both")
FORMS["smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh"] = _derived(
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh", "as "
    "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz, the pressure's term alone", counter_conformity="H")

#: forms compared by cross-validation in every calibration: the seed's; the representative stress
#: averaged over the flow curve, level-dependent counter-surface terms and the Level II shape
#: changing with the hardening exponent (_csl_w1_sn); with z·n terms of the collapse limits (_zn:
#: E_cv 1.58 against 1.64 %); and with those limits' z-terms in ln(1 + z) (_lz: E_cv 1.55 %; on the
#: validation set of 2026-11-26, 1 run above 5 % against 2 and 3, calibration/README.md). The steps
#: that led there (smooth2_fs2, _g, _xn_g, _xn2_g, _xn2n_g, _x2_g, _cs, _csl, _csl_w1, _zn) and the forms
#: they beat stay in FORMS for ``--forms``; so do the same with cubic collapse limits (_x3_g_csl_w1:
#: its F(h) fails the monotonicity check) and with quadratic z-terms (_zn_z2: E_cv 1.56 %, within
#: the parsimony margin of _zn, which has two parameters fewer). Since 2026-11-27 both read the
#: hardening exponent along the flow curve (_nl: on the same database E_cv 1.54 → 1.27 %, held-out
#: max F 14.2 → 9.9 %); the forms with one exponent per material stay for ``--forms``. Since the
#: rigid sphere's exact cap entered c² (2026-11-27, ``model/cap.py``) the z·n terms score better in
#: z itself than in ln(1 + z) (E_cv 1.21 against 1.28 %, calibration/README.md): _zn_lz_nl stays
#: for ``--forms``. Since 2026-11-27 the counter-surface terms' Level III values may change with the
#: conformity ζ = z/(1 + z) of the pressing surface (_cz: both terms, _czh: the pressure's alone;
#: E_cv 1.17 / 1.19 against 1.21 %, with the folds solved 1.23 / 1.23 against 1.25 %); _sn_nl, which
#: _zn_nl had beaten since the cap (1.24 against 1.21 %), stays for ``--forms``.
CANDIDATES = ("seed", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl",
              "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz")
