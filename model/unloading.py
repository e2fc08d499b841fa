"""Unloading and reloading below the largest approach reached: the elastic branch.

Below the largest approach h_max reached, two elastic–plastic spheres unload and reload
elastically along one branch (the FE's reloading retraces its unloading to 0.01 % of F_max)
from the peak state (h_max, F_max, a_max) down to the residual approach h_res, where the
force vanishes; beyond h_max they follow the loading curve again. With ξ = (h − h_res)/δ_e,
δ_e = h_max − h_res the elastic recovery,

    F = F_max ξ^m,   dF/dh = m F/(ξ δ_e),   a = a_max ξ^(m−1)

(a from Sneddon's dF/dh = 2E*a along the branch). Thornton (1997) takes Hertz from the
peak state: m = 3/2 and δ_e = 3F_max/(4E* a_max) — the default coefficients. The FE
cycles of campaign v2 show where that is off: the unloading stiffness S = m F_max/δ_e
reaches 2.0–2.2 × 2E*a_max at h/R = 0.3 (a flattened sphere is a squat body, stiffer than a
half-space), and m falls from 3/2 (an elastic peak) to 1.2–1.45 (a plastic one: a flattened,
more conforming residual profile). The law here (``UnloadingCoefficients``):

* each deformable body i has the compliance C_i = c_i/(2a g_i P), c_i = (1 − ν_i²)/E_i,
  g_i = 1 + [g_a (a/R_i)² + g_h · 2h_i/R_i][1 + g_ν (ν_i − 0.3)](1 − g_U U) (its contact radius
  and its own approach at the peak over its radius; the stiffening of a squat body falls with ν,
  and with the curvature of the contact surface: a body dented by a rigid sphere of its own
  size is not flattened like one pressed by a flat — without g_U the FE's deep rigid-sphere
  peaks, a/R* ≈ 0.9, unload up to 15 % softer than the law), P = (c²)^q with
  q = s_c (1 − w) + s_U U + s_z z̄ + s_2 ln c² (a plastic peak with pile-up, c² > 1, unloads
  stiffer than one that sinks in; less so under a curved counter-surface, when deep, or with
  much pile-up: ``UnloadingCoefficients.stiffness_c2_counter``, ``_depth``, ``_c2``);
  δ_e = m₀ F_max C/s₀ with C = Σ C_i;
* m = m₀ + (1 − w) m_Uz U z̄², m₀ = (1 − w)[(1 − U)(m_p + m_c2 ln c² + m_depth z̄ + m_λ λ)
  + U m_counter] + w (3/2 + m_el ȳ²), each clipped to [1, 3], with the elastic weight
  w = min(λ, 1)^k, λ = p_m/p_Hertz(a) = 3πR* p_m/(4E*a) (1 at an elastic peak, → 0 as the pressure
  flattens), c² = a²/(2R*h) of the peak, U = u/(1 + u), u = a|κ| the curvature of the contact
  surface (0 on a flat and between equal spheres, a/R_i against a rigid sphere), and ȳ, z̄ the
  compliance-weighted a/R_i and 2h_i/R_i. m_counter ≈ 1.1: the dent a small rigid sphere
  leaves conforms to it and reloads almost like a flat punch (m → 1); m_λ: the exponent rises
  with λ from the flat-punch-like uniform pressure (λ → 0) towards Hertz; m_Uz < 0: a deep
  dent under a curved counter-surface unloads flatter (towards a punch, m → 1) at the same
  elastic recovery δ_e, so the term is left out of δ_e (``m_counter_depth``; FE peak of a
  perfectly plastic sphere under a rigid sphere of its own radius at h/R 0.3: the best power
  law at the law's δ_e has m 1.07, the law without the term 1.21, 3.5 % of F_max off
  mid-branch);
* h_res = r · max(h_max − δ_e, 0), r the onset ramp of the body further into plasticity
  (``levels.onset_ramp``: 0 in Level I, 1 once its level weight reaches ``levels.ONSET`` = 10⁻³,
  linear in ln Λ between) read at Λ_u = E'a/(ρ √(σ_Y σ_rep)), Johnson's parameter with the
  geometric mean of the yield stress and the representative stress (``levels.onset_Lambda_u``): an
  elastic peak leaves no residual approach. Such a peak unloads
  along the loading curve itself (no hysteresis; ``Peak.plastic`` False);
* each body's residual approach (its share of the residual dent): h_res,i ∝ max(h_i −
  δ_e C_i/C, 0), scaled so that they add up to h_res.

Derived: the work returned by unloading F_max δ_e/(m + 1), the dissipated work and the
coefficient of restitution of a quasi-static impact (``cycle.py``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .coefficients import UnloadingCoefficients
from .levels import onset_ramp
from .unified import UnifiedPair, UnifiedState

__all__ = ["EXPONENT_RANGE", "Peak", "PeakFeatures", "features", "peak_features",
           "unloading_law", "peak_parameters", "branch", "work_returned"]

# ``levels.ONSET``: the level weight at which the residual approach has grown from 0 (Level I)
# to the law's value (FE cycles at weights 1e-4 / 1e-3 / 4e-3 left 0 / 4 / 3 % of h_max;
# ONSET = 1e-2 raised the validation branches above 3 % from 8 to 12)
#: the unloading exponent is kept in this range (F stays increasing and C¹ at h_res)
EXPONENT_RANGE = (1.0, 3.0)


class Peak(NamedTuple):
    """Unloading parameters at the largest approach reached (arrays of one shape)."""

    h_max: np.ndarray
    F_max: np.ndarray
    a_max: np.ndarray
    m: np.ndarray        # exponent of F = F_max ξ^m
    delta_e: np.ndarray  # elastic recovery h_max − h_res
    h_res: np.ndarray    # residual approach (F = 0 at and below it)
    h1_max: np.ndarray   # approaches of each body at the peak
    h2_max: np.ndarray
    h1_res: np.ndarray   # residual approach of each body (its share of the residual dent)
    h2_res: np.ndarray
    plastic: np.ndarray  # bool: the peak left the elastic Level I (False: no hysteresis)


class PeakFeatures(NamedTuple):
    """What the law reads from a loaded state (n peaks; body columns 0, 1; a rigid body has
    compliance 0). Built by :func:`peak_features` from the model, by calibration from the FE."""

    h: np.ndarray           # (n,) approach at the peak
    F: np.ndarray           # (n,) force
    a: np.ndarray           # (n,) contact radius
    h_i: np.ndarray         # (n, 2) each body's approach
    compliance: np.ndarray  # (n, 2) c_i = 1/E'_i
    nu: np.ndarray          # (n, 2) Poisson's ratio ν_i (any value for a rigid body)
    y: np.ndarray           # (n, 2) a/R_i (0 for a flat)
    z: np.ndarray           # (n, 2) 2h_i/R_i
    lam: np.ndarray         # (n,) λ = 3πR* p_m/(4E* a), at most 1
    U: np.ndarray           # (n,) u/(1 + u), u = a|κ|
    log_c2: np.ndarray      # (n,) ln(a²/(2R* h))
    onset: np.ndarray       # (n,) onset ramp r of the body further into Level II (``levels.onset_ramp``)


def features(h, F, a, h_i, compliance, nu, radius, kappa, R_star: float,
             onset) -> PeakFeatures:
    """:class:`PeakFeatures` from the peak values (arrays; ``h_i``, ``compliance``, ``nu``,
    ``radius`` with a last axis of 2, one column per body; radius inf for a flat)."""
    h, F, a = (np.asarray(v, dtype=float) for v in (h, F, a))
    h_i = np.asarray(h_i, dtype=float)
    c = np.broadcast_to(np.asarray(compliance, dtype=float), h_i.shape)
    R = np.broadcast_to(np.asarray(radius, dtype=float), h_i.shape)
    nu = np.broadcast_to(np.asarray(nu, dtype=float), h_i.shape)
    y = a[:, None] / R
    z = 2.0 * h_i / R
    p_m = F / (math.pi * a * a)
    lam = np.minimum(3.0 * math.pi * R_star * p_m * c.sum(axis=1) / (4.0 * a), 1.0)
    u = a * np.abs(np.asarray(kappa, dtype=float))
    return PeakFeatures(h=h, F=F, a=a, h_i=h_i, compliance=c, nu=nu, y=y, z=z, lam=lam, U=u / (1.0 + u),
                        log_c2=np.log(a * a / (2.0 * R_star * h)),
                        onset=np.asarray(onset, dtype=float))


def peak_features(p: UnifiedPair, st: UnifiedState) -> PeakFeatures:
    """:class:`PeakFeatures` of the model's loaded states ``st`` of the pair ``p``."""
    comp, nu, radius, s_max = [], [], [], np.zeros_like(st.a)
    for s, law, Lam, rho in ((p.s1, p.law1, st.Lambda1, st.rho1), (p.s2, p.law2, st.Lambda2, st.rho2)):
        comp.append(0.0 if s.is_rigid else 1.0 / s.material.E_prime)
        nu.append(s.material.nu)
        radius.append(s.radius)
        if not s.is_rigid and math.isfinite(s.material.sigma_y):
            s_max = np.maximum(s_max, onset_ramp(law.onset_Lambda(st.a / rho, Lam), p.coeffs))
    return features(st.h, st.F, st.a, np.stack([st.h1, st.h2], axis=1), comp, nu, radius, st.kappa,
                    p.R_star, s_max)


