"""Finite-strain J2 plasticity, axisymmetric: Hencky elasticity + exponential-map return.

Simo (1992, CMAME 99:61); de Souza Neto, Perić & Owen, *Computational Methods
for Plasticity* (2008), Box 14.3. Per quadrature point, with F = [[F_rr, F_rz],
[F_zr, F_zz]] ⊕ F_θθ and the stored plastic metric C_p⁻¹ (reference frame):

    b_e^tr = F C_p⁻¹ Fᵀ,        ε^tr = ½ ln b_e^tr                 (trial log strain)
    s^tr = 2μ dev ε^tr,          q^tr = √(3/2 s^tr : s^tr)
    f = q^tr − σ_f(ε_p,n) ≤ 0 elastic; else solve
        q^tr − 3μ Δγ − σ_f(ε_p,n + Δγ) = 0                          (radial return)
    s = (1 − 3μΔγ/q^tr) s^tr,    τ = K tr(ε^tr) I + s               (Kirchhoff stress)
    ε_e = ε^tr − Δγ (3/2) s^tr/q^tr,  b_e = exp(2 ε_e),  C_p⁻¹ = F⁻¹ b_e F⁻ᵀ
    P = τ F⁻ᵀ                                                         (first Piola–Kirchhoff)

Vectors of components are stacked on the first axis:
F and P as [rr, rz, zr, zz, θθ]; C_p⁻¹ as [rr, rz, zz, θθ].

The consistent tangent A = ∂P/∂F (5×5 per point) is the hand linearisation of these
steps (:func:`tangent`, real arithmetic, the five directions at once). Its reference is
complex-step differentiation (Squire & Trapp 1998; Tanaka et al. 2014, CMAME 269:454;
:func:`stress_and_tangent_complex`): every operation here is complex-analytic — the 2×2
tensor log and exp are written as α I + β B with α, β entire functions of the invariants,
so equal eigenvalues are no special case — and Im(P(F + i h e_k))/h is ∂P/∂F_k to machine
precision. The two agree to 1e-11 (tests); the hand linearisation costs about a quarter.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.material import Material

#: complex-step size (any tiny number works: no subtractive cancellation)
CSTEP = 1e-30
_SMALL = 1e-3  # |x| below which the series forms are used (truncation < 1e-21)


@dataclass
class PlasticState:
    """Converged internal variables at the quadrature points."""

    cp_inv: np.ndarray  # (4, N): C_p⁻¹ components rr, rz, zz, θθ
    eps_p: np.ndarray  # (N,): equivalent plastic strain
    dissipation: float = 0.0  # accumulated plastic dissipation (whole body)

    @classmethod
    def virgin(cls, n: int) -> PlasticState:
        cp = np.zeros((4, n))
        cp[0] = cp[2] = cp[3] = 1.0
        return cls(cp_inv=cp, eps_p=np.zeros(n))

    def copy(self) -> PlasticState:
        return PlasticState(self.cp_inv.copy(), self.eps_p.copy(), self.dissipation)


# --------------------------------------------------------------------------- 2×2 tensor functions
def _atanh_sqrt_over_sqrt(x):
    """G(x) = atanh(√x)/√x = Σ x^k/(2k+1), analytic for |x| < 1."""
    small = np.abs(x) < _SMALL
    xs = np.where(small, 0.5, x)
    r = np.sqrt(xs)
    full = np.arctanh(r) / r
    series = 1 + x * (1 / 3 + x * (1 / 5 + x * (1 / 7 + x * (1 / 9 + x * (1 / 11 + x / 13)))))
    return np.where(small, series, full)


def _sinhc_cosh(D):
    """(sinh(√D)/√D, cosh(√D)), entire functions of D."""
    small = np.abs(D) < _SMALL
    Ds = np.where(small, 1.0, D)
    y = np.sqrt(Ds)
    sinhc = np.where(small, 1 + D * (1 / 6 + D * (1 / 120 + D * (1 / 5040 + D / 362880))),
                     np.sinh(y) / y)
    cosh = np.where(small, 1 + D * (1 / 2 + D * (1 / 24 + D * (1 / 720 + D / 40320))), np.cosh(y))
    return sinhc, cosh


def log_sym2(b11, b12, b22):
    """Principal logarithm of a symmetric positive-definite 2×2 tensor: ln B = α I + β B."""
    m = 0.5 * (b11 + b22)
    D = (0.5 * (b11 - b22)) ** 2 + b12**2
    beta = _atanh_sqrt_over_sqrt(D / m**2) / m
    alpha = 0.5 * np.log(b11 * b22 - b12**2) - beta * m
    return alpha + beta * b11, beta * b12, alpha + beta * b22


def exp_sym2(e11, e12, e22):
    """Exponential of a symmetric 2×2 tensor: exp E = α I + β E."""
    m = 0.5 * (e11 + e22)
    D = (0.5 * (e11 - e22)) ** 2 + e12**2
    sinhc, cosh = _sinhc_cosh(D)
    em = np.exp(m)
    beta = em * sinhc
    alpha = em * cosh - beta * m
    return alpha + beta * e11, beta * e12, alpha + beta * e22


# --------------------------------------------------------------------------- return mapping
def solve_plastic_multiplier(q_tr, eps_p_n, material: Material, mu: float, tol=1e-12, maxit=100):
    """Δγ ≥ 0 with q_tr − 3μΔγ − σ_f(ε_p,n + Δγ) = 0, vectorised: the material's flow curve
    solves its own scalar equation (``FlowCurve.plastic_multiplier``: bracketed Newton; Ludwik
    in closed form when perfectly plastic and in y = ε_p^n when n < 1)."""
    return material.flow.plastic_multiplier(q_tr, eps_p_n, mu, tol, maxit)


@dataclass
class J2Return:
    """Result of :func:`hencky_j2_return`: returned deviator, Kirchhoff stress, Δγ, energy."""

    s_diag: tuple  # returned deviatoric stress, diagonal (or principal) components
    s_off: tuple  # returned deviatoric stress, off-diagonal components
    tau_diag: tuple  # Kirchhoff stress τ = K tr ε I + s, diagonal components
    tau_off: tuple  # Kirchhoff stress, off-diagonal components (= s_off)
    ev: np.ndarray  # volumetric log strain tr ε^tr (unchanged by the return)
    dgamma: np.ndarray  # plastic multiplier Δγ (complex-completed for complex input)
    psi: np.ndarray  # stored Hencky energy per reference volume after the return


def hencky_j2_return(e_diag, e_off, eps_p_n, material: Material, dgamma=None, elastic=None
                     ) -> J2Return:
    """Hencky elasticity and the J2 radial return on the trial logarithmic strain.

    The part of the exponential-map algorithm (Simo 1992; de Souza Neto et al. 2008,
    Box 14.3) that does not depend on how ε^tr = ½ ln b_e^tr was obtained; shared by the
    axisymmetric update (:func:`stress_update`: ε^tr by the 2×2 closed form plus the hoop
    component) and the 3D one (:mod:`.constitutive3d`: principal values by eigen-decomposition,
    no off-diagonal components). With ε^tr given by its diagonal components ε_ii and its
    off-diagonal components ε_ij (i < j, each counted twice in contractions):

        ε_v = Σ ε_ii,   s^tr = 2μ (ε^tr − ε_v/3 I),   q^tr = √(3/2 s^tr : s^tr)
        Δγ = 0 if q^tr ≤ σ_f(ε_p,n), else q^tr − 3μΔγ − σ_f(ε_p,n + Δγ) = 0
        s = (1 − 3μΔγ/q^tr) s^tr,   τ = K ε_v I + s,   ψ = s : s/(4μ) + ½ K ε_v²

    (de Souza Neto et al. 2008, Box 7.4, eqs. 7.90–7.93); Δγ from the material's flow curve
    (``FlowCurve.plastic_multiplier``), any law. For complex ε^tr (complex-step tangent) ``dgamma``
    must be the real multiplier; it is completed to first order in the imaginary part.

    Parameters
    ----------
    e_diag, e_off : sequences of arrays: diagonal and off-diagonal components of ε^tr.
    eps_p_n : array, equivalent plastic strain at the start of the increment.
    dgamma : real plastic multiplier, or None to solve for it.
    elastic : boolean mask of points kept elastic (Δγ = 0), or None.
    """
    mu = material.shear_modulus
    kappa = material.bulk_modulus
    ev = e_diag[0]
    for e in e_diag[1:]:
        ev = ev + e
    s_diag = [2 * mu * (e - ev / 3) for e in e_diag]
    s_off = [2 * mu * e for e in e_off]

    def contraction(d, o):  # s : s with off-diagonal pairs counted twice
        acc = d[0] ** 2
        for x in d[1:]:
            acc = acc + x**2
        for x in o:
            acc = acc + 2 * x**2
        return acc

    q_tr = np.sqrt(1.5 * contraction(s_diag, s_off))
    q_real = np.real(q_tr)
    if dgamma is None:
        if np.iscomplexobj(q_tr):
            raise ValueError("complex F needs the real plastic multiplier dgamma")
        dgamma = np.zeros_like(q_real)
        if np.isfinite(material.sigma_y):
            f_tr = q_real - material.flow_stress(eps_p_n)
            plastic = f_tr > 0.0
            if np.any(plastic):
                dgamma[plastic] = solve_plastic_multiplier(
                    q_real[plastic], eps_p_n[plastic], material, mu)
        if elastic is not None:
            dgamma = np.where(elastic, 0.0, dgamma)
    plastic = dgamma > 0.0
    if np.iscomplexobj(q_tr):
        slope = material.flow_slope(eps_p_n + dgamma) if np.isfinite(material.sigma_y) else 0.0
        dg = dgamma + np.where(plastic, (q_tr - q_real) / (3 * mu + slope), 0.0)
    else:
        dg = dgamma
    q_safe = np.where(plastic, q_tr, 1.0)
    factor = np.where(plastic, 1.0 - 3 * mu * dg / q_safe, 1.0)
    s_diag = tuple(factor * x for x in s_diag)
    s_off = tuple(factor * x for x in s_off)
    pk = kappa * ev
    psi = contraction(s_diag, s_off) / (4 * mu) + 0.5 * kappa * ev**2
    return J2Return(s_diag=s_diag, s_off=s_off, tau_diag=tuple(pk + x for x in s_diag),
                    tau_off=s_off, ev=ev, dgamma=dg, psi=psi)


@dataclass
class StressUpdate:
    """Result of one constitutive evaluation (arrays over the points)."""

    P: np.ndarray  # (5, ...) first Piola–Kirchhoff stress
    cp_inv: np.ndarray  # (4, ...) updated C_p⁻¹
    eps_p: np.ndarray  # (...) updated equivalent plastic strain
    dgamma: np.ndarray  # (...) plastic multiplier increment
    psi: np.ndarray  # (...) stored elastic energy per reference volume
    tau: np.ndarray  # (4, ...) Kirchhoff stress rr, rz, zz, θθ


def stress_update(F, state_cp_inv, state_eps_p, material: Material, dgamma=None,
                  stress_only: bool = False, elastic=None) -> StressUpdate | np.ndarray:
    """Exponential-map return mapping at deformation gradient ``F`` (real or complex).

    ``stress_only``: return P alone (what the complex-step tangent needs), skipping the
    updated internal variables. ``elastic``: boolean mask of points kept elastic (Δγ = 0)
    whatever their trial stress (Newton's frozen plastic set, ``solver.freeze_toggling``).

    ``dgamma``: the real plastic multiplier from a real call; with complex F it
    is completed to first order in the imaginary perturbation (one Newton step
    from the real root gives the exact complex-step derivative).
    """
    mu = material.shear_modulus
    a, b, c, d, ftt = F
    p, q, s, ctt = state_cp_inv
    # trial elastic left Cauchy–Green tensor b_e^tr = F C_p⁻¹ Fᵀ
    m11 = a * p + b * q
    m12 = a * q + b * s
    m21 = c * p + d * q
    m22 = c * q + d * s
    b11 = m11 * a + m12 * b
    b12 = m11 * c + m12 * d
    b22 = m21 * c + m22 * d
    btt = ftt * ftt * ctt
    e11, e12, e22 = log_sym2(b11, b12, b22)
    e11, e12, e22 = 0.5 * e11, 0.5 * e12, 0.5 * e22
    ett = 0.5 * np.log(btt)
    ret = hencky_j2_return((e11, e22, ett), (e12,), state_eps_p, material, dgamma, elastic)
    (s11, s22, stt), (s12,) = ret.s_diag, ret.s_off
    ev, dg = ret.ev, ret.dgamma
    t11, t22, ttt, t12 = ret.tau_diag + ret.tau_off
    det = a * d - b * c
    i11, i12, i21, i22 = d / det, -b / det, -c / det, a / det  # F⁻¹
    # P = τ F⁻ᵀ, F⁻ᵀ = [[i11, i21], [i12, i22]]
    P = np.stack([t11 * i11 + t12 * i12, t11 * i21 + t12 * i22,
                  t12 * i11 + t22 * i12, t12 * i21 + t22 * i22, ttt / ftt])
    if stress_only:
        return P
    # elastic log strain after return; b_e = exp(2 ε_e); C_p⁻¹ = F⁻¹ b_e F⁻ᵀ
    ee11 = ev / 3 + s11 / (2 * mu)
    ee22 = ev / 3 + s22 / (2 * mu)
    eett = ev / 3 + stt / (2 * mu)
    ee12 = s12 / (2 * mu)
    n11, n12, n22 = exp_sym2(2 * ee11, 2 * ee12, 2 * ee22)
    ntt = np.exp(2 * eett)
    k11 = i11 * n11 + i12 * n12
    k12 = i11 * n12 + i12 * n22
    k21 = i21 * n11 + i22 * n12
    k22 = i21 * n12 + i22 * n22
    cp_new = np.stack([k11 * i11 + k12 * i12, k11 * i21 + k12 * i22,
                       k21 * i21 + k22 * i22, ntt / (ftt * ftt)])
    return StressUpdate(P=P, cp_inv=cp_new, eps_p=state_eps_p + dg, dgamma=dg, psi=ret.psi,
                        tau=np.stack([t11, t12, t22, ttt]))


def _G_and_slope(x):
    """G(x) = atanh(√x)/√x (:func:`_atanh_sqrt_over_sqrt`) and G'(x) = (1/(1 − x) − G)/(2x)."""
    G = _atanh_sqrt_over_sqrt(x)
    small = np.abs(x) < _SMALL
    xs = np.where(small, 0.5, x)
    full = (1.0 / (1.0 - xs) - np.where(small, 1.0, G)) / (2.0 * xs)
    series = 1 / 3 + x * (2 / 5 + x * (3 / 7 + x * (4 / 9 + x * (5 / 11 + x * 6 / 13))))
    return G, np.where(small, series, full)


def tangent(F, state: PlasticState, material: Material, real: StressUpdate) -> np.ndarray:
    """Consistent tangent A[i, k] = ∂P_i/∂F_k, (5, 5, N), of :func:`stress_update` at real F,
    linearised by hand (forward mode, the five directions e_k at once, real arithmetic).

    The chain of :func:`stress_update`: b^tr = F C_p⁻¹ Fᵀ; ε^tr = ½ ln b^tr with
    ln B = α I + β B, β = G(D/m²)/m, α = ½ ln det B − β m (m = ½ tr B, D = ¼(B₁₁ − B₂₂)² + B₁₂²);
    s^tr = 2μ dev ε^tr; the radial return s = (1 − 3μΔγ/q^tr) s^tr with dΔγ = dq^tr/(3μ + H)
    (H = σ_f' at ε_p,n + Δγ; de Souza Neto et al. 2008, Box 7.4); τ = K tr ε I + s;
    P = τ F⁻ᵀ, dF⁻¹ = −F⁻¹ dF F⁻¹. Equals the complex-step derivative
    (:func:`stress_and_tangent_complex`) to rounding (tests/test_fem_core.py) at a
    fraction of its cost.
    """
    mu, kappa = material.shear_modulus, material.bulk_modulus
    a, b, c, d, ftt = F
    p, q, s, ctt = state.cp_inv
    n = a.shape[0]
    m11, m12 = a * p + b * q, a * q + b * s
    m21, m22 = c * p + d * q, c * q + d * s
    b11, b12, b22 = m11 * a + m12 * b, m11 * c + m12 * d, m21 * c + m22 * d
    btt = ftt * ftt * ctt
    zero = np.zeros(n)
    # db/dF_k, k = rr, rz, zr, zz, θθ: rows of (5, N)
    db11 = np.stack([2 * m11, 2 * m12, zero, zero, zero])
    db12 = np.stack([m21, m22, m11, m12, zero])
    db22 = np.stack([zero, zero, 2 * m21, 2 * m22, zero])
    # ε^tr = ½ ln b^tr and its derivative
    mm = 0.5 * (b11 + b22)
    hd = 0.5 * (b11 - b22)
    D = hd * hd + b12 * b12
    x = D / (mm * mm)
    G, Gx = _G_and_slope(x)
    beta = G / mm
    det_b = b11 * b22 - b12 * b12
    alpha = 0.5 * np.log(det_b) - beta * mm
    dm = 0.5 * (db11 + db22)
    dD = hd * (db11 - db22) + 2 * b12 * db12
    dx = dD / (mm * mm) - 2 * D * dm / (mm * mm * mm)
    dbeta = Gx * dx / mm - G * dm / (mm * mm)
    ddet = b22 * db11 + b11 * db22 - 2 * b12 * db12
    dalpha = 0.5 * ddet / det_b - dbeta * mm - beta * dm
    e11, e12, e22 = 0.5 * (alpha + beta * b11), 0.5 * beta * b12, 0.5 * (alpha + beta * b22)
    de11 = 0.5 * (dalpha + dbeta * b11 + beta * db11)
    de12 = 0.5 * (dbeta * b12 + beta * db12)
    de22 = 0.5 * (dalpha + dbeta * b22 + beta * db22)
    ett = 0.5 * np.log(btt)
    dett = np.stack([zero, zero, zero, zero, 1.0 / ftt])  # ½ dbtt/btt = dF_θθ/F_θθ
    ev = e11 + e22 + ett
    dev = de11 + de22 + dett
    s11, s22, stt, s12 = (2 * mu * (e11 - ev / 3), 2 * mu * (e22 - ev / 3), 2 * mu * (ett - ev / 3),
                          2 * mu * e12)
    ds11, ds22, dstt, ds12 = (2 * mu * (de11 - dev / 3), 2 * mu * (de22 - dev / 3),
                              2 * mu * (dett - dev / 3), 2 * mu * de12)
    # radial return: s = f s^tr, f = 1 − 3μΔγ/q^tr (f = 1 where elastic)
    dg = real.dgamma
    plastic = dg > 0.0
    if np.any(plastic):
        q_tr = np.sqrt(1.5 * (s11**2 + s22**2 + stt**2 + 2 * s12**2))
        q_safe = np.where(plastic, q_tr, 1.0)
        dq = 1.5 * (s11 * ds11 + s22 * ds22 + stt * dstt + 2 * s12 * ds12) / q_safe
        H = material.flow_slope(state.eps_p + dg) if np.isfinite(material.sigma_y) else 0.0
        fac = np.where(plastic, 1.0 - 3 * mu * dg / q_safe, 1.0)
        dfac = np.where(plastic, -3 * mu * dq * (1.0 / (3 * mu + H) - dg / q_safe) / q_safe, 0.0)
        ds11, ds22, dstt, ds12 = (dfac * s11 + fac * ds11, dfac * s22 + fac * ds22,
                                  dfac * stt + fac * dstt, dfac * s12 + fac * ds12)
        s11, s22, stt, s12 = fac * s11, fac * s22, fac * stt, fac * s12
    pk, dpk = kappa * ev, kappa * dev
    t11, t22, ttt, t12 = pk + s11, pk + s22, pk + stt, s12
    dt11, dt22, dttt, dt12 = dpk + ds11, dpk + ds22, dpk + dstt, ds12
    det = a * d - b * c
    i11, i12, i21, i22 = d / det, -b / det, -c / det, a / det
    # dF⁻¹ = −F⁻¹ dF F⁻¹ for dF = e_k (2×2 part; θθ does not enter)
    di11 = -np.stack([i11 * i11, i11 * i21, i12 * i11, i12 * i21, zero])
    di12 = -np.stack([i11 * i12, i11 * i22, i12 * i12, i12 * i22, zero])
    di21 = -np.stack([i21 * i11, i21 * i21, i22 * i11, i22 * i21, zero])
    di22 = -np.stack([i21 * i12, i21 * i22, i22 * i12, i22 * i22, zero])
    A = np.empty((5, 5, n))
    A[0] = dt11 * i11 + t11 * di11 + dt12 * i12 + t12 * di12
    A[1] = dt11 * i21 + t11 * di21 + dt12 * i22 + t12 * di22
    A[2] = dt12 * i11 + t12 * di11 + dt22 * i12 + t22 * di12
    A[3] = dt12 * i21 + t12 * di21 + dt22 * i22 + t22 * di22
    A[4] = dttt / ftt
    A[4, 4] -= ttt / (ftt * ftt)
    return A


def stress_and_tangent(F, state: PlasticState, material: Material, real: StressUpdate | None = None,
                       elastic=None):
    """Stress update at real F (shape (5, N)) and the tangent A[i, k] = ∂P_i/∂F_k, (5, 5, N)
    (:func:`tangent`).

    ``real``: the real stress update at this F when the caller already has it.
    ``elastic``: points kept elastic (:func:`stress_update`).
    """
    if real is None:
        real = stress_update(F, state.cp_inv, state.eps_p, material, elastic=elastic)
    return real, tangent(F, state, material, real)


def stress_and_tangent_complex(F, state: PlasticState, material: Material,
                               real: StressUpdate | None = None, elastic=None):
    """:func:`stress_and_tangent` with the tangent by complex-step differentiation (module
    docstring): exact to machine precision, about four times the cost; the reference the
    hand linearisation is tested against."""
    if real is None:
        real = stress_update(F, state.cp_inv, state.eps_p, material, elastic=elastic)
    Fc = F[:, None, :] + 1j * CSTEP * np.eye(5)[:, :, None]
    P = stress_update(Fc, state.cp_inv[:, None, :], state.eps_p[None, :], material,
                      dgamma=real.dgamma[None, :], stress_only=True)
    A = np.imag(P) / CSTEP
    return real, A
