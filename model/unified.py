"""Two dissimilar spheres — the unified model (docs/design.md §3).

The interface bends to a curvature κ; body i sees the relative radius ρ_i:

    1/ρ_1 = 1/R_1 − κ,   1/ρ_2 = 1/R_2 + κ,   1/ρ_1 + 1/ρ_2 = 1/R*.

For a given contact radius a, κ follows from equal mean pressures

    p_m = H̄(Λ_1) σ_rep,1 = H̄(Λ_2) σ_rep,2,   Λ_i = E'_i a/(σ_rep,i ρ_i),

and h_i = a²/(2 c_i² ρ_i), h = h_1 + h_2, F = π a² p_m (with ``counter_cap = "exact"``,
h_i = (a²/(2ρ_i) + w_i e_i)/c_i², e_i the depth of the partner's cap beyond its paraboloid and
w_i its weight, ``cap.py``). The κ root is found in the
variable u = ln(ρ_2/ρ_1) (ρ_1/R* = 1 + e^(−u)), where g(u) = ln p_1 − ln p_2 increases
monotonically; in Level I the root is u = ln(E'_2/E'_1) (ρ_i = E'_i R*/E*, Hertz).

Interface coupling (``Coefficients.interface_coupling`` λ, calibrated on the two-body runs):
once both bodies are plastic, p_m depends on ρ_i only through H̄(Λ_i), which flattens as
Λ_i → Λ_III, so near-equal hardness leaves the equal-pressure condition nearly neutral. The FE
with smooth frictionless contact surfaces follows it: two EPP spheres of equal σ_Y and E ratio
3 move from the Hertz partition h_1/h = 0.75 to 0.96 at h/R = 0.3, converged under mesh
refinement (``calibration/interface.py``). Equal pressures alone overshoot early (6 points at
h/R 0.06) and, for extreme pairs, lose the uniqueness of the root (E/σY 3·10⁴ against 150,
R_2 = 2R_1: F(h) falls where the root jumps). The interface equation is therefore

    g(u) = ln p_1 − ln p_2 + C(a) (u − u_A(a)) = 0,
    C = λ f_E s_1 s_2 exp(−(ln(P_1/P_2)/δ)²),   u_A = u_H/(1 + (a/(a_c R*))^k),
    f_E = u_H²/(u_H² + ε²),  u_H = ln(E'_2/E'_1),  ε = 0.1,

with s_i the level weights (0 in Level I, 1 in Level III) and P_i = H̄_III σ_rep,i the fully
plastic pressures of both bodies at the Hertz partition x_i = a/ρ_i,H. The coupling acts only
where both bodies are plastic and their fully plastic pressures are within about δ of each
other (the ill-conditioned case), and only where their moduli differ (f_E: the neutral drift
is driven by the E-dependence of H̄(Λ) in Level II; equal materials of unequal radii keep the
equal-pressure split). The calibrated anchor is the Hertz partition itself (a_c = ∞, u_A =
u_H), a weak pull (λ = 0.01 in the file of 2026-11-28) that keeps the root unique; a finite
a_c moves the anchor to equal strains x_1 = x_2 (u = 0) as the contact deepens (files before
2026-11-28, fitted to nodal-contact FE whose interlocked surfaces held the split). C and u_A do
not depend on u, so g still rises with u and the root is unique; C = 0 while either body is elastic or in
Level I (the Hertz split stays exact), and equal materials (u_H = 0) are left alone. The
contact pressure is then √(p_1 p_2) (p_1 = p_2 for λ = 0).

Scenes that need no κ solve: equal materials (with the finite-size ratio a/ρ or equal
radii: ρ_1 = ρ_2 = 2R*) and a rigid partner (ρ = R* for the deformable body).

The stiffness dF/dh is exact: implicit differentiation of g(u; a) = 0 gives
du/d ln a = −(∂g/∂ln a)/(∂g/∂u), and dF/dh = (dF/d ln a)/(dh/d ln a).

The plastic limit: where both bodies are (nearly) fully plastic their pressures hardly depend
on u, g is flat in u over a range, and the root u(a) jumps (h(a) nearly vertical, F nearly
constant: the approach moves from one body to the other at one contact radius). The inversion
h → a then fails or lands on another root; :meth:`UnifiedPair.state_from_h` solves those
approaches along the branch in u instead (a(u) from g(a, u) = 0, then u from h).

Domain (:attr:`UnifiedPair.domain`): h(a) and F(a) rise for every a > 0 (the large-
deformation terms are continued to constants beyond their fitted range, ``levels.py``), but
geometry bounds the approach: each deformable sphere's own approach stays within its radius,
h_i ≤ R_i (h_i is the shortening of the hemisphere of height R_i, docs/design.md §4; at h_i = R_i it
is flattened completely). The first sphere to reach it as a grows gives a_max and
h_max = h(a_max); approaches beyond h_max (radii beyond a_max) raise a ValueError naming h
(a) and the allowed range. A deformable flat has no such bound. (A contact radius beyond a
rigid indenter's radius is geometrically impossible too, but it is not a bound here: the
model reaches it inside the validation window for small indenters; the a/R check of
``range_check.py`` warns there.)
"""

from __future__ import annotations

import math
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np

from .cap import cap_gap_factor
from .coefficients import Coefficients, default_coefficients
from .profile import profile_factor
from .roots import solve_increasing
from .single import BodyLaw, BodyResponse, FixedTerms, curvature_ratio
from .sphere import Sphere

__all__ = ["UnifiedState", "UnifiedPair", "Domain", "pair"]


