"""The published peer laws applied to a validation case: where each applies, and how.

The laws of :mod:`.peers` are single-body laws (one deformable sphere against a
rigid flat) or equivalent-sphere laws. On a case they are evaluated at the FE
approaches with the effective quantities their papers use:

* **Scene parameters.** Flat scene: E' and R of the hemisphere and its approach h
  (exactly the scene of Hertz, Jackson–Green and Kogut–Etsion). Rigid sphere:
  E* = E'_1, 1/R* = 1/R_1 + 1/R_2, approach h. Two deformable spheres:
  1/E* = 1/E'_1 + 1/E'_2, R*, total approach h = h_1 + h_2.
* **Yield of a pair.** Jackson–Green, Kogut–Etsion and Thornton need one yield
  stress and one ν: those of the body that yields first in Hertz contact, i.e. the
  smaller critical peak pressure C(ν)S_y, C = 1.295 exp(0.736 ν) (Jackson & Green 2005).
  All three are fits or models of elastic–perfectly plastic spheres: a pair with a
  hardening body is outside them.
* **Johnson's cavity model** is a hardness law p_m(a/R): it is compared as the force
  π a_FE² p_m at the FE contact radius (its error is the error of p_m), in Johnson's own
  elastic–plastic range 3 ≤ E'a/(Yρ) ≤ 40 (Johnson 1985 §6.3–6.5: first yield to fully
  plastic), for one elastic–perfectly plastic body against a rigid surface or a pair of
  equal materials (each body then sees ρ = 2R*).
* **Biwa–Storåkers** is a rigid–plastic similarity law for one power-law material
  σ = σ_0 ε^n: perfect plasticity is n = 0; a Ludwik or tabulated curve is replaced by
  its secant power law through ε = 0.01 and 0.1. A pair of equal materials is two
  bodies each indented by h/2 at ρ = 2R*; dissimilar flow curves are outside it.
* **LAMMPS mdr** (Zunker & Kamrin 2024, ``pair_style granular`` with the ``mdr`` normal
  model) is not evaluated here but read from curves LAMMPS computed on the same scenes
  (:mod:`.mdr`, ``data/peers/mdr.json``): the equal pair at δ = 2h for the flat scene,
  the pair R1, R2 at δ = h for two bodies of one material. One elastic–perfectly plastic
  material and no rigid body: rigid indenters, two materials and hardening are outside it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .. import peers
from ..model import Material
from .cases import Case, is_perfectly_plastic, spheres
from .mdr import NAME as MDR
from .mdr import MdrStore, mdr_curve_at

__all__ = ["PEERS", "PeerPrediction", "NotApplicable", "Equivalent", "equivalent", "predict_peers",
           "power_law_fit", "CAVITY_RANGE", "RANGE_TEXT"]

PEERS = ("Hertz", "Jackson–Green 2005", "Kogut–Etsion 2002", "Thornton 1997",
         "Johnson cavity", "Biwa–Storåkers 1995", MDR)

#: range of Johnson's parameter E'a/(Yρ) where the cavity model is meant to hold
CAVITY_RANGE = peers.CAVITY_RANGE
#: each law's stated range of validity, as the report prints it (:mod:`.peers` holds the bounds)
RANGE_TEXT = {
    "Hertz": f"elastic: h ≤ ω_c (ω/ω_c ≤ {peers.HERTZ_RANGE[1]:g})",
    "Jackson–Green 2005": f"ω/ω_c ≤ {peers.JACKSON_GREEN_RANGE[1]:g}",
    "Kogut–Etsion 2002": f"ω/ω_c ≤ {peers.KOGUT_ETSION_RANGE[1]:g}",
    "Thornton 1997": f"δ/δ_y ≤ {peers.THORNTON_RANGE[1]:g} (not yet fully plastic)",
    "Johnson cavity": f"{peers.CAVITY_RANGE[0]:g} ≤ E'a/(σ_Y ρ) ≤ {peers.CAVITY_RANGE[1]:g}",
    "Biwa–Storåkers 1995": f"fully plastic: E'a/(σ_Y ρ) ≥ {peers.BIWA_STORAKERS_RANGE[0]:g}",
    MDR: "its stored curve (claims large deformation)",
}
#: strains of the secant power law replacing a non-power-law flow curve (Biwa–Storåkers)
POWER_FIT_STRAINS = (0.01, 0.1)


class PeerPrediction(NamedTuple):
    """A peer law on a case. ``basis`` "h": F and a at the FE approaches; "a": F at the
    FE contact radius (hardness laws; ``a`` is None). ``mask``: points where it is evaluated
    (None: all); ``in_range``: points inside the law's own stated range (None: all)."""

    F: np.ndarray
    a: np.ndarray | None
    basis: str = "h"
    mask: np.ndarray | None = None
    note: str = ""
    in_range: np.ndarray | None = None


