"""Incremental Newton solver: one elastic–plastic hemisphere pressed on a rigid obstacle.

Scene (docs/design.md §4): the meridian section of a hemisphere of radius R (pole at
the origin, equatorial plane z = R); the equatorial plane is moved towards the
obstacle by h (u_z = −h, free to slide radially), the axis has u_r = 0, the arc
meets a rigid flat or rigid sphere in frictionless contact (``contact.py``).

Each increment: tangent predictor (the last converged increment's factorised
tangent applied to the new approach step; the secant of the last two increments
where that is not at hand), then Newton on the free dofs with the exact tangent
(material ∂P/∂F linearised by hand, plus the rigid sphere's curvature term),
the contact active set updated in the same loop (primal–dual active set:
release on tensile reaction, close on penetration). With
``SolverOptions.penalty`` the contact is a penalty instead: every penetrating
node carries k_N A_i (−g_i) along the obstacle normal (Wriggers 2006, §5.2),
with no constrained dof; it exists to show what the exact method avoids. Increments grow after
easy steps and are cut back on divergence; below ``dh_min`` the run stops with
the converged part kept and flagged.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..model.material import Material
from ..peers import first_yield_approach as jg_first_yield
from .assembly import Discretisation, positive_jacobian
from .contact import EDGE_FITS, RigidObstacle, contact_edge, smooth_contact_radius, surface_areas
from .linsolve import METHODS as LINEAR_METHODS
from .linsolve import ConstrainedPattern, SymmetricSolver, shifted_diagonal
from .mesh import build_mesh
from .plasticity import PlasticState, stress_update, tangent
from .segment_penalty import SegmentPenalty

#: nodal-force roundoff of the stress update, in units of M R² with M = max(E, 3κ) the
#: stiffest elastic modulus (see ``_newton``; measured ~2e-14 M R² after a plastic cycle at
#: ν = 0.45, where 3κ = 10 E)
ROUNDOFF = 1e-15
#: an unloading branch whose increment fails below this fraction of F_max ends there, h_res
#: extrapolated (``residual_approach``) and the force reached kept in ``cycles["F_end"]``.
#: With heavy hardening the residual imprint is nearly conforming and the whole contact opens
#: within a few per cent of F_max (campaign v2, flat, K/σY = 7.7-7.9, n = 0.52: Newton fails at
#: 2.4-3.0 % of F_max). Cost measured on the 177 unloadings of campaign v2's first 49 runs cut at
#: their first point below 5 % F_max: h_res within 2.5 % of the recovery h_max - h_res (median
#: 0.25 %, 90 % within 1.5 %), always on the low side.
UNLOAD_TAIL = 0.05
#: the new loading of a cycle (from the largest approach reached before, h_top, up to an
#: unloading approach h_u) takes at least CYCLE_LOADING × ``unload_increments`` increments:
#: loading steps ≤ (h_u − h_top)/(CYCLE_LOADING · unload_increments), so that the cycle's energy
#: balance (work in − returned = dissipation + Δ stored) closes. With the strain bound alone the
#: loading steps of a stiff sphere are coarse for its plastic zone: EPP E/σY = 1000 on a flat,
#: default mesh, the stress deviator of the points flowing on rotates by θ = 0.2-0.4 rad per
#: step (Δγ-weighted mean), and the backward-Euler dissipation σ_Y Δγ exceeds the trapezoid of
#: the end-point stresses by ½ σ_Y Δγ (1 − cos θ) per point, which the work of the end-point
#: forces does not see (first order in the step: 1.29/0.59/0.24/0.14 % on 18/36/72/144 geometric
#: steps to h/R = 0.001). Cycles at h/R = 0.001 and 0.01 missed the balance by 0.56 % and
#: 1.20 %; with 2 × 24 increments 0.12 % and 0.31 % (1 × 24: 0.38 %, 0.80 %), and F at
#: h/R = 0.001 rose 1.7 %, onto the 144-step value. Steps about uniform in h suit the loading
#: work (about ∝ h^2.1: most of it in a leg's last part). Monotone runs (no unloading) are not
#: affected. A trapezoid dissipation instead would not close it: a contact node that closes
#: within a step takes its reaction at once in the end-point stresses (estimated from their
#: work: +1.9 % at h/R = 0.001).
CYCLE_LOADING = 2


def stiffest_modulus(material) -> float:
    """max(E, 3κ): the modulus the roundoff of the stresses scales with (3κ for ν → 1/2)."""
    return max(material.E, 3.0 * material.bulk_modulus)


class IncrementFailed(RuntimeError):
    """Newton did not converge in one increment (the increment is retried smaller)."""


#: ways of setting the penalty stiffness (SolverOptions.penalty_scale)
PENALTY_SCALES = ("modulus", "approach")
#: how two bodies integrate the segment penalty (SolverOptions.segment_scheme)
SEGMENT_SCHEMES = ("points", "mortar")


#: Newton's default tolerance, ‖free residual‖∞ ≤ NEWTON_TOL · largest reaction. 1e-4 stops each
#: increment one or two iterations before 1e-8 did and moves no answer: the standard run (EPP
#: E/σY 200, flat, h/R 0.3) stepped through the same approaches gives F within 9.5e-6 and a within
#: 6.5e-7 of the 1e-8 run (rigid sphere 2R: 9.0e-6, 1.2e-7), 500× below the 0.5 % the mesh checks
#: resolve; Newton iterations 993 → 799 on those approaches. Abaqus's default (5e-3 of the mean
#: nodal force) is looser still.
NEWTON_TOL = 1e-4


@dataclass
class SolverOptions:
    """Increment and Newton controls; lengths in units of the sphere radius R."""

    dh_first: float = 2e-4
    dh_max: float = 0.01
    dh_min: float = 1e-7
    growth: float = 1.5
    easy_iterations: int = 7  # grow the increment after at most this many iterations
    max_iterations: int = 25
    #: Newton converged: ‖free residual‖∞ ≤ tol · largest reaction (:data:`NEWTON_TOL`)
    tol: float = NEWTON_TOL
    strain_increment: float = 0.005  # dh ≤ strain_increment · a: bounds the strain per step
    #: dh ≤ relative_step · h once in contact (None: no such bound). The strain bound allows
    #: dh/h = strain_increment · a/h ≈ 0.01 c² R/a, 0.6 at a/R = 0.02: about ten increments a
    #: decade of h where a stiff sphere's contact is small
    relative_step: float | None = None
    max_wall_s: float = float("inf")  # stop (status "stopped", converged part kept) after this
    line_search: bool = True  # energy line search (off: full Newton steps, J > 0 guard only)
    #: None: exact contact (Lagrange multipliers). A number: penalty contact with stiffness
    #: k_N = penalty · E / ℓ per unit reference area, ℓ the length of the pole's surface element
    #: (two bodies: E* of the pair, symmetric two-pass; twobody.py)
    penalty: float | None = None
    #: "cholesky": CHOLMOD's supernodal Cholesky reusing its symbolic analysis, LDLᵀ where the
    #: tangent is not positive definite; "ldl": qdldl LDLᵀ reusing its symbolic analysis, SuperLU
    #: where it fails; "superlu": SuperLU only (``linsolve.SymmetricSolver``)
    linear_solver: str = "cholesky"
    #: one body, ``linear_solver`` "cholesky": where Cholesky refuses the tangent (not positive
    #: definite), factor K + shift · |diag K| instead (:func:`~.linsolve.shifted_diagonal`), a
    #: Newton step damped along the negative directions; 0 (default): LDLᵀ of K, the exact
    #: Newton step. E/σY 10⁴ on a flat (mesh 1.5×, to h/R 0.03), 0.1: no rejected increment
    #: instead of 13, so half the increments; not the default because the increments the
    #: failures no longer cost change the verified runs (fem/README.md, "Linear solves")
    definite_shift: float = 0.0
    #: the contact radius's sub-element fit (:func:`~.contact.contact_edge`): "hertz", the gap
    #: opening as (r − a)^{3/2} (the stored databases' a); "fitted", its exponent fitted in [1, 2]
    #: (1.1 at a plastic edge): the standard run's a at h/R 0.05 within 0.19 % of the 2× mesh's on
    #: the same approaches instead of 0.85 %, and 0.4–0.6 % higher on the surface-band mesh
    edge_fit: str = "hertz"
    #: "tangent": the last converged increment's factorised tangent applied to the new approach
    #: step (:meth:`IndentationSolver._tangent_predictor`), the secant where it is not at hand;
    #: "secant": the last increment's displacement change extrapolated
    predictor: str = "tangent"
    #: 0: penalty at the nodes; n > 0: penalty pressure integrated at n Gauss points per surface
    #: edge (segment_penalty.py), which needs ``penalty``
    segment_points: int = 0
    #: two bodies with ``segment_points``: "points", each Gauss point its own penalty, both
    #: bodies' points in turn (two passes); "mortar", one pass of the softer body's weighted gaps,
    #: ``segment_points`` Gauss points on each half edge (twobody.MortarContactPass). One body
    #: against a rigid obstacle takes "points" only
    segment_scheme: str = "points"
    #: how ``penalty`` sets k_N: "modulus", k_N = penalty · E / ℓ; "approach",
    #: k_N = penalty · p_m / h (p_m = F/πa² of the last converged loading increment, Hertz's
    #: before contact), so the obstacle is pressed in by about h / penalty at every approach and
    #: a surface edge that closes takes its pressure over a penetration of that size instead of
    #: at once (:meth:`IndentationSolver._approach_stiffness`). Fixed on unloading and reloading.
    penalty_scale: str = "modulus"
    #: increments per unloading branch, spread over the elastic recovery 1.5 F_max/(2E*a)
    #: (elastic reloading below the previous maximum uses the same increment); the new loading
    #: up to an unloading approach takes at least ``CYCLE_LOADING`` × as many
    unload_increments: int = 24

    def as_inputs(self) -> dict:
        """The options as stored with a run; None values are left out (HDF5 attributes have no
        None, and a missing key reads back as the default)."""
        return {k: v for k, v in vars(self).items() if v is not None}

    def validate(self) -> None:
        for name in ("dh_first", "dh_max", "dh_min", "tol", "strain_increment"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        if not self.max_wall_s > 0:
            raise ValueError(f"max_wall_s must be > 0 (inf: no limit), got {self.max_wall_s!r}")
        if self.dh_min > self.dh_first or self.dh_first > self.dh_max:
            raise ValueError("increments must satisfy dh_min <= dh_first <= dh_max")
        if self.relative_step is not None and not (np.isfinite(self.relative_step)
                                                   and 0.0 < self.relative_step <= 10.0):
            raise ValueError(f"relative_step must be None (no bound) or a number in (0, 10], "
                             f"got {self.relative_step!r}")
        if not self.growth >= 1.0:
            raise ValueError(f"growth must be >= 1, got {self.growth!r}")
        if not (isinstance(self.max_iterations, int) and 2 <= self.max_iterations <= 200):
            raise ValueError(f"max_iterations must be an integer in [2, 200], got {self.max_iterations!r}")
        if not (isinstance(self.segment_points, int) and 0 <= self.segment_points <= 64):
            raise ValueError(f"segment_points must be an integer in [0, 64] (0: nodal contact), "
                             f"got {self.segment_points!r}")
        if self.segment_points and self.penalty is None:
            raise ValueError("segment_points > 0 needs penalty contact: set penalty (> 0) as well")
        if self.segment_scheme not in SEGMENT_SCHEMES:
            raise ValueError(f"segment_scheme must be one of {SEGMENT_SCHEMES}, got {self.segment_scheme!r}")
        if self.segment_scheme == "mortar" and not self.segment_points:
            raise ValueError("segment_scheme 'mortar' needs segment_points > 0 (Gauss points per half edge)")
        if self.penalty_scale not in PENALTY_SCALES:
            raise ValueError(f"penalty_scale must be one of {PENALTY_SCALES}, got {self.penalty_scale!r}")
        if self.penalty_scale == "approach" and self.penalty is None:
            raise ValueError("penalty_scale 'approach' needs penalty contact: set penalty (> 0) as well")
        if not (isinstance(self.unload_increments, int) and 4 <= self.unload_increments <= 1000):
            raise ValueError(f"unload_increments must be an integer in [4, 1000], got "
                             f"{self.unload_increments!r}")
        if self.linear_solver not in LINEAR_METHODS:
            raise ValueError(f"linear_solver must be one of {', '.join(map(repr, LINEAR_METHODS))}, "
                             f"got {self.linear_solver!r}")
        if not (isinstance(self.definite_shift, (int, float)) and 0.0 <= self.definite_shift <= 10.0):
            raise ValueError(f"definite_shift must be a number in [0, 10] (0: LDL^T where Cholesky "
                             f"refuses the tangent), got {self.definite_shift!r}")
        if self.edge_fit not in EDGE_FITS:
            raise ValueError(f"edge_fit must be one of {', '.join(map(repr, EDGE_FITS))}, "
                             f"got {self.edge_fit!r}")
        if self.predictor not in ("tangent", "secant"):
            raise ValueError(f"predictor must be 'tangent' or 'secant', got {self.predictor!r}")
        if self.penalty is not None and not (isinstance(self.penalty, (int, float))
                                             and np.isfinite(self.penalty) and self.penalty > 0):
            raise ValueError(f"penalty must be None (exact contact) or a finite number > 0, "
                             f"got {self.penalty!r}")


@dataclass
class History:
    """Per converged increment records (lists; ``as_arrays`` packs them)."""

    h: list = field(default_factory=list)
    F: list = field(default_factory=list)
    F_support: list = field(default_factory=list)
    a: list = field(default_factory=list)
    a_nodes: list = field(default_factory=list)
    a_ref: list = field(default_factory=list)
    eps_p_max: list = field(default_factory=list)
    work_external: list = field(default_factory=list)
    energy_elastic: list = field(default_factory=list)
    dissipation: list = field(default_factory=list)
    iterations: list = field(default_factory=list)
    active_changes: list = field(default_factory=list)
    residuals: list = field(default_factory=list)
    profile_r: list = field(default_factory=list)
    profile_p: list = field(default_factory=list)
    profile_g: list = field(default_factory=list)
    penetration: list = field(default_factory=list)
    h_pole: list = field(default_factory=list)  # the body's shortening, equator to pole
    branch: list = field(default_factory=list)


@dataclass
class RunResult:
    """Outcome of one run: curves per converged increment, status, timings, final state."""

    inputs: dict
    curves: dict
    residuals: list
    profile_r: np.ndarray
    profile_p: np.ndarray
    profile_g: np.ndarray
    status: str  # "converged" (reached h_max) or "stopped"
    reason: str
    timings: dict
    final: dict  # final deformed mesh and fields
    cycles: dict = field(default_factory=dict)  # per unloading branch (cycles_as_arrays)

    @property
    def h(self):
        return self.curves["h"]

    @property
    def F(self):
        return self.curves["F"]

    @property
    def a(self):
        return self.curves["a"]


def work_increment(h0: float, h1: float, F0: float, F1: float) -> float:
    """∫ F dh over [h0, h1] with F = C h^p through both end points (exact for power laws;
    from h0 = 0 this is F1 h1/(p+1) with the Hertz exponent p = 3/2)."""
    if F0 <= 0.0 or h0 <= 0.0:
        return F1 * (h1 - h0) / 2.5
    if F1 <= 0.0:
        return 0.5 * (F0 + F1) * (h1 - h0)
    p = np.log(F1 / F0) / np.log(h1 / h0)
    if abs(p + 1.0) < 1e-9:
        return F0 * h0 * np.log(h1 / h0)
    return (F1 * h1 - F0 * h0) / (p + 1.0)


def quadratic_work(h0: float, h1: float, h2: float, F0: float, F1: float, F2: float) -> float:
    """∫ F dh over [h1, h2] of the parabola through (h0, F0), (h1, F1), (h2, F2) (error O(Δh⁴))."""
    c = np.polyfit([h0 - h1, 0.0, h2 - h1], [F0, F1, F2], 2)
    d = h2 - h1
    return float(c[0] * d**3 / 3 + c[1] * d**2 / 2 + c[2] * d)


def update_active_set(active: np.ndarray, lam: np.ndarray, gap: np.ndarray, gap_tol: float,
                      log: dict) -> tuple[np.ndarray, bool]:
    """Primal–dual active-set step over contact nodes ordered from the pole.

    A closed node stays closed while its reaction is compressive, an open one
    closes when it penetrates (gap < −gap_tol). The contact of a sphere on a
    flat, a sphere or another sphere is a disc: every node up to the outermost
    one that wants contact is closed (no holes from transient tensile forces).
    When the edge node flips in and out (one node of contact resolution), it is
    kept closed and ``log["frozen"]`` is set: the increment finishes with that
    set. ``log`` holds ``changes``, ``flips``, ``frozen``, ``seen`` (sets tried)
    and ``res`` (the residual history). Returns the new set and whether it changed.
    """
    wants = np.where(active, lam > 0.0, gap < -gap_tol)
    new = np.zeros_like(active)
    if wants.any():
        new[: np.flatnonzero(wants).max() + 1] = True
    if np.array_equal(new, active):
        return active, False
    log["changes"] += 1
    key = new.tobytes()
    flip = key in log["seen"] and np.count_nonzero(new != active) == 1
    log["flips"] += flip
    near = bool(log["res"]) and log["res"][-1] < 1e-4
    if flip and (near or log["flips"] >= 3):
        new = new | active
        log["frozen"] = True
    log["seen"].add(key)
    return new, not np.array_equal(new, active)


#: a Newton step "restores contact" when its prescribed normal corrections reach this
#: fraction of its largest component (:func:`restores_contact`)
RESTORING_STEP = 1e-3


def restores_contact(du_c: np.ndarray, du: np.ndarray) -> bool:
    """The step puts penetrating nodes back on the obstacle: max |du_c| ≥ ``RESTORING_STEP`` ·
    max |du| (du_c the prescribed normal corrections −g of the active nodes). Such a step is
    taken whole (:meth:`IndentationSolver._line_search`).

    On a curved obstacle every step that slides active nodes by du_t leaves them off the
    surface by about κ du_t²/2, so du_c is never exactly zero there (1e-14 … 1e-12 R). Taking
    every such step whole switched the line search off for rigid spheres: the sphere of
    R₂ = 0.88 R (Ludwik E/σY 1360, K/σY 1.16, n 0.2) needed 204 increments with 105 rejected
    to h/R = 0.002, the flat 37 with none; a radius of 10⁶ R, whose gaps round to zero, ran
    like the flat.
    """
    return bool(np.abs(du_c).max(initial=0.0) >= RESTORING_STEP * np.abs(du).max(initial=0.0) > 0.0)


def new_active_log() -> dict:
    """Empty bookkeeping of :func:`update_active_set` for one increment."""
    return {"changes": 0, "flips": 0, "frozen": False, "seen": set(), "res": []}


#: residuals repeating every other iteration within this fraction make a 2-cycle
CYCLE_MATCH = 0.05
def two_cycle(res) -> bool:
    """Newton ping-pongs between two states: each of the last two residuals within
    ``CYCLE_MATCH`` of the one two iterations before (r_k ≈ r_(k−2), r_(k−1) ≈ r_(k−3))."""
    if len(res) < 4:
        return False
    r = np.asarray(res[-4:], dtype=float)
    return bool(abs(r[3] - r[1]) <= CYCLE_MATCH * r[3] and abs(r[2] - r[0]) <= CYCLE_MATCH * r[2])


#: Newton has stalled near convergence: residual ≤ this, not 10× lower than two iterations before
STALL_BELOW = 1e-5


def stalled(res) -> bool:
    """A 2-cycle (:func:`two_cycle`), or the last two residuals ≤ ``STALL_BELOW`` and not
    10× below the two before (quadratic convergence gains far more)."""
    if two_cycle(res):
        return True
    if len(res) < 4:
        return False
    return max(res[-2:]) <= STALL_BELOW and min(res[-2:]) >= 0.1 * min(res[-4:-2])


def admissible_step(u, du, gradients, halvings: int = 6):
    """(u + β du, β, gradients there) with the largest β = 2^-k, k ≤ ``halvings``, keeping every
    Jacobian positive; ``gradients(u)`` → the F vectors (5, n) of each body at u, kept for the
    stress update at the step (not computed twice)."""
    beta = 1.0
    for _ in range(halvings + 1):
        trial = u + beta * du
        Fs = gradients(trial)
        if all(positive_jacobian(Fv) for Fv in Fs):
            return trial, beta, Fs
        beta *= 0.5
    raise IncrementFailed("inverted element (J <= 0) even after step halving")


def bracketed_line_search(slope, s0: float, max_steps: int = 4):
    """(α, payload) of an energy line search along a Newton step of slope s0 = s(0) < 0, where
    ``slope(α)`` → (s(α), payload) is the potential's slope at u + α du (Crisfield 1991, §9.3).

    α = 1 is taken when |s(1)| ≤ ½|s0| or s(1) < 0 (the zero lies beyond the step). Otherwise
    the zero of s is bracketed by [lo, hi], s(lo) < 0 < s(hi), and α moves to the secant zero
    within it, but not below the bracket's middle, until |s(α)| ≤ ½|s0|. A node that starts to
    penetrate a penalty contact within the step bends s up at once past its entry: the secant's
    zero then lies near lo, and accepting the first descending α (the rule of the one-body
    search) took 0.1 of the step per Newton iteration on the two-body penalty pair (E/σY 200 and
    600, R₂ = 2R₁, to h = 0.03 R₁, 4 trials each: 120 increments with 6 rejected, against 103
    with 4 here).
    Returns the accepted α, else the last descending α tried, else the last α tried.
    """
    alpha, lo, s_lo, hi, s_hi, below = 1.0, 0.0, s0, None, None, None
    for _ in range(max_steps):
        s_a, payload = slope(alpha)
        tried = (alpha, payload)
        if abs(s_a) <= 0.5 * abs(s0) or (s_a < 0.0 and hi is None):
            return tried
        if s_a < 0.0:
            lo, s_lo, below = alpha, s_a, tried
        else:
            hi, s_hi = alpha, s_a
        alpha = float(np.clip(lo + (hi - lo) * s_lo / (s_lo - s_hi), lo + 0.5 * (hi - lo), hi))
    return below or tried


def approach_pressure(run: _RunState, h_new: float, E_prime: float, R_rel: float) -> float:
    """p_m of the penalty scaled with the approach (``penalty_scale`` "approach", k_N = P p_m/h,
    the contact pressed in by about h/P at every approach): the last converged increment's
    F/(πa²), or Hertz's 4E′√(h/R*)/(3π) before contact (E′ the pair's contact modulus, R* its
    relative radius)."""
    if run.F > 0.0 and run.a > 0.0:
        return run.F / (np.pi * run.a**2)
    return 4.0 * E_prime * np.sqrt(h_new / R_rel) / (3.0 * np.pi)


def freeze_toggling(log: dict, plastic: np.ndarray, elastic: np.ndarray | None) -> np.ndarray | None:
    """The points Newton keeps elastic for the rest of the increment (``elastic`` grown).

    On unloading from large deformation with heavy hardening, Gauss points at the yield
    surface can toggle between the elastic and the plastic branch from one iteration to
    the next: a point's elastic–plastic tangent is ~20× softer than the elastic one and
    each overshoots into the other branch (half steps keep the cycle); with Ludwik n < 1
    a point at ε_p ~ 1e-16 … 1e-11 toggles with Δγ ~ 1e-20 that still moves its flow stress
    by ~1 % (slope ~ ε_p^(n−1)). Campaign v2, rigid sphere R2/R1 = 2.91, K/σY = 8.1, n = 0.18,
    E/σY = 41: residuals 1e-8 … 2e-7 for 25 iterations from h/R = 0.2876 on, until the
    increment fell below dh_min. When Newton stalls (:func:`stalled`) the points whose plastic
    flag changed since the last iteration (``plastic`` vs ``log["plastic"]``) are kept elastic,
    the problem is smooth again and Newton converges; such a point ends the increment
    slightly above yield (by about 3μΔγ) and returns to it in the next one. Counted in
    ``timings["plastic_frozen_increments"]``. At the default tolerance (:data:`NEWTON_TOL`) that
    increment converges before it stalls; the freeze serves 2-cycles and tighter tolerances.
    """
    before = log.get("plastic")
    log["plastic"] = plastic
    if before is None or before.shape != plastic.shape or not stalled(log["res"]):
        return elastic
    toggling = before != plastic
    if not toggling.any():
        return elastic
    log["plastic_frozen"] = True
    return toggling if elastic is None else elastic | toggling


def plastic_dissipation(disc: Discretisation, material: Material, eps_p_n: np.ndarray,
                        dgamma: np.ndarray) -> float:
    """Dissipation of one increment, ∫ σ_f(ε_p,n + Δγ) Δγ dV₀ (backward Euler)."""
    if not np.isfinite(material.sigma_y):
        return 0.0
    return disc.integrate(np.where(dgamma > 0, material.flow_stress(eps_p_n + dgamma) * dgamma, 0.0))


def finish_curves(curves: dict) -> dict:
    """Smoothed contact radii (raw ones kept), mean pressure and integer counters."""
    curves["a_raw"], curves["a_ref_raw"] = curves["a"], curves["a_ref"]
    branch = curves.get("branch", np.zeros(curves["h"].size))
    curves["a"], curves["a_ref"] = curves["a_raw"].copy(), curves["a_ref_raw"].copy()
    # smoothed over each run of increments of one branch (h monotone there)
    cuts = np.flatnonzero(np.diff(branch) != 0) + 1
    for seg in np.split(np.arange(branch.size), cuts):
        if seg.size:
            curves["a"][seg] = smooth_contact_radius(curves["h"][seg], curves["a_raw"][seg])
            curves["a_ref"][seg] = smooth_contact_radius(curves["h"][seg], curves["a_ref_raw"][seg])
    with np.errstate(divide="ignore", invalid="ignore"):
        curves["p_m"] = np.where(curves["a"] > 0, curves["F"] / (np.pi * curves["a"] ** 2), 0.0)
    for k in ("iterations", "active_changes", "branch"):
        if k in curves:
            curves[k] = curves[k].astype(int)
    return curves

#: branch labels of ``curves["branch"]``
LOAD, UNLOAD, RELOAD = 0, 1, 2
#: per-cycle summaries of ``RunResult.cycles`` (one value per unloading branch)
CYCLE_KEYS = ("h_max", "F_max", "a_max", "h_res", "pole_radius", "work_in", "work_returned",
              "dissipation", "elastic_energy_change", "increment_start", "increment_peak",
              "increment_end", "F_end")


def first_yield_approach(materials, R_rel: float, E_star: float) -> float:
    """Approach of first yield by Hertz, ω_c = R*(π C σ_Y/(2E*))², C = 1.295 e^(0.736 ν)
    (Jackson & Green 2005, :func:`spherecontact.peers.first_yield_approach`), the smallest over
    ``materials`` (the deformable bodies); inf when they are elastic."""
    return min((jg_first_yield(R_rel, E_star, m.sigma_y, m.nu) for m in materials), default=math.inf)


def first_step(options: SolverOptions, length: float, scale: float, first_yield: float) -> float:
    """The first loading step (:meth:`CycleLegs._strain_step`): dh_first · s² · R, at most
    strain_increment² · s · R, and at most the approach of first yield (not below dh_min · R)."""
    step = min(options.dh_first * scale**2, options.strain_increment**2 * scale) * length
    return min(step, max(first_yield, options.dh_min * length))


def start_of_loading(options: SolverOptions, material: Material, radius: float,
                     partner_radius: float, material2: Material | None = None) -> tuple[float, float]:
    """(first loading step, approach of first yield) of a scene: ``material`` of ``radius``
    against a rigid partner of ``partner_radius`` (inf: a flat; steps in units of the body's
    radius, scaled by s = min(1, partner/radius)), or against a deformable ``material2`` of
    ``partner_radius`` (two bodies: steps in units of the smaller radius, E* and R* of the pair)."""
    R_rel = 1.0 / (1.0 / radius + 1.0 / partner_radius)
    if material2 is None:
        h_y = first_yield_approach([material], R_rel, material.E_prime)
        return first_step(options, radius, min(1.0, partner_radius / radius), h_y), h_y
    bodies = [m for m in (material, material2) if math.isfinite(m.E)]
    h_y = first_yield_approach(bodies, R_rel, 1.0 / sum(1.0 / m.E_prime for m in bodies))
    return first_step(options, min(radius, partner_radius), 1.0, h_y), h_y


def check_unload_at(unload_at, h_max: float) -> np.ndarray:
    """The unloading approaches as an increasing array in (0, h_max]; ValueError otherwise."""
    if unload_at is None:
        return np.zeros(0)
    pts = np.atleast_1d(np.asarray(unload_at, dtype=float))
    if pts.ndim != 1 or pts.size == 0 or not np.all(np.isfinite(pts)):
        raise ValueError(f"unload_at must be a non-empty list of finite approaches, got {unload_at!r}")
    if np.any(pts <= 0) or np.any(pts > h_max * (1 + 1e-12)):
        raise ValueError(f"unload_at: every unloading approach must lie in (0, h_max] = (0, {h_max:g}], "
                         f"got {pts.tolist()}")
    if np.any(np.diff(pts) <= 0):
        raise ValueError(f"unload_at must be strictly increasing, got {pts.tolist()}")
    return np.minimum(pts, h_max)


def residual_approach(h: np.ndarray, F: np.ndarray) -> float:
    """Approach where an unloading curve reaches F = 0, from its last two points with F > 0 and
    the Hertzian end of unloading F ∝ (h − h_res)^{3/2} (Thornton 1997); linear if that fails."""
    (h1, h2), (F1, F2) = h[-2:], F[-2:]
    r = (F2 / F1) ** (2.0 / 3.0)
    h_res = (h2 - r * h1) / (1.0 - r) if r < 1.0 else h2
    if not (0.0 <= h_res <= h2):
        h_res = h2 - F2 * (h1 - h2) / (F1 - F2) if F1 > F2 else h2
    return float(max(h_res, 0.0))


def pole_radius(r: np.ndarray, z: np.ndarray, r_fit: float) -> float:
    """Curvature radius of a surface z(r) at the pole: least squares z = z₀ + r²/(2 R_p) over
    r ≤ r_fit (inf for a flat pole, negative for a dent that curves the other way)."""
    sel = r <= r_fit
    if sel.sum() < 3:
        return float("nan")
    A = np.stack([np.ones(sel.sum()), r[sel] ** 2 / 2], axis=1)
    (_, k), *_ = np.linalg.lstsq(A, z[sel], rcond=None)
    return float(1.0 / k) if k != 0 else float("inf")


def cycles_as_arrays(cycles: list[dict], n_surface: int) -> dict:
    """Per-cycle summaries as arrays (``CYCLE_KEYS``) plus the residual surface
    (``profile_r``, ``profile_z``: (n_cycles, n_surface) deformed r, z of the unloaded surface)."""
    out = {k: np.array([c[k] for c in cycles], dtype=float) for k in CYCLE_KEYS}
    for k in ("profile_r", "profile_z"):
        out[k] = np.array([c[k] for c in cycles], dtype=float).reshape(-1, n_surface)
    return out if cycles else {}


#: most loading increments a run may undo (:meth:`CycleLegs._back_up`), and the step it then
#: takes from the state before, as a fraction of the undone step
MAX_BACK_UPS = 10
BACK_UP_STEP = 0.3

#: a loading step that fails after contact caps the strain step at this fraction of its size
#: (``_RunState.step_factor``), and each easy increment lets the cap grow back by this factor
STEP_SHRINK = 0.7
STEP_RECOVERY = 1.03


#: the phases of a Newton iteration the solvers time (``timers``, ``timings[f"{phase}_s"]``):
#: the linear phase split into the linear solver's factorisation and triangular solves and the
#: rest (``constraints``: the system's set-up); ``predictor``: the tangent predictor's solves
PHASES = ("constitutive", "assembly", "contact", "constraints", "factorisation", "solve", "line_search",
          "predictor")


def phase_split(timings: dict) -> dict:
    """Milliseconds per Newton iteration of each of :data:`PHASES` a run timed (``RunResult.timings``;
    timings stored before a phase was split off lack it)."""
    n = max(timings["newton_iterations"], 1)
    return {k: round(1e3 * timings[f"{k}_s"] / n, 2) for k in PHASES if f"{k}_s" in timings}


def iteration_split(timings: dict) -> dict:
    """Milliseconds per Newton iteration: the whole run's and :func:`phase_split`."""
    n = max(timings["newton_iterations"], 1)
    return {"total": round(1e3 * timings["wall_s"] / n, 2), **phase_split(timings)}


