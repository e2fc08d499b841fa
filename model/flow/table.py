"""A tabulated flow curve: any monotone (non-decreasing) σ_f(ε_p) given at points, interpolated
linearly and continued beyond the last point with the last segment's slope."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .base import FlowCurve

__all__ = ["Table", "EPS_TABLE_MAX"]

#: largest plastic strain a flow table may reach: beyond it the strains are likely in per cent
EPS_TABLE_MAX = 5.0


@dataclass(frozen=True)
class Table(FlowCurve):
    """σ_f by linear interpolation of (``eps_table``, ``sigma_table``); σ_Y = ``sigma_table[0]``.

    ``eps_table`` must start at 0, increase strictly and stay ≤ ``EPS_TABLE_MAX`` (fractions,
    not per cent); ``sigma_table`` must be positive and non-decreasing; at least two points.
    Stored as tuples of floats.
    """

    name = "table"
    kind = "flow table"

    eps_table: tuple[float, ...]
    sigma_table: tuple[float, ...]

    def __post_init__(self) -> None:
        eps = np.asarray(self.eps_table, dtype=float)
        sig = np.asarray(self.sigma_table, dtype=float)
        if eps.ndim != 1 or sig.ndim != 1 or eps.shape != sig.shape:
            raise ValueError(
                "eps_p and sigma must be 1-D arrays of equal length, "
                f"got shapes {eps.shape} and {sig.shape}"
            )
        if eps.size < 2:
            raise ValueError(f"flow table needs at least 2 points, got {eps.size}")
        if not (np.all(np.isfinite(eps)) and np.all(np.isfinite(sig))):
            raise ValueError("eps_p and sigma must be finite (no NaN/inf)")
        if eps[0] != 0.0:
            raise ValueError(f"eps_p must start at 0, got eps_p[0] = {eps[0]!r}")
        if np.any(np.diff(eps) <= 0.0):
            raise ValueError("eps_p must be strictly increasing")
        if sig[0] <= 0.0:
            raise ValueError(f"sigma must be > 0, got sigma[0] = {sig[0]!r}")
        if np.any(np.diff(sig) < 0.0):
            raise ValueError("sigma must be non-decreasing (a monotone flow curve)")
        if eps[-1] > EPS_TABLE_MAX:
            raise ValueError(
                f"eps_p reaches {eps[-1]:g}, above {EPS_TABLE_MAX:g}: plastic strains look like per "
                f"cent; give them as fractions (e.g. 0.2, not 20)")
        object.__setattr__(self, "eps_table", tuple(eps.tolist()))
        object.__setattr__(self, "sigma_table", tuple(sig.tolist()))

    @classmethod
    def of(cls, flow: FlowCurve, eps_p) -> Table:
        """``flow`` tabulated at the strains ``eps_p`` (starting at 0)."""
        return cls(eps_p, flow.stress(np.asarray(eps_p, dtype=float)))

    @property
    def sigma_y(self) -> float:
        return self.sigma_table[0]

    @property
    def segments(self) -> int:
        return len(self.eps_table) - 1

    @cached_property
    def arrays(self):
        """(ε, σ, segment slopes, last slope) as arrays (made once)."""
        et, st = np.asarray(self.eps_table), np.asarray(self.sigma_table)
        return et, st, np.diff(st) / np.diff(et), (st[-1] - st[-2]) / (et[-1] - et[-2])

    def _stress(self, e):
        et, st, _, slope_end = self.arrays
        return np.where(e <= et[-1], np.interp(e, et, st), st[-1] + slope_end * (e - et[-1]))

    def _slope(self, e):
        et, _, slopes, _ = self.arrays
        idx = np.clip(np.searchsorted(et, e, side="right") - 1, 0, slopes.size - 1)
        return slopes[idx]

    def hardens(self) -> bool:
        return self.sigma_table[-1] > self.sigma_table[0]

    def segment(self, eps) -> np.ndarray:
        et = self.arrays[0]
        return np.clip(np.searchsorted(et, eps, side="right") - 1, 0, et.size - 2)

    def parameters(self) -> dict:
        return {"eps_table": list(self.eps_table), "sigma_table": list(self.sigma_table)}

    def describe(self) -> dict:
        return {"flow": self.name, **self.parameters()}

    def material_description(self) -> dict:
        """``{"eps_table", "sigma_table"}`` (no "flow" key: the stored runs' form)."""
        return self.parameters()

    def spec(self) -> str:
        raise ValueError("a flow table has no --flow form; give it as a CSV file with --flow-table")

    def text(self) -> str:
        return f"flow table of {len(self.eps_table)} points"

    def label(self, sy: str = "sy") -> str:
        return "table"
