"""The model's design goal, per run: max |error| ≤ 3 % in F and a, RMS ≤ 1.5 %, split ≤ 5 points.

Reported, never the exit status (``thresholds.toml`` ``[goal]``; the exit status is ``[model]``).
Each run is scored twice over the acceptance window: against the FE curves as stored, and
against them with their increment-to-increment scatter smoothed out (``metrics.smooth_loglog``,
a local quadratic in ln h over 11 increments), which tells a miss of the model's form from one
the FE's own noise makes.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..metrics import EMPTY, Summary, relative_error, smooth_loglog, summarise, trapezoid_weights
from .compare import W_ACCEPT, Comparison
from .config import Thresholds
from .tables import pct

__all__ = ["GoalRow", "goal_rows", "goal_section"]


@dataclass(frozen=True)
class GoalRow:
    """One run against the goal: summaries (max, RMS) of the F and a errors, raw and against
    the smoothed FE, and the largest split error (NaN for one body)."""

    label: str
    F: Summary
    a: Summary
    F_smooth: Summary
    a_smooth: Summary
    split: float

    def misses(self, th: Thresholds, smooth: bool = False) -> list[str]:
        """What the run misses: ``F max``, ``a max``, ``F rms``, ``a rms``, ``split``."""
        F, a = (self.F_smooth, self.a_smooth) if smooth else (self.F, self.a)
        out = [f"{q} max" for q, s, lim in (("F", F, th.goal_F_max), ("a", a, th.goal_a_max))
               if not s.empty and s.max > lim]
        out += [f"{q} rms" for q, s in (("F", F), ("a", a)) if not s.empty and s.rms > th.goal_rms_max]
        if self.split > th.goal_split_max:
            out.append("split")
        return out


def _smoothed(c: Comparison, q: str) -> Summary:
    pred = getattr(c.model, q)
    fe = getattr(c.case, q)
    if pred is None or fe is None or fe.size < 2:
        return EMPTY
    e = relative_error(pred, smooth_loglog(c.case.h, fe))
    return summarise(e, c.masks[W_ACCEPT] & c.resolved, trapezoid_weights(c.case.h))


def goal_rows(comps: list[Comparison]) -> list[GoalRow]:
    """Every run's errors against the goal (module docstring)."""
    rows = []
    for c in comps:
        sp = c.model.summary(W_ACCEPT, "split")
        rows.append(GoalRow(c.case.label, c.model.summary(W_ACCEPT, "F"), c.model.summary(W_ACCEPT, "a"),
                            _smoothed(c, "F"), _smoothed(c, "a"), float("nan") if sp.empty else sp.max))
    return rows


def goal_section(rows: list[GoalRow], th: Thresholds) -> list[str]:
    """Markdown lines: the count of runs that miss the goal, raw and smoothed, and the table of
    those that miss it."""
    raw = [r for r in rows if r.misses(th)]
    smooth = [r for r in rows if r.misses(th, smooth=True)]
    goal = (f"max |error| ≤ {100 * th.goal_F_max:g} % in F and {100 * th.goal_a_max:g} % in a, "
            f"RMS ≤ {100 * th.goal_rms_max:g} %, two bodies' h₁/h split within "
            f"{100 * th.goal_split_max:g} points")
    lines = [f"Goal ({goal}; `[goal]`, reported, not the exit status): "
             + (f"**met on all {len(rows)} runs**." if not raw else
                f"**missed on {len(raw)} of {len(rows)} runs**; against the FE curves with their "
                f"increment scatter smoothed out (local quadratic over 11 increments) on "
                f"{len(smooth)}.")]
    if raw:
        lines += ["", "| run | misses | F max (rms) % | a max (rms) % | F / a max % against smoothed FE "
                  "| split max (pp) |", "|---|---|---|---|---|---|"]
        for r in sorted(raw, key=lambda r: -max(r.F.max, r.a.max)):
            lines.append(f"| {r.label} | {', '.join(r.misses(th))} | {pct(r.F.max)} ({pct(r.F.rms)}) "
                         f"| {pct(r.a.max)} ({pct(r.a.rms)}) | {pct(r.F_smooth.max)} / "
                         f"{pct(r.a_smooth.max)} | {pct(r.split)} |")
    return lines