class NotApplicable(NamedTuple):
    reason: str


class Equivalent(NamedTuple):
    """Equivalent-sphere quantities of a case."""

    E_star: float
    R_star: float
    delta: np.ndarray          # approach the laws are evaluated at
    yielding: Material | None  # body that yields first (None: no body can yield)
    equal_materials: bool      # both bodies deform with the same material
    rigid_partner: bool        # one deformable body against a rigid flat or sphere
    rho: float                 # relative radius each deforming body sees (R* or 2R*)
    per_body_delta: np.ndarray  # approach each deforming body takes (h or h/2)


def _C(nu: float) -> float:
    return 1.295 * math.exp(0.736 * nu)


def equivalent(case: Case) -> Equivalent:
    """E*, R*, the approach and the yielding body of a case (module docstring)."""
    s1, s2 = spheres(case)
    h = case.h
    deformable = [s.material for s in (s1, s2) if not s.is_rigid]
    E_star = 1.0 / sum(1.0 / m.E_prime for m in deformable)
    R_star = 1.0 / (1.0 / s1.radius + 1.0 / s2.radius)
    plastic = [m for m in deformable if math.isfinite(m.sigma_y)]
    yielding = min(plastic, key=lambda m: _C(m.nu) * m.sigma_y) if plastic else None
    rigid_partner = len(deformable) == 1
    equal = not rigid_partner and s1.material == s2.material
    rho = 2.0 * R_star if equal else R_star
    return Equivalent(E_star, R_star, h, yielding, equal, rigid_partner, rho,
                      h / 2.0 if equal else h)


def power_law_fit(m: Material) -> tuple[float, float]:
    """(σ_0, n) of the secant power law σ_0 ε^n through the flow curve at POWER_FIT_STRAINS."""
    lo, hi = POWER_FIT_STRAINS
    s_lo, s_hi = (float(m.flow_stress(e)) for e in (lo, hi))
    n = math.log(s_hi / s_lo) / math.log(hi / lo)
    return s_hi / hi**n, n


def predict_peers(case: Case, mdr: MdrStore | None = None) -> dict:
    """Every peer law on ``case``: name → :class:`PeerPrediction` or :class:`NotApplicable`.

    ``mdr``: the stored LAMMPS mdr curves (:func:`.mdr.load_store`); None: mdr is not given.
    """
    out = _predict_laws(case)
    got = mdr_curve_at(case, mdr)
    if isinstance(got, str):
        out[MDR] = NotApplicable(got)
    else:
        F, a, mask, note, _ = got
        out[MDR] = PeerPrediction(F, a, mask=mask, note=note, in_range=mask)
    return out


