"""Fast path for many contacts of one sphere pair: a monotone table of the exact solution.

``ContactLaw(s1, s2)`` solves the unified model (DESIGN §3) once on a grid of contact
radii and stores, against s = ln h, the cubic Hermite interpolants of

    ln F(s),  ln a(s),  φ(s) = h_1/h

with the exact slopes d ln F/d ln h = (d ln F/d ln a)/(d ln h/d ln a) etc. at every node.
Nodes are uniform in ln(a/R*) plus every point where the model itself has a kink
(level boundaries Λ_i = Λ_I, Λ_III and flow-table breakpoints at ε_rep), with one-sided
slopes there, so each interval interpolates a smooth function. The interpolation error
is measured against the exact solve inside every interval at build time and reported
as :attr:`ContactLaw.error` (relative, with a safety factor 2); the table is refined
until it is below ``rtol``. Approaches outside [h_min, h_max] fall back to the exact
solve, so every input gets an answer of known accuracy.

Setup cost is the number of vectorised κ solves (an evaluation of the body responses has a
fixed cost that dominates at a table's ~600 points): the inversion of the two table ends,
one solve for the regular grid, one per pass of the kink search (sections per pass chosen
for the fewest passes, warm-started between the bracket ends) and one for the nodes, the
one-sided points at kinks and the error probes together (warm-started from the grid).

Evaluation is a uniform bucket lookup (no binary search), one gather of the interval's
polynomial coefficients, a Horner step and one exponential: no loops over contacts.

Calibrated range (``range_check.py``): material and pair causes warn once, when the
table is built. The approach-dependent causes (h/R, a/R, Λ_i, flow-table slope) are
tabulated at build time as their running maximum over the nodes, which gives for each
cause the approach h where it first leaves the range; an evaluation compares only the
largest approach of the call with the smallest of these (one reduction, no per-contact
work), and a cause found warns once per ``ContactLaw`` (recorded in
:attr:`ContactLaw.range_issues`) — never per contact or per time step. Approaches outside
the table are checked on their exact states.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .coefficients import Coefficients, default_coefficients
from .contact import ContactState, as_approach
from .range_check import emit, range_check
from .sphere import Sphere
from .unified import UnifiedPair, UnifiedState, pair

__all__ = ["ContactLaw", "contact_table"]

#: ln(a/R*) step of the regular nodes (halved, in the intervals whose measured error exceeds
#: rtol, up to three times).
DEFAULT_STEP = 0.02
_ONE_SIDED = 1e-8  # offset in ln a for the one-sided slopes at kinks
_KINK_TOL = 1e-11  # kink location tolerance in ln a
_KINK_POINTS = 1024  # points per pass of the kink search, shared by the kinks (≥ 16 each)
_PROBES = (0.21, 0.5, 0.79)  # error probes: fractions of every interval in ln a
_SAFETY = 2.0      # error bound = safety × largest error found at the probe points


def _refine(reg: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``reg`` with the midpoint added to every one of its intervals that overlaps a table
    interval [lo, hi] whose measured error is too large (local refinement: the rest of the
    table keeps its nodes)."""
    n = reg.size - 1
    i = np.clip(np.searchsorted(reg, lo, side="right") - 1, 0, n - 1)
    j = np.clip(np.searchsorted(reg, hi, side="left"), i + 1, n)  # reg intervals i .. j-1
    mark = np.zeros(n + 1, dtype=np.int64)
    np.add.at(mark, i, 1)
    np.add.at(mark, j, -1)
    idx = np.flatnonzero(np.cumsum(mark)[:n] > 0)
    return np.sort(np.concatenate([reg, 0.5 * (reg[idx] + reg[idx + 1])]))


def _hermite(y0, y1, d0, d1, ds):
    """Coefficients c0..c3 of y(t) = c0 + c1 t + c2 t² + c3 t³ on t ∈ [0, 1] (slopes in s)."""
    m0, m1 = d0 * ds, d1 * ds
    return np.stack([y0, m0, 3.0 * (y1 - y0) - 2.0 * m0 - m1, 2.0 * (y0 - y1) + m0 + m1], axis=1)


def _take(st: UnifiedState, sel) -> UnifiedState:
    """The states ``sel`` (slice or indices) of a batch of states."""
    return UnifiedState(*(f[sel] for f in st))


