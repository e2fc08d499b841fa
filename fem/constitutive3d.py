"""Finite-strain J2 plasticity in 3D: Hencky elasticity + exponential-map return (3×3).

The same algorithm as the axisymmetric update (:mod:`.plasticity`; Simo 1992, CMAME 99:61;
de Souza Neto, Perić & Owen 2008, Box 14.3), for a general deformation gradient F (3×3)
and a general plastic metric C_p⁻¹ (symmetric 3×3, reference frame). Per point:

    b_e^tr = F C_p⁻¹ Fᵀ = Σ λ_i n_i ⊗ n_i                 (spectral decomposition, eigh)
    ε_i^tr = ½ ln λ_i                                      (principal trial log strains)
    (τ_i, Δγ, ψ) = hencky_j2_return(ε^tr_i)                (shared with the axisymmetric update)
    τ = Σ τ_i n_i ⊗ n_i,   P = τ F⁻ᵀ
    ε_e,i = ε_v/3 + s_i/(2μ),   b_e = Σ exp(2 ε_e,i) n_i ⊗ n_i,   C_p⁻¹ = F⁻¹ b_e F⁻ᵀ

Hencky elasticity and the J2 return are isotropic, so they act on the principal values
alone and the return keeps the eigenvectors (the exponential map's coaxiality; de Souza
Neto et al. 2008, §14.4). The return itself is :func:`.plasticity.hencky_j2_return`, the
very function the axisymmetric update calls (every flow curve through
``material.flow.plastic_multiplier``); only the tensor log/exp differ: eigen-decomposition
here, the closed 2×2 form plus the hoop component there. For an axisymmetric F (hoop the
third principal direction) both give the same stress and state to rounding (tests).

Arrays: F, P, C_p⁻¹ as (N, 3, 3); the tangent as (N, 9, 9), A[q, 3i+j, 3k+l] = ∂P_ij/∂F_kl.

The tangent is, for now, the central difference of P over the nine components of F
(step :data:`FD_STEP`), each perturbed state returned afresh, so it is the consistent
tangent (Δγ linearised) to about 1e-8 relative — enough for Newton's quadratic
convergence down to the solver tolerance, at 18 stress updates per evaluation. The hand
linearisation of the spectral form (de Souza Neto et al. 2008, Appendix A) is the next step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.material import Material
from .plasticity import hencky_j2_return

#: central-difference step of the tangent, ≈ ε_machine^(1/3)
FD_STEP = 6e-6


@dataclass
class PlasticState3:
    """Converged internal variables at the quadrature points (3D)."""

    cp_inv: np.ndarray  # (N, 3, 3) plastic metric C_p⁻¹
    eps_p: np.ndarray  # (N,) equivalent plastic strain
    dissipation: float = 0.0  # accumulated plastic dissipation (whole body)

    @classmethod
    def virgin(cls, n: int) -> PlasticState3:
        return cls(cp_inv=np.broadcast_to(np.eye(3), (n, 3, 3)).copy(), eps_p=np.zeros(n))

    def copy(self) -> PlasticState3:
        return PlasticState3(self.cp_inv.copy(), self.eps_p.copy(), self.dissipation)


@dataclass
class StressUpdate3:
    """Result of one 3D constitutive evaluation (arrays over the points)."""

    P: np.ndarray  # (N, 3, 3) first Piola–Kirchhoff stress
    cp_inv: np.ndarray  # (N, 3, 3) updated C_p⁻¹
    eps_p: np.ndarray  # (N,) updated equivalent plastic strain
    dgamma: np.ndarray  # (N,) plastic multiplier increment
    psi: np.ndarray  # (N,) stored elastic energy per reference volume
    tau: np.ndarray  # (N, 3, 3) Kirchhoff stress


def _spectral(values: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """Σ_i values_i n_i ⊗ n_i for eigenvectors in the columns of ``vectors`` (N, 3, 3)."""
    return np.einsum("nia,na,nja->nij", vectors, values, vectors)


def stress_update3(F: np.ndarray, cp_inv: np.ndarray, eps_p: np.ndarray, material: Material,
                   dgamma=None, elastic=None, stress_only: bool = False):
    """Exponential-map return mapping at deformation gradients ``F`` (N, 3, 3) (module docstring).

    Parameters
    ----------
    F : (N, 3, 3) deformation gradients.
    cp_inv, eps_p : converged state at the start of the increment.
    dgamma : plastic multiplier to use instead of solving for it (None: solve).
    elastic : boolean mask (N,) of points kept elastic, or None.
    stress_only : return P alone.
    """
    mu = material.shear_modulus
    be = F @ cp_inv @ np.swapaxes(F, 1, 2)
    lam, vec = np.linalg.eigh(be)
    e = 0.5 * np.log(lam)
    ret = hencky_j2_return((e[:, 0], e[:, 1], e[:, 2]), (), eps_p, material, dgamma, elastic)
    tau = _spectral(np.stack(ret.tau_diag, axis=-1), vec)
    Finv = np.linalg.inv(F)
    P = tau @ np.swapaxes(Finv, 1, 2)
    if stress_only:
        return P
    ee = ret.ev[:, None] / 3 + np.stack(ret.s_diag, axis=-1) / (2 * mu)
    be_new = _spectral(np.exp(2 * ee), vec)
    cp_new = Finv @ be_new @ np.swapaxes(Finv, 1, 2)
    return StressUpdate3(P=P, cp_inv=cp_new, eps_p=eps_p + ret.dgamma, dgamma=ret.dgamma,
                         psi=ret.psi, tau=tau)


def tangent3(F: np.ndarray, state: PlasticState3, material: Material, real: StressUpdate3
             ) -> np.ndarray:
    """Consistent tangent A (N, 9, 9), A[:, 3i+j, 3k+l] = ∂P_ij/∂F_kl, by central differences.

    Points elastic in ``real`` stay elastic in the perturbed evaluations (the elastic
    predictor's tangent); plastic points are returned afresh, so dΔγ/dF is included
    (de Souza Neto et al. 2008, Box 7.4, in its finite-strain form). Error ≈ 1e-8 relative.
    """
    n = F.shape[0]
    elastic = real.dgamma <= 0.0
    E = np.eye(9).reshape(9, 3, 3) * FD_STEP
    Fp = (F[None] + E[:, None]).reshape(9 * n, 3, 3)
    Fm = (F[None] - E[:, None]).reshape(9 * n, 3, 3)
    Fs = np.concatenate([Fp, Fm])
    cp = np.broadcast_to(state.cp_inv, (18, n, 3, 3)).reshape(18 * n, 3, 3)
    ep = np.broadcast_to(state.eps_p, (18, n)).reshape(-1)
    el = np.broadcast_to(elastic, (18, n)).reshape(-1)
    P = stress_update3(Fs, cp, ep, material, elastic=el, stress_only=True).reshape(2, 9, n, 9)
    return ((P[0] - P[1]) / (2 * FD_STEP)).transpose(1, 2, 0)


def stress_and_tangent3(F: np.ndarray, state: PlasticState3, material: Material):
    """Stress update at F (N, 3, 3) from ``state`` and its tangent (N, 9, 9)."""
    real = stress_update3(F, state.cp_inv, state.eps_p, material)
    return real, tangent3(F, state, material, real)
