"""Fast path for many contacts of one sphere pair: a monotone table of the exact solution.

``ContactLaw(s1, s2)`` solves the unified model (docs/design.md §3) once on a grid of contact
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
fixed cost that dominates at a table's ~600 points): one for the regular grid (from the
Hertz radii of h_min and h_max, extended where it falls short; its states are the table's
nodes), one for the two ends (inverse Hermite of the grid and one Newton step of h(a) = h),
one per pass of the kink search (sections per pass chosen for the fewest passes; pieces
only, no full states), one for the ends, the kinks, the one-sided points at kinks and the
error probes together, and one per refinement for the new midpoints and the probes of their
halves (every other interval keeps its nodes and probes). All but the grid are warm-started
by the grid's cubic Hermite of u = ln(ρ_2/ρ_1).

Evaluation is a uniform bucket lookup (no binary search), one gather of the interval's
polynomial coefficients, a Horner step and one exponential: no loops over contacts.

Calibrated range (``range_check.py``): material and pair causes warn once, when the
table is built. The approach-dependent causes (h/R, a/R, Λ_i, flow-table slope) are
tabulated at build time as their running maximum over the nodes, which gives for each
cause the approach h where it first leaves the range (for h/R, max_i h_i/R_i of the table's
h_1, within its bound, inside the table); an evaluation compares only the
largest approach of the call with the smallest of these (one reduction, no per-contact
work), and a cause found warns once per ``ContactLaw`` (recorded in
:attr:`ContactLaw.range_issues`) — never per contact or per time step. Approaches outside
the table are checked on their exact states.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from .coefficients import Coefficients, default_coefficients
from .contact import ContactState, as_approach, as_history
from .range_check import emit, range_check
from .sphere import Sphere
from .unified import UnifiedPair, UnifiedState, pair
from .unloading import peak_parameters

__all__ = ["ContactLaw", "contact_table"]

#: ln(a/R*) step of the regular nodes (an interval whose measured error exceeds rtol gets a
#: node at its midpoint, up to ``_REFINEMENTS`` times).
DEFAULT_STEP = 0.02
_REFINEMENTS = 3
_ONE_SIDED = 1e-8  # offset in ln a for the one-sided slopes at kinks
_KINK_TOL = 1e-11  # kink location tolerance in ln a
_KINK_POINTS = 1024  # points per pass of the kink search, shared by the kinks (≥ 16 each)
_KINKS_PER_STEP = 8  # searches of one grid interval for further piece changes after the first
_PROBES = (0.21, 0.5, 0.79)  # error probes: fractions of every interval in ln a
_SAFETY = 2.0      # error bound = safety × largest error found at the probe points
#: a change of u = ln(ρ_2/ρ_1) between neighbouring grid nodes that misses the one predicted by
#: the nodes' du/d ln a by more than this is a jump of the κ root (the prediction is within 0.2
#: where u moves by up to 1.5 a node on the way to a pair's plastic limit; a jump misses it by
#: several units)
_U_JUMP = 0.5
_BELOW = 2.0       # grid steps of the grid's bottom below the Hertz radius of h_min
_WIDER = 0.7       # ln a of the grid's top above the Hertz radius of h_max
_EXTEND = 8        # grid steps added at a time where the grid falls short of an end
_MAX_EXTEND = 100  # extensions before h(a) is taken not to reach an end (16 in ln a)
_END_STEP = 1e-6   # largest Newton step (ln a) of an end taken without the exact inversion
_END_NEWTON = 3    # Newton steps on the exact states at the ends before the exact inversion
#: target bound of the unloading branch's F error (relative to F_max) from the linear
#: interpolation of the recovery and exponent between nodes (``ContactLaw._unloading_error``)
UNLOADING_RTOL = 1e-3


def _midpoints(nodes: np.ndarray, bad: np.ndarray) -> np.ndarray:
    """Midpoints of the intervals [nodes[j], nodes[j + 1]] with ``bad[j]`` (local refinement:
    the other intervals keep their nodes)."""
    return 0.5 * (nodes[:-1][bad] + nodes[1:][bad])


def _probe_points(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The error probes of the intervals [lo, hi], interval by interval (``_PROBES`` of each)."""
    return (lo[:, None] + (hi - lo)[:, None] * np.array(_PROBES)[None, :]).ravel()


def _hermite(y0, y1, d0, d1, ds):
    """Coefficients c0..c3 of y(t) = c0 + c1 t + c2 t² + c3 t³ on t ∈ [0, 1] (slopes in s)."""
    m0, m1 = d0 * ds, d1 * ds
    return np.stack([y0, m0, 3.0 * (y1 - y0) - 2.0 * m0 - m1, 2.0 * (y0 - y1) + m0 + m1], axis=1)


def _hermite_at(x, xs, ys, dys):
    """Cubic Hermite interpolant of (xs, ys) with slopes dys (xs increasing) at x; beyond the
    ends, the end interval's cubic."""
    j = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
    w = xs[j + 1] - xs[j]
    t = (x - xs[j]) / w
    c = _hermite(ys[j], ys[j + 1], dys[j], dys[j + 1], w)
    return c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))


def _take(st, sel):
    """The states ``sel`` (slice or indices) of a batch of states (:class:`UnifiedState` or
    :class:`_Peaks`)."""
    return type(st)(*(f[sel] for f in st))


def _join(a, b):
    """The batches of states a and b, one after the other."""
    return type(a)(*(np.concatenate([x, y]) for x, y in zip(a, b, strict=True)))


class _Peaks(NamedTuple):
    """The unloading branch of a peak at each of a batch of solved states (``unloading.py``)."""

    recovery: np.ndarray  # δ_e/h_max
    m: np.ndarray         # exponent of F = F_max ξ^m
    h1_res: np.ndarray    # body 1's residual approach over h_max