class UnifiedState(NamedTuple):
    """State of the two-body contact at contact radius a (1-D arrays)."""

    a: np.ndarray
    kappa: np.ndarray     # interface curvature κ
    rho1: np.ndarray      # relative radius seen by body 1 (inf: body 1 rigid)
    rho2: np.ndarray
    p_m: np.ndarray       # mean contact pressure
    h1: np.ndarray        # approach taken by body 1
    h2: np.ndarray
    h: np.ndarray         # h = h1 + h2
    F: np.ndarray         # contact force π a² p_m
    stiffness: np.ndarray  # dF/dh
    Lambda1: np.ndarray
    Lambda2: np.ndarray
    piece: np.ndarray     # smooth-piece id of the pair (changes at level/table kinks)
    dlnF_dlna: np.ndarray  # d ln F/d ln a
    dlnh_dlna: np.ndarray  # d ln h/d ln a
    dlnh1_dlna: np.ndarray  # d ln h_1/d ln a (0 if body 1 is rigid)


class Domain(NamedTuple):
    """Approaches the model accepts, 0 < h ≤ h_max, i.e. contact radii 0 < a ≤ a_max."""

    h_max: float  # inf: unbounded
    a_max: float
    bound: str    # the geometric bound reached at h_max (for messages)


#: multiplier of body 2's piece id in the pair's piece id (ids of one body stay below it)
_PIECES = 1 << 32
#: relative slack of the domain checks (the domain end of a general pair is found to ~1e-12,
#: the inversion h → a is exact to ~1e-14)
_DOMAIN_SLACK = 1.0 + 1e-9
#: largest |h1 + h2 − h|/h a state from the inversion may have (it is ~1e-14 where the κ root is
#: unique; a larger gap means the root jumped: ``state_from_h`` then solves the branch in u, and
#: raises if that state misses h by more than ``_CONSISTENT``). At a pair's plastic limit the κ
#: root is poorly determined and the inversion in a can land within 1e-8 of h, not 1e-14 (a
#: limit pair with the interface coupling 0.01: 1e-8): the branch solve takes those too.
_RESOLVE = 1e-11
_CONSISTENT = 1e-8
#: iterations of the inversion in a before the branch solve in u takes over (it needs ≤ 6
#: evaluations for 60 random plastic pairs where the κ root is unique)
_INVERT_MAXITER = 40
#: step in u of the difference quotient d ln h/du along the branch (:meth:`UnifiedPair._invert_in_u`)
_DU = 1e-6
#: sections per pass and passes of the search for the domain end of a general pair
_DOMAIN_SECTIONS = 64
_DOMAIN_PASSES = 6
#: largest change of u = ln(ρ_2/ρ_1) predicted from du/d ln a for the κ warm start of the
#: inversion (the inner solve is bracketed anyway; this only keeps a long outer step sane)
_PREDICT = 1.0
#: ε of the interface coupling's modulus factor u_H²/(u_H² + ε²), u_H = ln(E'_2/E'_1): the coupling
#: corrects the split's run-away driven by unequal moduli; equal moduli (u_H = 0) keep λ = 0's
#: equation (equal materials of unequal radii: FE splits of radius ratio 2 and 4 within 9.2 and
#: 6.4 percentage points without it, 33 with the coupling at full strength)
_MODULUS_RATIO = 0.1
#: ln a step of the grid on which a pair's similarity factor is checked once (``_similar_somewhere``)
_SIMILAR_STEP = 0.02


class _BodyFixed(NamedTuple):
    """One body's response terms that move with a alone (:meth:`UnifiedPair._fixed_at`)."""

    terms: FixedTerms
    profile: tuple | None  # pressure-profile factor 1/φ and d ln(1/φ)/d ln a

    def take(self, idx, with_c2: bool = True) -> _BodyFixed:
        """The terms at the points ``idx`` (without those of c² unless ``with_c2``)."""
        return _BodyFixed(self.terms.take(idx, with_c2), None if self.profile is None else
                          tuple(v[idx] for v in self.profile))


def _held_at(hit, a: np.ndarray) -> bool:
    """True when ``hit``, a cache entry (a, ...) kept for the last contact radii, holds these a."""
    return hit is not None and hit[0].shape == a.shape and np.array_equal(hit[0], a)


def _num(x: float) -> str:
    return f"{x:.6g}"


def _sphere_text(i: int, s: Sphere) -> str:
    """Sphere i's radius and material, for error messages."""
    m = s.material
    if m.is_rigid:
        mat = "rigid"
    elif math.isinf(m.sigma_y):
        mat = f"E = {_num(m.E)}, nu = {_num(m.nu)}, elastic"
    else:
        mat = f"E = {_num(m.E)}, nu = {_num(m.nu)}, {m.flow.text()}"
    return f"sphere {i}: R = {_num(s.radius)}, {mat}"


def _values(v: np.ndarray) -> str:
    """Up to three values of an array, for error messages."""
    v = np.asarray(v).ravel()
    text = ", ".join(_num(float(x)) for x in v[:3])
    return text + (f", … ({v.size} values)" if v.size > 3 else "")


def _sigmoid(u):
    """w = 1/(1 + e^(−u)) and 1 − w, without overflow."""
    e = np.exp(-np.abs(u))
    big = 1.0 / (1.0 + e)
    small = e / (1.0 + e)
    pos = u >= 0
    return np.where(pos, big, small), np.where(pos, small, big)