@dataclass
class _RunState:
    """The state an incremental run carries from one converged increment to the next."""

    t_start: float
    u: np.ndarray
    state: PlasticState
    active: np.ndarray
    dh: float
    u_prev: np.ndarray | None = None
    dh_prev: float | None = None
    h: float = 0.0
    h_top: float = 0.0  # largest approach reached so far
    work: float = 0.0
    F: float = 0.0
    a: float = 0.0
    status: str = "converged"
    reason: str = "reached h_max"
    dh_cycle: float = 0.0  # increment of the current unloading branch and elastic reloading
    last_iterations: int = 0
    step_factor: float = 1.0  # multiplies the strain step; lowered where a step failed (STEP_SHRINK)
    cycle_base: dict = field(default_factory=lambda: {"work": 0.0, "dissipation": 0.0,
                                                      "energy_elastic": 0.0, "increment": 0})


class CycleLegs:
    """Loading, unloading and elastic reloading legs of an incremental run (docs/design.md §3b).

    The solver provides ``options``, ``_length`` (its length scale), ``_step_scale``, ``_hist`` (lists ``h``,
    ``F``, ``a``, ``a_nodes``, ``work_external``, ``dissipation``, ``energy_elastic``,
    ``branch``), ``_solve(run, h)`` (the converged increment or the exception),
    ``_commit(run, h, solved, branch)``, ``_solved_contact(solved)`` → (F, any contact),
    ``_pair_modulus()`` → E*, ``_start_of_loading()`` → (first step, approach of first yield;
    :func:`start_of_loading`), ``_residual_surface(u)`` → (r, z) of the contact surface and
    ``_tangent_predictor(u, dh)`` → the predicted displacements or None (:meth:`_predicted`).
    """

    def _walk(self, run: _RunState, h_max: float, unload: np.ndarray, targets=None) -> list[dict]:
        """Load to each unloading approach, unload, reload; then load to h_max. The cycles."""
        peaks = list(unload)
        if not peaks or peaks[-1] < h_max * (1 - 1e-12):
            peaks.append(h_max)
        cycles = []
        for peak in peaks:
            unloads = bool(unload.size) and bool(np.any(np.abs(unload - peak) <= 1e-12 * self._length))
            if not self._load_leg(run, peak, targets, cycle=unloads):
                break
            if unloads:
                cycle = self._unload_leg(run)
                if cycle is None:
                    break
                cycles.append(cycle)
        return cycles

    def _add_work(self, run: _RunState, h_new: float, F: float, branch: int) -> None:
        """External work of the increment to h_new: power law through the end points on loading
        (the first increment corrected with the exponent measured at the second), the parabola
        through the last three points on unloading and reloading."""
        hist = self._hist
        if branch == LOAD:
            run.work += work_increment(run.h, h_new, run.F, F)
            if len(hist.h) == 1 and run.F > 0 and F > run.F:
                p = np.log(F / run.F) / np.log(h_new / run.h)
                first = run.F * run.h / (p + 1.0)
                run.work += first - hist.work_external[0]
                hist.work_external[0] = first
        elif hist.branch and hist.branch[-1] == branch and len(hist.h) >= 2:
            run.work += quadratic_work(hist.h[-2], run.h, h_new, hist.F[-2], run.F, F)
        else:  # first interval of a branch
            run.work += 0.5 * (run.F + F) * (h_new - run.h)

    def _forget_tangent(self) -> None:
        """No stored tangent (a new run, a new linear solver): the next predictors are secants."""
        self._tangent = None  # the solver's matrix of its last linear solve (see _tangent_predictor)
        self._tangent_ready = False  # _tangent belongs to the last converged increment

    def _predicted(self, run: _RunState, dh: float, first) -> np.ndarray:
        """Displacements predicted for the next increment of ``dh``: ``first()`` for the first
        increment and the first after a reversal; the solver's ``_tangent_predictor`` when the
        option asks for it and the last converged increment's factors are at hand; else the
        secant of the last two increments. ``_commit`` marks the stored tangent as ready."""
        tangent_ready, self._tangent_ready = self._tangent_ready, False
        if run.u_prev is None:
            return first()
        if tangent_ready and self.options.predictor == "tangent":
            t0 = time.perf_counter()
            u_pred = self._tangent_predictor(run.u, dh)
            self.timers["predictor"] += time.perf_counter() - t0
            if u_pred is not None:
                return u_pred
        return run.u + (dh / run.dh_prev) * (run.u - run.u_prev)

    def _timed_linear(self, t0: float, step, *args):
        """``step(*args)``, the Newton step's linear phase begun at ``t0``, timed into
        ``factorisation`` and ``solve`` (the linear solver's own) and ``constraints`` (the rest:
        the system's or the penalty tangent's assembly, the pattern)."""
        lin = self.linear.times
        f0, s0 = lin["factorisation"], lin["solve"]
        out = step(*args)
        fact, solve = lin["factorisation"] - f0, lin["solve"] - s0
        self.timers["factorisation"] += fact
        self.timers["solve"] += solve
        self.timers["constraints"] += time.perf_counter() - t0 - fact - solve
        return out

    def _out_of_time(self, run: _RunState) -> bool:
        if time.perf_counter() - run.t_start > self.options.max_wall_s:
            run.status = "stopped"
            run.reason = (f"wall-time limit of {self.options.max_wall_s:g} s reached at "
                          f"h/R = {run.h / self._length:.6g}")
            return True
        return False

    def _cut_back(self, run: _RunState, dh: float, err) -> bool:
        """False (and the run stopped) when the halved increment falls below dh_min."""
        if 0.5 * dh < self.options.dh_min * self._length:
            run.status = "stopped"
            run.reason = (f"increment below dh_min = {self.options.dh_min:g} R at "
                          f"h/R = {run.h / self._length:.6g}: {err}")
            return False
        return True

    def _per_increment_lists(self) -> dict[str, list]:
        """Every list that grows by one entry per increment (the curves in ``self._hist``); a
        solver that keeps more per-increment records adds them."""
        return {k: v for k, v in vars(self._hist).items() if isinstance(v, list)}

    def _snapshot(self, run: _RunState, dh: float) -> tuple:
        """The run before an increment of ``dh`` is committed (for :meth:`_back_up`)."""
        return copy.copy(run), {k: len(v) for k, v in self._per_increment_lists().items()}, dh

    def _back_up(self, run: _RunState, before: tuple | None) -> bool:
        """Undo the last loading increment when every step from it has failed down to dh_min,
        and go on from the state before it with a step of ``BACK_UP_STEP`` × the undone one.

        A converged increment can end in a state Newton cannot leave: campaign v2, rigid sphere
        R2/R1 = 2.07, K/σY = 6.2, n = 0.149 (the flow stress rises by 1.6 σY within ε_p = 1e-4)
        converged to h/R = 6.3e-4 with its contact edge node flipping, frozen closed with a
        reaction of −4.2 % of F, and from there every increment failed down to dh_min. At most
        ``MAX_BACK_UPS`` per run; counted in ``timings["backed_up_increments"]``.
        """
        if before is None or self.backed_up_increments >= MAX_BACK_UPS:
            return False
        saved, lengths, dh = before
        vars(run).update(vars(saved))
        lists = self._per_increment_lists()
        for key, n in lengths.items():
            del lists[key][n:]
        run.dh = BACK_UP_STEP * dh
        self.backed_up_increments += 1
        return True

    def _strain_step(self, a_last: float, h: float) -> float:
        """Largest loading step: strain_increment · a (times the step scale s), a the contact
        radius reached; before contact the first step dh_first · s² · R, cut to the step whose own
        Hertz radius √(R·dh) satisfies the same bound (dh = strain_increment² · s · R) and to the
        approach of first yield (:func:`start_of_loading`, not below dh_min · R): the first step stays
        elastic and the elastic–plastic transition is crossed by steps that grow by ``growth``.

        A first step across the transition leaves the next increments biased, by more the stiffer
        the material: re-run from a first step of h₁/50, campaign v2's stored runs (h₁ = 2e-4 R)
        were 4.8 % low at 3 h₁ (flat, Ludwik K/σY 1.75, n 0.53, E/σY 1220), 3 % at 7 h₁
        (K/σY 10, n 0.6, E/σY 10⁴), and a run with the strain bound alone (h₁ = 2.5e-5 R, EPP
        E/σY 2500) 2.9 % low at 3–4 h₁.

        A first step of dh_first = 2e-4 R alone spans the elastic–plastic transition of a sphere
        with E/σY ≳ 500 (first yield at h/R ≈ 5e-6 for E/σY = 1000) in one increment; with
        segment-integrated penalty contact it converged and left F 3 % low at h/R = 1e-3 and
        0.8 % low at 3e-3 (path dependence), where the exact contact's first step had failed and
        been cut back to 2.5e-5 R.
        """
        opt, R, s = self.options, self._length, self._step_scale
        if a_last > 0.0 and h > 0.0:
            return max(opt.strain_increment * a_last * s, opt.dh_min * R)
        return self._start_of_loading()[0]

    def _load_leg(self, run: _RunState, peak: float, targets=None, cycle: bool = False) -> bool:
        """Load (elastic reloading first, below the largest approach reached) up to ``peak``;
        ``cycle``: ``peak`` is an unloading approach, and the loading steps above the largest
        approach reached are ≤ (peak − that)/(``CYCLE_LOADING`` · unload_increments).

        A step that fails after contact is halved, and the strain step is capped at
        ``STEP_SHRINK`` × the failed step's size from then on, the cap growing back by
        ``STEP_RECOVERY`` per easy increment: without the cap, growth by ``growth`` after easy
        increments brought the step back to the size that had failed within two increments, and
        the E/σY 10⁴ flat to h/R 0.3 failed 94 of its loading steps (111 s, 3830 factorisations,
        the failed increments' included); with it 24 (76 s, 2658), F at h/R 0.3 within 0.05 %.
        The equal EPP pair with penalty contact to h = 0.6 R (make verify-pair): 36 failed steps
        and 2383 factorisations against 135 and 2876 (437 s against 503 s, side by side).
        Recovery 1.1 instead of 1.03: 3069 on the stiff flat, 2132 on the pair."""
        opt, R = self.options, self._length
        cycle_step = (max((peak - run.h_top) / (CYCLE_LOADING * opt.unload_increments), opt.dh_min * R)
                      if cycle else math.inf)
        before = None  # the run before the last loading increment (_back_up)
        while run.h < peak * (1 - 1e-12):
            if self._out_of_time(run):
                return False
            if run.h < run.h_top * (1 - 1e-12):  # elastic reloading up to the previous maximum
                dh, branch = min(run.dh_cycle, run.h_top - run.h), RELOAD
            else:
                a_last = self._hist.a_nodes[-1] if self._hist.a_nodes else 0.0
                if targets is not None:
                    ahead = targets[targets > run.h * (1 + 1e-12)]
                    run.dh = min(run.dh, (ahead[0] if ahead.size else peak) - run.h)
                else:
                    strain = self._strain_step(a_last, run.h)
                    relative = opt.relative_step * run.h if opt.relative_step and a_last > 0.0 else math.inf
                    run.dh = min(run.dh, peak - run.h, opt.dh_max * R, run.step_factor * strain, cycle_step,
                                 relative)
                dh, branch = run.dh, LOAD
            solved = self._solve(run, run.h + dh)
            if isinstance(solved, Exception):
                if branch == LOAD and targets is None and a_last > 0.0:
                    run.step_factor = min(run.step_factor, STEP_SHRINK * dh / strain)
                if not self._cut_back(run, dh, solved):
                    factor = run.step_factor
                    if branch == LOAD and self._back_up(run, before):
                        run.step_factor = min(run.step_factor, factor)
                        before = None
                        continue
                    return False
                if branch == RELOAD:
                    run.dh_cycle *= 0.5
                else:
                    run.dh *= 0.5
                continue
            before = self._snapshot(run, dh) if branch == LOAD else None
            self._commit(run, run.h + dh, solved, branch)
            if branch == LOAD:
                if targets is not None:
                    run.dh = np.inf
                elif run.last_iterations <= opt.easy_iterations:
                    run.dh *= opt.growth
                    run.step_factor = min(1.0, run.step_factor * STEP_RECOVERY)
        return True

    def _unload_leg(self, run: _RunState) -> dict | None:
        """Unload from the current approach until the force vanishes; the cycle's summary.

        Increments: about ``options.unload_increments`` over the elastic recovery estimated from
        Sneddon's initial stiffness 2E*a, Δh ≈ 1.5 F_max/(2E*a); one cut back after a failed
        increment grows again (``growth``) after each easy one, up to that step. The last increment lands on
        h_res, extrapolated from the last two points with F > 0 (:func:`residual_approach`).
        When an increment fails once F ≤ ``UNLOAD_TAIL`` F_max (the contact of a nearly
        unloaded body opening at once), the branch ends there with h_res extrapolated the same
        way and the force reached kept as ``F_end`` (0 when the branch reached F = 0).
        """
        hist, R = self._hist, self._length
        i_peak = len(hist.h) - 1
        h_peak, F_peak, a_peak = run.h, run.F, run.a
        E_star = self._pair_modulus()
        recovery = 1.5 * F_peak / (2.0 * E_star * a_peak) if a_peak > 0 else run.h
        run.dh_cycle = max(min(recovery, run.h) / self.options.unload_increments, self.options.dh_min * R * 4)
        run.u_prev = None
        dh = run.dh_cycle
        lost, h_lost, tail = False, 0.0, False

        def extrapolated_h_res() -> float:  # from the branch's last two points with F > 0
            return residual_approach(np.array(hist.h[i_peak:]), np.array(hist.F[i_peak:]))

        while True:
            if self._out_of_time(run):
                return None
            if not lost:
                h_new = run.h - dh
            elif len(hist.h) - i_peak >= 2:
                h_new = min(max(extrapolated_h_res(), h_lost), run.h)
            else:
                h_new = 0.5 * (run.h + h_lost)
            if h_new <= 0.0:
                h_new, lost = 0.0, True
            solved = self._solve(run, h_new)
            if isinstance(solved, Exception):
                if run.F <= UNLOAD_TAIL * F_peak and len(hist.h) - i_peak >= 3:
                    tail = True  # the force has all but vanished: h_res extrapolated below
                    break
                if not self._cut_back(run, dh, solved):
                    return None
                dh *= 0.5
                continue
            F_new, in_contact = self._solved_contact(solved)
            if lost or (F_new > 1e-9 * F_peak and in_contact):
                self._commit(run, h_new, solved, UNLOAD)
                if lost or h_new == 0.0:
                    break
                if run.last_iterations <= self.options.easy_iterations:  # back to the design step
                    dh = min(dh * self.options.growth, run.dh_cycle)
                continue
            lost, h_lost = True, h_new  # contact lost between run.h and h_new: land on h_res next
        base = run.cycle_base
        i_end = len(hist.h) - 1
        xs = self._residual_surface(run.u)
        h_res = min(max(extrapolated_h_res(), 0.0), run.h) if tail else run.h
        cycle = {"h_max": h_peak, "F_max": F_peak, "a_max": hist.a[i_peak], "h_res": h_res,
                 "pole_radius": pole_radius(xs[0], xs[1], 0.5 * hist.a[i_peak]),
                 "work_in": hist.work_external[i_peak] - base["work"],
                 "work_returned": hist.work_external[i_peak] - hist.work_external[i_end],
                 "dissipation": hist.dissipation[i_end] - base["dissipation"],
                 "elastic_energy_change": hist.energy_elastic[i_end] - base["energy_elastic"],
                 "increment_start": base["increment"], "increment_peak": i_peak, "increment_end": i_end,
                 "F_end": hist.F[i_end] if tail else 0.0,
                 "profile_r": xs[0].copy(), "profile_z": xs[1].copy()}
        run.cycle_base = {"work": hist.work_external[i_end], "dissipation": hist.dissipation[i_end],
                          "energy_elastic": hist.energy_elastic[i_end], "increment": i_end + 1}
        run.u_prev = None
        return cycle


