"""One loading–unloading cycle to the largest approach h_max: residual approach, energies,
restitution (``unloading.py`` gives the branch).

* W_in = ∫₀^h_max F dh along the loading curve: Gauss–Legendre in ln h on ``PANELS`` panels
  of ``POINTS`` points between 10⁻⁹ h_max and h_max, plus F(h_lo) h_lo/(1 + d ln F/d ln h)
  below (a power law there);
* W_returned = ∫_h_res^h_max F dh = F_max δ_e/(m + 1) on the unloading branch (W_in where the
  peak is elastic: the contact returns along the loading curve);
* dissipated work W_in − W_returned (plastic work, and the elastic energy locked in the
  residual stresses);
* e = √(W_returned/W_in): the coefficient of restitution of a quasi-static impact that
  reaches h_max, the kinetic energy of the approach being W_in.

The restitution coefficient is quasi-static: it ignores rate effects (strain-rate hardening
raises the dynamic flow stress), the energy carried away by elastic waves (small unless
the impact is fast against the spheres' wave speeds; Hunter 1957, Johnson 1985 §11.4),
adhesion, friction and the unloading of a contact that was still loading elsewhere.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .coefficients import Coefficients, default_coefficients
from .contact import as_history
from .range_check import emit, range_check
from .sphere import Sphere
from .unified import pair
from .unloading import peak_parameters, work_returned

__all__ = ["Cycle", "cycle", "PANELS", "POINTS", "LOWEST"]

#: quadrature of W_in: panels uniform in ln h, Gauss–Legendre points per panel, lowest h/h_max
PANELS = 24
POINTS = 8
LOWEST = 1e-9


class Cycle(NamedTuple):
    """A cycle to h_max (every field shaped like h_max)."""

    h_max: np.ndarray
    F_max: np.ndarray
    a_max: np.ndarray
    h_res: np.ndarray       # residual approach
    h1_res: np.ndarray      # each body's share of it
    h2_res: np.ndarray
    work_in: np.ndarray     # ∫ F dh while loading from 0 to h_max
    work_returned: np.ndarray
    dissipated: np.ndarray
    restitution: np.ndarray


def _nodes() -> tuple[np.ndarray, np.ndarray]:
    """Points x = ln(h/h_max) and weights of the composite Gauss–Legendre rule."""
    g, wg = np.polynomial.legendre.leggauss(POINTS)
    edges = np.linspace(math.log(LOWEST), 0.0, PANELS + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    x = (mid[:, None] + half[:, None] * g[None, :]).ravel()
    w = (half[:, None] * wg[None, :]).ravel()
    return x, w


def cycle(s1: Sphere, s2: Sphere, h_max, coeffs: Coefficients | None = None) -> Cycle:
    """The cycle to the largest approach ``h_max`` (> 0, any shape) of the pair (module docstring)."""
    hm = as_history(h_max, np.shape(h_max))
    if not np.all(hm > 0.0):
        raise ValueError("h_max (largest approach reached) must be > 0 for a cycle")
    co = default_coefficients() if coeffs is None else coeffs
    p = pair(s1, s2, co)
    chk = range_check(s1, s2, co)
    flat = hm.reshape(-1)
    p.check_approach(flat, "h_max")
    st = p.state_from_h(flat)
    pk = peak_parameters(p, st)
    x, w = _nodes()
    h = flat[:, None] * np.exp(x)[None, :]
    sq = p.state_from_h(h.ravel())
    F = sq.F.reshape(h.shape)
    lo = p.state_from_h(flat * LOWEST)
    tail = lo.F * lo.h / (1.0 + lo.stiffness * lo.h / lo.F)
    w_in = (F * h) @ w + tail
    w_ret = np.where(pk.plastic, work_returned(pk), w_in)
    emit([*chk.static.values(), *chk.messages(chk.check_state(st))])
    shape = hm.shape

    def out(v):
        v = np.asarray(v, dtype=float).reshape(shape)
        return v[()] if v.ndim == 0 else v

    return Cycle(h_max=out(flat), F_max=out(st.F), a_max=out(st.a), h_res=out(pk.h_res),
                 h1_res=out(pk.h1_res), h2_res=out(pk.h2_res), work_in=out(w_in),
                 work_returned=out(w_ret), dissipated=out(w_in - w_ret),
                 restitution=out(np.sqrt(np.clip(w_ret / w_in, 0.0, 1.0))))