class UnifiedPair:
    """The unified two-sphere model for one pair of spheres and one coefficient set.

    Parameters
    ----------
    s1, s2 : the two spheres (a flat has radius inf; a rigid body ``Material.rigid()``).
    coeffs : coefficient set; default :func:`default_coefficients`.
    """

    def __init__(self, s1: Sphere, s2: Sphere, coeffs: Coefficients | None = None) -> None:
        if not isinstance(s1, Sphere) or not isinstance(s2, Sphere):
            raise ValueError("contact needs two Sphere objects")
        if s1.is_rigid and s2.is_rigid:
            raise ValueError("both bodies are rigid: at least one must be deformable (finite E)")
        if s1.is_flat and s2.is_flat:
            raise ValueError(
                "both bodies are flat (radius inf): at least one radius must be finite"
            )
        self.s1, self.s2 = s1, s2
        self.coeffs = default_coefficients() if coeffs is None else coeffs
        R1, R2 = s1.radius, s2.radius
        self.R_star = 1.0 / (1.0 / R1 + 1.0 / R2)
        self.E_star = 1.0 / (1.0 / s1.material.E_prime + 1.0 / s2.material.E_prime)
        self.law1 = None if s1.is_rigid else BodyLaw(s1.material, self.coeffs)
        self.law2 = None if s2.is_rigid else BodyLaw(s2.material, self.coeffs)
        ratio_rho = self.coeffs.finite_size_ratio == "a_over_rho"
        self._ratio_rho = ratio_rho
        if s2.is_rigid:
            self.mode = "rigid2"
        elif s1.is_rigid:
            self.mode = "rigid1"
        elif s1.material == s2.material and (ratio_rho or R1 == R2):
            self.mode = "equal"
        else:
            self.mode = "general"
        self._coupled = False  # interface terms evaluated (general mode, ``_similar_somewhere``)
        if self.mode == "general":
            self._u0 = math.log(s2.material.E_prime / s1.material.E_prime)
            # Hertz partition ρ_i,H = E'_i R*/E* (Level I root), where the coupling's weights are taken
            self._rho_hertz = tuple(s_.material.E_prime * self.R_star / self.E_star for s_ in (s1, s2))
            self._coupled = self.coeffs.interface_coupling > 0.0 and self._similar_somewhere()
        # radius ρ_c of the surface pressing each body, 1/ρ_c = (1 − w)/ρ_H + w/R* (Hertz partition
        # ρ_H = E'_i R*/E*, moved towards the rigid-partner geometry R* by the harder partner's weight
        # w): the counter-surface ratio a/ρ_c and the collapse limits' curvature ratio
        # z_i = R_i/ρ_c − 1 (constants of the pair, so the κ root stays unique); and the radius and
        # weight of the partner's cap in each body's gap (``cap.py``: 1 for a rigid partner, w for a
        # harder one; weight 0: the paraboloid)
        self._z = {}
        self._inv_rho_c = {}  # 1/ρ_c of each body (``_body``)
        self._cap = {}
        exact = self.coeffs.counter_cap == "exact"
        for law, s_, s_o in ((self.law1, s1, s2), (self.law2, s2, s1)):
            if law is None:
                continue
            rho_h = self.R_star if s_o.is_rigid else s_.material.E_prime * self.R_star / self.E_star
            w = harder_partner_weight(s_, s_o)
            self._inv_rho_c[id(law)] = (1.0 - w) / rho_h + w / self.R_star
            self._z[id(law)] = curvature_ratio(s_.radius, 1.0 / self._inv_rho_c[id(law)])
            self._cap[id(law)] = (s_o.radius, (1.0 if s_o.is_rigid else w) if exact else 0.0)
        # the partner whose pressure profile each body is loaded by (``profile.py``; a/R ratio only:
        # the factor depends on a alone, which the y slot of the slopes carries)
        self._profile = {}
        self._fixed = None  # (a, with_c2, terms) of the last :meth:`_fixed_at`
        self._coupling_last = None  # (a, terms) of the last :meth:`_coupling`
        if self.mode == "general" and self.coeffs.pressure_profile == "flattened" and not self._ratio_rho:
            self._profile = {id(self.law1): self.law2, id(self.law2): self.law1}

    # ------------------------------------------------------------------ body responses
    def _body(self, law: BodyLaw, a, k, R, pressure_only: bool = False, fixed=None) -> BodyResponse:
        """Body ``law``'s response at contact radius a and 1/ρ = k (``fixed``: its terms of
        :meth:`_fixed_at` at a, if at hand), times the pressure-profile factor."""
        x = a * k
        y = x if self._ratio_rho else a / R
        if fixed is None:
            fixed = self._fixed_at(a, not pressure_only)
            fixed = None if fixed is None else fixed[id(law)]
        terms, profile = (None, None) if fixed is None else fixed
        r = law.response(x, y, self._z[id(law)], a * self._inv_rho_c[id(law)], pressure_only, fixed=terms)
        if profile is None:
            return r
        q, dln_q = profile
        return r._replace(p_m=r.p_m * q, dlnp_dlny=r.dlnp_dlny + dln_q)

    def _fixed_at(self, a, with_c2: bool = True):
        """The terms of each body's response that move with a alone, by body law (None when the
        finite-size ratio is a/ρ: they move with the partition then): ``BodyLaw.fixed_terms`` at
        y = a/R, xc = a/ρ_c (those of c² only ``with_c2``), and the pressure-profile factor 1/φ
        with its d/d ln a (``profile.py``, None without it). Kept for the last a: a κ solve reads
        them at every iterate, the state at its root once more."""
        if self._ratio_rho:
            return None
        a = np.asarray(a, dtype=float)
        hit = self._fixed
        if _held_at(hit, a) and (hit[1] or not with_c2):
            return hit[2]
        laws = [(law, s_.radius) for law, s_ in ((self.law1, self.s1), (self.law2, self.s2))
                if law is not None]
        level = {}  # the level weights at a/ρ_c: the profile factor reads both bodies'
        if self._profile:
            level = {id(law): law.level_state_at(a * self._inv_rho_c[id(law)]) for law, _ in laws}
        out = {}
        for law, R in laws:
            terms = law.fixed_terms(a / R, self._z[id(law)], a * self._inv_rho_c[id(law)], level.get(id(law)),
                                    with_c2)
            other = self._profile.get(id(law))
            profile = None
            if other is not None:
                ln_q, dln_q = profile_factor(*level[id(law)], *level[id(other)])
                profile = (np.exp(ln_q), dln_q)
            out[id(law)] = _BodyFixed(terms, profile)
        self._fixed = (a.copy(), with_c2, out)
        return out

    def _g(self, a, u, C=0.0, uA=0.0, fixed=None):
        """g = ln p_1 − ln p_2 + C (u − u_A) at (a, u), its u-derivative, and both responses
        (C, u_A: :meth:`_coupling` at a, constants of the κ solve; the pressures alone,
        ``BodyLaw.response`` with ``pressure_only``; ``fixed``: :meth:`_fixed_at` at a if at hand)."""
        w1, w2 = _sigmoid(u)
        f1, f2 = (None, None) if fixed is None else (fixed[id(self.law1)], fixed[id(self.law2)])
        r1 = self._body(self.law1, a, w1 / self.R_star, self.s1.radius, True, f1)
        r2 = self._body(self.law2, a, w2 / self.R_star, self.s2.radius, True, f2)
        A1 = r1.dlnp_dlnx + (r1.dlnp_dlny if self._ratio_rho else 0.0)
        A2 = r2.dlnp_dlnx + (r2.dlnp_dlny if self._ratio_rho else 0.0)
        g = np.log(r1.p_m) - np.log(r2.p_m) + C * (u - uA)
        return g, A1 * w2 + A2 * w1 + C, r1, r2

    def _coupling(self, a):
        """C(a) = λ s_1 s_2 e^(−(ln(P_1/P_2)/δ)²) of the interface equation, the anchor
        u_A(a) = u_H/(1 + (a/(a_c R*))^k) and their derivatives in ln a (module docstring), from
        both bodies at the Hertz partition x_i = a/ρ_i,H. λ = 0: (0, 0, 0, 0). Kept for the last
        a: a κ solve and the state at its root read them."""
        if not self._coupled:
            return 0.0, 0.0, 0.0, 0.0
        a = np.asarray(a, dtype=float)
        hit = self._coupling_last
        if _held_at(hit, a):
            return hit[1]
        co = self.coeffs
        s1, d1, P1, m1 = self.law1.plastic_state_at(a / self._rho_hertz[0])
        s2, d2, P2, m2 = self.law2.plastic_state_at(a / self._rho_hertz[1])
        delta = co.interface_similarity
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            q = np.where(np.isfinite(P1) & np.isfinite(P2), np.log(P1 / P2) / delta, np.inf)
            e = np.exp(-q * q)
            de = np.where(e > 0.0, -2.0 * q * e * (m1 - m2) / delta, 0.0)
            t = (a / (co.interface_radius * self.R_star)) ** co.interface_exponent
        phi = t / (1.0 + t)
        lam = co.interface_coupling * self._u0**2 / (self._u0**2 + _MODULUS_RATIO**2)  # E-driven only
        C = lam * s1 * s2 * e
        dC = lam * ((d1 * s2 + s1 * d2) * e + s1 * s2 * de)
        out = C, dC, self._u0 * (1.0 - phi), -self._u0 * co.interface_exponent * phi * (1.0 - phi)
        self._coupling_last = (a.copy(), out)
        return out

    def _similar_somewhere(self) -> bool:
        """False when the similarity factor e^(−q²), q = ln(P_1/P_2)/δ, is below e^(−36) at every
        contact radius 1e-7 R* ≤ a ≤ 2 min(R_1, R_2) (beyond any approach the domain admits; a grid
        0.02 apart in ln a, with |dq/d ln a| = |m_1 − m_2|/δ bounding q between the nodes): the
        coupling is then zero to rounding and is not evaluated (pairs of clearly unequal
        hardness)."""
        a_top = 2.0 * min(r for r in (self.s1.radius, self.s2.radius) if math.isfinite(r))
        a = self.R_star * np.exp(np.arange(math.log(1e-7), math.log(a_top / self.R_star) + _SIMILAR_STEP,
                                           _SIMILAR_STEP))
        _, _, P1, m1 = self.law1.plastic_state_at(a / self._rho_hertz[0])
        _, _, P2, m2 = self.law2.plastic_state_at(a / self._rho_hertz[1])
        if not (np.all(np.isfinite(P1)) and np.all(np.isfinite(P2))):
            return False  # an elastic body: C = 0 (its level weight is 0)
        delta = self.coeffs.interface_similarity
        q = np.abs(np.log(P1 / P2)) / delta
        slack = np.max(np.abs(m1 - m2)) / delta * 0.5 * _SIMILAR_STEP
        return bool(np.min(q) - slack <= 6.0)

    def describe(self) -> str:
        """Both spheres (radius, material), for error messages."""
        return f"{_sphere_text(1, self.s1)}; {_sphere_text(2, self.s2)}"

    def solve_u(self, a, u_guess=None, with_c2: bool = True) -> np.ndarray:
        """κ solve: u = ln(ρ_2/ρ_1) with equal mean pressures, for each a (1-D). ``with_c2`` False:
        the bodies' terms fixed during the solve (:meth:`_fixed_at`) without those of c², which
        only a state at the roots reads."""
        a = np.asarray(a, dtype=float)
        u0 = np.full(a.shape, self._u0) if u_guess is None else np.asarray(u_guess, dtype=float)
        C, _, uA, _ = (np.broadcast_to(v, a.shape) for v in self._coupling(a))  # fixed during the solve
        fixed = self._fixed_at(a, with_c2)  # so are the bodies' terms that move with a alone

        def f(u, idx):
            at = fixed
            if fixed is not None and idx.size < a.size:
                at = {k: v.take(idx, with_c2=False) for k, v in fixed.items()}  # pressures alone
            g, dg, _, _ = self._g(a[idx], u, C[idx], uA[idx], at)
            return g, dg

        def describe(idx):
            return f"interface-curvature solve at contact radius a = {_values(a[idx])} ({self.describe()})"

        return solve_increasing(f, u0, step=1.0, tol=1e-14, describe=describe)

    # ------------------------------------------------------------------ state given a
    def state_at_a(self, a, u=None) -> UnifiedState:
        """Full state for contact radii a (1-D, > 0); ``u`` skips the κ solve if given."""
        a = np.asarray(a, dtype=float)
        Rs = self.R_star
        R1, R2 = self.s1.radius, self.s2.radius
        zero = np.zeros_like(a)
        inf = np.full_like(a, math.inf)
        if self.mode in ("rigid1", "rigid2"):
            law, R = (self.law1, R1) if self.mode == "rigid2" else (self.law2, R2)
            r = self._body(law, a, 1.0 / Rs, R)
            G, dlnG = cap_gap_factor(a, 1.0 / Rs, *self._cap[id(law)])
            hb = a * a / (Rs * 2.0 * r.c2) * G
            F = math.pi * a * a * r.p_m
            dlnF = 2.0 + r.dlnp_dlnx + r.dlnp_dlny
            dlnh = 2.0 - r.dlnc2_dlnx - r.dlnc2_dlny + dlnG
            stiff = F * dlnF / (hb * dlnh)
            if self.mode == "rigid2":
                kappa = np.full_like(a, -1.0 / R2)
                return UnifiedState(a, kappa, np.full_like(a, Rs), inf, r.p_m, hb, zero, hb, F,
                                    stiff, r.Lambda, zero, r.piece, dlnF, dlnh, dlnh)
            kappa = np.full_like(a, 1.0 / R1)
            return UnifiedState(a, kappa, inf, np.full_like(a, Rs), r.p_m, zero, hb, hb, F,
                                stiff, zero, r.Lambda, r.piece, dlnF, dlnh, zero)

        if self.mode == "equal":
            u = np.zeros_like(a)
        elif u is None:
            u = self.solve_u(a)
        return self._two_body_state(a, u)[0]

    def piece_at(self, a, u=None) -> np.ndarray:
        """The ``piece`` of :meth:`state_at_a` at contact radii a (1-D) and, for two deformable
        bodies, u = ln(ρ_2/ρ_1) (default: the equal pair's 0), from the bodies' ratios alone
        (no response; the κ solve is the caller's)."""
        a = np.asarray(a, dtype=float)
        if self.mode in ("rigid1", "rigid2"):
            law, R = (self.law1, self.s1.radius) if self.mode == "rigid2" else (self.law2, self.s2.radius)
            x = a * (1.0 / self.R_star)
            return law.piece_at(x, x if self._ratio_rho else a / R)
        w1, w2 = _sigmoid(np.zeros_like(a) if u is None else u)
        x1, x2 = a * (w1 / self.R_star), a * (w2 / self.R_star)
        y1, y2 = (x1, x2) if self._ratio_rho else (a / self.s1.radius, a / self.s2.radius)
        return self.law1.piece_at(x1, y1) + _PIECES * self.law2.piece_at(x2, y2)

    def _two_body_state(self, a, u):
        """State of two deformable bodies at (a, u) and du/d ln a along the κ root
        (implicit differentiation of g(u; a) = 0, module docstring)."""
        Rs = self.R_star
        R1, R2 = self.s1.radius, self.s2.radius
        w1, w2 = _sigmoid(u)
        k1, k2 = w1 / Rs, w2 / Rs
        r1 = self._body(self.law1, a, k1, R1)
        r2 = self._body(self.law2, a, k2, R2)
        rho = self._ratio_rho
        # ∂/∂ln k_i at fixed a (A, Ca) and ∂/∂ln a at fixed k_i (B, Cb)
        A1 = r1.dlnp_dlnx + (r1.dlnp_dlny if rho else 0.0)
        A2 = r2.dlnp_dlnx + (r2.dlnp_dlny if rho else 0.0)
        B1 = r1.dlnp_dlnx + r1.dlnp_dlny
        B2 = r2.dlnp_dlnx + r2.dlnp_dlny
        Ca1 = r1.dlnc2_dlnx + (r1.dlnc2_dlny if rho else 0.0)
        Ca2 = r2.dlnc2_dlnx + (r2.dlnc2_dlny if rho else 0.0)
        Cb1 = r1.dlnc2_dlnx + r1.dlnc2_dlny
        Cb2 = r2.dlnc2_dlnx + r2.dlnc2_dlny
        if self.mode == "equal":
            du = np.zeros_like(a)
        else:
            C, dC, uA, duA = self._coupling(a)
            den = A1 * w2 + A2 * w1 + C
            with np.errstate(divide="ignore", invalid="ignore"):
                du = np.where(den > 0.0, -_dg_dlna(B1, B2, u, dC, uA, C, duA) / den, 0.0)
        dlnk1 = w2 * du
        dlnk2 = -w1 * du
        # p_1 = p_2 (λ = 0); with the coupling term the contact pressure is their geometric mean
        p = np.sqrt(r1.p_m * r2.p_m)
        dlnp = 0.5 * (B1 + A1 * dlnk1 + B2 + A2 * dlnk2)
        # h_i = a²k_i G_i/(2c_i²), G_i the partner's cap (``cap.py``; ∂ln G_i/∂ln k_i = 1/G_i − 1)
        G1, dlnG1 = cap_gap_factor(a, k1, *self._cap[id(self.law1)])
        G2, dlnG2 = cap_gap_factor(a, k2, *self._cap[id(self.law2)])
        h1 = a * a * k1 / (2.0 * r1.c2) * G1
        h2 = a * a * k2 / (2.0 * r2.c2) * G2
        dlnh1 = 2.0 + (1.0 / G1 - Ca1) * dlnk1 - Cb1 + dlnG1
        dh = h1 * dlnh1 + h2 * (2.0 + (1.0 / G2 - Ca2) * dlnk2 - Cb2 + dlnG2)
        F = math.pi * a * a * p
        h = h1 + h2
        dlnF = 2.0 + dlnp
        stiff = F * dlnF / dh
        with np.errstate(divide="ignore"):
            rho1, rho2 = 1.0 / k1, 1.0 / k2
        kappa = 1.0 / R1 - k1
        if self.mode == "equal":  # exact closed form, no rounding from 1/R1 − 1/(2R*)
            kappa = np.full_like(a, 0.5 * (1.0 / R1 - 1.0 / R2))
        st = UnifiedState(a, kappa, rho1, rho2, p, h1, h2, h, F, stiff,
                          r1.Lambda, r2.Lambda, r1.piece + _PIECES * r2.piece, dlnF, dh / h, dlnh1)
        return st, du

    # ------------------------------------------------------------------ inversion h → a
    def _invert(self, h, with_u: bool = True):
        """Contact radius a (and the κ variable u, general mode and ``with_u``; else None) for
        approaches h > 0 (1-D): a monotone root in ln a with the κ solve inside; approaches it
        does not converge for within ``_INVERT_MAXITER`` iterations are solved along the branch
        in u (:meth:`_invert_in_u`)."""
        h = np.asarray(h, dtype=float)
        lnh = np.log(h)
        t0 = 0.5 * (lnh + math.log(self.R_star))  # Hertz: a² = R* h

        def describe(idx):
            return f"inversion h -> a at h = {_values(h[idx])} ({self.describe()})"

        if self.mode != "general":
            def f(t, idx):
                s = self.state_at_a(np.exp(t))
                return np.log(s.h) - lnh[idx], s.dlnh_dlna
            return np.exp(solve_increasing(f, t0, step=0.5, tol=1e-14, describe=describe)), None

        # κ warm start: u at the last iterate t_w, continued to t along the root (du/d ln a)
        t_w, u_w, du_w = t0.copy(), np.full(h.shape, self._u0), np.zeros(h.shape)

        def guess(t, idx):
            return u_w[idx] + np.clip(du_w[idx] * (t - t_w[idx]), -_PREDICT, _PREDICT)

        def f(t, idx):
            a = np.exp(t)
            u = self.solve_u(a, guess(t, idx))
            s, du = self._two_body_state(a, u)
            t_w[idx], u_w[idx], du_w[idx] = t, u, du
            return np.log(s.h) - lnh[idx], s.dlnh_dlna

        t = solve_increasing(f, t0, step=0.5, tol=1e-14, describe=describe, strict=False,
                             maxiter=_INVERT_MAXITER)
        a = np.exp(t)
        failed = ~np.isfinite(t)
        u = None
        if with_u:
            u = np.full(h.shape, np.nan)
            u[~failed] = self.solve_u(a[~failed], guess(t[~failed], ~failed))
        if failed.any():
            a_f, u_f = self._invert_in_u(h[failed], np.exp(t_w[failed]))
            a[failed] = a_f
            if with_u:
                u[failed] = u_f
        return a, u

    def _invert_in_u(self, h, a0):
        """(a, u) for approaches h where the inversion in a fails: where both bodies are (nearly)
        fully plastic their pressures hardly depend on the partition, g(u; a) is flat in u over a
        range and the κ root jumps with a (a near-vertical stretch of h(a), the load nearly
        constant while h grows: the pair's plastic limit). There the branch is solved the other
        way round: a(u) from g(a, u) = 0 (rising in ln a at fixed u: the pressure difference the
        bodies' sizes make), then u with h(a(u), u) = h (h changes monotonically along the
        branch as the approach moves from one body to the other). ``a0``: start of the first
        a-solve. ValueError if either solve does not converge."""
        lnh = np.log(h)
        t_a = np.log(np.asarray(a0, dtype=float)).copy()

        def a_of(u, idx):
            def g(t, j):
                a, uu = np.exp(t), u[j]
                C, dC, uA, duA = self._coupling(a)
                gv, _, r1, r2 = self._g(a, uu, C, uA)
                B1, B2 = r1.dlnp_dlnx + r1.dlnp_dlny, r2.dlnp_dlnx + r2.dlnp_dlny
                return gv, _dg_dlna(B1, B2, uu, dC, uA, C, duA)

            def describe(j):
                return f"pressure balance in a at u = {_values(u[j])} ({self.describe()})"
            return solve_increasing(g, t_a[idx], step=0.05, tol=1e-14, describe=describe)

        def ln_h(u, idx):  # ln h along the branch and d ln h/du
            t = a_of(u, idx)
            t_a[idx] = t
            lnh_u = np.log(self._two_body_state(np.exp(t), u)[0].h)
            lnh_du = np.log(self._two_body_state(np.exp(a_of(u + _DU, idx)), u + _DU)[0].h)
            return lnh_u, (lnh_du - lnh_u) / _DU

        u0 = np.full(h.shape, self._u0)
        sign = -np.sign(ln_h(u0, np.arange(h.size))[1])  # solved in v = sign·u, along which h falls
        sign[sign == 0.0] = 1.0

        def f(v, idx):
            lnh_u, d = ln_h(sign[idx] * v, idx)
            return lnh[idx] - lnh_u, -sign[idx] * d

        def describe(idx):
            return f"inversion h -> (a, u) at h = {_values(h[idx])} ({self.describe()})"

        u = sign * solve_increasing(f, sign * u0, step=1.0, tol=1e-13, describe=describe)
        return np.exp(a_of(u, np.arange(h.size))), u

    def a_from_h(self, h) -> np.ndarray:
        """Contact radius for approaches h (1-D, 0 < h ≤ ``domain.h_max``): monotone root of
        h(a) = h in ln a."""
        self.check_approach(h)
        return self._invert(h, with_u=False)[0]

    def state_from_h(self, h) -> UnifiedState:
        """Full state for approaches h (1-D, 0 < h ≤ ``domain.h_max``): inversion then
        forward evaluation."""
        self.check_approach(h)
        a, u = self._invert(h)
        st = self.state_at_a(a, u)
        h = np.asarray(h, dtype=float)
        off = np.abs(st.h - h) > _RESOLVE * h
        if np.any(off) and self.mode == "general":  # the root jumped: the branch solved in u
            a[off], u[off] = self._invert_in_u(h[off], a[off])
            st = self.state_at_a(a, u)
            off = np.abs(st.h - h) > _CONSISTENT * h
        if np.any(off):
            raise ValueError(
                f"the two-body partition (kappa solve) has no consistent root at h = {_values(h[off])}: "
                f"the state found gives h1 + h2 = {_values(st.h[off])} ({self.describe()}); the "
                "model is not defined there for this pair (two nearly fully plastic bodies whose "
                "pressures no longer depend on the partition)")
        return st

    # ------------------------------------------------------------------ domain
    def check_approach(self, h, name: str = "h") -> None:
        """ValueError naming ``name``, its largest value and the allowed range if an approach
        lies beyond the domain (:attr:`domain`); one reduction over h."""
        h = np.asarray(h, dtype=float)
        if h.size == 0:
            return
        top = float(np.max(h))
        d = self.domain
        if top > d.h_max * _DOMAIN_SLACK:
            raise ValueError(
                f"{name} = {_num(top)} (approach) is outside the model's domain 0 < h <= "
                f"{_num(d.h_max)} (h <= 0: no contact); at h = {_num(d.h_max)} {d.bound} "
                f"({self.describe()})")

    def check_radius(self, a) -> None:
        """ValueError naming a, its largest value and the allowed range beyond the domain."""
        a = np.asarray(a, dtype=float)
        d = self.domain
        if a.size and float(np.max(a)) > d.a_max * _DOMAIN_SLACK:
            raise ValueError(
                f"a = {_num(float(np.max(a)))} (contact radius) is outside the model's domain "
                f"0 < a <= {_num(d.a_max)}; at a = {_num(d.a_max)} {d.bound} ({self.describe()})")

    @cached_property
    def domain(self) -> Domain:
        """The approaches the model accepts (module docstring): up to the first deformable
        sphere's own approach reaching its radius, h_i = R_i (inf if no sphere is finite)."""
        own = [(i, s.radius) for i, s in ((1, self.s1), (2, self.s2))
               if not s.is_rigid and not s.is_flat]
        if not own:
            return Domain(math.inf, math.inf, "")
        i, R = min(own, key=lambda c: c[1])
        if self.mode in ("rigid1", "rigid2"):  # h_i = h
            return Domain(R, float(self._invert(np.array([R]))[0][0]), self._own_text(i, R))
        if self.mode == "equal":  # h_1 = h_2 = h/2
            return Domain(2.0 * R, float(self._invert(np.array([2.0 * R]))[0][0]), self._own_text(i, R))
        return self._general_domain(own)

    def _own_ratio(self, a, own, u_guess=None) -> tuple[np.ndarray, np.ndarray]:
        """max_i h_i/R_i over the deformable spheres ``own`` at contact radii a (general mode),
        and the κ roots u there (``u_guess``: where their solve starts)."""
        u = self.solve_u(a, u_guess)
        st = self.state_at_a(a, u)
        h_i = {1: st.h1, 2: st.h2}
        return np.maximum.reduce([h_i[i] / R for i, R in own] + [np.zeros_like(a)]), u

    def _general_domain(self, own) -> Domain:
        """The domain of two deformable spheres: the smallest a with max_i h_i/R_i = 1 (a scan
        in ln a, then :meth:`_refine_crossing`)."""
        t = math.log(self.R_star) + np.arange(-14.0, 7.0, 0.1)
        ratio, u = self._own_ratio(np.exp(t), own)
        above = np.nonzero(ratio >= 1.0)[0]
        if above.size == 0:
            return Domain(math.inf, math.inf, "")
        j = above[0]
        i = max(j - 1, 0)
        a = math.exp(self._refine_crossing(t[i], t[j], own, (t[i], u[i]), (t[j], u[j])))
        st = self.state_at_a(np.array([a]))
        h_i = {1: float(st.h1[0]), 2: float(st.h2[0])}
        k, R = max(own, key=lambda c: h_i[c[0]] / c[1])
        return Domain(float(st.h[0]), a, self._own_text(k, R))

    def _refine_crossing(self, lo: float, hi: float, own, at_lo, at_hi) -> float:
        """ln a where max_i h_i/R_i first reaches 1 in [lo, hi] (multi-section passes, one
        vectorised κ solve each, started from u interpolated between the roots ``at_lo``,
        ``at_hi`` = (ln a, u) at the ends); returns the upper end (≥ 1 side)."""
        frac = np.arange(1, _DOMAIN_SECTIONS) / _DOMAIN_SECTIONS
        for _ in range(_DOMAIN_PASSES):
            pts = lo + (hi - lo) * frac
            guess = np.interp(pts, (at_lo[0], at_hi[0]), (at_lo[1], at_hi[1]))
            ratio, u = self._own_ratio(np.exp(pts), own, guess)
            k = np.nonzero(ratio >= 1.0)[0]
            first = k[0] if k.size else frac.size
            if first > 0:
                lo, at_lo = pts[first - 1], (pts[first - 1], u[first - 1])
            if first < frac.size:
                hi, at_hi = pts[first], (pts[first], u[first])
        return float(hi)

    @staticmethod
    def _own_text(i: int, R: float) -> str:
        return (f"the approach of sphere {i} reaches its radius, h_{i} = R_{i} = {_num(R)} "
                "(the hemisphere is flattened completely)")


