"""Single-body global relations (docs/design.md §2): one body pressed by a rigid surface of radius ρ.

With x = a/ρ (all quantities are functions of a and ρ only through x, except the
finite-size ratio when it is a/R):

    ε_rep = β x (1 + γ x),  σ_rep = σ_f(ε_rep),  Λ = E' x/σ_rep   (seed eqs. 2–4; γ below)

(with a strain spread W > 0, σ_rep averages σ_f over strains about ε_rep:
:func:`representative_stress`)
    p_m = H̄(Λ) σ_rep  (Level I: p_m = 4E'x/(3π), Hertz)          (seed eq. 1)
    h = a²/(2c²ρ) = a x/(2c²),   F = π a² p_m                   (seed eq. 5)

The seed's ε_rep = β x holds while the contact is shallow; γ = ``beta_growth`` (0: the
seed's form) lets it grow faster once the contact is deep, where the body's mean strain
follows h/ρ ∝ x² (flattening, then whole-body compression). On campaign v2 the fit of H̄ over
82 single-body runs went from 3.05 % RMS (max 28.8 %) with γ = 0 to 2.49 % (max 14.4 %) with
γ = 4–6 (β then 0.10–0.08).

Log slopes used by the two-body solver and for dF/dh (m = d ln σ_rep/d ln x = m_f g, with
m_f = d ln σ_f/d ln ε at ε_rep and g = d ln ε_rep/d ln x = (1 + 2γx)/(1 + γx)):

    ∂ln p_m/∂ln x = (d ln H̄/d ln Λ)(1 − m) + m,   ∂ln c²/∂ln x = (d ln c²/d ln Λ)(1 − m),

where H̄ and c² include the finite-size factor f(y, Λ) (its Λ-dependence through the
level weight enters d/d ln Λ; y is the finite-size ratio).

With a collapse block (``levels.collapse_blend``; y = finite-size ratio, n = effective
exponent: one per material, or read along the curve at ε_rep, :func:`local_exponent`, whose
slope dn/d ln x then enters every slope below through the n-terms), the half-space
p_hs = H̄_hs σ_rep and c²_hs are blended with the whole-body limits:
ln r = ln p_hs − ln σ_rep − ln H̄_c(y, n, z), w = r^k/(1 + r^k),
w_c = (r e^s)^(k_c)/(1 + (r e^s)^(k_c)) (s constant), p_m = p_hs (1 + r^k)^(−1/k),
c² = c²_hs^(1−w_c) c²_c(y, n, z)^(w_c), and

    ∂ln p_m = (1 − w) ∂ln p_hs + w (∂ln σ_rep + ∂ln H̄_c),
    ∂ln c²  = (1 − w_c) ∂ln c²_hs + w_c ∂ln c²_c + (ln c²_c − ln c²_hs) k_c w_c (1 − w_c) ∂ln r.

z is the curvature ratio R/ρ_c − 1 of the body with ρ_c the radius of the surface that
presses it, a constant of the pair (:func:`curvature_ratio`; ``unified.harder_partner_weight``):
0 for equal spheres (flat interface), R/R_i against a rigid sphere of radius R_i. Being constant it leaves
p_m(x) monotone in 1/ρ, so the κ solve keeps a single root.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .coefficients import Coefficients, default_coefficients, exp_poly_log_and_slope
from .flow.averages import ludwik_representative_stress, spread_average, spread_factors
from .levels import (
    blend_from_logs,
    blend_pressure,
    collapse_blend,
    collapse_pressure,
    counter_surface,
    finite_size_blend,
    finite_size_terms,
    level_t,
    level_weight,
    levels_scalar_n,
    levels_with_n_slopes,
    onset_Lambda_u,
    onset_stage,
    stage,
)
from .material import Material

__all__ = [
    "representative_strain",
    "representative_stress",
    "ludwik_representative_stress",
    "spread_factors",
    "curvature_ratio",
    "flow_log_slope",
    "spread_average",
    "effective_exponent",
    "local_exponent",
    "capped_exponent",
    "hardening_magnitude",
    "BodyResponse",
    "FixedTerms",
    "BodyLaw",
    "IndentState",
    "indent",
]

_HERTZ = 4.0 / (3.0 * math.pi)


def flow_log_slope(material: Material, eps) -> np.ndarray:
    """m = d ln σ_f / d ln ε_p = ε σ_f'(ε)/σ_f(ε), vectorised (0 at ε = 0 and for elastic bodies;
    ``FlowCurve.log_slope``)."""
    if material.is_elastic:
        return np.zeros_like(np.asarray(eps, dtype=float))
    return material.flow.log_slope(eps)


def representative_strain(x, beta: float, growth: float = 0.0):
    """ε_rep = β x (1 + γ x) and its log slope g = d ln ε_rep/d ln x = (1 + 2γx)/(1 + γx)
    (vectorised; x = a/ρ, β = ``beta``, γ = ``growth``: a coefficient set's ``beta`` and
    ``beta_growth``)."""
    x = np.asarray(x, dtype=float)
    gx = growth * x
    g1 = 1.0 + gx
    return beta * x * g1, (1.0 + 2.0 * gx) / g1


def representative_stress(material: Material, eps, spread: float = 0.0):
    """σ_rep and m = d ln σ_rep/d ln ε_rep at ε_rep (vectorised): the flow curve averaged over a
    log-normal distribution of strains of log-width W = ``spread`` about ε_rep,

        σ_rep = Σ_j w_j σ_f(ε_rep e^(W t_j))   (three-point Gauss–Hermite: ⅔, ⅙, ⅙ at t = 0, ±√3),

    the strains of the plastic zone spreading from its elastic boundary to several ε_rep under
    the contact. For a power law σ_f = K εⁿ it is σ_f(ε_rep) times a constant (absorbed by H̄);
    for a curve with a yield plateau, a saturating or a linear one it weighs the strains
    around ε_rep. W = 0: σ_f(ε_rep) and :func:`flow_log_slope`, bit for bit."""
    if material.is_elastic:
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        return sum(w * material.flow_stress(f * e) for f, w in spread_factors(spread)), np.zeros_like(e)
    return material.flow.representative(eps, spread)


def curvature_ratio(radius, rho_hertz):
    """z = R/ρ_H − 1 of a body of radius R whose Hertz relative radius is ρ_H (vectorised).

    ρ_H = E'_i R*/E* (docs/design.md §3): 0 for equal spheres, R/R_i against a rigid sphere of
    radius R_i; 0 for a flat body (R = inf, no collapse).
    """
    R = np.asarray(radius, dtype=float)
    with np.errstate(invalid="ignore"):
        z = np.where(np.isinf(R), 0.0, R / np.asarray(rho_hertz, dtype=float) - 1.0)
    return float(z) if z.ndim == 0 else z


def effective_exponent(material: Material, coeffs: Coefficients) -> float:
    """Effective power-law hardening exponent n used in H̄_III(n), c²_III(n).

    ``secant_loglog``: n = ln(σ_f(ε_hi)/σ_f(ε_lo)) / ln(ε_hi/ε_lo) — exact for
    σ_f = K ε^n, 0 for perfect plasticity; one value per material, so Level III
    stays self-similar (Biwa & Storåkers 1995) and F(h) stays smooth. σ_f is the averaged
    curve the representative stress reads (:func:`representative_stress`).
    """
    if material.is_elastic:
        return 0.0
    return material.flow.secant_exponent(coeffs.eps_lo, coeffs.eps_hi, coeffs.strain_spread)


def local_exponent(material: Material, eps, coeffs: Coefficients):
    """Hardening exponent read along the flow curve (``local_secant``) and d n/d ln ε at ε_rep
    = ``eps`` (vectorised): the secant n₀ = ln(σ_rep(Kε)/σ_rep(ε/K))/ln K² of the averaged curve
    (:func:`representative_stress`), capped softly, n = n₀/(1 + (n₀/c)⁴)^¼ (K =
    ``coeffs.exponent_window``, c = ``coeffs.exponent_cap``); dn/dn₀ = (1 + (n₀/c)⁴)^(−5/4).
    Exact for σ_f = K εⁿ below the cap. Without the cap linear hardening reads n → 1 at large
    strain, where c²_III(n) falls, and F(h) turned non-monotone (d ln h/d ln a down to −0.35)."""
    eps = np.asarray(eps, dtype=float)
    if material.is_rigid or math.isinf(material.sigma_y):
        zero = np.zeros_like(eps)
        return zero, zero
    return _stress_and_local_exponent(material, eps, coeffs)[2:]


def _stress_and_local_exponent(material: Material, eps, coeffs: Coefficients):
    """σ_rep, d ln σ_rep/d ln ε (:func:`representative_stress`), n and dn/d ln ε
    (:func:`local_exponent`) at ε_rep = ``eps`` from one evaluation of the averaged curve."""
    eps = np.asarray(eps, dtype=float)
    K, e = coeffs.exponent_window, eps.ravel()
    sig, m = representative_stress(material, np.concatenate([e, e / K, e * K]), coeffs.strain_spread)
    k, span = e.size, 2.0 * math.log(K)
    n, dn_dn0 = capped_exponent(np.log(sig[2 * k:] / sig[k:2 * k]) / span, coeffs.exponent_cap)
    shape = eps.shape
    return (sig[:k].reshape(shape), m[:k].reshape(shape), n.reshape(shape),
            (dn_dn0 * (m[2 * k:] - m[k:2 * k]) / span).reshape(shape))


def capped_exponent(n0, cap: float):
    """n = n₀/(1 + (n₀/c)⁴)^¼ and dn/dn₀ = (1 + (n₀/c)⁴)^(−5/4), c = ``cap``
    (:func:`local_exponent`)."""
    q = 1.0 + (np.asarray(n0, dtype=float) / cap) ** 4
    return n0 * q ** -0.25, q ** -1.25


def hardening_magnitude(material: Material, coeffs: Coefficients) -> float:
    """Hardening magnitude K/σ_Y of a flow curve (the calibrated-range axis next to n).

    Ludwik σ_Y + K εⁿ: K/σ_Y (0 for perfect plasticity or an elastic body). Flow table: the
    Ludwik curve through σ_f at ε = 0, ε_lo and ε_hi (``hardening_exponent`` strains),
    Δσ = σ_f(ε) − σ_f(0): n_L = ln(Δσ(ε_hi)/Δσ(ε_lo))/ln(ε_hi/ε_lo) clipped to [0, 1],
    K = Δσ(ε_hi)/ε_hi^n_L — exact for a tabulated Ludwik curve.
    """
    if material.is_elastic:
        return 0.0
    return material.flow.hardening_magnitude(coeffs.eps_lo, coeffs.eps_hi)


def _segment(material: Material, eps, spread: float = 0.0, window: float = 0.0) -> np.ndarray:
    """Index of the flow-curve piece containing ε (0 for Ludwik curves); with a strain spread,
    one index for the pieces of all the strains σ_rep reads (:func:`representative_stress`); with
    a ``window`` K > 0 (the exponent read along the curve, :func:`local_exponent`) the pieces of
    the strains ε/K and Kε it reads as well, added as a sum: every index grows with ε, so the sum
    changes wherever one of them does and never comes back to a value."""
    flow, eps = material.flow, np.asarray(eps)
    idx = np.zeros(np.shape(eps), dtype=np.int64)
    factors = spread_factors(spread)
    for f, _ in factors:
        idx = idx * flow.segments + flow.segment(f * eps)
    if window > 0.0:
        moved = sum(flow.segment(f * g * eps) for f, _ in factors for g in (1.0 / window, window))
        idx = idx + flow.segments ** len(factors) * moved
    return idx


class BodyResponse(NamedTuple):
    """Response of one body at x = a/ρ (and finite-size ratio y); arrays."""

    p_m: np.ndarray        # mean contact pressure
    c2: np.ndarray         # contact-area parameter c²
    Lambda: np.ndarray     # Johnson's parameter Λ
    sigma_rep: np.ndarray  # representative stress
    dlnp_dlnx: np.ndarray  # ∂ln p_m/∂ln x
    dlnp_dlny: np.ndarray  # ∂ln p_m/∂ln y (finite-size factor)
    dlnc2_dlnx: np.ndarray
    dlnc2_dlny: np.ndarray
    piece: np.ndarray      # smooth-piece id (level, flow-table segment, continuation); kinks where it changes


class FixedTerms(NamedTuple):
    """The terms of :meth:`BodyLaw.response` that move with the finite-size ratio y and the
    counter-surface ratio xc alone (both are a over a constant of the pair): a κ solve moves
    x = a/ρ at fixed a (``unified.py``) and reads them at every iterate. Each field is a tuple of
    arrays shaped like y, or None (a term the coefficient set lacks, or the c² terms of a
    pressure-only response)."""

    fs_H: tuple | None         # finite-size factors of H̄ at y (``levels.finite_size_terms``)
    fs_c2: tuple | None
    counter_H: tuple | None    # exp(q_H s(u)) and its two d/d ln y terms (u = xc − y)
    counter_c2: tuple | None
    collapse_H: tuple | None   # y-terms of the collapse limit H̄_c (``CollapseLimitAtZ.x_terms``)
    collapse_c2: tuple | None

    def take(self, idx, with_c2: bool = True) -> FixedTerms:
        """The terms at the points ``idx`` (without those of c² unless ``with_c2``)."""
        return FixedTerms(*(None if f is None or (name.endswith("c2") and not with_c2) else
                            tuple(v[idx] for v in f) for name, f in zip(self._fields, self, strict=True)))


@dataclass(frozen=True)
class BodyLaw:
    """Single-body law p_m(x), c²(x) of one deformable material (docs/design.md §2)."""

    material: Material
    coeffs: Coefficients
    n_eff: float = field(init=False)
    H_bar_III: float = field(init=False)
    c2_III: float = field(init=False)
    x_fit_max: float = field(init=False)   # fitted terms continued beyond (``levels.py``)
    continued: bool = field(init=False)    # the set has x-dependent terms to continue

    def __post_init__(self) -> None:
        if self.material.is_rigid:
            raise ValueError("BodyLaw: a rigid body has no deformation law (E = inf)")
        n = effective_exponent(self.material, self.coeffs)
        object.__setattr__(self, "n_eff", n)
        object.__setattr__(self, "H_bar_III", float(self.coeffs.H_bar_III(n)))
        object.__setattr__(self, "c2_III", float(self.coeffs.c2_III(n)))
        object.__setattr__(self, "x_fit_max", self.coeffs.x_fit_max)
        object.__setattr__(self, "continued", self.coeffs.has_finite_size)

    @property
    def E_prime(self) -> float:
        return self.material.E_prime

    def level_state_at(self, x) -> tuple[np.ndarray, np.ndarray]:
        """The first two of :meth:`plastic_state_at`, s and ds/d ln x, without the pressure."""
        mat, co = self.material, self.coeffs
        x = np.asarray(x, dtype=float)
        if math.isinf(mat.sigma_y):
            zero = np.zeros_like(x)
            return zero, zero
        eps, g = representative_strain(x, co.beta, co.beta_growth)
        sig, m = representative_stress(mat, eps, co.strain_spread)
        s, ds = level_weight(mat.E_prime * x / sig, co)
        return s, ds * (1.0 - m * g)

    def plastic_state_at(self, x) -> tuple[np.ndarray, ...]:
        """At x = a/ρ (vectorised): the level weight s(Λ) = 3t² − 2t³ (0 in Level I, 1 in
        Level III; ``levels.level_weight``), ds/d ln x = (ds/d ln Λ)(1 − m), the fully plastic
        pressure P = H̄_III σ_rep and d ln P/d ln x = m (m = d ln σ_rep/d ln x). An elastic
        body: s = 0 and P = inf."""
        mat, co = self.material, self.coeffs
        x = np.asarray(x, dtype=float)
        if math.isinf(mat.sigma_y):
            zero = np.zeros_like(x)
            return zero, zero, np.full_like(x, math.inf), zero
        eps, g = representative_strain(x, co.beta, co.beta_growth)
        if not co.exponent_local:
            sig, m = representative_stress(mat, eps, co.strain_spread)
            m = m * g
            s, ds = level_weight(mat.E_prime * x / sig, co)
            return s, ds * (1.0 - m), self.H_bar_III * sig, m
        sig, m, n, dn = _stress_and_local_exponent(mat, eps, co)
        m = m * g
        s, ds = level_weight(mat.E_prime * x / sig, co)
        lnH3, dlnH3 = exp_poly_log_and_slope(co.H_bar_III_exp_poly, n)
        return s, ds * (1.0 - m), co.H_bar_III_prefactor * np.exp(lnH3) * sig, m + dlnH3 * dn * g

    def _piece(self, Lam, eps, y, x) -> np.ndarray:
        """Smooth-piece id from the level of Λ (``levels.stage``), the stage of the unloading
        onset ramp (``levels.onset_stage`` of Λ_u, x = a/ρ), ε_rep (flow-table segment) and y
        (beyond x_fit_max)."""
        mat, co = self.material, self.coeffs
        piece = (stage(Lam, co) + 3 * onset_stage(self.onset_Lambda(x, Lam), co)
                 + 9 * _segment(mat, eps, co.strain_spread, co.exponent_window))
        if self.continued:  # the fitted terms are continued beyond x_fit_max: C¹, not C²
            piece = 2 * piece + (y > self.x_fit_max)
        return piece

    def onset_Lambda(self, x, Lam) -> np.ndarray:
        """Λ_u at x = a/ρ from Johnson's Λ there (``levels.onset_Lambda_u``, Λ_Y = E'x/σ_Y): what
        the unloading onset ramp reads (0 for an elastic body)."""
        mat = self.material
        return onset_Lambda_u(Lam, mat.E_prime * np.asarray(x, dtype=float) / mat.sigma_y)

    def piece_at(self, x, y=None) -> np.ndarray:
        """The smooth-piece id of :meth:`response` at x = a/ρ (finite-size ratio y, default x)
        without the rest of the response: the level of Λ = E'x/σ_rep (Λ = 0 for an elastic body),
        the stage of the unloading onset ramp, the flow-table segment of ε_rep and whether y lies
        beyond x_fit_max."""
        mat, co = self.material, self.coeffs
        x = np.asarray(x, dtype=float)
        y = x if y is None else np.asarray(y, dtype=float)
        eps, _ = representative_strain(x, co.beta, co.beta_growth)
        if math.isinf(mat.sigma_y):
            Lam = np.zeros_like(x)
        else:
            Lam = mat.E_prime * x / representative_stress(mat, eps, co.strain_spread)[0]
        return self._piece(Lam, eps, y, x)

    def fixed_terms(self, y, z: float = 0.0, xc=None, level_c=None, with_c2: bool = True) -> FixedTerms:
        """The terms of :meth:`response` that do not move with x at finite-size ratio y, curvature
        ratio z and counter-surface ratio xc (:class:`FixedTerms`; the counter-surface terms only
        with xc, else they read x); ``level_c``: the level weight and its slope at xc if at hand;
        ``with_c2`` False: the c² terms are None."""
        co, xm = self.coeffs, self.x_fit_max
        y = np.asarray(y, dtype=float)
        fs_H = finite_size_terms(y, co.finite_size_H_bar, co.fs_H_bar_plastic, xm)
        fs_c2 = finite_size_terms(y, co.finite_size_c2, co.fs_c2_plastic, xm) if with_c2 else None
        counter = (None, None)
        if co.has_counter_surface and xc is not None:
            xc = np.asarray(xc, dtype=float)
            su, su_x, su_y = counter_surface(xc, y)
            s_c, ds_c = self.level_state_at(xc) if level_c is None else level_c
            # exp(q s(u)) and its d/d ln y, q s_y + (dq/ds) s(u) ds_c/d ln a (q(s_c), z: the pair's)
            counter = tuple((np.exp(q * su), q * (su_x + su_y), dq * su * ds_c)
                            for q, dq in co.counter_by_level(s_c, z))
        collapse = (None, None)
        if co.has_collapse and co.exponent_local and not math.isinf(self.material.sigma_y):
            lim_H, lim_c = self._collapse_limits(z)
            collapse = (lim_H.x_terms(y, xm), lim_c.x_terms(y, xm) if with_c2 else None)
        return FixedTerms(fs_H, fs_c2, counter[0], counter[1] if with_c2 else None, *collapse)

    def _collapse_limits(self, z):
        """The collapse limits of H̄ and c² at curvature ratio z with n free (``CollapseLimit.at_z``)."""
        co = self.coeffs
        zv, zm = float(co.collapse_z(z)), float(co.collapse_z(co.z_fit_max))
        return co.collapse_H_bar.at_z(zv, zm), co.collapse_c2.at_z(zv, zm)

    def response(self, x, y=None, z: float = 0.0, xc=None, pressure_only: bool = False,
                 level_c=None, fixed: FixedTerms | None = None) -> BodyResponse:
        """Evaluate at x = a/ρ; ``y`` is the finite-size ratio (defaults to x, i.e. a/ρ);
        ``z`` the curvature ratio of the collapse limits (a constant of the pair,
        :func:`curvature_ratio`); ``xc`` the contact radius over the body's Hertz relative
        radius ρ_H (a constant of the pair times a) for the counter-surface terms, u = xc − y
        (default x: against a rigid surface ρ = ρ_H). Given ``xc``, those terms depend on a
        alone, not on the partition: their slopes go to the y slot, so that they leave the
        two-body κ equation monotone in u (``unified.py``; with u = x − y the pressure term's
        negative slope in x made the κ equation lose its single root for some plastic pairs).
        With the c² term alone on u = x − y the pair grid's monotonicity check fails. The level
        weight that moves the terms' coefficients (``counter_by_level``) is read at xc as well, for
        the same reason: read at x it left 27 of 300 random plastic pairs without a consistent root
        from h/R ≈ 0.32 on. ``pressure_only``: p_m and its slopes alone (what the κ solve reads;
        c², its slopes and the piece are None), without the c² terms' cost. ``level_c``: the
        level weight and its slope at ``xc`` (:meth:`level_state_at`) when the caller has them;
        ``fixed``: the terms that do not move with x (:meth:`fixed_terms` at y, z, xc, with c² unless
        ``pressure_only``) when the caller has them (a κ solve reads them at every iterate)."""
        mat, co = self.material, self.coeffs
        x = np.asarray(x, dtype=float)
        y = x if y is None else np.asarray(y, dtype=float)
        Ep = mat.E_prime
        eps, g = representative_strain(x, co.beta, co.beta_growth)
        if math.isinf(mat.sigma_y):  # elastic: always Level I
            sig = np.full_like(x, math.inf)
            Lam = np.zeros_like(x)
            m = np.zeros_like(x)
        elif co.exponent_local:  # σ_rep at ε_rep, ε_rep/K and K ε_rep in one evaluation
            sig, m, n, n_x = _stress_and_local_exponent(mat, eps, co)
            Lam = Ep * x / sig
            m, n_x = m * g, n_x * g  # d ln σ_rep/d ln x, dn/d ln x
        else:
            sig, m = representative_stress(mat, eps, co.strain_spread)
            Lam = Ep * x / sig
            m = m * g  # d ln σ_rep/d ln x
        with_c2 = not pressure_only
        t = level_t(Lam, co)
        local = co.exponent_local and not math.isinf(mat.sigma_y)
        if local:  # n(x) along the curve: its slope n_x = dn/d ln x enters every n-term
            H, sH, H_n, c, sc, c_n, lev = levels_with_n_slopes(Lam, co, n, t, with_c2)
        else:
            n = self.n_eff
            H, sH, c, sc, lev = levels_scalar_n(Lam, co, self.H_bar_III, self.c2_III, n, t, with_c2)
        with np.errstate(invalid="ignore"):
            p = np.where(lev == 1, _HERTZ * Ep * x, H * sig)
        s_l, ds_l = level_weight(Lam, co, t)
        if fixed is None:
            fixed = self.fixed_terms(y, z, xc, level_c, with_c2)
        fH, dfH, lfH = finite_size_blend(fixed.fs_H, s_l, ds_l)
        p = p * fH
        dp_x, dp_y = (sH + lfH) * (1.0 - m) + m, dfH
        if local:
            dp_x = dp_x + H_n * n_x
        piece = dc_x = dc_y = None
        if with_c2:
            fc, dfc, lfc = finite_size_blend(fixed.fs_c2, s_l, ds_l)
            piece = self._piece(Lam, eps, y, x)
            c = c * fc
            dc_x, dc_y = (sc + lfc) * (1.0 - m), dfc
            if local:
                dc_x = dc_x + c_n * n_x
        if co.has_counter_surface and xc is None:  # exp(q s(u)), u = x − y (``levels.counter_surface``)
            su, su_x, su_y = counter_surface(x, y)
            lev_x = ds_l * (1.0 - m)  # the level weight's d/d ln x (its d/d ln y is 0)
            (qH, dqH), (qc, dqc) = co.counter_by_level(s_l, z)  # q(s), dq/ds (z: a constant of the pair)
            p = p * np.exp(qH * su)
            dp_x, dp_y = dp_x + qH * su_x + dqH * su * lev_x, dp_y + qH * su_y
            if with_c2:
                c = c * np.exp(qc * su)
                dc_x, dc_y = dc_x + qc * su_x + dqc * su * lev_x, dc_y + qc * su_y
        elif co.has_counter_surface:  # u = xc − y moves with a only: its terms are fixed (x slopes 0)
            factor, dy_su, dy_level = fixed.counter_H
            p = p * factor
            dp_y = dp_y + dy_su + dy_level
            if with_c2:
                factor, dy_su, dy_level = fixed.counter_c2
                c = c * factor
                dc_y = dc_y + dy_su + dy_level
        if co.has_collapse and local:
            return self._collapse_local(p, sig, m, c, n, n_x, z, Lam, piece,
                                        (dp_x, dp_y), (dc_x, dc_y), fixed)
        if co.has_collapse and not math.isinf(mat.sigma_y):
            if not with_c2:
                Hb, w, dlnHc = collapse_pressure(p / sig, y, co, self.n_eff, z)
                return BodyResponse(p_m=Hb * sig, c2=None, Lambda=Lam, sigma_rep=sig,
                                    dlnp_dlnx=(1.0 - w) * dp_x + w * m,
                                    dlnp_dlny=(1.0 - w) * dp_y + w * dlnHc,
                                    dlnc2_dlnx=None, dlnc2_dlny=None, piece=None)
            b = collapse_blend(p / sig, c, y, co, self.n_eff, z)
            w, wc = b.w, b.w_c2
            v = co.c2_sharpness * wc * (1.0 - wc) * b.lnc2_gap
            dr_x, dr_y = dp_x - m, dp_y - b.dlnHc_dlnx  # ∂ln r
            p = b.H_bar * sig
            dp_x, dp_y = (1.0 - w) * dp_x + w * m, (1.0 - w) * dp_y + w * b.dlnHc_dlnx
            dc_x = (1.0 - wc) * dc_x + v * dr_x
            dc_y = (1.0 - wc) * dc_y + wc * b.dlnc2c_dlnx + v * dr_y
            c = b.c2
        return BodyResponse(
            p_m=p, c2=c, Lambda=Lam, sigma_rep=sig,
            dlnp_dlnx=dp_x, dlnp_dlny=dp_y,
            dlnc2_dlnx=dc_x, dlnc2_dlny=dc_y, piece=piece,
        )

    def _collapse_local(self, p, sig, m, c, n, n_x, z, Lam, piece, dp, dc, fixed) -> BodyResponse:
        """The collapse blend of :meth:`response` with n read along the curve: the limits'
        n-terms move with x, ∂ln H̄_c/∂ln x += (∂ln H̄_c/∂n) n_x (likewise c²_c), in the x slot
        (``levels.collapse_blend``'s equations; the limits at the pair's z, ``CollapseLimit.at_z``,
        their y-terms from ``fixed``)."""
        co = self.coeffs
        lim_H, lim_c = self._collapse_limits(z)
        lnHc, sHc, Hc_n = lim_H.with_n(fixed.collapse_H, n)
        (dp_x, dp_y), (dc_x, dc_y) = dp, dc
        if c is None:  # pressure only: the H̄ half of the blend (``levels.collapse_pressure``)
            Hb, w, _ = blend_pressure(p / sig, lnHc, co.collapse_sharpness)
            return BodyResponse(p_m=Hb * sig, c2=None, Lambda=Lam, sigma_rep=sig,
                                dlnp_dlnx=(1.0 - w) * dp_x + w * (m + Hc_n * n_x),
                                dlnp_dlny=(1.0 - w) * dp_y + w * sHc,
                                dlnc2_dlnx=None, dlnc2_dlny=None, piece=None)
        lncc, scc, cc_n = lim_c.with_n(fixed.collapse_c2, n)
        Hb, c2, w, gap, wc = blend_from_logs(p / sig, c, lnHc, lncc, co.collapse_sharpness,
                                             co.collapse_sharpness_c2, co.collapse_offset_c2)
        dr_x, dr_y = dp_x - m - Hc_n * n_x, dp_y - sHc  # ∂ln r
        v = co.c2_sharpness * wc * (1.0 - wc) * gap
        return BodyResponse(
            p_m=Hb * sig, c2=c2, Lambda=Lam, sigma_rep=sig,
            dlnp_dlnx=(1.0 - w) * dp_x + w * (m + Hc_n * n_x), dlnp_dlny=(1.0 - w) * dp_y + w * sHc,
            dlnc2_dlnx=(1.0 - wc) * dc_x + wc * cc_n * n_x + v * dr_x,
            dlnc2_dlny=(1.0 - wc) * dc_y + wc * scc + v * dr_y, piece=piece)


class IndentState(NamedTuple):
    """Single body against a rigid surface of relative radius ρ."""

    a: np.ndarray
    p_m: np.ndarray
    F: np.ndarray
    h: np.ndarray
    Lambda: np.ndarray
    H_bar: np.ndarray
    c2: np.ndarray
    stiffness: np.ndarray  # dF/dh


def indent(material: Material, a, rho: float, radius: float | None = None,
           coeffs: Coefficients | None = None) -> IndentState:
    """Single-body relations given the contact radius a (vectorised).

    Parameters
    ----------
    material : deformable material.
    a : contact radius (array), > 0.
    rho : relative radius ρ of the rigid surface seen by the body.
    radius : body radius R (for the finite-size ratio a/R and the curvature ratio R/ρ − 1 of
        the collapse limits); defaults to ρ.
    coeffs : coefficient set; default :func:`default_coefficients`.

    Returns
    -------
    IndentState with p_m = H̄ σ_rep, h = a²/(2c²ρ), F = πa²p_m and dF/dh.
    """
    co = default_coefficients() if coeffs is None else coeffs
    a = np.asarray(a, dtype=float)
    law = BodyLaw(material, co)
    x = a / rho
    R = rho if radius is None else radius
    y = x if co.finite_size_ratio == "a_over_rho" else a / R
    r = law.response(x, y, curvature_ratio(R, rho))
    F = math.pi * a**2 * r.p_m
    h = a * x / (2.0 * r.c2)
    dlnF = 2.0 + r.dlnp_dlnx + r.dlnp_dlny
    dlnh = 2.0 - r.dlnc2_dlnx - r.dlnc2_dlny
    with np.errstate(invalid="ignore", divide="ignore"):
        H = np.where(np.isfinite(r.sigma_rep), r.p_m / r.sigma_rep, np.nan)
        k = F * dlnF / (h * dlnh)
    return IndentState(a=a, p_m=r.p_m, F=F, h=h, Lambda=r.Lambda, H_bar=H, c2=r.c2, stiffness=k)
