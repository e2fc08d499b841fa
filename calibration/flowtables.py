"""The tabulated flow curves of a dataset, evaluated at every point in one pass.

``Material.flow_stress`` and ``flow_slope`` read one table; the fits evaluate the representative
stress of every tabulated run at each new β (``forms._stress_at``), which one numpy pass over
all of them does faster than a loop over the runs. The values are those of the per-material
functions bit for bit: the interpolation repeats ``np.interp``'s arithmetic, slope·(ε − ε_j) + σ_j
with the node value at a node, and the tables are padded with +inf strains and searched by one
bisection of all points at once (tested).
"""

from __future__ import annotations

import numpy as np

from ..model.material import Material

__all__ = ["FlowTables"]


class FlowTables:
    """The tables of ``materials`` (each ``is_tabulated``) stacked as rows of one flat array;
    ``rows`` below give each point's table."""

    def __init__(self, materials: list[Material]):
        self.width = max(len(m.eps_table) for m in materials)
        eps = np.full((len(materials), self.width), np.inf)
        sig, slopes = np.zeros_like(eps), np.zeros_like(eps)
        self.last = np.array([len(m.eps_table) - 1 for m in materials])
        self.slope_end = np.empty(len(materials))
        for i, m in enumerate(materials):
            et, st, sl, self.slope_end[i] = m.flow.arrays
            eps[i, :et.size], sig[i, :st.size], slopes[i, :sl.size] = et, st, sl
        self.eps, self.sig, self.slopes = eps.ravel(), sig.ravel(), slopes.ravel()

    def flow(self, rows, eps) -> tuple[np.ndarray, np.ndarray]:
        """σ_f(ε) and dσ_f/dε of each point's table (``Material.flow_stress``, linear beyond the
        table's end, and ``Material.flow_slope``, the right derivative)."""
        e = np.maximum(np.asarray(eps, dtype=float), 0.0)
        base = rows * self.width
        lo, hi = np.zeros(e.size, dtype=int), np.full(e.size, self.width)
        for _ in range(self.width.bit_length()):  # bisection: nodes[:lo] ≤ e < nodes[hi:]
            mid = (lo + hi) // 2
            below = self.eps[base + np.minimum(mid, self.width - 1)] <= e
            lo, hi = np.where(below & (mid < hi), mid + 1, lo), np.where(below, hi, mid)
        j, last = lo - 1, self.last[rows]  # j: the last node ≤ e (−1 below the table)
        k = base + np.clip(j, 0, last - 1)  # the segment, clipped to the table
        e0, s0, slope = self.eps[k], self.sig[k], self.slopes[k]
        inner = np.where(e0 == e, s0, slope * (e - e0) + s0)
        e_end, s_end = self.eps[base + last], self.sig[base + last]
        inside = np.where(j < 0, self.sig[base], np.where(j >= last, s_end, inner))
        return np.where(e <= e_end, inside, s_end + self.slope_end[rows] * (e - e_end)), slope