#: exponent k of :func:`harder_partner_weight`, chosen on the six two-body calibration runs: the
#: sum over them of the largest F and a errors (h/R ≤ 0.3) was 81.8 / 79.4 / 75.8 / 72.4 / 72.2 %
#: for k = 0 (the Hertz partition alone) / 1 / 2 / 4 / ∞ (a step at equal yield stresses) when the
#: weight moved the counter-surface ratio only; with the collapse limits' z moved too (2026-11-26),
#: 49.7 / 43.8 / 43.0 % for k = 2 / 4 / 8 (validation runs above 5 %: 5 / 3 / 3)
HARDER_PARTNER_EXPONENT = 4.0
#: width δ in ln(σ_Y ratio) within which the modulus ratio decides which body of a pair is the
#: harder (:func:`harder_partner_weight`; the interface coupling's similarity width)
MODULUS_TIE_WIDTH = 0.1


def _dg_dlna(B1, B2, u, dC, uA, C, duA):
    """∂g/∂ln a at fixed u of the interface equation g = ln p_1 − ln p_2 + C (u − u_A): B_i the
    bodies' d ln p_i/d ln a at fixed k_i, dC and du_A the coupling's ln a derivatives."""
    return B1 - B2 + dC * (u - uA) - C * duA


def harder_partner_weight(s: Sphere, partner: Sphere) -> float:
    """Weight w of the rigid-partner geometry in the radius ρ_c of the surface pressing body ``s``:
    1/ρ_c = (1 − w)/ρ_H + w/R* (``BodyLaw.response``'s xc = a/ρ_c and z = R/ρ_c − 1).
    w = 2·max(r^k/(1 + r^k) − ½, 0) with k = ``HARDER_PARTNER_EXPONENT`` and r how much harder
    the partner is: 0 for a partner no harder (the Hertz partition), → 1 for a much harder one,
    which the body sees as a rigid sphere of its radius (a/ρ_c − a/R = a/R_partner). A constant of
    the pair, so the κ equation stays monotone in u.

    r = q · (E'_p/E'_s)^g with q = σ_Y,p/σ_Y,s the yield ratio and g = exp(−(ln q/δ)²), δ =
    ``MODULUS_TIE_WIDTH``: the yield stress decides which body is the harder, and where the
    yield stresses (nearly) agree the modulus does. Of two spheres of equal yield stress the
    stiffer indents the other as a rigid sphere would (FE with smooth frictionless contact, E/σY
    300 against 900 at h/R 0.1–0.3: p_m within 0.5–1.2 % of the softer sphere's under a rigid
    sphere of the partner's radius, the stiffer taking 4–9 % of the approach); with w = 0 there
    the model's F was 10.1 / 4.9 % off on campaign v2's two such calibration pairs and a
    5.8 / 5.4 % (with the modulus tie-break 3.2 / 2.0 % and 1.1 / 1.0 %, coupling refitted).
    Sum over the six two-body calibration runs of their largest F and a errors (h/R ≤ 0.3, no
    coupling), the modulus ratio to the power 0 / ¼ / ½ / ¾ / 1 / 2 in r at every yield ratio:
    44.3 / 36.6 / 32.1 / 31.7 / 31.8 / 31.8 %; at every yield ratio, though, the modulus made
    a sphere of lower yield stress (E/σY 1400) the harder of a pair against one of 1.48 times
    its yield stress and a third of its modulus, whose F(h) then fell: hence the tie-break g."""
    if partner.is_rigid or s.is_rigid:
        return 0.0
    ys, yp = s.material.sigma_y, partner.material.sigma_y
    if not math.isfinite(ys):
        return 0.0
    if not math.isfinite(yp):
        return 1.0
    q = yp / ys
    g = math.exp(-(math.log(q) / MODULUS_TIE_WIDTH) ** 2)
    r = q * (partner.material.E_prime / s.material.E_prime) ** g
    if r <= 1.0:
        return 0.0
    t = r ** HARDER_PARTNER_EXPONENT
    return 2.0 * (t / (1.0 + t) - 0.5)


def pair(s1: Sphere, s2: Sphere, coeffs: Coefficients | None = None) -> UnifiedPair:
    """Cached :class:`UnifiedPair` (spheres and coefficient sets are hashable). Keyed by the
    calibrated range too: it sets where the fitted terms are continued (``levels.py``), and
    coefficient sets that differ only in provenance compare equal."""
    co = default_coefficients() if coeffs is None else coeffs
    return _cached_pair(s1, s2, co, co.calibrated_range)


@lru_cache(maxsize=256)
def _cached_pair(s1: Sphere, s2: Sphere, coeffs: Coefficients, rng) -> UnifiedPair:
    return UnifiedPair(s1, s2, coeffs)
