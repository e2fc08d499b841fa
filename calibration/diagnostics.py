"""Where the misfit is: residuals by band, and the scatter of the FE points themselves.

* :func:`breakdown` — RMS and max of the relative residuals of H̄ and c² per Λ band (the
  levels), per a/R and h/R band, per hardening and per E/σY, with each group's share of
  the total squared error.
* :func:`noise_floor` — a lower bound of the RMS any smooth law can reach: the scatter of
  the calibration points about a local smooth curve of their own run. For every point,
  ln p_m and ln c² are predicted from the other points of the run within ±``NOISE_WINDOW``
  grid steps by a cubic in ln h (leave-one-out), and the RMS of the prediction errors is
  reported; the same on the raw FE increments (a quadratic over ±0.1 decade of h) gives
  the scatter of one increment's F and a. The resampling on the ln h grid already averages
  the increments, so the first figure is the floor of the fit residuals; it does not
  contain systematic FE errors (discretisation), which move whole stretches of a curve.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.coefficients import Coefficients
from .dataset import PER_DECADE, Dataset, quantities
from .fit import rms

__all__ = ["NOISE_WINDOW", "noise_floor", "breakdown"]

#: half-width of the local cubic of the noise floor, in grid steps (±0.25 decade of h)
NOISE_WINDOW = 4
#: half-width of the local quadratic on the raw increments, in decades of h
RAW_WINDOW = 0.1


def _loo_scatter(x: np.ndarray, y: np.ndarray, half: float, deg: int) -> np.ndarray:
    """Leave-one-out errors of y about a local polynomial in x over |x − x_j| ≤ half."""
    out = np.full(x.size, np.nan)
    for j in range(x.size):
        sel = np.abs(x - x[j]) <= half
        sel[j] = False
        if np.count_nonzero(sel) < deg + 3:
            continue
        c = np.polyfit(x[sel] - x[j], y[sel], deg)
        out[j] = y[j] - c[-1]
    return out


def noise_floor(ds: Dataset) -> dict[str, float]:
    """RMS scatter (relative) of the calibration points and of the raw FE increments.

    Returns
    -------
    dict with ``H_bar``, ``c2`` (points on the ln h grid, leave-one-out about a local cubic,
    the floor of the fit residuals; H̄ ∝ p_m at fixed a) and ``F_increment``,
    ``a_increment`` (one FE increment about a local quadratic), ``points`` used.
    """
    half = (NOISE_WINDOW + 0.5) * math.log(10.0) / PER_DECADE
    eH, ec, eF, ea = [], [], [], []
    for i, c in enumerate(ds.curves):
        m = ds.run == i
        x = np.log(ds.h[m])
        eH.append(_loo_scatter(x, np.log(ds.p_m[m]), half, 3))
        ec.append(_loo_scatter(x, np.log(ds.c2[m]), half, 3))
        sel = c.a_fe >= c.a_min
        xr = np.log(c.h_fe[sel])
        eF.append(_loo_scatter(xr, np.log(c.F_fe[sel]), RAW_WINDOW * math.log(10.0), 2))
        ea.append(_loo_scatter(xr, np.log(c.a_fe[sel]), RAW_WINDOW * math.log(10.0), 2))
    fin = lambda parts: (lambda v: v[np.isfinite(v)])(np.concatenate(parts))  # noqa: E731
    H, C = fin(eH), fin(ec)
    return {"H_bar": rms(H), "c2": rms(C), "F_increment": rms(fin(eF)), "a_increment": rms(fin(ea)),
            "points": int(H.size)}


def _row(label: str, m: np.ndarray, eH: np.ndarray, ec: np.ndarray) -> dict:
    tot_H, tot_c = float(np.sum(eH * eH)), float(np.sum(ec * ec))
    return {"label": label, "points": int(np.count_nonzero(m)),
            "H_rms": rms(eH[m]), "H_max": float(np.max(np.abs(eH[m]))),
            "c2_rms": rms(ec[m]), "c2_max": float(np.max(np.abs(ec[m]))),
            "H_share": float(np.sum(eH[m] ** 2)) / tot_H, "c2_share": float(np.sum(ec[m] ** 2)) / tot_c}


def _bands(label: str, v: np.ndarray, edges, fmt, eH, ec) -> list[dict]:
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        m = (v >= lo) & (v < hi)
        if m.any():
            rows.append(_row(f"{label} {fmt(lo)}–{fmt(hi)}", m, eH, ec))
    return rows


def breakdown(ds: Dataset, coeffs: Coefficients, errors: dict[str, np.ndarray]) -> dict[str, list[dict]]:
    """Residual statistics of ``errors`` (relative, per point) grouped by band.

    Groups: ``level`` (Λ bands split at Λ_I and Λ_III), ``a/R``, ``h/R``, ``hardening``
    (perfectly plastic or Ludwik K, n), ``E/σY``, ``scene``. Each row: points, RMS and max
    of H̄ and c², and the share of the total squared error of each.
    """
    eH, ec = np.asarray(errors["H_bar"]), np.asarray(errors["c2"])
    lam = quantities(ds, coeffs.beta, coeffs.beta_growth, coeffs.strain_spread)["Lambda"]
    l1, l3 = coeffs.Lambda_I, coeffs.Lambda_III
    inner = [v for v in (10.0, 30.0, 100.0, 300.0, 1000.0) if l1 < v < l3]
    g = lambda v: f"{v:.3g}"  # noqa: E731
    out = {"level": _bands("Λ", lam, [0.0, l1, *inner, l3, math.inf], g, eH, ec),
           "a/R": _bands("a/R", ds.x_R, [0.0, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 1.0], g, eH, ec),
           "h/R": _bands("h/R", ds.h_R, [0.0, 0.003, 0.01, 0.03, 0.1, 0.2, math.inf], g, eH, ec)}
    mats = [c.material for c in ds.curves]
    hard = np.array([m.flow.label("σY") or "perfectly plastic" for m in mats])[ds.run]
    out["hardening"] = [_row(h, hard == h, eH, ec) for h in sorted(set(hard))]
    E = np.array([m.E / m.sigma_y for m in mats])[ds.run]
    out["E/σY"] = [_row(f"E/σY = {v:g}", E == v, eH, ec) for v in sorted(set(E))]
    scene = np.array([c.scene for c in ds.curves])[ds.run]
    out["scene"] = [_row(s, scene == s, eH, ec) for s in sorted(set(scene))]
    last = np.zeros(ds.size, dtype=bool)
    for i in range(len(ds.curves)):
        last[np.flatnonzero(ds.run == i)[-1]] = True
    out["end of run"] = [_row("final approach of each run", last, eH, ec),
                         _row("all other points", ~last, eH, ec)]
    return out
