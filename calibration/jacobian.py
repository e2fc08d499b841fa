"""Jacobian of the fit's residual rows in a form's parameters (``fit.Residuals``).

The data rows r_F = ln p_m + s_F ln c² − (FE) and r_a = s_a ln c² − (FE) (``fit``) depend on
most parameters through a few per-point quantities (``model.levels``):

    H̄_hs = H̄_q(Λ, n) f_H(x, s),   c²_hs = c²_q(Λ, n) f_c(x, s)       half space
    f = (1 − s)(1 + Σ e_k x^(k+1)) + s (1 + Σ q_k x^(k+1))           finite size, s = 3t² − 2t³
    H̄_q = H̄_I + (H̄_III − H̄_I) S(t) + H̄_I L t (1 − t)²               Level II (smooth; S: shape)
    ln H̄_c, ln c²_c  linear in every coefficient but the sharpness    collapse limits
    ln H̄ = ln H̄_hs − softplus(k ln r)/k,  ln c² = ln c²_hs + w_c (ln c²_c − ln c²_hs)

with r = H̄_hs/H̄_c, w = σ(k ln r), w_c = σ(k_c (ln r + s_c)); the counter-surface terms multiply
H̄_hs and c²_hs by exp(q s(u)), so ∂ln H̄_hs/∂q_H = ∂ln c²_hs/∂q_c = s(u) (their Level III values,
fitted at the conformity ζ = 0 and 1 when they change with it: s_l (1 − ζ) s(u) and s_l ζ s(u)).
Their derivatives are written out here, so a column costs a few array operations instead of an
evaluation of the model:

    ∂ln H̄/∂ln H̄_hs = 1 − w,  ∂ln H̄/∂ln H̄_c = w,  ∂ln H̄/∂ln k = softplus(k ln r)/k − w ln r,
    ∂ln c²/∂ln c²_hs = 1 − w_c,  ∂ln c²/∂ln c²_c = w_c,
    ∂ln c²/∂ln H̄_hs = −∂ln c²/∂ln H̄_c = (ln c²_c − ln c²_hs) k_c w_c (1 − w_c).

β and γ move σ_rep = σ_f(ε_rep) by m d ln ε_rep (m: the flow curve's log slope) and Λ by the
opposite, which acts through d ln H̄_hs/d ln Λ and d ln c²_hs/d ln Λ (the level functions' slopes
and the level weight of the finite-size factors; with the exponent read along the curve,
``local_secant``, they move n as well, by (dn/d ln ε_rep) d ln ε_rep, which acts through
∂ln p_m/∂n and ∂ln c²/∂n, written out: ``levels.levels_with_n_slopes`` and
``CollapseLimit.dlog_dn``); ln Λ_I and L = ln(Λ_III/Λ_I) move
t = (ln Λ − ln Λ_I)/L and H̄_I = 4Λ_I/(3π) (``_Parts.level_bounds``). A parameter not named
here would get forward differences of the whole residual (scipy's '2-point' step rule). The
penalty rows get forward differences for every parameter they depend on, those of a penalty
that is inactive at the point (every margin above ``fit.ACTIVE_MARGIN``, rows that are zero
whatever the parameters aside) excepted: they are zero (each penalty recomputed only when its
coefficients change, ``fit.Residuals``).
"""

from __future__ import annotations

import math

import numpy as np

from ..model import levels
from ..model.coefficients import Coefficients
from .forms import (
    X_C2,
    counter_surface_at,
    exponent_slope_at,
    flow_log_slope_at,
    point_inputs,
    raw_curvature_ratio,
)

__all__ = ["residual_jacobian"]

_REL_STEP = math.sqrt(np.finfo(float).eps)