def unloading_law(f: PeakFeatures, co: UnloadingCoefficients):
    """The law of the module docstring: (m, δ_e, h_res, h_res,1) for the peaks ``f``."""
    c = f.compliance
    w = f.lam ** co.elastic_weight
    size = ((co.size_a * f.y**2 + co.size_h * f.z) * (1.0 + co.size_nu * (f.nu - 0.3))
            * (1.0 - co.size_counter * f.U[:, None]))
    y_bar = (c * f.y).sum(axis=1) / c.sum(axis=1)
    z_bar = (c * f.z).sum(axis=1) / c.sum(axis=1)
    q = (co.stiffness_c2 * (1.0 - w) + co.stiffness_c2_counter * f.U + co.stiffness_c2_depth * z_bar
         + co.stiffness_c2_c2 * f.log_c2)
    pile_up = np.exp(q * f.log_c2)  # P = (c²)^q
    Ci = c / (2.0 * f.a[:, None] * (1.0 + size) * pile_up[:, None])
    C = Ci.sum(axis=1)
    m_flat = co.m_plastic + co.m_c2 * f.log_c2 + co.m_depth * z_bar + co.m_lambda * f.lam
    m_p = (1.0 - f.U) * m_flat + f.U * co.m_counter
    m_0 = np.clip((1.0 - w) * m_p + w * (1.5 + co.m_elastic_size * y_bar**2), *EXPONENT_RANGE)
    delta = m_0 * f.F * C / co.stiffness
    m = np.clip(m_0 + (1.0 - w) * co.m_counter_depth * f.U * z_bar**2, *EXPONENT_RANGE)
    h_res = f.onset * np.maximum(f.h - delta, 0.0)
    delta_e = f.h - h_res
    share = np.where(c > 0.0, np.maximum(f.h_i - delta_e[:, None] * Ci / C[:, None], 0.0), 0.0)  # rigid: none
    total = share.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        h1_res = np.where(total > 0.0, h_res * (share[:, 0] / total), 0.0)  # exact for one share
    return m, delta_e, h_res, h1_res


