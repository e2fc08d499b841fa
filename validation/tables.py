"""Markdown tables of the validation: per run, per class (model against each peer), per level."""

from __future__ import annotations

import math

from ..metrics import EMPTY, LEVELS, Summary, pool, scatter
from .cases import CLASSES
from .compare import MODEL, W_ACCEPT, W_LARGE, Comparison
from .config import Thresholds
from .peer_scenes import PEERS, RANGE_TEXT

__all__ = ["markdown_table", "pct", "cell", "run_table", "class_tables", "class_matrix",
           "level_table", "failures", "Failure", "range_tables"]

METHODS = (MODEL, *PEERS)


def markdown_table(header, rows) -> str:
    """A Markdown table from a header row and a list of rows (cells converted with str)."""
    lines = ["| " + " | ".join(map(str, header)) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(map(str, r)) + " |" for r in rows]
    return "\n".join(lines)


def pct(x: float, digits: int = 1) -> str:
    """A relative error as per cent (— for NaN)."""
    return "—" if not math.isfinite(x) else f"{100 * x:.{digits}f}"


def cell(s: Summary) -> str:
    """"max (rms)" in per cent, — for an empty set."""
    return "—" if s.empty else f"{pct(s.max)} ({pct(s.rms)})"


# ============================================================================ per run
class Failure:
    """A validation run whose model error exceeds a threshold."""

    def __init__(self, label: str, key: str, what: list[str]):
        self.label, self.key, self.what = label, key, what

    def __str__(self) -> str:
        return f"{self.label} [{self.key}]: " + "; ".join(self.what)


def failures(comps: list[Comparison], th: Thresholds) -> list[Failure]:
    """Runs whose max |error| of the model in the acceptance window exceeds F_max or a_max.

    A run with no point in the window (it stays in Level I, or starts beyond the window)
    cannot be accepted and is listed too.
    """
    out = []
    for c in comps:
        what = []
        for q, limit in (("F", th.F_max), ("a", th.a_max)):
            s = c.model.summary(W_ACCEPT, q)
            if s.empty:
                what.append(f"{q}: no FE point in the window")
            elif s.max > limit:
                what.append(f"{q} max error {pct(s.max)} % > {pct(limit, 0)} %")
        if what:
            out.append(Failure(c.case.label, c.case.key, what))
    return out


def run_table(comps: list[Comparison], th: Thresholds) -> str:
    """Model against FE, one row per run."""
    failed = {f.key for f in failures(comps, th)}
    two = any(c.case.scene == "two_body" for c in comps)
    header = ["run", "classes", "FE to h/R", "Level I ends at h/R", "F max (rms) %", "a max (rms) %"]
    if two:
        header += ["h₁ max (rms) %", "h₂ max (rms) %", "h₁/h split max (pp)"]
    header += [f"F max % {W_LARGE}", f"a max % {W_LARGE}", "FE scatter F / a %", "model ms/curve",
               "FE s/curve", "verdict"]
    rows = []
    for c in comps:
        m = c.model
        end = c.h_over_R[-1] if c.h_over_R.size else math.nan
        status = "" if c.case.status == "converged" else f" ({c.case.status})"
        row = [c.case.label, ", ".join(c.classes), f"{end:.3g}{status}", f"{c.start:.2g}",
               cell(m.summary(W_ACCEPT, "F")), cell(m.summary(W_ACCEPT, "a"))]
        if two:
            sp = m.summary(W_ACCEPT, "split")
            row += [cell(m.summary(W_ACCEPT, "h1")), cell(m.summary(W_ACCEPT, "h2")),
                    "—" if sp.empty else pct(sp.max)]
        w = c.masks[W_ACCEPT]
        noise = f"{pct(scatter(c.case.h, c.case.F, w))} / {pct(scatter(c.case.h, c.case.a, w))}"
        row += [pct(m.summary(W_LARGE, "F").max), pct(m.summary(W_LARGE, "a").max), noise,
                f"{1e3 * c.model_time_s:.2f}", f"{c.case.wall_s:.0f}",
                "**fail**" if c.case.key in failed else "pass"]
        rows.append(row)
    return markdown_table(header, rows)


# ============================================================================ per class
def _class_members(comps, cls):
    return [c for c in comps if cls in c.classes]


def _pooled(members, method: str, window: str, q: str) -> tuple[Summary, int, list[str]]:
    """Pooled summary over the runs where the method applies; count; reasons where it does not."""
    sums, reasons, n = [], [], 0
    for c in members:
        me = c.methods[method]
        if me.applies:
            n += 1
            sums.append(me.summary(window, q))
        elif me.note not in reasons:
            reasons.append(me.note)
    return (pool(sums) if sums else EMPTY), n, reasons