#: indexed parameter families (name = family + index k)
_FAMILIES = ("H_III_n", "c2_III_n", "H_shape", "c2_shape", "H_shape_n", "c2_shape_n", "fs_H", "fs_c2",
             "fsp_H", "fsp_c2",
             "Hc_x", "Hc_n", "Hc_z", "Hc_xn", "Hc_zn", "c2c_x", "c2c_n", "c2c_z", "c2c_xn", "c2c_zn")


#: the half-space parameter families of H̄ and c² and what they are (``_Parts._level_values``)
_HALF_SPACE_H = {"H_III": "III", "H_III_n": "III_n", "H_shape": "shape", "H_shape_n": "shape_n",
                 "fs_H": "fs", "fsp_H": "fsp"}
_HALF_SPACE_C = {"c2_III": "III", "c2_III_n": "III_n", "c2_shape": "shape", "c2_shape_n": "shape_n",
                 "fs_c2": "fs", "fsp_c2": "fsp"}


def _split(name: str) -> tuple[str, int]:
    """'Hc_xn1' → ('Hc_xn', 1), 'fs_c21' → ('fs_c2', 1); a name of no family → (name, −1)."""
    for fam in sorted(_FAMILIES, key=len, reverse=True):
        rest = name[len(fam):]
        if name.startswith(fam) and rest.isdigit():
            return fam, int(rest)
    return name, -1


def fd_step(x: float, lo: float, hi: float) -> float:
    """Forward step of scipy's '2-point' scheme: √eps · max(1, |x|) with the sign of x, taken
    backwards when the forward point leaves the bounds; exactly representable (x + h − x)."""
    h = _REL_STEP * (1.0 if x >= 0.0 else -1.0) * max(1.0, abs(x))
    if not lo <= x + h <= hi and lo <= x - h <= hi:
        h = -h
    return (x + h) - x


