"""Error metrics: relative errors on a run's approach grid, max and RMS over h/R windows.

Pure, vectorised functions. For a prediction y and the FE value y_FE at the same
approaches, the relative error is e = y/y_FE − 1. Over a set of points (a window
or a level) the report gives

* max |e|, and
* RMS = √(∫ e² dh / ∫ dh), the trapezoid rule over the run's approaches restricted
  to the points of the set — an RMS uniform in h, independent of how densely the FE
  increments sample the curve.

Several runs (a class) are pooled as max over the runs' max and √(mean of RMS²),
each run weighted equally.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

__all__ = [
    "Summary",
    "EMPTY",
    "relative_error",
    "trapezoid_weights",
    "summarise",
    "pool",
    "level_labels",
    "LEVELS",
    "interp_loglog",
    "scatter",
    "smooth_loglog",
]

#: point categories of the per-level tables
LEVELS = ("I", "II", "III", "large")


class Summary(NamedTuple):
    """Max |e| and RMS of e over a set of points; n = number of points (0: empty set)."""

    max: float
    rms: float
    n: int

    @property
    def empty(self) -> bool:
        return self.n == 0


EMPTY = Summary(math.nan, math.nan, 0)


def relative_error(pred, ref) -> np.ndarray:
    """e = pred/ref − 1 (NaN where ref ≤ 0 or either value is not finite)."""
    p = np.asarray(pred, dtype=float)
    r = np.asarray(ref, dtype=float)
    ok = (r > 0) & np.isfinite(r) & np.isfinite(p)
    out = np.full(np.broadcast(p, r).shape, np.nan)
    np.divide(p, r, out=out, where=ok)
    return np.where(ok, out - 1.0, np.nan)


def trapezoid_weights(x) -> np.ndarray:
    """Weights w with Σ w f = trapezoid integral of f over the grid x (ascending)."""
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return np.ones_like(x)
    dx = np.diff(x)
    w = np.zeros_like(x)
    w[:-1] += 0.5 * dx
    w[1:] += 0.5 * dx
    return w


def summarise(err, mask=None, weights=None) -> Summary:
    """Max |e| and weighted RMS of e over the points where ``mask`` holds and e is finite."""
    e = np.asarray(err, dtype=float)
    m = np.isfinite(e) if mask is None else (np.asarray(mask, dtype=bool) & np.isfinite(e))
    if not np.any(m):
        return EMPTY
    w = np.ones_like(e) if weights is None else np.asarray(weights, dtype=float)
    ww = w[m]
    if ww.sum() <= 0:
        ww = np.ones_like(ww)
    rms = math.sqrt(float(np.sum(ww * e[m] ** 2) / np.sum(ww)))
    return Summary(float(np.max(np.abs(e[m]))), rms, int(m.sum()))


def pool(summaries) -> Summary:
    """Several runs: max of the maxima, √(mean RMS²) (each run weighted equally)."""
    s = [x for x in summaries if not x.empty]
    if not s:
        return EMPTY
    return Summary(max(x.max for x in s), math.sqrt(sum(x.rms**2 for x in s) / len(s)),
                   sum(x.n for x in s))


def level_labels(levels, h_over_R, large_from: float) -> np.ndarray:
    """Point categories: ``large`` beyond h/R = ``large_from``, else the level I, II or III."""
    lev = np.asarray(levels)
    names = np.array(["I", "II", "III"])[np.clip(lev.astype(int), 1, 3) - 1]
    return np.where(np.asarray(h_over_R) > large_from, "large", names)


def interp_loglog(x_new, x, y) -> np.ndarray:
    """y(x_new) interpolated linearly in ln x, ln y (power laws exactly); NaN outside [x0, x1]."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    xn = np.asarray(x_new, dtype=float)
    ok = (x > 0) & (y > 0)
    x, y = x[ok], y[ok]
    out = np.full(xn.shape, np.nan)
    if x.size < 2:
        return out
    inside = (xn >= x[0]) & (xn <= x[-1]) & (xn > 0)
    out[inside] = np.exp(np.interp(np.log(xn[inside]), np.log(x), np.log(y)))
    return out


def smooth_loglog(h, y, window: int = 11) -> np.ndarray:
    """ln y smoothed by a local quadratic in ln h over ``window`` increments, as y.

    At each point, a least-squares quadratic through the ``window`` increments centred on
    it (one-sided at the ends); points with h ≤ 0 or y ≤ 0 are returned unchanged.
    """
    h = np.asarray(h, dtype=float)
    y = np.asarray(y, dtype=float)
    out = y.copy()
    ok = (h > 0) & (y > 0) & np.isfinite(y)
    n = int(ok.sum())
    if n < window:
        return out
    x, ly = np.log(h[ok]), np.log(y[ok])
    k = window // 2
    sm = np.empty(n)
    for i in range(n):
        lo = min(max(0, i - k), n - window)
        sm[i] = np.polyfit(x[lo:lo + window] - x[i], ly[lo:lo + window], 2)[-1]
    out[ok] = np.exp(sm)
    return out


def local_fit_at(h, y, at: float, window: int = 11) -> float:
    """y at approach ``at`` read on the least-squares quadratic in ln h (of ln y) through the
    ``window`` increments nearest to it: the curve's value with the increment-to-increment
    scatter (:func:`scatter`) averaged out, for comparing two FE runs at one approach."""
    h = np.asarray(h, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = (h > 0) & (y > 0)
    h, y = h[ok], y[ok]
    if h.size < window:
        raise ValueError(f"local_fit_at needs at least window = {window} points with h, y > 0, got {h.size}")
    idx = np.argsort(np.abs(np.log(h) - math.log(at)))[:window]
    c = np.polyfit(np.log(h[idx]) - math.log(at), np.log(y[idx]), 2)
    return float(np.exp(c[-1]))


def scatter(h, y, mask=None, window: int = 11) -> float:
    """Increment-to-increment scatter of a positive curve: max |ln y − smooth(ln y)|.

    The smooth curve is :func:`smooth_loglog`; NaN with fewer points than ``window``.
    Measures the noise of an FE curve against which a model's max error is read.
    """
    h = np.asarray(h, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = (h > 0) & (y > 0)
    if mask is not None:
        ok &= np.asarray(mask, dtype=bool)
    if ok.sum() < window:
        return math.nan
    return float(np.max(np.abs(np.log(y[ok]) - np.log(smooth_loglog(h[ok], y[ok], window)))))