def _peaks_at(p: UnifiedPair, st: UnifiedState) -> _Peaks:
    """:class:`_Peaks` of peaks at the states ``st`` of the pair p (``unloading.peak_parameters``)."""
    pk = peak_parameters(p, st)
    return _Peaks(pk.delta_e / st.h, pk.m, pk.h1_res / st.h)


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


def _jumps(lnX: np.ndarray, u: np.ndarray, du: np.ndarray) -> np.ndarray:
    """Indices j where u(lnX) jumps between nodes j and j + 1: the change misses the trapezoidal
    prediction from du/d ln a by more than ``_U_JUMP``."""
    pred = 0.5 * (du[:-1] + du[1:]) * np.diff(lnX)
    return np.nonzero(np.abs(np.diff(u) - pred) > _U_JUMP)[0]


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
        ValueError naming it and the allowed range, as do approaches beyond it later), and at
        most ``h_limit``.
    h_min : smallest approach tabulated; default 1e-10·R*. Below it and above h_max
        the exact solve is used.
    coeffs : coefficient set; default ``model/coefficients.json``.
    rtol : target relative interpolation error of F, a and dF/dh.
    beyond : ``"exact"`` (default): approaches outside [h_min, h_max] take the exact solve;
        ``"table"``: they take the table's own explicit rule, the one a DEM code applies to a
        table file (``dem/FORMAT.md``): ln F and ln a continue linearly in ln h with the end
        node's one-sided slope, h_1/h and the unloading parameters (recovery, m, h1_res) keep
        the end node's values (no limit on h; κ and ρ_i there are NaN).

    Attributes
    ----------
    error : dict of measured error bounds (relative) for ``F``, ``a``, ``stiffness``, ``h1``,
        and ``unloading_F`` (F on unloading branches, relative to F_max; target ``UNLOADING_RTOL``).
    setup_time : seconds spent building the table.
    nodes : number of table nodes; ``kinks``: the approaches h where the model has kinks.
    h_limit : approach of the last grid node before the κ root jumps (two deformable spheres
        at their plastic limit, where h(a) is nearly vertical: ``unified.py``), inf if it does
        not; the table ends there and the exact solve, which follows the branch, takes the
        approaches beyond (slower: 8–10 ms a contact for the pairs of the tests).
    unloading_table : plain arrays at the table's nodes for the unloading branch of a peak
        there (``unloading.py``): ``ln_h`` (the nodes, ln of the peak approach), ``recovery``
        δ_e/h_max (1: an elastic peak, which returns along the loading curve), ``m`` (exponent
        of F = F_max ξ^m) and ``h1_res`` (body 1's residual approach over h_max); linear in
        ln h between nodes. With the loading table they define ``force(h, h_max)`` completely.
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
                 rtol: float = 1e-6, beyond: str = "exact") -> None:
        t0 = time.perf_counter()
        if beyond not in ("exact", "table"):
            raise ValueError(f"beyond must be 'exact' or 'table', got {beyond!r}")
        self.beyond = beyond
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
        reg, st_reg = self._regular_grid()
        self.h_limit = self._plastic_limit(st_reg)
        self.h_max = min(self.h_max, self.h_limit)
        self._lnX = self._ends(reg, st_reg)
        kinks = self._find_kinks(reg, st_reg)
        self._build(reg, st_reg, kinks)
        self.error, bad = self._measure()
        for _ in range(_REFINEMENTS):
            if not bad.any():
                break
            self._refine(bad)
            self.error, bad = self._measure()
        self.kinks = np.exp(self._s[np.isin(self._lnX_nodes, kinks)]) if kinks.size else kinks
        self.range_issues: dict[str, str] = {}
        self._range_thresholds()
        self.h_calibrated = self._h_trigger
        self._report(self._check.static)
        self.setup_time = time.perf_counter() - t0

    # ------------------------------------------------------------------ construction
    def _solve(self, lnX, u_guess=None):
        """Exact states at a = R* e^lnX and du/d ln a along the κ root (None for scenes
        without a κ solve); the κ solve starts from ``u_guess`` if given, else from the Hertz
        root."""
        a = self.pair.R_star * np.exp(lnX)
        if self.pair.mode != "general":
            return self.pair.state_at_a(a), None
        return self.pair._two_body_state(a, self.pair.solve_u(a, u_guess))

    def _u_at(self, lnX):
        """Warm start for the κ variable u = ln(ρ_2/ρ_1): cubic Hermite of u and du/d ln a of
        the regular grid (None for scenes without a κ solve)."""
        if self._u_grid is None:
            return None
        return _hermite_at(lnX, *self._u_grid)

    def _regular_grid(self):
        """Nodes ``DEFAULT_STEP`` apart in ln(a/R*) and their exact states, over radii that
        cover [h_min, h_max]: from ``_BELOW`` steps below the Hertz radius of h_min (a² = R* h,
        the small-contact limit) to ``_WIDER`` above that of h_max (plastic contacts are wider),
        at most one step beyond the end of the domain; extended by ``_EXTEND`` steps at a
        time while an end falls short. One vectorised κ solve (from the Hertz root)."""
        Rs, step = self.pair.R_star, DEFAULT_STEP
        lo = 0.5 * math.log(self.h_min / Rs) - _BELOW * step
        hi = 0.5 * math.log(self.h_max / Rs) + _WIDER
        a_max = self.pair.domain.a_max
        if math.isfinite(a_max):
            hi = min(hi, math.log(a_max / Rs) + step)
        reg = lo + step * np.arange(max(int(math.ceil((hi - lo) / step)), 1) + 1)
        st, du = self._solve(reg)
        self._u_grid = None if du is None else (reg, self._u_of(st), du)
        for _ in range(_MAX_EXTEND + 1):
            if st.h[0] <= self.h_min and st.h[-1] >= self.h_max:
                return reg, st
            if st.h[0] > self.h_min:
                more = reg[0] - step * np.arange(_EXTEND, 0, -1)
            else:
                more = reg[-1] + step * np.arange(1, _EXTEND + 1)
            st_more, du_more = self._solve(more, self._u_at(more))
            order = np.argsort(np.concatenate([reg, more]))
            reg, st = np.concatenate([reg, more])[order], _take(_join(st, st_more), order)
            if du is not None:
                du = np.concatenate([du, du_more])[order]
                self._u_grid = (reg, self._u_of(st), du)
        raise ValueError("the coefficient set gives an approach h(a) that is not increasing "
                         f"(h = {st.h[0]:.6g} … {st.h[-1]:.6g} over contact radii "
                         f"{Rs * math.exp(reg[0]):.6g} … {Rs * math.exp(reg[-1]):.6g}, "
                         f"h_min = {self.h_min:.6g}, h_max = {self.h_max:.6g})")

    def _plastic_limit(self, st: UnifiedState) -> float:
        """The approach of the last node of the regular grid (``st``, whose u and du/d ln a
        ``self._u_grid`` holds) before the κ root first jumps (a pair at its plastic limit: h(a)
        nearly vertical, ``unified.py``), inf if it does not. A table in a cannot follow the
        branch there; approaches beyond it take the exact solve, which does."""
        if self._u_grid is None:
            return math.inf
        j = _jumps(*self._u_grid)
        j = j[st.h[j] > self.h_min]
        return float(st.h[j[0]]) if j.size else math.inf

    def _ends(self, reg: np.ndarray, st: UnifiedState) -> tuple[float, float]:
        """ln(a/R*) of h_min and h_max: inverse cubic Hermite of the grid (ln a against ln h,
        slopes 1/(d ln h/d ln a)) and up to ``_END_NEWTON`` Newton steps of ln h(a) = ln h on the
        exact states there (warm-started κ solves; the error after a step ≤ ``_END_STEP`` is
        ~ step² ≤ 1e-12); the exact inversion (``UnifiedPair.a_from_h``) where the last step is
        still larger (one step sufficed until the pair's counter-surface terms moved to the
        Hertz partition; steel 2R / aluminium R then needed the inversion: 102 body responses
        against 60 with three steps)."""
        target = np.log([self.h_min, self.h_max])
        t = _hermite_at(target, np.log(st.h), reg, 1.0 / st.dlnh_dlna)
        for _ in range(_END_NEWTON):
            se, _ = self._solve(t, self._u_at(t))
            dt = (np.log(se.h) - target) / se.dlnh_dlna
            t = t - dt
            if np.all(np.abs(dt) <= _END_STEP):
                break
        far = np.abs(dt) > _END_STEP
        if far.any():
            t[far] = np.log(self.pair.a_from_h(np.exp(target[far])) / self.pair.R_star)
        return float(t[0]), float(t[1])

    def _pieces(self, lnX, u_guess=None):
        """Smooth-piece ids at a = R* e^lnX and the κ variable u there (None for scenes without
        a κ solve): the κ solve from ``u_guess`` and the bodies' pieces, no full state."""
        a = self.pair.R_star * np.exp(lnX)
        if self.pair.mode != "general":
            return self.pair.piece_at(a), None
        u = self.pair.solve_u(a, u_guess, with_c2=False)
        return self.pair.piece_at(a, u), u

    def _find_kinks(self, grid: np.ndarray, st: UnifiedState) -> np.ndarray:
        """ln(a/R*) of every piece change of the pair between grid nodes inside the table
        (``self._lnX``), by multi-section: the first pass splits each grid interval at every
        change between its sections (:meth:`_split_changes`), the next passes narrow each part
        to its first change (:meth:`_first_changes`). A part can still hold more than one
        change (two within one section of the first pass): while the piece just above the
        change found differs from the piece at the part's upper end, the rest of it is searched
        again. With the first change per grid interval alone, the second of two changes in one
        interval (a Λ level and the end of the onset ramp, or a flow table's nodes crossed by
        the representative stress's three strains) took a whole second search."""
        lo_end, hi_end = self._lnX
        piece = st.piece
        j = np.nonzero((piece[1:] != piece[:-1]) & (grid[1:] > lo_end) & (grid[:-1] < hi_end))[0]
        if j.size == 0:
            return np.empty(0)
        u = self._u_of(st)
        lo, hi, p_lo, p_hi, u_lo, u_hi = self._split_changes(
            grid[j], grid[j + 1], piece[j], piece[j + 1],
            None if u is None else u[j], None if u is None else u[j + 1])
        found = []
        for _ in range(_KINKS_PER_STEP):
            kink, p_kink, u_kink = self._first_changes(lo, hi, p_lo, p_hi, u_lo, u_hi)
            found.append(kink)
            more = p_kink != p_hi
            if not more.any():
                break
            lo, hi, p_lo, p_hi = kink[more], hi[more], p_kink[more], p_hi[more]
            if u is not None:
                u_lo, u_hi = u_kink[more], u_hi[more]
        kinks = np.sort(np.concatenate(found))
        return kinks[(kinks > lo_end) & (kinks < hi_end)]

    def _split_changes(self, lo, hi, p_lo, p_hi, u_lo, u_hi):
        """The first pass of the kink search: the pieces at the sections of every bracket
        [lo, hi] (one vectorised κ solve warm-started by the grid's Hermite of u) and, for
        every change between consecutive points (the ends included), the section that holds
        it: its ends, their pieces and their u (None for scenes without a κ solve)."""
        n = _sections(float(np.max(hi - lo)), lo.size)
        pts = lo[:, None] + (hi - lo)[:, None] * (np.arange(1, n) / n)[None, :]
        pieces, up = self._pieces(pts.ravel(), None if u_lo is None else self._u_at(pts.ravel()))
        X = np.concatenate([lo[:, None], pts, hi[:, None]], axis=1)
        P = np.concatenate([p_lo[:, None], pieces.reshape(pts.shape), p_hi[:, None]], axis=1)
        r, k = np.nonzero(P[:, 1:] != P[:, :-1])  # row by row, left to right
        if u_lo is None:
            return X[r, k], X[r, k + 1], P[r, k], P[r, k + 1], None, None
        U = np.concatenate([u_lo[:, None], up.reshape(pts.shape), u_hi[:, None]], axis=1)
        return X[r, k], X[r, k + 1], P[r, k], P[r, k + 1], U[r, k], U[r, k + 1]

    def _first_changes(self, lo, hi, p_lo, p_hi, u_lo, u_hi):
        """The first piece change above ``lo`` in each bracket [lo, hi] whose ends have the
        pieces ``p_lo``, ``p_hi``, to ``_KINK_TOL``: one vectorised κ solve per pass (and the
        pieces, :meth:`_pieces`), warm-started by u interpolated between the ends of each bracket
        (u = ln(ρ_2/ρ_1) of the pass before; the brackets are sections of the first pass,
        :meth:`_split_changes`, where this guess is closer than the grid's Hermite). Returns the point
        just above each change, its piece and u there (None for scenes without a κ solve): the
        upper end of the last bracket, whose piece and u a pass has solved (the first pass, or the
        one that moved it there)."""
        p_lo = p_lo[:, None]
        n = _sections(float(np.max(hi - lo)), lo.size)
        frac = np.arange(1, n) / n
        rows = np.arange(lo.size)
        while np.max(hi - lo) > _KINK_TOL:
            pts = lo[:, None] + (hi - lo)[:, None] * frac[None, :]
            guess = None if u_lo is None else (u_lo[:, None] + (u_hi - u_lo)[:, None] * frac[None, :]).ravel()
            pieces, up = self._pieces(pts.ravel(), guess)
            changed = pieces.reshape(pts.shape) != p_lo
            first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), frac.size)
            below, above = np.maximum(first - 1, 0), np.minimum(first, frac.size - 1)
            keep_lo, keep_hi = first == 0, first == frac.size
            lo, hi = np.where(keep_lo, lo, pts[rows, below]), np.where(keep_hi, hi, pts[rows, above])
            p_hi = np.where(keep_hi, p_hi, pieces.reshape(pts.shape)[rows, above])
            if u_lo is not None:
                up = up.reshape(pts.shape)
                u_lo = np.where(keep_lo, u_lo, up[rows, below])
                u_hi = np.where(keep_hi, u_hi, up[rows, above])
        return hi, p_hi, u_hi

    def _u_of(self, st: UnifiedState):
        """u = ln(ρ_2/ρ_1) of solved states (None if the pair needs no κ solve)."""
        return np.log(st.rho2 / st.rho1) if self.pair.mode == "general" else None

    def _build(self, reg: np.ndarray, st_reg: UnifiedState, kinks: np.ndarray) -> None:
        """Nodes, their states and slopes, and the error probes of the table: the grid nodes
        inside the ends (``self._lnX``) that are more than a quarter step from an end or a
        kink (their states are the grid's), the ends and the kinks. The ends, the kinks, the
        one-sided points next to every kink and the probes of :meth:`_measure` are solved
        together (one vectorised κ solve, warm-started from the grid)."""
        ends = np.array(self._lnX)
        fixed = np.concatenate([ends, kinks])
        keep = (reg > ends[0]) & (reg < ends[1])
        keep &= np.min(np.abs(reg[:, None] - fixed[None, :]), axis=1) >= 0.25 * DEFAULT_STEP
        lnX = np.concatenate([reg[keep], fixed])
        order = np.argsort(lnX, kind="stable")
        lnX = lnX[order]
        probes = _probe_points(lnX[:-1], lnX[1:])
        m, nk = fixed.size, kinks.size
        pts = np.concatenate([fixed, kinks - _ONE_SIDED, kinks + _ONE_SIDED, probes])
        batch, _ = self._solve(pts, self._u_at(pts))
        st = _take(_join(_take(st_reg, keep), _take(batch, slice(0, m))), order)
        slopes = np.array([_log_slopes(st)] * 2)  # [left, right][ln F, ln a, φ][node]
        k = np.nonzero(np.isin(lnX, kinks))[0]
        for side in (0, 1):  # one-sided at kinks
            slopes[side][:, k] = _log_slopes(_take(batch, slice(m + side * nk, m + (side + 1) * nk)))
        self._lnX_nodes, self._node_state, self._slopes = lnX, st, slopes
        self._probe_state = _take(batch, slice(m + 2 * nk, None))
        # the unloading branches of peaks at the nodes and probes, kept with their states
        self._node_peaks = _peaks_at(self.pair, st)
        self._probe_peaks = _peaks_at(self.pair, self._probe_state)
        self._assemble()

    def _refine(self, bad: np.ndarray) -> None:
        """Local refinement: a node at the midpoint of every interval ``bad`` (its probes
        missed rtol), solved together with the probes of the halves (one vectorised κ solve);
        every other interval keeps its nodes, slopes and probes."""
        X = self._lnX_nodes
        mid = _midpoints(X, bad)
        left = np.concatenate([X[:-1][bad], mid])
        right = np.concatenate([mid, X[1:][bad]])
        pts = np.concatenate([mid, _probe_points(left, right)])
        batch, _ = self._solve(pts, self._u_at(pts))
        st_mid = _take(batch, slice(0, mid.size))
        order = np.argsort(np.concatenate([X, mid]), kind="stable")
        self._lnX_nodes = np.concatenate([X, mid])[order]
        self._node_state = _take(_join(self._node_state, st_mid), order)
        self._node_peaks = _take(_join(self._node_peaks, _peaks_at(self.pair, st_mid)), order)
        new = np.array(_log_slopes(st_mid))  # midpoints lie inside smooth pieces: one slope
        self._slopes = np.concatenate([self._slopes, np.stack([new, new])], axis=2)[:, :, order]
        # probes, interval by interval: the rows of the kept intervals and those of the halves,
        # ordered by the intervals' left ends
        P, n_old = len(_PROBES), self._probe_state.a.size
        rows = np.concatenate([np.arange(n_old).reshape(-1, P)[~bad],
                               n_old + np.arange(left.size * P).reshape(-1, P)])
        rows = rows[np.argsort(np.concatenate([X[:-1][~bad], left]), kind="stable")]
        st_new = _take(batch, slice(mid.size, None))
        self._probe_state = _take(_join(self._probe_state, st_new), rows.ravel())
        self._probe_peaks = _take(_join(self._probe_peaks, _peaks_at(self.pair, st_new)), rows.ravel())
        self._assemble()

    def _assemble(self) -> None:
        """Hermite coefficients of ln F, ln a and φ against s = ln h from the nodes' states and
        slopes (one-sided at kinks: left limit for the interval ending there, right for the
        next), the monotonicity checks and the lookup."""
        st = self._node_state
        (dF_l, da_l, dphi_l), (dF_r, da_r, dphi_r) = self._slopes
        phi = st.h1 / st.h
        s = np.log(st.h)
        ds = np.diff(s)
        if not np.all(ds > 0.0):
            raise ValueError("the coefficient set gives an approach h(a) that is not increasing")
        yF = np.log(st.F)
        if not np.all(np.diff(yF) > 0.0) or not np.all(dF_l > 0.0) or not np.all(dF_r > 0.0):
            raise ValueError("the coefficient set gives a force F(h) that is not increasing")
        self._s = s
        self._inv_ds = 1.0 / ds
        self._cF = _hermite(yF[:-1], yF[1:], dF_r[:-1], dF_l[1:], ds)
        self._cF_cols = tuple(np.ascontiguousarray(self._cF[:, i]) for i in range(4))
        ya = np.log(st.a)
        self._ca = _hermite(ya[:-1], ya[1:], da_r[:-1], da_l[1:], ds)
        self._cphi = _hermite(phi[:-1], phi[1:], dphi_r[:-1], dphi_l[1:], ds)
        # Fritsch–Carlson sufficient condition for a monotone cubic in each interval
        dy = np.diff(yF)
        al, be = dF_r[:-1] * ds / dy, dF_l[1:] * ds / dy
        self.monotone = bool(np.all(al**2 + be**2 <= 9.0))
        # unloading branch of a peak at each node (``unloading.py``), interpolated linearly in s:
        # recovery δ_e/h_max (1: an elastic peak, which unloads along the loading curve), the
        # exponent m and body 1's residual approach over h_max
        pk = self._node_peaks
        self.unloading_table = {"ln_h": s, "recovery": pk.recovery, "m": pk.m, "h1_res": pk.h1_res}
        tab = self.unloading_table  # per interval: value at its start and increment over it
        self._un = {k: (tab[k][:-1].copy(), np.diff(tab[k])) for k in ("recovery", "m", "h1_res")}
        # peaks up to the last node of the elastic prefix (recovery 1: Level I) unload along the
        # loading curve
        plastic = np.flatnonzero(tab["recovery"] < 1.0 - 1e-9)  # the node at Λ_I may be 1 − 1e-12
        first = plastic[0] if plastic.size else s.size
        self._h_elastic = float(np.exp(s[first - 1])) if first > 0 else 0.0
        # the table's rule beyond its ends (``beyond="table"``): value and one-sided slope of
        # ln F, ln a at the end nodes (first: right slope, last: left slope), φ and the unloading
        # parameters there; columns [first node, last node]
        self._ends_rule = {"s": s[[0, -1]], "lnF": yF[[0, -1]], "dlnF": np.array([dF_r[0], dF_l[-1]]),
                           "lna": ya[[0, -1]], "dlna": np.array([da_r[0], da_l[-1]]),
                           "phi": phi[[0, -1]],
                           **{k: tab[k][[0, -1]] for k in ("recovery", "m", "h1_res")}}
        self._build_lookup()

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
        st = self._probe_state  # exact states at the probes, solved by :meth:`_build`, :meth:`_refine`
        F, k, a, h1 = self._eval(st.h, full=True)
        eF, ea, ek = (_SAFETY * np.abs(x / y - 1.0) for x, y in ((F, st.F), (a, st.a), (k, st.stiffness)))
        n = self._lnX_nodes.size - 1  # probes are ordered interval by interval
        bad = (np.maximum(np.maximum(eF, ea), ek) > self.rtol).reshape(n, len(_PROBES)).any(axis=1)
        eU = self._unloading_error(st, self._probe_peaks)
        bad |= (eU > UNLOADING_RTOL).reshape(n, len(_PROBES)).any(axis=1)
        return {
            "F": float(np.max(eF)),
            "a": float(np.max(ea)),
            "stiffness": float(np.max(ek)),
            "h1": _SAFETY * float(np.max(np.abs(h1 - st.h1) / st.h)),
            "unloading_F": float(np.max(eU)),
        }, bad

    def _unloading_error(self, st: UnifiedState, pk: _Peaks) -> np.ndarray:
        """Bound on the unloading branch's F error (relative to F_max) of the linear recovery and
        exponent at exact states ``st`` (their peaks' exact branches ``pk``): |Δδ_e|/δ_e
        + |Δm|/(e m) (F = F_max ξ^m: a relative error ε of δ_e moves F by at most ~ε F_max, an
        error Δm by at most Δm/(e m) F_max), × the safety factor."""
        s = np.log(st.h)
        j = self._index(s)
        t = (s - self._s[j]) * self._inv_ds[j]
        r0, dr = self._un["recovery"]
        m0, dm = self._un["m"]
        rec, m = r0[j] + t * dr[j], m0[j] + t * dm[j]
        return _SAFETY * (np.abs(rec / pk.recovery - 1.0) + np.abs(m - pk.m) / (math.e * pk.m))

    # ------------------------------------------------------------------ calibrated range
    def _range_thresholds(self) -> None:
        """Running maximum of every approach-dependent check over the nodes, and the
        approach where each first exceeds its limit (linear in ln h between nodes; the h/R
        check on the table's h_1 inside the table, :meth:`_approach_limit`)."""
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

    def _own_ratio(self, h: float, r: np.ndarray) -> float:
        """max_i h_i/R_i (the h/R check) at approach h: from the table's h_1 inside the table
        (within the bound ``error["h1"]``), else h · r(h) (r: the nodes' ratio over h, the last
        node's beyond the table)."""
        if not self.h_min <= h <= self.h_max:
            return h * self._ratio_at(r, h)
        hh = np.array([h])
        h1 = self._eval(hh, full=True)[3]
        return float(self._check.approach_ratio(hh, h1, hh - h1)[0])

    def _approach_limit(self, r: np.ndarray, lim: float) -> float:
        """Smallest h with max_i h_i/R_i = lim, from r = (running max of max_i h_i/R_i)/h at
        the nodes: r varies slowly with h (it is constant for a rigid partner and an equal
        pair), so the fixed-point iteration t = t · lim/ratio(t) (:meth:`_own_ratio`)
        converges in a few steps from the first node beyond the limit."""
        h = np.exp(self._s)
        above = np.nonzero(h * r > lim)[0]
        if above.size == 0:
            return lim / r[-1] if r[-1] > 0.0 else math.inf
        t = lim / r[above[0]]
        for _ in range(30):
            t_new = t * lim / self._own_ratio(t, r)
            if abs(t_new - t) <= 1e-14 * t:
                return t_new
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
            # run holds h_i/R_i over h for the h/R check, which is read from the table's h_1
            v = self._own_ratio(hi, run) if key == "h_over_R" else self._ratio_at(run, hi)
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
        c0, c1, c2, c3 = (col[j] for col in self._cF_cols)  # 1-D gathers: ~10× a row gather
        y = c3 * t
        y += c2
        y *= t
        y += c1
        y *= t
        y += c0
        dy = c3 * (3.0 * t)
        dy += 2.0 * c2
        dy *= t
        dy += c1
        dy *= inv
        F = np.exp(y)
        dy *= F
        dy /= h
        k = dy
        if not full:
            return F, k
        ca, cp = self._ca[j], self._cphi[j]
        a = np.exp(ca[:, 0] + t * (ca[:, 1] + t * (ca[:, 2] + t * ca[:, 3])))
        phi = cp[:, 0] + t * (cp[:, 1] + t * (cp[:, 2] + t * cp[:, 3]))
        return F, k, a, phi * h

    def _end_of(self, h):
        """Index into the end-node columns of ``_ends_rule``: 0 below the table, 1 above it."""
        return (np.log(h) > self._ends_rule["s"][0]).astype(np.intp)

    def _eval_beyond(self, h, full: bool = False):
        """The table's rule for h > 0 outside [h_min, h_max] (``beyond="table"``): ln F and ln a
        linear in s = ln h from the nearer end node with its one-sided slope, φ = h_1/h constant;
        F and dF/dh = F (d ln F/d ln h)/h (and a, h1 if ``full``)."""
        e = self._end_of(h)
        r = self._ends_rule
        ds = np.log(h) - r["s"][e]
        F = np.exp(r["lnF"][e] + r["dlnF"][e] * ds)
        k = F * r["dlnF"][e] / h
        if not full:
            return F, k
        a = np.exp(r["lna"][e] + r["dlna"][e] * ds)
        return F, k, a, r["phi"][e] * h

    def _peaks(self, hm):
        """(F_max, a_max, h1_max, recovery δ_e/h_max, m, h1_res/h_max) of peaks at hm (1-D, > 0):
        the table inside it, the exact state and law outside."""
        hm = np.asarray(hm, dtype=float)
        n = hm.size
        out = [np.zeros(n) for _ in range(6)]
        inside = (hm >= self.h_min) & (hm <= self.h_max)
        if inside.any():
            x = hm[inside]
            F, _, a, h1 = self._eval(x, full=True)
            s = np.log(x)
            j = self._index(s)
            t = (s - self._s[j]) * self._inv_ds[j]
            vals = [F, a, h1] + [self._un[k][0][j] + t * self._un[k][1][j]
                                 for k in ("recovery", "m", "h1_res")]
            for o, v in zip(out, vals, strict=True):
                o[inside] = v
        if not inside.all() and self.beyond == "table":
            x = hm[~inside]
            F, _, a, h1 = self._eval_beyond(x, full=True)
            e = self._end_of(x)
            vals = [F, a, h1] + [self._ends_rule[k][e] for k in ("recovery", "m", "h1_res")]
            for o, v in zip(out, vals, strict=True):
                o[~inside] = v
        elif not inside.all():
            x = hm[~inside]
            self.pair.check_approach(x, "h_max")
            st = self.pair.state_from_h(x)
            pk = peak_parameters(self.pair, st)
            vals = [st.F, st.a, st.h1, pk.delta_e / x, pk.m, pk.h1_res / x]
            for o, v in zip(out, vals, strict=True):
                o[~inside] = v
        return out

    def _force_history(self, h, hm):
        """F and dF/dh with history when every loading contact's h and every plastic peak lie in
        the table (the hot path: one lookup per contact, at h where it loads or its peak is
        elastic — back along the loading curve — else at its peak h_max; in place where it saves a
        pass). Returns None when some contact needs the exact solve."""
        loading = h >= hm
        loading |= hm <= self._h_elastic
        q = np.where(loading, h, hm)               # where the table is read
        if q.size and q.max() > self.h_max:
            return None
        low = q < self.h_min                       # h ≤ 0 (no contact) or below the table
        any_low = bool(low.any())
        if any_low and self.beyond == "table" and bool(np.any(low & (h > 0.0))):
            return None                            # the table's rule below h_min: the general path
        if any_low:
            q[low] = self.h_min
        s = np.log(q)
        j = self._index(s)
        inv = self._inv_ds[j]
        t = s
        t -= self._s[j]
        t *= inv                                   # position in the interval
        c0, c1, c2, c3 = (col[j] for col in self._cF_cols)
        y = c3 * t
        y += c2
        y *= t
        y += c1
        y *= t
        y += c0                                    # ln F(q)
        dy = c3 * (3.0 * t)
        dy += 2.0 * c2
        dy *= t
        dy += c1
        dy *= inv                                  # d ln F/d ln h at q
        r0, dr = self._un["recovery"]
        m0, dm = self._un["m"]
        delta = dr[j] * t
        delta += r0[j]
        delta *= q                                 # δ_e of a peak at q
        m1 = dm[j] * t
        m1 += m0[j]
        m1 -= 1.0                                  # exponent − 1
        xi = h - q
        xi /= delta
        xi += 1.0
        np.clip(xi, 0.0, 1.0, out=xi)              # ξ (1 where the table is read at h)
        w = np.maximum(xi, 1e-300)
        np.log(w, out=w)
        w *= m1
        w += y
        np.exp(w, out=w)
        w *= xi > 0.0                              # F(q) ξ^(m−1), 0 where ξ = 0
        F = w * xi
        dy *= F
        dy /= q                                    # loading stiffness
        m1 += 1.0
        w *= m1
        w /= delta                                 # unloading stiffness
        k = np.where(loading, dy, w)
        if any_low:
            F[low], k[low] = 0.0, 0.0
            pos = low & (h > 0.0)                  # 0 < h < h_min: the exact solve
            if pos.any():
                F[pos], k[pos] = self.loading_force(h[pos])
        return F, k

    def _unload(self, h, hm, full: bool = False):
        """F and dF/dh (and a, h1 if ``full``) on the unloading branches of peaks at hm > h;
        an elastic peak (recovery 1) returns along the loading curve. F and dF/dh alone come
        from :meth:`_force_history` where the table holds the peaks."""
        if not full:
            fast = self._force_history(h, hm)
            if fast is not None:
                return fast
        F_max, a_max, h1_max, rec, m, h1r = self._peaks(hm)
        delta = rec * hm
        xi = np.clip((h - hm + delta) / delta, 0.0, 1.0)
        on = xi > 0.0
        xm1 = np.where(on, xi ** (m - 1.0), 0.0)
        F = F_max * xi * xm1
        k = m * F_max * xm1 / delta
        a = a_max * xm1
        h1_res = h1r * hm
        h1 = np.where(on, h1_res + xi * (h1_max - h1_res), 0.0)
        elastic = (hm <= self._h_elastic) & (h > 0.0)
        if elastic.any():
            if full:
                st = self(h[elastic])
                F[elastic], k[elastic], a[elastic], h1[elastic] = st.F, st.stiffness, st.a, st.h1
            else:
                F[elastic], k[elastic] = self.loading_force(h[elastic])
        return (F, k, a, h1) if full else (F, k)

    def force(self, h, h_max):
        """Contact force F and stiffness dF/dh for approaches h with their history.

        The hot path for DEM: interpolation for h in [h_min, h_max], exact solve outside.

        Parameters
        ----------
        h : approaches (any shape; h ≤ 0: no contact, zeros).
        h_max : the largest approach each contact has reached before (scalar or shaped like
            h). Below it the contact is on its unloading/reloading branch (``unloading.py``;
            F = 0 at and below the residual approach), at or above it on the loading curve.
            Keep the history with ``np.maximum(h_max, h)`` after each step; for a first
            loading without history use :meth:`loading_force`.

        Returns
        -------
        F, dF/dh : arrays shaped like h (floats for a scalar h).
        """
        hh = as_approach(h)
        hm = as_history(h_max, hh.shape).reshape(-1)
        flat = hh.reshape(-1)
        fast = self._force_history(flat, hm)
        if fast is not None:
            F, k = fast
            found = self._table_causes(np.array([flat.max(), hm.max()]) if flat.size else flat)
            if found:
                self._report(found)
            F, k = F.reshape(hh.shape), k.reshape(hh.shape)
            return (F[()], k[()]) if hh.ndim == 0 else (F, k)
        below = flat < hm  # some contact needs the exact solve: loading and unloading apart
        F = np.zeros(flat.shape)
        k = np.zeros(flat.shape)
        F[below], k[below] = self._unload(flat[below], hm[below])
        up = ~below
        if up.any():
            F[up], k[up] = self.loading_force(flat[up])
        F, k = F.reshape(hh.shape), k.reshape(hh.shape)
        return (F[()], k[()]) if hh.ndim == 0 else (F, k)

    def loading_force(self, h):
        """F and dF/dh on the first loading curve (every contact at its largest approach so far).

        The same as ``force(h, h_max=h)``; a contact that has unloaded needs :meth:`force`.
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
            if out.any() and self.beyond == "table":
                F[out], k[out] = self._eval_beyond(flat[out])
                found = {**self._table_causes(flat[out]), **found}
            elif out.any():
                st = self.pair.state_from_h(flat[out])
                F[out], k[out] = st.F, st.stiffness
                found = self._exact_causes(st, found)
        if found:
            self._report(found)
        F, k = F.reshape(hh.shape), k.reshape(hh.shape)
        return (F[()], k[()]) if hh.ndim == 0 else (F, k)

    def __call__(self, h, h_max=None) -> ContactState:
        """Full state (F, a, h1, h2, stiffness; p_m, κ, ρ_i) shaped like h; ``h_max`` as in
        :meth:`force` (on an unloading branch κ and ρ_i are the peak's)."""
        if h_max is not None:
            return self._state_with_history(h, h_max)
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
        if rest.any() and self.beyond == "table":
            hr = flat[rest]
            F, k, a, h1 = self._eval_beyond(hr, full=True)
            out["F"][rest], out["stiffness"][rest], out["a"][rest] = F, k, a
            out["h1"][rest], out["h2"][rest] = h1, hr - h1
            out["p_m"][rest] = F / (math.pi * a * a)
            out["kappa"][rest] = out["rho1"][rest] = out["rho2"][rest] = np.nan
            found = {**self._table_causes(hr), **found}
        elif rest.any():
            st = self.pair.state_from_h(flat[rest])
            for f in ("F", "a", "h1", "h2", "stiffness", "p_m", "kappa", "rho1", "rho2"):
                out[f][rest] = getattr(st, f)
            found = self._exact_causes(st, found)
        if found:
            self._report(found)
        shaped = {f: v.reshape(hh.shape) for f, v in out.items()}
        return ContactState(**{f: (v[()] if hh.ndim == 0 else v) for f, v in shaped.items()})

    def _state_with_history(self, h, h_max) -> ContactState:
        hh = as_approach(h)
        hm = as_history(h_max, hh.shape).reshape(-1)
        flat = hh.reshape(-1)
        below = flat < hm
        st = self(np.where(below, 0.0, flat))  # loading points (zeros where below)
        out = {f: np.array(getattr(st, f), dtype=float).reshape(-1) for f in ContactState._fields}
        if below.any():
            x, xm = flat[below], hm[below]
            F, k, a, h1 = self._unload(x, xm, full=True)
            on = F > 0.0
            peak = self(xm)
            for f, v in (("F", F), ("stiffness", k), ("a", a), ("h1", h1), ("h2", np.where(on, x - h1, 0.0))):
                out[f][below] = v
            with np.errstate(invalid="ignore", divide="ignore"):
                out["p_m"][below] = np.where(on, F / (math.pi * a * a), 0.0)
            for f in ("kappa", "rho1", "rho2"):
                out[f][below] = np.where(on, getattr(peak, f), 0.0 if f == "kappa" else np.inf)
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

    def tables(self) -> dict:
        """The table as plain arrays, enough to evaluate ``force(h, h_max)`` elsewhere (a DEM code).

        Keys: ``ln_h`` (n nodes, increasing), ``ln_F_hermite`` (n − 1, 4): c₀…c₃ of
        ln F = c₀ + c₁t + c₂t² + c₃t³ on interval j, t = (ln h − ln_h[j])/(ln_h[j+1] − ln_h[j]);
        ``recovery`` and ``m`` (n): δ_e/h_max and the exponent of a peak at each node, linear in
        t; ``h_elastic``: peaks up to it unload along the loading curve; ``h_min``, ``h_max``: the
        table's range (outside it, the exact solve, or with ``beyond="table"`` the rule of
        :meth:`_eval_beyond`). The node values and one-sided slopes (against ln h) the Hermite
        coefficients are built from: ``ln_F``, ``dln_F_left``, ``dln_F_right``, and the same of
        ln a (``ln_a``…) and φ = h_1/h (``phi``…); ``h1_res``: body 1's residual approach over
        h_max of a peak at each node. For a contact at h with largest approach hm:

        * loading (h ≥ hm) or elastic peak (hm ≤ h_elastic): q = h, F = exp(ln F(q)),
          dF/dh = F (d ln F/dt)/(q Δ_j), Δ_j = ln_h[j+1] − ln_h[j];
        * else q = hm, δ_e = recovery(q)·hm, ξ = clip((h − hm)/δ_e + 1, 0, 1),
          F = exp(ln F(q)) ξ^m, dF/dh = m exp(ln F(q)) ξ^(m−1)/δ_e (0 at ξ = 0);
        * h ≤ 0: F = dF/dh = 0.
        """
        st = self._node_state
        (dF_l, da_l, dphi_l), (dF_r, da_r, dphi_r) = self._slopes
        return {"ln_h": self._s.copy(), "ln_F_hermite": self._cF.copy(),
                "recovery": self.unloading_table["recovery"].copy(),
                "m": self.unloading_table["m"].copy(), "h_elastic": self._h_elastic,
                "h_min": self.h_min, "h_max": self.h_max,
                "h1_res": self.unloading_table["h1_res"].copy(),
                "ln_F": np.log(st.F), "dln_F_left": dF_l.copy(), "dln_F_right": dF_r.copy(),
                "ln_a": np.log(st.a), "dln_a_left": da_l.copy(), "dln_a_right": da_r.copy(),
                "phi": st.h1 / st.h, "dphi_left": dphi_l.copy(), "dphi_right": dphi_r.copy()}

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