def _sections(width: float, kinks: int) -> int:
    """Sections S per pass of the kink search: the fewest passes P that shrink brackets of
    ``width`` to ``_KINK_TOL`` with at most ``_KINK_POINTS`` points (≥ 16 per kink), then
    the fewest sections for P passes, width/S^P ≤ _KINK_TOL (1 % margin for rounding)."""
    ratio = width / _KINK_TOL
    if ratio <= 1.0:
        return 2
    most = max(_KINK_POINTS // kinks, 16)
    passes = math.ceil(math.log(ratio) / math.log(most))
    return min(math.ceil(1.01 * ratio ** (1.0 / passes)), most)


def _log_slopes(st: UnifiedState):
    """Slopes in s = ln h of ln F, ln a and φ = h_1/h: (d ln F/d ln a)/(d ln h/d ln a) etc."""
    phi = st.h1 / st.h
    return (st.dlnF_dlna / st.dlnh_dlna, 1.0 / st.dlnh_dlna,
            phi * (st.dlnh1_dlna - st.dlnh_dlna) / st.dlnh_dlna)


class ContactLaw:
    """Tabulated exact contact law of one sphere pair (fast path for DEM codes).

    Parameters
    ----------
    s1, s2 : the spheres.
    h_max : largest approach tabulated; default 0.5·min(R_1, R_2) (R* for a flat partner),
        at most the end of the model's domain (``UnifiedPair.domain``; a larger h_max raises
        ValueError naming it and the allowed range, as do approaches beyond it later).
    h_min : smallest approach tabulated; default 1e-10·R*. Below it and above h_max
        the exact solve is used.
    coeffs : coefficient set; default ``data/coefficients.json``.
    rtol : target relative interpolation error of F, a and dF/dh.

    Attributes
    ----------
    error : dict of measured error bounds (relative) for ``F``, ``a``, ``stiffness``, ``h1``.
    setup_time : seconds spent building the table.
    nodes : number of table nodes; ``kinks``: the approaches h where the model has kinks.
    range_issues : dict cause → message of every calibrated-range warning this law has
        issued (material and pair causes at build; approach causes when first met).
    h_calibrated : largest approach at which every approach-dependent check of the
        calibrated range passes (h/R, a/R, Λ, flow-table slope); the h/R limit beyond the
        table is extrapolated with the last node's shares h_i/h (exact for a rigid partner
        and an equal pair); inf if no check is reached.

    Warns
    -----
    CalibrationRangeWarning: at build for materials or pairs outside the calibrated range;
    at evaluation, once per law and cause, when approaches leave it.
    """

    def __init__(self, s1: Sphere, s2: Sphere, h_max: float | None = None,
                 h_min: float | None = None, coeffs: Coefficients | None = None,
                 rtol: float = 1e-6) -> None:
        t0 = time.perf_counter()
        co = default_coefficients() if coeffs is None else coeffs
        self.pair: UnifiedPair = pair(s1, s2, co)
        self._check = range_check(s1, s2, co)
        Rs = self.pair.R_star
        if h_max is None:
            h_max = 0.5 * min(s1.radius, s2.radius) if math.isfinite(min(s1.radius, s2.radius)) \
                else 0.5 * Rs
            h_max = min(max(h_max, 0.5 * Rs), self.pair.domain.h_max)
        if h_min is None:
            h_min = 1e-10 * Rs
        for name, v in (("h_max", h_max), ("h_min", h_min)):
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        self.pair.check_approach(h_max, "h_max")
        if not h_min < h_max:
            raise ValueError(f"need h_min < h_max, got h_min={h_min!r}, h_max={h_max!r}")
        if not rtol > 0.0:
            raise ValueError(f"rtol must be > 0, got {rtol!r}")
        self.h_min, self.h_max, self.rtol = float(h_min), float(h_max), float(rtol)
        a_lo, a_hi = self.pair.a_from_h(np.array([h_min, h_max]))
        self._lnX = (math.log(a_lo / Rs), math.log(a_hi / Rs))
        lo_end, hi_end = self._lnX
        reg = np.linspace(lo_end, hi_end, max(int(math.ceil((hi_end - lo_end) / DEFAULT_STEP)), 1) + 1)
        self._u_grid = None
        kinks = None
        for _ in range(4):
            kinks = self._build(reg, kinks)
            self.error, bad = self._measure()
            if not bad.any():
                break
            reg = _refine(reg, self._lnX_nodes[:-1][bad], self._lnX_nodes[1:][bad])
        self.kinks = np.exp(self._s[np.isin(self._lnX_nodes, kinks)]) if kinks.size else kinks
        self.range_issues: dict[str, str] = {}
        self._range_thresholds()
        self.h_calibrated = self._h_trigger
        self._report(self._check.static)
        self.setup_time = time.perf_counter() - t0

    # ------------------------------------------------------------------ construction
    def _state(self, lnX, u_guess=None) -> UnifiedState:
        """Exact state at a = R* e^lnX; the κ solve starts from ``u_guess`` if given."""
        a = self.pair.R_star * np.exp(lnX)
        if self.pair.mode != "general":
            return self.pair.state_at_a(a)
        return self.pair.state_at_a(a, self.pair.solve_u(a, u_guess))

    def _u_at(self, lnX):
        """Warm start for the κ variable u = ln(ρ_2/ρ_1), interpolated from the last grid
        (None before the first grid is solved)."""
        if self.pair.mode != "general" or self._u_grid is None:
            return None
        return np.interp(lnX, *self._u_grid)

    def _find_kinks(self, grid: np.ndarray, st: UnifiedState) -> np.ndarray:
        """ln(a/R*) of every piece change of the pair between grid nodes, by multi-section:
        one vectorised κ solve per pass, warm-started by u interpolated between the ends of
        each bracket (u = ln(ρ_2/ρ_1) of the last pass)."""
        piece = st.piece
        j = np.nonzero(piece[1:] != piece[:-1])[0]
        if j.size == 0:
            return np.empty(0)
        lo, hi = grid[j], grid[j + 1]
        u = self._u_of(st)
        u_lo, u_hi = (None, None) if u is None else (u[j], u[j + 1])
        p_lo = piece[j][:, None]
        n = _sections(float(np.max(hi - lo)), lo.size)
        frac = np.arange(1, n) / n
        rows = np.arange(lo.size)
        while np.max(hi - lo) > _KINK_TOL:
            pts = lo[:, None] + (hi - lo)[:, None] * frac[None, :]
            guess = None if u is None else (u_lo[:, None] + (u_hi - u_lo)[:, None] * frac[None, :]).ravel()
            sp = self._state(pts.ravel(), guess)
            changed = sp.piece.reshape(pts.shape) != p_lo
            first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), frac.size)
            below, above = np.maximum(first - 1, 0), np.minimum(first, frac.size - 1)
            keep_lo, keep_hi = first == 0, first == frac.size
            lo, hi = np.where(keep_lo, lo, pts[rows, below]), np.where(keep_hi, hi, pts[rows, above])
            if u is not None:
                up = self._u_of(sp).reshape(pts.shape)
                u_lo = np.where(keep_lo, u_lo, up[rows, below])
                u_hi = np.where(keep_hi, u_hi, up[rows, above])
        return hi

    def _u_of(self, st: UnifiedState):
        """u = ln(ρ_2/ρ_1) of solved states (None if the pair needs no κ solve)."""
        return np.log(st.rho2 / st.rho1) if self.pair.mode == "general" else None

    def _build(self, reg: np.ndarray, kinks: np.ndarray | None = None) -> np.ndarray:
        """Nodes, kinks and Hermite coefficients on the regular nodes ``reg`` (increasing
        ln(a/R*), the table's ends included); returns kinks. ``kinks``: those of a coarser
        build (a refinement keeps them: they are located to ``_KINK_TOL``), else searched.

        Nodes, the one-sided points next to every kink and the error probes of
        :meth:`_measure` are solved together (one vectorised κ solve)."""
        if kinks is None:
            st_reg = self._state(reg, self._u_at(reg))
            if self.pair.mode == "general":
                self._u_grid = (reg, self._u_of(st_reg))
            kinks = self._find_kinks(reg, st_reg)
        if kinks.size:
            gap = np.diff(reg)
            spacing = np.minimum(np.append(gap, gap[-1]), np.append(gap[0], gap))  # local step
            near = np.min(np.abs(reg[:, None] - kinks[None, :]), axis=1) < 0.25 * spacing
            near[[0, -1]] = False
            reg = reg[~near]
        lnX = np.unique(np.concatenate([reg, kinks]))
        k = np.nonzero(np.isin(lnX, kinks))[0]
        probes = np.concatenate([lnX[:-1] + f * np.diff(lnX) for f in _PROBES])
        m, nk = lnX.size, k.size
        pts = np.concatenate([lnX, lnX[k] - _ONE_SIDED, lnX[k] + _ONE_SIDED, probes])
        batch = self._state(pts, self._u_at(pts))
        st = _take(batch, slice(0, m))
        self._probe_state = _take(batch, slice(m + 2 * nk, None))
        # one-sided slopes at kinks: left limit for the interval ending there, right for the next
        dF_l, da_l, dphi_l = _log_slopes(st)
        dF_r, da_r, dphi_r = dF_l.copy(), da_l.copy(), dphi_l.copy()
        for side, (dF, da, dphi) in ((0, (dF_l, da_l, dphi_l)), (1, (dF_r, da_r, dphi_r))):
            sk = _take(batch, slice(m + side * nk, m + (side + 1) * nk))
            dF[k], da[k], dphi[k] = _log_slopes(sk)
        phi = st.h1 / st.h
        s = np.log(st.h)
        ds = np.diff(s)
        if not np.all(ds > 0.0):
            raise ValueError("the coefficient set gives an approach h(a) that is not increasing")
        yF = np.log(st.F)
        if not np.all(np.diff(yF) > 0.0) or not np.all(dF_l > 0.0) or not np.all(dF_r > 0.0):
            raise ValueError("the coefficient set gives a force F(h) that is not increasing")
        self._lnX_nodes = lnX
        self._node_state = st
        self._s = s
        self._inv_ds = 1.0 / ds
        self._cF = _hermite(yF[:-1], yF[1:], dF_r[:-1], dF_l[1:], ds)
        ya = np.log(st.a)
        self._ca = _hermite(ya[:-1], ya[1:], da_r[:-1], da_l[1:], ds)
        self._cphi = _hermite(phi[:-1], phi[1:], dphi_r[:-1], dphi_l[1:], ds)
        # Fritsch–Carlson sufficient condition for a monotone cubic in each interval
        dy = np.diff(yF)
        al, be = dF_r[:-1] * ds / dy, dF_l[1:] * ds / dy
        self.monotone = bool(np.all(al**2 + be**2 <= 9.0))
        self._build_lookup()
        return kinks

    def _build_lookup(self) -> None:
        """Uniform buckets in s mapping to the first candidate interval."""
        s = self._s
        span = s[-1] - s[0]
        width = max(np.min(np.diff(s)), span / 2**16)
        nb = int(math.ceil(span / width)) + 1
        self._s0 = s[0]
        self._inv_w = 1.0 / width
        edges = s[0] + width * np.arange(nb)
        self._lut = np.clip(np.searchsorted(s, edges, side="right") - 1, 0, s.size - 2)
        counts = np.diff(np.append(self._lut, s.size - 2))
        self._passes = max(int(np.max(counts)) if counts.size else 1, 1)
        self._s_next = np.append(s[1:], np.inf)  # right end of interval j, guarded

    def _measure(self) -> tuple[dict, np.ndarray]:
        """Largest relative error at three probes inside every interval (× safety factor), and
        the intervals whose F, a or stiffness error exceeds ``rtol`` there (to be refined)."""
        st = self._probe_state  # exact states at the probes, solved by :meth:`_build`
        F, k, a, h1 = self._eval(st.h, full=True)
        eF, ea, ek = (_SAFETY * np.abs(x / y - 1.0) for x, y in ((F, st.F), (a, st.a), (k, st.stiffness)))
        n = self._lnX_nodes.size - 1  # probes are ordered fraction by fraction over the intervals
        bad = (np.maximum(np.maximum(eF, ea), ek) > self.rtol).reshape(len(_PROBES), n).any(axis=0)
        return {
            "F": float(np.max(eF)),
            "a": float(np.max(ea)),
            "stiffness": float(np.max(ek)),
            "h1": _SAFETY * float(np.max(np.abs(h1 - st.h1) / st.h)),
        }, bad

    # ------------------------------------------------------------------ calibrated range
    def _range_thresholds(self) -> None:
        """Running maximum of every approach-dependent check over the nodes, and the
        approach where each first exceeds its limit (linear in ln h between nodes)."""
        chk, st = self._check, self._node_state
        vals = chk.values(st)
        self._pending: dict[str, tuple[np.ndarray, float]] = {}
        for key, v in vals.items():
            lim = chk.limits[key]
            run = np.maximum.accumulate(v)
            if key == "h_over_R":
                # h_i/R_i = h · r(h): r = run/h is constant for a rigid partner (1/R_1) and an
                # equal pair (1/2R), so interpolating r keeps the check exact there
                run = run / st.h
                t = self._approach_limit(run, lim)
            else:
                above = np.nonzero(run > lim)[0]
                if above.size == 0:
                    t = math.inf
                elif above[0] == 0:
                    t = 0.0
                else:
                    j = above[0]
                    f = (lim - run[j - 1]) / (run[j] - run[j - 1])
                    t = math.exp(self._s[j - 1] + f * (self._s[j] - self._s[j - 1]))
            self._pending[key] = (run, t)
        self._update_trigger()

    def _ratio_at(self, r: np.ndarray, h: float) -> float:
        """r(h) interpolated linearly in ln h (clamped to the end nodes)."""
        return float(np.interp(math.log(h), self._s, r))

    def _approach_limit(self, r: np.ndarray, lim: float) -> float:
        """Smallest h with h · r(h) = lim; r > 0 varies slowly with h, so a fixed-point
        iteration t = lim/r(t) converges in a few steps (beyond the table r is its last node's)."""
        h = np.exp(self._s)
        above = np.nonzero(h * r > lim)[0]
        if above.size == 0:
            return lim / r[-1] if r[-1] > 0.0 else math.inf
        t = lim / r[above[0]]
        for _ in range(20):
            t_new = lim / self._ratio_at(r, t)
            if abs(t_new - t) <= 1e-14 * t:
                break
            t = t_new
        return t

    def _update_trigger(self) -> None:
        self._h_trigger = min((t for _, t in self._pending.values()), default=math.inf)

    def _table_causes(self, h_in: np.ndarray) -> dict[str, float]:
        """Approach causes met by table points h_in: one max() unless the range is left."""
        if h_in.size == 0 or not self._pending:
            return {}
        hi = float(h_in.max())
        if hi <= self._h_trigger:
            return {}
        out = {}
        chk = self._check
        for key, (run, t) in self._pending.items():
            if hi <= t:
                continue
            v = self._ratio_at(run, hi)
            if key == "h_over_R":
                v *= hi  # run holds h_i/R_i over h
            if v > chk.limits[key]:
                out[key] = v
        return out

    def _exact_causes(self, st: UnifiedState, found: dict[str, float]) -> dict[str, float]:
        """Add the approach causes of exact states (points outside the table) to ``found``."""
        if not self._pending:
            return found
        for key, v in self._check.check_state(st).items():
            if key in self._pending:
                found[key] = max(v, found.get(key, -math.inf))
        return found

    def _report(self, causes: dict) -> None:
        """Warn once per cause (values: message or approach value); record it when issued."""
        for key, v in causes.items():
            msg = v if isinstance(v, str) else self._check.message(key, v)
            emit([msg])  # may raise (filter "error"): then the cause stays pending
            self.range_issues[key] = msg
            if key in self._pending:
                del self._pending[key]
                self._update_trigger()

    # ------------------------------------------------------------------ evaluation
    def _index(self, s):
        b = ((s - self._s0) * self._inv_w).astype(np.intp)
        np.clip(b, 0, self._lut.size - 1, out=b)
        j = self._lut[b]
        for _ in range(self._passes):
            j += s >= self._s_next[j]
        np.minimum(j, self._s.size - 2, out=j)
        return j

    def _eval(self, h, full: bool = False):
        """Interpolated F and dF/dh (and a, h1 if ``full``) for h inside the table."""
        s = np.log(h)
        j = self._index(s)
        inv = self._inv_ds[j]
        t = (s - self._s[j]) * inv
        c = self._cF[j]
        y = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
        dy = (c[:, 1] + t * (2.0 * c[:, 2] + 3.0 * t * c[:, 3])) * inv
        F = np.exp(y)
        k = F * dy / h
        if not full:
            return F, k
        ca, cp = self._ca[j], self._cphi[j]
        a = np.exp(ca[:, 0] + t * (ca[:, 1] + t * (ca[:, 2] + t * ca[:, 3])))
        phi = cp[:, 0] + t * (cp[:, 1] + t * (cp[:, 2] + t * cp[:, 3]))
        return F, k, a, phi * h

    def force(self, h):
        """Contact force F and stiffness dF/dh for approaches h (any shape; h ≤ 0: zeros).

        The hot path for DEM: interpolation for h in [h_min, h_max], exact solve outside.
        """
        hh = as_approach(h)
        flat = hh.reshape(-1)
        inside = (flat >= self.h_min) & (flat <= self.h_max)
        if inside.all():
            F, k = self._eval(flat)
            found = self._table_causes(flat)
        else:
            F = np.zeros(flat.shape)
            k = np.zeros(flat.shape)
            found = {}
            if inside.any():
                hin = flat[inside]
                F[inside], k[inside] = self._eval(hin)
                found = self._table_causes(hin)
            out = ~inside & (flat > 0.0)
            if out.any():
                st = self.pair.state_from_h(flat[out])
                F[out], k[out] = st.F, st.stiffness
                found = self._exact_causes(st, found)
        if found:
            self._report(found)
        F, k = F.reshape(hh.shape), k.reshape(hh.shape)
        return (F[()], k[()]) if hh.ndim == 0 else (F, k)

    def __call__(self, h) -> ContactState:
        """Full state (F, a, h1, h2, stiffness; p_m, κ, ρ_i) shaped like h."""
        hh = as_approach(h)
        flat = hh.reshape(-1)
        n = flat.size
        out = {f: np.zeros(n) for f in ContactState._fields}
        out["rho1"][:] = np.inf
        out["rho2"][:] = np.inf
        inside = (flat >= self.h_min) & (flat <= self.h_max)
        found = {}
        if inside.any():
            hi = flat[inside]
            found = self._table_causes(hi)
            F, k, a, h1 = self._eval(hi, full=True)
            out["F"][inside], out["stiffness"][inside], out["a"][inside] = F, k, a
            out["h1"][inside], out["h2"][inside] = h1, hi - h1
            out["p_m"][inside] = F / (math.pi * a * a)
            self._fill_radii(out, inside, a)
        rest = ~inside & (flat > 0.0)
        if rest.any():
            st = self.pair.state_from_h(flat[rest])
            for f in ("F", "a", "h1", "h2", "stiffness", "p_m", "kappa", "rho1", "rho2"):
                out[f][rest] = getattr(st, f)
            found = self._exact_causes(st, found)
        if found:
            self._report(found)
        shaped = {f: v.reshape(hh.shape) for f, v in out.items()}
        return ContactState(**{f: (v[()] if hh.ndim == 0 else v) for f, v in shaped.items()})

    def _fill_radii(self, out: dict, mask: np.ndarray, a: np.ndarray) -> None:
        """κ, ρ_i on table points: closed form for no-solve scenes, exact κ solve otherwise."""
        p = self.pair
        if p.mode == "general":
            st = p.state_at_a(a)
            vals = st.kappa, st.rho1, st.rho2
        else:
            st = p.state_at_a(a[:1])
            vals = st.kappa[0], st.rho1[0], st.rho2[0]
        out["kappa"][mask], out["rho1"][mask], out["rho2"][mask] = vals

    @property
    def nodes(self) -> int:
        return int(self._s.size)

    def describe(self) -> dict:
        """Plain-dict summary: range, node count, measured error bounds, setup time."""
        return {
            "h_min": self.h_min, "h_max": self.h_max, "nodes": self.nodes,
            "kinks_h": [float(x) for x in self.kinks], "error_bound": dict(self.error),
            "monotone": self.monotone, "setup_time_s": self.setup_time, "mode": self.pair.mode,
            "h_calibrated": self.h_calibrated,
            "calibrated_range_warnings": list(self.range_issues.values()),
        }


def contact_table(s1: Sphere, s2: Sphere, h_max: float | None = None,
                  coeffs: Coefficients | None = None, rtol: float = 1e-6) -> ContactLaw:
    """Build the fast per-pair :class:`ContactLaw` up to ``h_max``."""
    return ContactLaw(s1, s2, h_max=h_max, coeffs=coeffs, rtol=rtol)