def peak_parameters(p: UnifiedPair, st: UnifiedState, law: UnloadingCoefficients | None = None) -> Peak:
    """The unloading parameters of the loaded states ``st`` (the largest approaches reached)
    of the pair ``p`` (module docstring); ``law`` defaults to the pair's coefficients'."""
    f = peak_features(p, st)
    m, delta_e, h_res, h1_res = unloading_law(f, p.coeffs.unloading if law is None else law)
    return Peak(h_max=st.h, F_max=st.F, a_max=st.a, m=m, delta_e=delta_e, h_res=h_res,
                h1_max=st.h1, h2_max=st.h2, h1_res=h1_res, h2_res=h_res - h1_res,
                plastic=f.onset > 0.0)


class Branch(NamedTuple):
    F: np.ndarray
    stiffness: np.ndarray
    a: np.ndarray
    h1: np.ndarray
    h2: np.ndarray


def branch(h, pk: Peak) -> Branch:
    """F, dF/dh, a and each body's approach on the unloading branch of ``pk`` at approaches h
    (h ≤ h_max; below h_res: zeros)."""
    h = np.asarray(h, dtype=float)
    xi = np.clip((h - pk.h_res) / pk.delta_e, 0.0, 1.0)
    on = xi > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        xm1 = np.where(on, xi ** (pk.m - 1.0), 0.0)
    F = pk.F_max * xi * xm1
    k = pk.m * pk.F_max * xm1 / pk.delta_e
    a = pk.a_max * xm1
    h1 = np.where(on, pk.h1_res + xi * (pk.h1_max - pk.h1_res), 0.0)
    h2 = np.where(on, pk.h2_res + xi * (pk.h2_max - pk.h2_res), 0.0)
    return Branch(F=F, stiffness=k, a=a, h1=h1, h2=h2)


def work_returned(pk: Peak) -> np.ndarray:
    """Work returned by the unloading from h_max to h_res: ∫F dh = F_max δ_e/(m + 1)."""
    return pk.F_max * pk.delta_e / (pk.m + 1.0)