class IndentationSolver(CycleLegs):
    """Hemisphere (radius R, material) on a rigid obstacle; call ``run(h_max)``."""

    def __init__(self, material: Material, radius: float = 1.0, obstacle: RigidObstacle | None = None,
                 density: float = 1.0, element: str = "q8r", options: SolverOptions | None = None,
                 edge_band: float = 0.0, band_floor: float | None = None, *, options_checked: bool = False):
        if material.is_rigid:
            raise ValueError("the deformable body must not be rigid (E = inf)")
        self.material = material
        self.radius = float(radius)
        self.obstacle = obstacle or RigidObstacle()
        self.options = options or SolverOptions()
        if not options_checked:  # io.run_checked passes options io.check_inputs validated
            self.options.validate()
        t0 = time.perf_counter()
        self.hmesh = build_mesh(self.radius, density, linear=(element == "q4"), edge_band=edge_band,
                                band_floor=band_floor)
        self.disc = Discretisation(self.hmesh, element)
        self.t_setup = time.perf_counter() - t0
        hm, nd = self.hmesh, self.disc.n_dofs
        self.arc = hm.surface  # ordered from the pole; the last node is the equator corner
        self.surface = self.arc[:-1]  # contact candidates
        self.X = hm.X
        self.on_axis = np.isin(self.surface, hm.axis)
        self.fixed_base = np.concatenate([2 * hm.equator + 1, 2 * hm.axis])  # u_z equator, u_r axis
        self.n_points = self.disc.n_elements * self.disc.n_qp
        self._elastic = None  # points Newton keeps elastic in the current increment
        self.timers = dict.fromkeys(PHASES, 0.0)  # seconds per phase of the run
        self._diag_slots = self.disc.slots(np.arange(nd), np.arange(nd))
        self._upper = ConstrainedPattern(*self.disc.csr_pattern)
        self._nd = nd
        self.k_penalty = None
        self._forget_tangent()  # _tangent: (K, fixed dofs, their diagonal value, nodal frames)
        if self.options.penalty is not None:
            x_arc = self.X[:, self.arc]
            pole_edge = float(np.hypot(*(x_arc[:, 2] - x_arc[:, 0])))
            self.k_penalty = self.options.penalty * material.E / pole_edge
            self.area0 = surface_areas(x_arc)[:-1]
        self.segments = None
        if self.options.segment_scheme != "points":
            raise ValueError(f"segment_scheme {self.options.segment_scheme!r} is for two deformable bodies; "
                             "a rigid obstacle takes 'points'")
        if self.options.segment_points:
            self.segments = SegmentPenalty(self.X[:, self.arc], self.k_penalty, self.options.segment_points)
            na = self.arc[self.segments.edges]  # (e, 3) nodes of each edge
            self._seg_slots = self.disc.node_block_slots(
                np.repeat(na, 3, axis=1).ravel(), np.tile(na, (1, 3)).ravel()).reshape(-1, 3, 3, 2, 2)

    @staticmethod
    def _nodal(v: np.ndarray, nodes: np.ndarray) -> np.ndarray:
        """(2, n) r and z components of an interleaved nodal vector at ``nodes``."""
        return np.stack([v[2 * nodes], v[2 * nodes + 1]])

    # ------------------------------------------------------------------ penalty contact
    def _penalty_force(self, u: np.ndarray):
        """Penalty contact at u: gap, normal, curvature, penetrating nodes, nodal force
        magnitudes p_i = k_N A_i (−g_i) and the assembled contact force vector."""
        gap, normal, curv = self.obstacle.gap_normal(self.X[:, self.surface] + self._nodal(u, self.surface))
        fc = np.zeros(self._nd)
        if self.segments is not None:  # pressure integrated over the edges (segment_penalty.py)
            points = self.segments.evaluate(self.X[:, self.arc] + self._nodal(u, self.arc), self.obstacle)
            force = points[4]
            fc[2 * self.arc], fc[2 * self.arc + 1] = force
            p = np.einsum("ci,ci->i", force[:, :-1], normal)  # normal reaction of each surface node
            return gap, normal, curv, p > 0.0, p, fc, points
        pen = gap < 0.0
        p = np.where(pen, self.k_penalty * self.area0 * -gap, 0.0)
        fc[2 * self.surface] = p * normal[0]
        fc[2 * self.surface + 1] = p * normal[1]
        return gap, normal, curv, pen, p, fc, None

    def _penalty_tangent(self, data, gap, normal, curv, pen, points=None):
        """Add ∂(−f_c)/∂u = k_N A [n nᵀ + g κ (I − n nᵀ)] at the penetrating nodes (κ: 1/|x − c|),
        or the segment-integrated blocks of :class:`SegmentPenalty`."""
        if points is not None:
            np.add.at(data, self._seg_slots, self.segments.tangent_blocks(*points[:4]))
            return data
        idx = np.flatnonzero(pen)
        nodes = self.surface[idx]
        kA = self.k_penalty * self.area0[idx]
        n, gk = normal[:, idx], gap[idx] * curv[idx]
        nn = np.einsum("ik,jk->kij", n, n)
        blocks = kA[:, None, None] * (nn + gk[:, None, None] * (np.eye(2) - nn))
        np.add.at(data, self.disc.node_block_slots(nodes, nodes), blocks)
        return data

    # ------------------------------------------------------------------ one Newton solve
    def _frames(self, active: np.ndarray, normal: np.ndarray):
        """Nodal frames Q (u = Q ũ, Q = Qᵀ = Q⁻¹) of the active off-axis nodes on a curved
        obstacle, and the constrained local dofs carrying the contact condition."""
        nodes = self.surface[active]
        if self.obstacle.is_flat:
            return None, 2 * nodes + 1
        rot = active & ~self.on_axis
        rn = self.surface[rot]
        n_r, n_z = normal[:, rot]
        # u = n ũ_n + t ũ_t with t = (n_z, −n_r): local dof 2i ↔ ũ_n, 2i+1 ↔ ũ_t
        Q = np.stack([np.stack([n_r, n_z], -1), np.stack([n_z, -n_r], -1)], 1)
        on_axis_nodes = self.surface[active & self.on_axis]
        return (rn, Q), np.concatenate([2 * rn, 2 * on_axis_nodes + 1])

    @staticmethod
    def _rotate(v: np.ndarray, frames) -> np.ndarray:
        """T v for the nodal frames (T = Tᵀ = T⁻¹: global ↔ local components)."""
        if frames is None:
            return v
        nodes, Q = frames
        out = v.copy()
        pairs = out.reshape(-1, 2)
        pairs[nodes] = np.einsum("nab,nb->na", Q, pairs[nodes])
        return out

    def _exact_contact(self, f, gap, normal, active, log):
        """Lagrange-multiplier contact: reactions, active-set update, nodal frames, and the
        rotated residual and prescribed normal displacements of the constrained dofs."""
        lam = np.einsum("ci,ci->i", self._nodal(f, self.surface), normal)
        changed = False
        if not log["frozen"]:
            active, changed = update_active_set(active, lam, gap, 1e-12 * self.radius, log)
        frames, cdofs = self._frames(active, normal)
        r = self._rotate(f, frames)
        du_c = np.zeros(self._nd)
        du_c[cdofs] = -gap[active] if self.obstacle.is_flat else np.concatenate(
            [-gap[active & ~self.on_axis], -gap[active & self.on_axis]])
        return lam, changed, active, frames, cdofs, r, du_c

    def _exact_tangent(self, data, lam, normal, curv, active, frames):
        """The tangent data of exact contact: the obstacle's curvature term −λκ t tᵀ at the
        active off-axis nodes, rotated into their nodal frames (the pattern is unchanged)."""
        if frames is None:
            return data
        idx = np.flatnonzero(active & ~self.on_axis)
        nodes = self.surface[idx]
        n = normal[:, idx]
        tt = np.stack([n[1], -n[0]])
        blocks = -(lam[idx] * curv[idx])[:, None, None] * np.einsum("ik,jk->kij", tt, tt)
        data = data.copy()
        np.add.at(data, self.disc.node_block_slots(nodes, nodes), blocks)
        return self.disc.rotate_blocks(data, *frames)

    def _newton(self, u: np.ndarray, h: float, state: PlasticState, active: np.ndarray):
        opt = self.options
        disc, mat = self.disc, self.material
        R = self.radius
        Xs = self.X[:, self.surface]
        log = new_active_log()
        res_hist = log["res"]
        self._elastic = None  # points kept elastic in this increment (freeze_toggling)
        known = None  # (F, real stress update, internal force) at u from the line search
        for it in range(opt.max_iterations):
            t0 = time.perf_counter()
            if known is None:
                Fv = disc.deformation_gradient(u)
                if not positive_jacobian(Fv):
                    raise IncrementFailed("inverted element (J <= 0)")
                upd = stress_update(Fv, state.cp_inv, state.eps_p, mat, elastic=self._elastic)
                f = disc.internal_force(upd.P)
            else:
                Fv, upd, f = known
            t1 = time.perf_counter()
            # the residual first: the tangent is built only when Newton goes on
            if self.k_penalty is not None:
                gap, normal, curv, pen, p, fc, points = self._penalty_force(u)
                changed = not np.array_equal(pen, active)
                active = pen
                self._points = points
                r, frames, cdofs = f - fc, None, np.zeros(0, dtype=int)
                lam = p
                du_c = np.zeros(self._nd)
                log["changes"] += changed
            else:
                gap, normal, curv = self.obstacle.gap_normal(Xs + self._nodal(u, self.surface))
                lam, changed, active, frames, cdofs, r, du_c = self._exact_contact(
                    f, gap, normal, active, log)
            fixed = np.concatenate([self.fixed_base, cdofs])
            free = np.ones(self._nd, dtype=bool)
            free[fixed] = False
            ref = max(np.abs(r[fixed]).max(), 1e-300)
            res = float(np.abs(r[free]).max()) / ref
            # roundoff floor: F = I + ∇u carries strains next to 1, so stresses carry an
            # absolute error ~1e-16 M per operation and nodal forces ~1e-15 M R² (matters at
            # h ≲ 1e-5 R, and near zero force on unloading)
            floor = ROUNDOFF * stiffest_modulus(mat) * R**2 / ref
            res_hist.append(res)
            self._elastic = freeze_toggling(log, upd.dgamma > 0, self._elastic)
            t2 = time.perf_counter()
            self.timers["constitutive"] += t1 - t0
            self.timers["contact"] += t2 - t1
            if not np.isfinite(res) or res > 1e6:
                raise IncrementFailed(f"Newton diverged (relative residual {res:.2e})")
            if not changed and res <= max(opt.tol, floor) and np.abs(du_c).max(initial=0.0) <= 1e-12 * R:
                self.plastic_frozen_increments += log.get("plastic_frozen", False)
                return (u, upd, active, it, log["changes"], res_hist, f, gap, np.where(active, lam, 0.0),
                        normal)
            A = tangent(Fv, state, mat, upd)
            t3 = time.perf_counter()
            data = disc.tangent(A).data
            t4 = time.perf_counter()
            if self.k_penalty is not None:
                data = self._penalty_tangent(data.copy(), gap, normal, curv, active, points)
            else:
                data = self._exact_tangent(data, lam, normal, curv, active, frames)
            t5 = time.perf_counter()
            self.timers["constitutive"] += t3 - t2
            self.timers["assembly"] += t4 - t3
            self.timers["contact"] += t5 - t4
            du = self._timed_linear(t5, self._newton_step, data, r, du_c, fixed, frames)
            t6 = time.perf_counter()
            u, known = self._line_search(u, du, free, frames, state, r[free],
                                         restores_contact(du_c, du))
            self.timers["line_search"] += time.perf_counter() - t6
        raise IncrementFailed(f"no convergence in {opt.max_iterations} iterations "
                              f"(last relative residual {res_hist[-1]:.2e})")

    def _newton_step(self, data, r, du_c, fixed, frames) -> np.ndarray:
        """Newton's step du with K du = −r on the free dofs (K: the tangent's CSR ``data``; where
        Cholesky refuses it, K shifted by ``definite_shift``) and du = ``du_c`` on the ``fixed``
        ones, in global components; K is kept for the tangent predictor."""
        K = self.disc.matrix(data)
        rhs = -r - K @ du_c
        scale = float(np.abs(data[self._diag_slots]).mean())
        rhs[fixed] = scale * du_c[fixed]
        U, diag = self._upper.upper(data, fixed, scale)
        shift = self.options.definite_shift
        definite = (lambda: shifted_diagonal(U, diag, shift)) if shift > 0 else None
        du = self.linear.solve_upper(U, diag, rhs, self._upper, definite)
        self._tangent = (K, fixed, scale, frames)
        du[fixed] = du_c[fixed]
        return self._rotate(du, frames)

    def _line_search(self, u, du, free, frames, state, r0, prescribed=False, max_steps: int = 4):
        """u + α du by an energy line search (Crisfield 1991, §9.3).

        s(α) = du_f · r_f(u + α du) is the slope of the potential along the step;
        α = 1 is taken when |s(1)| ≤ ½|s(0)|, otherwise α moves to the secant zero
        of s (clipped to [0.1, 1]). Steps that would invert an element are halved.
        Returns the new u and, when the accepted step was evaluated, its
        (F, real stress update, internal force) for the next iteration.
        """
        if not self.options.line_search:
            return self._admissible(u, du)[0], None
        duf = self._rotate(du, frames)[free]
        s0 = float(np.dot(duf, r0))
        if s0 >= 0.0:
            return self._admissible(u, du)[0], None
        alpha, lo, s_lo = 1.0, 0.0, s0
        for _ in range(max_steps):
            trial, beta, Fv = self._admissible(u, alpha * du)
            alpha *= beta
            real = stress_update(Fv, state.cp_inv, state.eps_p, self.material, elastic=self._elastic)
            f = self.disc.internal_force(real.P)
            known = (Fv, real, f)
            r = self._rotate(f, frames)
            if self.k_penalty is not None:
                r = f - self._penalty_force(trial)[5]
            s_a = float(np.dot(duf, r[free]))
            if abs(s_a) <= 0.5 * abs(s0):
                return trial, known
            if alpha == 1.0 and prescribed:
                return trial, known  # the step puts penetrating nodes back on the obstacle
            if s_a < 0.0:  # still descending: the zero lies beyond α
                return trial, known
            new = lo + (alpha - lo) * s_lo / (s_lo - s_a)
            alpha = float(np.clip(new, 0.1 * alpha, alpha))
        return trial, known  # the last admissible step tried

    def _admissible(self, u, du):
        """(u + β du, β, F there): :func:`admissible_step` on the one body."""
        trial, beta, (Fv,) = admissible_step(u, du, lambda x: (self.disc.deformation_gradient(x),))
        return trial, beta, Fv

    # ------------------------------------------------------------------ increments and legs
    def _solve(self, run: _RunState, h_new: float):
        """Newton for one increment to approach ``h_new`` from the run's state; returns the
        converged tuple of :meth:`_newton`, or the exception when it failed (recorded)."""
        dh = h_new - run.h
        if self.options.penalty_scale == "approach" and h_new > run.h_top:
            self._approach_stiffness(run, h_new)

        def first():  # at h = 0 a rigid translation by dh/2: its intersection radius √(R dh) is Hertz's a
            u_pred = run.u.copy()
            if run.h == 0.0:
                u_pred[1::2] -= 0.5 * dh
            return u_pred

        u_pred = self._predicted(run, dh, first)
        u_pred[2 * self.hmesh.equator + 1] = -h_new
        u_pred[2 * self.hmesh.axis] = 0.0
        try:
            return self._newton(u_pred, h_new, run.state, run.active.copy())
        except (IncrementFailed, RuntimeError, np.linalg.LinAlgError) as err:
            self.rejected.append((h_new, dh, str(err)))
            return err

    def _tangent_predictor(self, u: np.ndarray, dh: float) -> np.ndarray | None:
        """u + Δu with K Δu = 0 on the free dofs and Δu_z = −dh on the equator: the step the
        last converged increment's tangent K (its last factorisation, reused: one pair of
        triangular solves) gives for the next approach step, the active contact nodes held on
        the obstacle. None when that factorisation is not at hand.

        The secant predictor extrapolates the last increment's displacement change, which
        carries the jump of every surface node that closed in it; the tangent carries the
        present contact set only. Standard run (EPP E/σY 200, flat, h/R 0.3): 1097 → 993
        Newton iterations; rigid sphere 2R: 1031 → 951 (both side by side on two cores).
        """
        K, fixed, scale, frames = self._tangent
        du_c = np.zeros(self._nd)
        du_c[2 * self.hmesh.equator + 1] = -dh
        rhs = -(K @ du_c)
        rhs[fixed] = scale * du_c[fixed]
        du = self.linear.resolve(rhs)
        if du is None or not np.all(np.isfinite(du)):
            return None
        du[fixed] = du_c[fixed]
        return u + self._rotate(du, frames)

    def _approach_stiffness(self, run: _RunState, h_new: float) -> None:
        """k_N = penalty · p_m / h for a loading increment to ``h_new`` (penalty_scale "approach").

        Node-to-surface contact lets the contact edge advance one surface node at a time; in the
        fully plastic regime each node that closes adds a ring of nearly full pressure at once,
        and F(h) climbs in steps of about 2Δs/a. With the pressure integrated over the edges
        (``segment_points``) and k_N = P p_m/h, a closing edge is pressed in over about h/P and
        takes its pressure gradually; the penetration is then the same fraction 1/P of the
        approach at every h, and the body's own shortening (curve ``h``) excludes it
        (:func:`approach_pressure`).
        """
        R_rel = 1.0 / (1.0 / self.radius + 1.0 / self.obstacle.radius)
        p_m = approach_pressure(run, h_new, self._pair_modulus(), R_rel)
        self.k_penalty = self.options.penalty * p_m / h_new
        if self.segments is not None:
            self.segments.k_n = self.k_penalty

    def _contact_force(self, lam, normal) -> float:
        """Axial contact force of a converged state."""
        if self.segments is not None:
            return float(self._points[4][1].sum())
        return float(np.sum(lam * normal[1]))

    @property
    def _length(self) -> float:
        return self.radius

    @property
    def _step_scale(self) -> float:
        """s = min(1, R_indenter/R): loading steps ≤ s · strain_increment · a, first s² · dh_first · R.

        On campaign v2's band mesh (edge_band 0.03) a rigid sphere of R_indenter/R = 0.337
        (K/σY = 4.6, n = 0.54, E/σY = 548) stopped at h/R = 3.7e-4 with the default steps
        (Newton diverged; 2024-T351 under R/2: inverted elements at 3.3e-4, and at 9.5e-4 with
        dh_first alone divided by 10); with strain_increment 0.002 and dh_first 2e-5 it reached
        h/R = 0.003 (113 increments). Flats and larger spheres keep the default steps.
        """
        return min(1.0, self.obstacle.radius / self.radius)

    def _solved_contact(self, solved) -> tuple[float, bool]:
        return self._contact_force(solved[8], solved[9]), bool(np.any(solved[2]))

    def _pair_modulus(self) -> float:
        return self.material.E / (1.0 - self.material.nu**2)  # rigid partner: E* = E'

    def _start_of_loading(self) -> tuple[float, float]:
        return start_of_loading(self.options, self.material, self.radius, self.obstacle.radius)

    def _residual_surface(self, u: np.ndarray) -> np.ndarray:
        return self.X[:, self.surface] + self._nodal(u, self.surface)

    def _commit(self, run: _RunState, h_new: float, solved, branch: int) -> None:
        """Record a converged increment and make it the run's state."""
        hist = self._hist
        u_new, upd, act, its, changes, res_hist, f, gap, lam, normal = solved
        self._tangent_ready = self._tangent is not None
        state = run.state
        diss_inc = plastic_dissipation(self.disc, self.material, state.eps_p, upd.dgamma)
        run.state = PlasticState(upd.cp_inv, upd.eps_p, state.dissipation + diss_inc)
        dh = h_new - run.h
        run.u_prev, run.u, run.dh_prev, run.active = run.u, u_new, dh, act
        F_support = -float(f[2 * self.hmesh.equator + 1].sum())
        xs = self.X[:, self.surface] + self._nodal(u_new, self.surface)
        F = self._contact_force(lam, normal)
        areas = surface_areas(self.X[:, self.arc] + self._nodal(u_new, self.arc))[:-1]
        pressure = np.where(act, lam / areas, 0.0)
        a_nodes, a_sub, a_ref = contact_edge(self.X[0, self.surface], xs[0], gap, act,
                                              self.options.edge_fit)
        if self.segments is not None:  # where the gap of the points crosses zero
            a_ref = self.segments.contact_radius(self._points[0])
            a_sub = float(np.interp(a_ref, self.X[0, self.surface], xs[0]))
        self._add_work(run, h_new, F, branch)
        run.h, run.F, run.a = h_new, F, a_ref
        run.h_top = max(run.h_top, h_new)
        hist.h.append(h_new)
        hist.F.append(F)
        hist.F_support.append(F_support)
        hist.a.append(a_sub)
        hist.a_nodes.append(a_nodes)
        hist.a_ref.append(a_ref)
        hist.eps_p_max.append(float(run.state.eps_p.max()))
        hist.penetration.append(float(max(-gap.min(initial=0.0), 0.0)))
        hist.h_pole.append(h_new + float(u_new[2 * self.surface[0] + 1]))
        hist.work_external.append(run.work)
        hist.energy_elastic.append(self.disc.integrate(upd.psi))
        hist.dissipation.append(run.state.dissipation)
        hist.iterations.append(its)
        hist.active_changes.append(changes)
        hist.residuals.append(res_hist)
        hist.profile_r.append(xs[0].copy())
        hist.profile_p.append(pressure)
        # penalty contact: the closed nodes' gap is their penetration
        hist.profile_g.append(gap if self.k_penalty is not None else np.where(act, 0.0, gap))
        hist.branch.append(branch)
        if self._progress is not None:
            self._progress(h_new)
        run.last_iterations = its

    # ------------------------------------------------------------------ the incremental run
    def run(self, h_max: float, progress=None, schedule=None, unload_at=None) -> RunResult:
        """Press the hemisphere to approach ``h_max``; ``progress(h)`` is called per increment.

        ``schedule``: increasing approaches the run steps to instead of its adaptive
        increments (cut back only where one fails), e.g. another run's approaches, so two runs
        compare without the path dependence of plasticity on the increment sequence.
        ``unload_at``: increasing approaches in (0, h_max] at which the body is unloaded until
        the force vanishes and then reloaded (:func:`check_unload_at`); every increment is
        labelled in ``curves["branch"]`` (0 load, 1 unload, 2 reload) and each unloading
        branch is summarised in ``result.cycles``.
        """
        R = self.radius
        h_max = float(h_max)
        if not (np.isfinite(h_max) and 0 < h_max <= 0.8 * R):
            raise ValueError(f"h_max must lie in (0, 0.8 R] = (0, {0.8 * R:g}], got {h_max!r}")
        unload = check_unload_at(unload_at, h_max)
        if unload.size and schedule is not None:
            raise ValueError("schedule and unload_at cannot be combined (schedule: monotone loading)")
        opt = self.options
        run = _RunState(t_start=time.perf_counter(), u=np.zeros(self._nd),
                        state=PlasticState.virgin(self.n_points),
                        active=np.zeros(self.surface.size, dtype=bool),
                        dh=opt.dh_first * R * self._step_scale**2)
        for k in self.timers:
            self.timers[k] = 0.0
        self.linear = SymmetricSolver(opt.linear_solver)
        self._forget_tangent()
        self.rejected = []
        self.plastic_frozen_increments = 0
        self.backed_up_increments = 0
        hist = History()
        self._hist, self._progress = hist, progress
        targets = None
        if schedule is not None:
            targets = np.asarray(schedule, dtype=float)
            if targets.ndim != 1 or np.any(np.diff(targets) <= 0) or not np.all(targets > 0):
                raise ValueError("schedule must be an increasing sequence of approaches > 0")
            targets = np.append(targets[targets < h_max * (1 - 1e-12)], h_max)
            run.dh = np.inf
        cycles = self._walk(run, h_max, unload, targets)
        status, reason = run.status, run.reason
        u, state = run.u, run.state
        wall = time.perf_counter() - run.t_start
        curves = {k: np.asarray(getattr(hist, k), dtype=float) for k in (
            "h", "F", "F_support", "a", "a_nodes", "a_ref", "eps_p_max", "work_external",
            "energy_elastic", "dissipation", "iterations", "active_changes", "branch")}
        if self.k_penalty is not None:  # penalty contact: the obstacle presses into the body
            curves["penetration"] = np.asarray(hist.penetration, dtype=float)
            curves["h_applied"] = curves["h"]
            curves["h"] = np.asarray(hist.h_pole, dtype=float)  # the body's own shortening
            if cycles:
                for cycle in cycles:
                    cycle["h_max"] = hist.h_pole[cycle["increment_peak"]]
        finish_curves(curves)  # a: sub-element estimates smoothed over increments
        nsurf = self.surface.size
        prof_r = np.array(hist.profile_r).reshape(-1, nsurf)
        prof_p = np.array(hist.profile_p).reshape(-1, nsurf)
        prof_g = np.array(hist.profile_g).reshape(-1, nsurf)
        timings = {"wall_s": wall, "setup_s": self.t_setup, **{f"{k}_s": v for k, v in self.timers.items()},
                   "increments": len(hist.h), "newton_iterations": int(curves["iterations"].sum()),
                   "rejected_increments": len(self.rejected),
                   "plastic_frozen_increments": self.plastic_frozen_increments,
                   "backed_up_increments": self.backed_up_increments,
                   **{f"linear_{k}": v for k, v in self.linear.stats.items()}}
        final = {"X": self.X, "u": u, "cells": self.disc.basis.element_dofs.T.copy(),
                 "eps_p": state.eps_p.reshape(self.disc.n_elements, self.disc.n_qp)}
        inputs = {"material": self.material.describe(), "radius": R,
                  "indenter_radius": float(self.obstacle.radius), "h_max": h_max,
                  "mesh_density": self.hmesh.density, "edge_band": self.hmesh.edge_band,
                  "band_floor": self.hmesh.band_floor, "element": self.disc.element,
                  "n_elements": self.disc.n_elements, "n_dofs": self._nd,
                  "options": self.options.as_inputs()}
        inputs["unload_at"] = [float(x) for x in unload]
        return RunResult(inputs=inputs, curves=curves, residuals=hist.residuals,
                         profile_r=prof_r, profile_p=prof_p, profile_g=prof_g, status=status, reason=reason,
                         timings=timings, final=final, cycles=cycles_as_arrays(cycles, self.surface.size))