def class_matrix(comps: list[Comparison]) -> str:
    """Classes × methods: max |error| of F / of a (per cent) in the acceptance window."""
    header = ["class (runs)", *METHODS]
    rows = []
    for cls in CLASSES:
        members = _class_members(comps, cls)
        if not members:
            continue
        row = [f"{cls} ({len(members)})"]
        for meth in METHODS:
            sF, n, _ = _pooled(members, meth, W_ACCEPT, "F")
            sa, _, _ = _pooled(members, meth, W_ACCEPT, "a")
            if n == 0:
                row.append("n/a")
                continue
            part = "" if n == len(members) else f" [{n}/{len(members)}]"
            row.append(f"{pct(sF.max)} / {pct(sa.max)}{part}")
        rows.append(row)
    return markdown_table(header, rows)


def class_tables(comps: list[Comparison]) -> str:
    """One table per class: each method's pooled max (RMS) errors and where it does not apply."""
    out = []
    for cls in CLASSES:
        members = _class_members(comps, cls)
        if not members:
            continue
        names = ", ".join(c.case.label for c in members)
        rows = []
        for meth in METHODS:
            sF, n, reasons = _pooled(members, meth, W_ACCEPT, "F")
            sa, _, _ = _pooled(members, meth, W_ACCEPT, "a")
            lF, _, _ = _pooled(members, meth, W_LARGE, "F")
            la, _, _ = _pooled(members, meth, W_LARGE, "a")
            notes = sorted({c.methods[meth].note for c in members
                            if c.methods[meth].applies and c.methods[meth].note})
            why = "; ".join([*(f"not applicable: {r}" for r in reasons), *notes])
            rows.append([meth, f"{n}/{len(members)}", cell(sF), cell(sa), pct(lF.max), pct(la.max),
                         why])
        out.append(f"**{cls}** ({names})\n\n" + markdown_table(
            ["method", "runs", f"F max (rms) % {W_ACCEPT}", f"a max (rms) % {W_ACCEPT}",
             f"F max % {W_LARGE}", f"a max % {W_LARGE}", "notes"], rows))
    return "\n\n".join(out)


def range_tables(comps: list[Comparison]) -> str:
    """One table per class: each peer over the whole window beside the peer and the model on the
    same points inside the peer's own stated range (resolved points from h = 0 to the window end)."""
    out = []
    for cls in CLASSES:
        members = _class_members(comps, cls)
        if not members:
            continue
        rows = []
        for peer in PEERS:
            have = [c for c in members if c.peers[peer].applies]
            if not have:
                rows.append([peer, RANGE_TEXT[peer], f"0/{len(members)}", "n/a", "—", "—", "—", "—", "—"])
                continue
            sF, _, _ = _pooled(members, peer, W_ACCEPT, "F")
            own = {q: pool([c.peers[peer].own_range.get(q, EMPTY) for c in have]) for q in ("F", "a")}
            mod = {q: pool([c.model_in_range[peer].get(q, EMPTY) for c in have]) for q in ("F", "a")}
            runs_in = sum(1 for c in have if not c.peers[peer].own_range.get("F", EMPTY).empty)
            rows.append([peer, RANGE_TEXT[peer], f"{len(have)}/{len(members)}", cell(sF),
                         f"{own['F'].n} ({runs_in} runs)", cell(own["F"]), cell(mod["F"]), cell(own["a"]),
                         cell(mod["a"])])
        out.append(f"**{cls}**\n\n" + markdown_table(
            ["peer", "its stated range", "runs", f"whole window: peer F max (rms) % {W_ACCEPT}",
             "in range: points", "peer F max (rms) %", "model F max (rms) %", "peer a max (rms) %",
             "model a max (rms) %"], rows))
    return "\n\n".join(out)


def level_table(comps: list[Comparison], quantity: str = "F") -> str:
    """Methods × point categories (Level I, II, III, large deformation), pooled over all runs."""
    header = ["method", *(f"{lab}" if lab != "large" else "large deformation" for lab in LEVELS)]
    rows = []
    for meth in METHODS:
        row = [meth]
        for lab in LEVELS:
            sums = [c.methods[meth].level_summary(lab, quantity) for c in comps
                    if c.methods[meth].applies]
            row.append(cell(pool(sums)))
        rows.append(row)
    return markdown_table(header, rows)