class _Parts:
    """The per-point quantities of the module docstring at one coefficient set."""

    def __init__(self, ds, co: Coefficients, tied: bool, conformity: tuple[bool, bool] = (False, False)):
        n, _, Lam, elastic, y, z = point_inputs(ds, co)
        self.n, self.y, self.z, self.elastic = n, y, z, elastic
        lam1, lam3 = co.Lambda_I, co.Lambda_III
        L = math.log(lam3 / lam1)
        with np.errstate(divide="ignore"):
            t = np.clip(np.log(Lam / lam1) / L, 0.0, 1.0)
        self.t = t
        lev = levels.level(Lam, co)
        self.lev2, self.lev3 = lev == 2, lev == 3
        self.H_III, self.c_III = co.H_bar_III(n), co.c2_III(n)
        H_q, self.sH = levels.H_bar_and_slope(Lam, co, n)
        c_q, self.sc = levels.c2_and_slope(Lam, co, n)
        s, ds_l = levels.level_weight(Lam, co)
        self.s = s
        self.fH, _, self.lfH = levels.finite_size_by_level(y, s, ds_l, co.finite_size_H_bar,
                                                           co.fs_H_bar_plastic)
        self.fc, _, self.lfc = levels.finite_size_by_level(y, s, ds_l, co.finite_size_c2, co.fs_c2_plastic)
        self.L = L
        self.m, self.x_rho = flow_log_slope_at(ds, co), ds.x_rho
        self.beta, self.growth = co.beta, co.beta_growth
        self.fH_elastic = levels.finite_size_factor(y, co.finite_size_H_bar)[0]
        self.tied = tied  # one finite-size coefficient set for all levels (no fsp_ parameters)
        self.H_q, self.c_q = H_q, c_q
        self.H_I = co.H_bar_I
        self.smooth = co.level_II_smooth
        self.shape_H = self._shape_sum(co.H_bar_shape, co.H_bar_shape_n)
        self.shape_c = self._shape_sum(co.c2_shape, co.c2_shape_n)
        self.su = counter_surface_at(ds, co)  # s(u) of the counter-surface terms
        z_raw = raw_curvature_ratio(ds)
        self.zeta = z_raw / (1.0 + z_raw)  # conformity ζ of the pressing surface
        # the Level III counter-surface values are fitted at ζ = 0 and 1 (q_III, q_III + q_ζ)
        self.conformity, self.conformity_c2 = conformity
        H_hs, c_hs = H_q * self.fH, c_q * self.fc
        if co.has_counter_surface:
            (qH, dqH), (qc, dqc) = co.counter_by_level(s, z_raw)
            H_hs, c_hs = H_hs * np.exp(qH * self.su), c_hs * np.exp(qc * self.su)
            # their level weight moves with Λ like the finite-size factors' (d ln/d ln Λ)
            self.lfH = self.lfH + dqH * ds_l * self.su
            self.lfc = self.lfc + dqc * ds_l * self.su
        self.pos = pos = (H_hs > 0.0) & ~elastic
        zero = np.zeros_like(H_hs)
        one = np.ones_like(H_hs)
        if co.exponent_local:  # ∂ln H̄_q/∂n, ∂ln c²_q/∂n (``levels.levels_with_n_slopes``)
            self.dn = exponent_slope_at(ds, co)
            _, _, Hq_n, _, _, cq_n, _ = levels.levels_with_n_slopes(Lam, co, n)
            self.Hq_n, self.cq_n = np.where(pos, Hq_n, 0.0), np.where(pos, cq_n, 0.0)
            self.p_n, self.c_n = self.Hq_n, self.cq_n  # without a collapse block
        if not co.has_collapse:
            self.A, self.B, self.CcH, self.Ccc = one, zero, zero, one
            self.dH_dlnk = self.dc_dlnk = self.dc_dlnkc = self.dc_ds = zero
            return
        lnHc = co.collapse_H_bar.log_and_slope(y, n, z)[0]
        lncc = co.collapse_c2.log_and_slope(y, n, z)[0]
        k = co.collapse_sharpness
        k_c = co.collapse_sharpness_c2
        s_c = co.collapse_offset_c2 or 0.0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            lnr = np.where(pos, np.log(np.where(pos, H_hs, 1.0)) - lnHc, 0.0)
            w, softplus = levels._weight(k * lnr)
            kc = k if k_c is None else k_c
            wc = w if (k_c is None or k_c == k) and not s_c else levels._weight(kc * (lnr + s_c))[0]
            w, softplus, wc = (np.where(pos, v, 0.0) for v in (w, softplus, wc))
            gap = np.where(pos & ((w > 0.0) | (wc > 0.0)), lncc - np.log(c_hs), 0.0)
        dwc = wc * (1.0 - wc)  # dw_c/d(k_c (ln r + s_c))
        self.A, self.B = 1.0 - w, w
        self.CcH = gap * kc * dwc
        self.Ccc = 1.0 - wc
        self.dH_dlnk = np.where(pos, softplus / k - w * lnr, 0.0)
        self.dc_dlnkc = gap * dwc * (lnr + s_c) * kc
        self.dc_dlnk = self.dc_dlnkc if k_c is None else zero
        self.dc_ds = gap * kc * dwc
        if co.exponent_local:  # ∂ln p_m/∂n, ∂ln c²/∂n through both halves of the blend
            Hc_n = co.collapse_H_bar.dlog_dn(y, n, z)
            cc_n = co.collapse_c2.dlog_dn(y, n, z)
            self.p_n = np.where(pos, self.A * self.Hq_n + self.B * Hc_n, 0.0)
            self.c_n = np.where(pos, self.CcH * (self.Hq_n - Hc_n) + self.Ccc * self.cq_n
                                + (1.0 - self.Ccc) * cc_n, 0.0)

    def _shape_sum(self, b, bn=()):
        """S(t) of the Level II shape (``levels._shape`` without the slope term m₀) and the
        factor t²(1 − t)² (smooth) or t(1 − t) (polynomial) that multiplies Σ (b_k + bn_k n) t^k."""
        t = self.t
        u = 1.0 - t
        P = levels._poly_and_derivative(t, b)[0] if b else np.zeros_like(t)
        if bn:
            P = P + self.n * levels._poly_and_derivative(t, bn)[0]
        if self.smooth:
            base = t * t * u * u
            return t * t * (3.0 - 2.0 * t) + base * P, base
        base = t * u
        return t + base * P, base

    # ---- per-parameter derivatives of the parts (relative: d ln(part)/dθ)
    def _level_values(self, kind: str, k: int, q_III, prefactor: float, q_q, q_I, shape, f):
        """d ln q_hs/dθ of the half-space value q = H̄ or c² for θ its Level III prefactor
        (``kind`` 'III'), n-coefficient k ('III_n'), Level II shape coefficient k ('shape') or
        finite-size coefficient k of Level I ('fs') or III ('fsp'); q_III, q_q, q_I: its
        Level III, half-space (no finite size) and Level I values, ``shape`` = (S(t), its
        shape-term factor), f its finite-size factor."""
        S, shape_base = shape
        d_III = np.where(self.lev3, 1.0, np.where(self.lev2, S, 0.0))  # ∂q_q/∂q_III
        with np.errstate(divide="ignore", invalid="ignore"):
            if kind == "III":
                return d_III * q_III / prefactor / q_q
            if kind == "III_n":
                return d_III * q_III * self.n ** (k + 1) / q_q
            if kind == "shape":
                return np.where(self.lev2, (q_III - q_I) * shape_base * self.t ** k, 0.0) / q_q
            if kind == "shape_n":
                return np.where(self.lev2, (q_III - q_I) * shape_base * self.t ** k * self.n, 0.0) / q_q
            if kind in ("fs", "fsp"):
                return self._finite(kind == "fs", f, k)
        raise KeyError(kind)

    def half_space_H(self, kind: str, k: int, co: Coefficients):
        """d ln H̄_hs/dθ for the plastic points and d ln p_m/dθ of the elastic (Hertz) points."""
        g = self._level_values(kind, k, self.H_III, co.H_bar_III_prefactor, self.H_q, self.H_I,
                               self.shape_H, self.fH)
        elastic = self.y ** (k + 1) / self.fH_elastic if kind == "fs" else np.zeros_like(self.n)
        return np.where(self.pos, g, 0.0), elastic

    def half_space_c(self, kind: str, k: int, co: Coefficients):
        """d ln c²_hs/dθ (elastic points included: their c² carries the finite-size factor)."""
        g = self._level_values(kind, k, self.c_III, co.c2_III_prefactor, self.c_q, levels.C2_HERTZ,
                               self.shape_c, self.fc)
        return np.where(np.isfinite(g), g, 0.0)

    def level_bounds(self, name: str):
        """d ln H̄_hs/dθ and d ln c²_hs/dθ for θ = ln Λ_I or L = ln(Λ_III/Λ_I), Λ fixed.

        t = (ln Λ − ln Λ_I)/L, so ∂t/∂ln Λ_I = −1/L and ∂t/∂L = −t/L; in Level II
        H̄_q = H̄_I (1 − S(t) + L t (1 − t)²) + H̄_III S(t) (smooth; the polynomial shape has
        no L term) with H̄_I = 4Λ_I/(3π), c²_q = ½ + (c²_III − ½) S_c(t); the level weight of
        the finite-size factors moves with t as well (d ln f/d ln Λ = ``lf``).
        """
        t, u, L = self.t, 1.0 - self.t, self.L
        S = self.shape_H[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            if name == "ln_Lambda_I":
                own = self.H_I * (1.0 - S + (L * t * u * u if self.smooth else 0.0)) / self.H_q
                gH = np.where(self.lev2, own - self.sH, 0.0) - self.lfH
                gc = np.where(self.lev2, -self.sc, 0.0) - self.lfc
            else:
                own = self.H_I * t * u * u / self.H_q if self.smooth else 0.0
                gH = np.where(self.lev2, own - t * self.sH, 0.0) - t * self.lfH
                gc = np.where(self.lev2, -t * self.sc, 0.0) - t * self.lfc
        return np.where(self.pos, gH, 0.0), np.where(self.pos, gc, 0.0)

    def exponent_move(self, name: str):
        """dn/dθ for θ = β or γ of the exponent read along the curve: (dn/d ln ε_rep) d ln ε_rep/dθ."""
        return np.where(self.pos, self.dn * self._dln_eps(name), 0.0)

    def _dln_eps(self, name: str):
        x = self.x_rho
        return 1.0 / self.beta if name == "beta" else x / (1.0 + self.growth * x)

    def strain(self, name: str):
        """d ln σ_rep/dθ for θ = β or γ of ε_rep = β x (1 + γ x): m d ln ε_rep/dθ, with m the
        flow curve's log slope at ε_rep (``single.flow_log_slope``); Λ = E'x/σ_rep moves by
        −d ln σ_rep."""
        return np.where(self.pos, self.m * self._dln_eps(name), 0.0)

    def _finite(self, elastic_coefficient: bool, f, k: int):
        """d ln f/d e_k (Level I coefficient) or d ln f/d q_k (Level III); both when tied."""
        weight = 1.0 if self.tied else ((1.0 - self.s) if elastic_coefficient else self.s)
        return weight * self.y ** (k + 1) / f


def _collapse_basis(parts: _Parts, base: str, k: int):
    """d ln H̄_c/dθ ('H') or d ln c²_c/dθ ('c') of a collapse-limit coefficient, or None."""
    y, n, z = parts.y, parts.n, parts.z
    one = np.ones_like(y)
    table = {
        "ln_Hc": ("H", lambda: one),
        "Hc_exponent": ("H", lambda: -np.log(y)),
        "Hc_x": ("H", lambda: y ** (k + 1)),
        "Hc_n": ("H", lambda: n ** (k + 1)),
        "Hc_z": ("H", lambda: z ** (k + 1)),
        "Hc_xn": ("H", lambda: n * y ** (k + 1)),
        "Hc_zn": ("H", lambda: n * z ** (k + 1)),
        "ln_c2c": ("c", lambda: one),
        "c2c_x": ("c", lambda: (y - X_C2) ** (k + 1)),
        "c2c_n": ("c", lambda: n ** (k + 1)),
        "c2c_z": ("c", lambda: z ** (k + 1)),
        "c2c_xn": ("c", lambda: n * (y - X_C2) ** (k + 1)),
        "c2c_zn": ("c", lambda: n * z ** (k + 1)),
    }
    if base not in table:
        return None
    which, make = table[base]
    return which, make()


def _log_derivatives(parts: _Parts, name: str, co: Coefficients):
    """(d ln p_m/dθ, d ln c²/dθ) at every point, or None for a numerical column."""
    base, k = _split(name)
    zero = np.zeros_like(parts.y)
    if name in ("ln_Lambda_I", "ln_Lambda_III_over_I"):
        gH, gc = parts.level_bounds(name)
        return parts.A * gH, parts.CcH * gH + parts.Ccc * gc
    if name in ("beta", "beta_growth"):  # σ_rep moves, Λ by −d ln σ_rep (and n along the curve)
        dsig = parts.strain(name)
        gH, gc = parts.sH + parts.lfH, parts.sc + parts.lfc
        dp, dc = dsig * (1.0 - parts.A * gH), -dsig * (parts.CcH * gH + parts.Ccc * gc)
        if co.exponent_local:
            dn = parts.exponent_move(name)
            dp = dp + dn * parts.p_n
            dc = dc + dn * parts.c_n
        return dp, dc
    if name in ("counter_H", "counter_H3"):  # ln H̄_hs (and the Hertz p_m of elastic points)
        # move by s(u), by the level weight's share when the terms depend on the level
        lev = parts.s * (1.0 - parts.zeta if parts.conformity else 1.0) if name == "counter_H3" else (
            1.0 - parts.s if co.counter_H_bar_plastic is not None else 1.0)
        g = np.where(parts.pos, lev * parts.su, 0.0)
        return np.where(parts.elastic, lev * parts.su, parts.A * g), parts.CcH * g
    if name == "counter_H31":  # the Level III value at ζ = 1: ln H̄_hs moves by s_l ζ s(u)
        g = np.where(parts.pos, parts.s * parts.zeta * parts.su, 0.0)
        return parts.A * g, parts.CcH * g
    if name == "counter_c231":
        return zero, parts.Ccc * parts.s * parts.zeta * parts.su
    if name in ("counter_c2", "counter_c23"):
        lev = parts.s * (1.0 - parts.zeta if parts.conformity_c2 else 1.0) if name == "counter_c23" else (
            1.0 - parts.s if co.counter_c2_plastic is not None else 1.0)
        return zero, parts.Ccc * lev * parts.su
    if base in _HALF_SPACE_H:
        g, elastic = parts.half_space_H(_HALF_SPACE_H[base], k, co)
        return np.where(parts.elastic, elastic, parts.A * g), parts.CcH * g
    if base in _HALF_SPACE_C:
        return zero, parts.Ccc * parts.half_space_c(_HALF_SPACE_C[base], k, co)
    if co.has_collapse:
        col = _collapse_basis(parts, base, k)
        if col is not None:
            which, b = col
            if which == "H":
                return np.where(parts.pos, parts.B * b, 0.0), -parts.CcH * b
            return zero, (1.0 - parts.Ccc) * b
        if name == "ln_sharpness":
            return parts.dH_dlnk, parts.dc_dlnk
        if name == "ln_sharpness_c2":
            return zero, parts.dc_dlnkc
        if name == "offset_c2":
            return zero, parts.dc_ds
    return None


def residual_jacobian(res, x: np.ndarray) -> np.ndarray:
    """∂r/∂x of ``res`` (a ``fit.Residuals``) at ``x``: analytic columns for the data rows of
    the parameters above, forward differences elsewhere (module docstring)."""
    x = np.asarray(x, dtype=float)
    co0 = res.coefficients(x)
    r0 = res(x)
    J = np.zeros((r0.size, x.size))
    if co0 is None:  # invalid parameters: constant residual
        return J
    lo, hi = res.form.bounds()
    n_data = 2 * res.ds.size
    finite = np.isfinite(res.raw_data_rows(co0))
    blocks = [res.penalty_block(i, co0) for i in range(res.n_penalties)]
    offsets = np.cumsum([n_data] + [b.size for b in blocks])
    active = [i for i in range(res.n_penalties) if res.active(i, co0)]
    parts = _Parts(res.ds, co0, tied=not any(n.startswith("fsp_") for n in res.form.names),
                   conformity=("counter_H31" in res.form.names, "counter_c231" in res.form.names))
    sF, sa = res.ds.slope_F, res.ds.slope_a
    for j, name in enumerate(res.form.names):
        h = fd_step(x[j], lo[j], hi[j])
        xj = x.copy()
        xj[j] += h
        d = _log_derivatives(parts, name, co0)
        if d is None:
            J[:, j] = (res(xj) - r0) / h
            continue
        dp, dc = d
        col = np.concatenate([dp + sF * dc, sa * dc])
        J[:n_data, j] = np.where(finite, col, 0.0)
        moved = [i for i in res.depends[j] if i in active]
        co_j = res.coefficients(xj) if moved else None
        for i in moved if co_j is not None else ():
            J[offsets[i]:offsets[i + 1], j] = (res.penalty_block(i, co_j) - blocks[i]) / h
    return J