def _predict_laws(case: Case) -> dict:
    eq = equivalent(case)
    s1, s2 = spheres(case)
    deformable = [s.material for s in (s1, s2) if not s.is_rigid]
    epp = all(is_perfectly_plastic(m) for m in deformable)
    out: dict = {}
    two = case.scene == "two_body" and not eq.rigid_partner
    pair_note = "E*, R*, total h" if two else ""

    hz = peers.hertz(eq.delta, eq.E_star, eq.R_star)
    Y = eq.yielding
    # elastic range: up to first yield of the body that yields first (Jackson–Green's ω_c)
    hz_range = (None if Y is None else peers.in_range(
        eq.delta / peers.jackson_green_critical(eq.R_star, eq.E_star, Y.sigma_y, Y.nu)[0],
        peers.HERTZ_RANGE))
    out["Hertz"] = PeerPrediction(hz.F, hz.a, note=pair_note or "elastic law", in_range=hz_range)

    if Y is None:
        reason = "no body can yield"
        for name in PEERS[1:]:
            if name != MDR:
                out[name] = NotApplicable(reason)
        return out
    yield_note = (f"S_y, ν of the body yielding first (σ_Y = {Y.sigma_y:g}, ν = {Y.nu:g})"
                  if two and not eq.equal_materials else "")
    note = "; ".join(x for x in (pair_note, yield_note) if x)
    if epp:
        w_jg = peers.jackson_green_critical(eq.R_star, eq.E_star, Y.sigma_y, Y.nu)[0]
        w_ke = peers.kogut_etsion_critical(eq.R_star, eq.E_star, Y.sigma_y, Y.nu)[0]
        jg = peers.jackson_green(eq.delta, eq.R_star, eq.E_star, Y.sigma_y, Y.nu)
        out["Jackson–Green 2005"] = PeerPrediction(
            jg.F, jg.a, note=note, in_range=peers.in_range(eq.delta / w_jg, peers.JACKSON_GREEN_RANGE))
        ke = peers.kogut_etsion(eq.delta, eq.R_star, eq.E_star, Y.sigma_y, Y.nu)
        out["Kogut–Etsion 2002"] = PeerPrediction(
            ke.F, ke.a, note=note, in_range=peers.in_range(eq.delta / w_ke, peers.KOGUT_ETSION_RANGE))
        th = peers.thornton(eq.delta, eq.E_star, eq.R_star, _C(Y.nu) * Y.sigma_y)
        # δ_y = (π p_y/(2E*))² R* with p_y = C σ_Y is Jackson–Green's ω_c
        out["Thornton 1997"] = PeerPrediction(
            th.F, th.a, note="; ".join(x for x in (note, "p_y = C(ν)σ_Y, peak Hertz pressure at "
                                                    "first yield") if x),
            in_range=peers.in_range(eq.delta / w_jg, peers.THORNTON_RANGE))
    else:
        reason = "fit/model for elastic–perfectly plastic spheres; this case hardens"
        for name in ("Jackson–Green 2005", "Kogut–Etsion 2002", "Thornton 1997"):
            out[name] = NotApplicable(reason)

    single = eq.rigid_partner or eq.equal_materials
    if not epp:
        out["Johnson cavity"] = NotApplicable("cavity model with a constant yield stress; "
                                              "this case hardens")
    elif not single:
        out["Johnson cavity"] = NotApplicable("one elastic–plastic body under a rigid indenter; "
                                              "the pair's materials differ")
    else:
        a_fe = case.a
        pm = Y.sigma_y * peers.johnson_cavity_hardness(a_fe / eq.rho, Y.E, Y.nu, Y.sigma_y)
        x = Y.E_prime * a_fe / (Y.sigma_y * eq.rho)
        lo, hi = CAVITY_RANGE
        inside = peers.in_range(x, CAVITY_RANGE)
        out["Johnson cavity"] = PeerPrediction(
            math.pi * a_fe**2 * pm, None, basis="a", mask=inside, in_range=inside,
            note=f"p_m at the FE contact radius, for {lo:g} ≤ E'a/(σ_Y ρ) ≤ {hi:g}"
                 + (", ρ = 2R*" if eq.equal_materials else ""))

    if not single:
        out["Biwa–Storåkers 1995"] = NotApplicable("similarity law for one power-law material; "
                                                   "the pair's flow curves differ")
    else:
        sigma_0, n = (Y.sigma_y, 0.0) if is_perfectly_plastic(Y) else power_law_fit(Y)
        bs = peers.biwa_storakers(eq.per_body_delta, eq.rho, sigma_0, n)
        fit = "" if is_perfectly_plastic(Y) else (f"secant power law σ_0 = {sigma_0:.3g}, "
                                                  f"n = {n:.3g}")
        eqn = "each body h/2 at ρ = 2R*" if eq.equal_materials else ""
        plastic = peers.in_range(Y.E_prime * bs.a / (Y.sigma_y * eq.rho), peers.BIWA_STORAKERS_RANGE)
        out["Biwa–Storåkers 1995"] = PeerPrediction(bs.F, bs.a, in_range=plastic,
                                                    note="; ".join(x for x in (fit, eqn) if x))
    return out
