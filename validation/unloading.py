"""Unloading branches of the validation runs: the model and published unloading laws against the FE.

Every unloading branch of a validation run (campaign v2 unloads at h/R = 0.01, 0.03, 0.1,
0.3) is predicted four ways, each at the FE's approaches along the branch:

* **law** — the model's unloading law (``model/unloading.py``) given the FE's peak (F_max,
  a_max, each body's approach, the curvature of the contact surface): the unloading law
  alone, the quantity the thresholds ``[unloading]`` accept;
* **model** — the whole model: it loads to the FE's h_max and unloads along its own branch
  (``contact(s1, s2, h, h_max=…)``), so its loading error at h_max is part of it;
* **Thornton (1997)** — Hertz from the FE's peak: residual radius R_p = 4E*a_max³/(3F_max),
  F = (4/3)E*√R_p (h − h_res)^(3/2), δ_e = 3F_max/(4E*a_max) (J. Appl. Mech. 64:383);
* **Etsion, Kligerman & Kadin (2005)**, residual as quoted by Jackson, Chusoipin & Green
  (2007, J. Tribol. 129:484) — FE fit for an elastic–plastic sphere unloaded from a rigid flat
  (Int. J. Solids Struct. 42:3716; the primary text was not reachable here, the residual is
  taken in the form its implementations quote): with ω* = h_max/ω_c (Kogut–Etsion critical
  interference, ``peers.kogut_etsion_critical``),
  h_res/h_max = 1.02[1 − ((ω* + 5.9)/6.9)^−0.54], which vanishes at first yield (ω* = 1), and
  F/F_max = ((h − h_res)/(h_max − h_res))^(1.5 ω*^−0.0331) (Hertz's 3/2 at ω* = 1); fitted for
  1 ≤ ω* ≤ 110 (:data:`EKK_RANGE`): beyond it ω* is held at 110 and the cycle flagged, below 1
  the unloading is elastic (h_res = 0, exponent 3/2); F_max from the FE. For two spheres E*,
  R* and the yield stress and ν of the softer body;
* **LAMMPS mdr** — its stored unloading from its own loading to the FE run's last h_max
  (``data/peers/mdr.json``; the scenes mdr applies to, ``mdr.mdr_scene``): compared on the FE's
  branch from the same h_max, its loading error at the peak included like the model's.

Each method's own range (``UnloadingRow.in_range``): the EKK fit 1 ≤ ω* ≤ 110; Thornton's
elastic–perfectly plastic spheres past first yield up to a fully plastic contact (1 ≤ h_max/δ_y
≤ 110, δ_y Jackson–Green's ω_c = Thornton's yield approach with p_y = C(ν)σ_Y); mdr wherever it
is given; the model's law and the model everywhere.

Errors: max |F − F_FE|/F_max,FE along the branch and |h_res − h_res,FE|/h_max. The restitution
coefficient e = √(W_returned/W_in) of the first cycle (loaded from 0) is compared with the FE's
(its external work in and out).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..cycles import UnloadingCurve, law_branch, run_cycles
from ..model import Coefficients, contact, cycle, default_coefficients
from ..model.coefficients import UnloadingCoefficients
from ..model.run_inputs import spheres_from_inputs
from ..peers import THORNTON_RANGE, jackson_green_critical, kogut_etsion_critical
from .cases import Case, is_perfectly_plastic, scene_of

__all__ = ["UnloadingRow", "unloading_rows", "unloading_failures", "ekk_branch", "ekk_residual", "METHODS",
           "EKK", "EKK_RANGE", "RANGE_TEXT"]

#: the EKK residual is taken as Jackson, Chusoipin & Green quote it
EKK = "EKK 2005 (JCG 2007 form)"
METHODS = ("law", "model", "Thornton 1997", EKK, "LAMMPS mdr")
#: ω* range of the Etsion–Kligerman–Kadin fit
EKK_RANGE = (1.0, 110.0)
#: each method's own range, as the report prints it
RANGE_TEXT = {"law": "everywhere", "model": "everywhere",
              "Thornton 1997": f"elastic–perfectly plastic, 1 ≤ h_max/δ_y ≤ {THORNTON_RANGE[1]:g}",
              EKK: f"{EKK_RANGE[0]:g} ≤ ω* ≤ {EKK_RANGE[1]:g}", "LAMMPS mdr": "wherever given"}


@dataclass
class UnloadingRow:
    """One unloading branch of a validation run."""

    run: str
    key: str
    cycle: int
    h_over_R: float
    h_res_fe: float          # h_res/h_max of the FE
    F_err: dict              # method → max |ΔF|/F_max along the branch
    h_res_err: dict          # method → |Δh_res|/h_max
    e_fe: float              # restitution of the first cycle (nan for later cycles)
    e_model: float
    ekk_outside: bool        # ω* outside the EKK fit
    in_range: dict           # method → the branch lies in the method's own range
    curve: UnloadingCurve
    branches: dict           # method → F/F_max at the FE's approaches (charts)


def ekk_residual(omega_star) -> np.ndarray:
    """h_res/h_max of Etsion, Kligerman & Kadin (2005) as quoted by Jackson, Chusoipin & Green:
    1.02[1 − ((ω* + 5.9)/6.9)^−0.54] for ω* ≥ 1 (0 at first yield), 0 below (elastic)."""
    ws = np.maximum(np.asarray(omega_star, dtype=float), 1.0)
    return 1.02 * (1.0 - ((ws + 5.9) / 6.9) ** -0.54)


def ekk_branch(h, h_max: float, F_max: float, omega_c: float) -> tuple[np.ndarray, float]:
    """Etsion, Kligerman & Kadin (2005): F on the branch from (h_max, F_max) and h_res (ω* held
    in the fit's range 1 … 110: the residual of :func:`ekk_residual`, the exponent 1.5 ω*^−0.0331)."""
    ws = min(max(h_max / omega_c, EKK_RANGE[0]), EKK_RANGE[1])
    h_res = h_max * float(ekk_residual(ws))
    xi = np.clip((np.asarray(h, dtype=float) - h_res) / (h_max - h_res), 0.0, 1.0)
    return F_max * xi ** (1.5 * ws ** -0.0331), h_res


def _softer(s1, s2):
    """(yield stress, ν) of the deformable body with the lower yield stress."""
    b = [s for s in (s1, s2) if not s.is_rigid]
    s = min(b, key=lambda s: s.material.sigma_y)
    return s.material.sigma_y, s.material.nu


def _branch_error(f_pred, c: UnloadingCurve) -> float:
    return float(np.max(np.abs(np.asarray(f_pred) - c.f)))


def _mdr_unloading(case: Case, store):
    """mdr's stored unloading branch of the case as (h_max, F(h) on the branch), or None."""
    if store is None:
        return None
    from .mdr import mdr_scene

    scene = mdr_scene(case)
    c = store.find(scene) if isinstance(scene, dict) else None
    if c is None or c.unloading is None or c.unloading["delta"].size < 3:
        return None
    d, F = c.unloading["delta"], c.unloading["F"]
    order = np.argsort(d)
    f = c.delta_over_h
    return float(d[0] / f), lambda h: np.interp(h * f, d[order], F[order], left=0.0)


def _case_rows(case: Case, co: Coefficients, store=None) -> list[UnloadingRow]:
    if not case.cycles or "h_max" not in case.cycles:
        return []
    curves = run_cycles(case.label, case, co)
    if not curves:
        return []
    s1, s2 = spheres_from_inputs(case.inputs, scene_of(case.params, case.inputs))
    E_star = 1.0 / sum(0.0 if s.is_rigid else 1.0 / s.material.E_prime for s in (s1, s2))
    R_star = 1.0 / sum(1.0 / s.radius for s in (s1, s2))
    Y, nu = _softer(s1, s2)
    omega_c = kogut_etsion_critical(R_star, E_star, Y, nu)[0] if math.isfinite(Y) else math.inf
    delta_y = jackson_green_critical(R_star, E_star, Y, nu)[0] if math.isfinite(Y) else math.inf
    epp = all(is_perfectly_plastic(s.material) for s in (s1, s2) if not s.is_rigid)
    F_fe_max = np.asarray(case.cycles["F_max"], dtype=float)
    cyc_model = cycle(s1, s2, np.array([c.h_max for c in curves]), co)
    mdr = _mdr_unloading(case, store)
    rows = []
    for k, c in enumerate(curves):
        st = contact(s1, s2, c.h, co, h_max=c.h_max)
        f_model = st.F / F_fe_max[k]
        f_ekk, h_res_ekk = ekk_branch(c.h, c.h_max, 1.0, omega_c)
        f_law, h_res_law = _law_branch(co.unloading, c)
        f_th, h_res_th = _law_branch(UnloadingCoefficients(), c)
        w_in = float(case.cycles["work_in"][k]) if "work_in" in case.cycles else math.nan
        w_ret = float(case.cycles["work_returned"][k]) if "work_returned" in case.cycles else math.nan
        first = k == 0
        ws = c.h_max / omega_c
        F_err, h_err, branches = {}, {}, {}
        if mdr is not None and math.isclose(mdr[0], c.h_max, rel_tol=1e-3):
            f_mdr = mdr[1](c.h) / F_fe_max[k]
            hh = np.linspace(0.0, c.h_max, 4001)
            on = np.flatnonzero(mdr[1](hh) > 0.0)
            h_res_mdr = hh[on[0] - 1] if on.size and on[0] > 0 else 0.0
            F_err["LAMMPS mdr"] = _branch_error(f_mdr, c)
            h_err["LAMMPS mdr"] = abs(h_res_mdr - c.h_res) / c.h_max
            branches["LAMMPS mdr"] = f_mdr
        rows.append(UnloadingRow(
            run=case.label, key=case.key, cycle=k + 1, h_over_R=c.h_max / c.R, h_res_fe=c.h_res / c.h_max,
            F_err={"law": _branch_error(f_law, c), "model": _branch_error(f_model, c),
                   "Thornton 1997": _branch_error(f_th, c), EKK: _branch_error(f_ekk, c),
                   **F_err},
            h_res_err={"law": abs(h_res_law - c.h_res) / c.h_max,
                       "model": abs(float(cyc_model.h_res[k]) - c.h_res) / c.h_max,
                       "Thornton 1997": abs(h_res_th - c.h_res) / c.h_max,
                       EKK: abs(h_res_ekk - c.h_res) / c.h_max, **h_err},
            e_fe=math.sqrt(max(w_ret / w_in, 0.0)) if first and w_in > 0 else math.nan,
            e_model=float(cyc_model.restitution[k]) if first else math.nan,
            ekk_outside=not (EKK_RANGE[0] <= ws <= EKK_RANGE[1]),
            in_range={"law": True, "model": True, EKK: EKK_RANGE[0] <= ws <= EKK_RANGE[1],
                      "Thornton 1997": epp and 1.0 <= c.h_max / delta_y <= THORNTON_RANGE[1],
                      "LAMMPS mdr": "LAMMPS mdr" in F_err},
            curve=c, branches={"law": f_law, "model": f_model, "Thornton 1997": f_th,
                               EKK: f_ekk, **branches}))
    return rows


def _law_branch(law: UnloadingCoefficients, c: UnloadingCurve) -> tuple[np.ndarray, float]:
    """F/F_max of ``law`` given the FE's peak at the branch's approaches, and its h_res."""
    f, h_res = law_branch(law, c.peak, np.zeros(c.h.size, dtype=int), c.h)
    return f, float(h_res[0])


def unloading_rows(cases: list[Case], coeffs: Coefficients | None = None, mdr=None) -> list[UnloadingRow]:
    """Every unloading branch of ``cases`` (runs without cycles give none); ``mdr``: the stored
    LAMMPS mdr curves (``mdr.load_store``; None: mdr left out)."""
    co = default_coefficients() if coeffs is None else coeffs
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # calibrated-range warnings are reported by the loading part
        for case in cases:
            out += _case_rows(case, co, mdr)
    return out


def unloading_failures(rows: list[UnloadingRow], F_limit: float, h_res_limit: float) -> list[str]:
    """Branches whose law error exceeds the limits (text per branch)."""
    out = []
    for r in rows:
        what = []
        if r.F_err["law"] > F_limit:
            what.append(f"F max error {100 * r.F_err['law']:.1f} % of F_max > {100 * F_limit:.0f} %")
        if r.h_res_err["law"] > h_res_limit:
            what.append(f"h_res error {100 * r.h_res_err['law']:.1f} % of h_max > {100 * h_res_limit:.0f} %")
        if what:
            out.append(f"{r.run} cycle {r.cycle} (h_max/R = {r.h_over_R:.3g}): " + "; ".join(what))
    return out
