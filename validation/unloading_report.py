"""The report's unloading section: tables and charts of :mod:`.unloading`."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .charts import DPI, pyplot
from .tables import markdown_table, pct
from .unloading import EKK, METHODS, RANGE_TEXT, UnloadingRow, unloading_failures

__all__ = ["unloading_section", "summary_table", "range_table", "run_rows", "COLORS"]

COLORS = {"law": "tab:blue", "model": "tab:cyan", "Thornton 1997": "tab:orange",
          EKK: "tab:green", "LAMMPS mdr": "tab:red"}


def _stats(x) -> tuple[float, float, float]:
    x = np.asarray([v for v in x if math.isfinite(v)])
    if not x.size:
        return math.nan, math.nan, math.nan
    return float(np.median(x)), float(np.percentile(x, 95)), float(np.max(x))


def summary_table(rows: list[UnloadingRow], F_limit: float, h_res_limit: float) -> str:
    """Per method: median / 95th percentile / max of the branch errors, and the branches above the limits."""
    out = []
    for m in METHODS:
        F = [r.F_err[m] for r in rows if m in r.F_err]
        hr = [r.h_res_err[m] for r in rows if m in r.h_res_err]
        if not F:
            continue
        f, h = _stats(F), _stats(hr)
        out.append([m, len(F), " / ".join(pct(v) for v in f), sum(v > F_limit for v in F),
                    " / ".join(pct(v) for v in h), sum(v > h_res_limit for v in hr)])
    return markdown_table(["method", "branches", "max |ΔF|/F_max %: median / p95 / max",
                           f"branches > {pct(F_limit, 0)} %", "|Δh_res|/h_max %: median / p95 / max",
                           f"branches > {pct(h_res_limit, 0)} %"], out)


def range_table(rows: list[UnloadingRow]) -> str:
    """Each published law on the branches inside its own range, beside the model's law and the whole
    model on the same branches (median / max of the branch errors, %)."""
    out = []

    def mm(x):
        f = _stats(x)
        return f"{pct(f[0])} / {pct(f[2])}"

    for m in METHODS[2:]:
        have = [r for r in rows if m in r.F_err]
        inside = [r for r in have if r.in_range[m]]
        if not have:
            continue
        cells = [m, RANGE_TEXT[m], f"{len(inside)} of {len(have)}"]
        for who in (m, "law", "model"):
            cells += [mm([r.F_err[who] for r in inside]), mm([r.h_res_err[who] for r in inside])]
        out.append(cells)
    return markdown_table(["method", "its stated range", "branches in range",
                           "its F %: median / max", "its h_res %: median / max",
                           "law F %", "law h_res %", "model F %", "model h_res %"], out)


def run_rows(rows: list[UnloadingRow]) -> str:
    """Per run: the worst branch of each method (F error, h_res error) and the restitution."""
    by_run: dict[str, list[UnloadingRow]] = {}
    for r in rows:
        by_run.setdefault(r.run, []).append(r)
    out = []
    for run, rs in by_run.items():
        cells = [run, " ".join(f"{r.h_over_R:.2g}" for r in rs)]
        for m in METHODS:
            have = [r for r in rs if m in r.F_err]
            if not have:
                cells.append("—")
                continue
            w = max(have, key=lambda r: r.F_err[m])
            cells.append(f"{pct(w.F_err[m])} / {pct(max(r.h_res_err[m] for r in have))}"
                         + (" ‡" if m == EKK and any(r.ekk_outside for r in rs) else ""))
        first = rs[0]
        cells.append(f"{first.e_fe:.3f} / {first.e_model:.3f}" if math.isfinite(first.e_fe) else "—")
        out.append(cells)
    return markdown_table(["run", "h_max/R of the cycles", *(f"{m}: F / h_res %" for m in METHODS),
                           "e (1st cycle) FE / model"], out)


def _error_chart(rows: list[UnloadingRow], F_limit: float, out: Path) -> Path:
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for m in METHODS:
        have = [r for r in rows if m in r.F_err]
        x = [r.h_over_R for r in have]
        ax[0].scatter(x, [100 * r.F_err[m] for r in have], s=12, color=COLORS[m], label=m, alpha=0.8)
        ax[1].scatter(x, [100 * r.h_res_err[m] for r in have], s=12, color=COLORS[m], label=m, alpha=0.8)
    for a, t in zip(ax, ("max |ΔF|/F_max along the branch (%)", "|Δh_res|/h_max (%)"), strict=True):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("h_max/R")
        a.set_ylabel(t)
        a.axhline(100 * F_limit, color="0.5", lw=0.8, ls="--")
        a.grid(alpha=0.3, which="both")
    ax[0].legend(fontsize=7)
    fig.suptitle("Unloading branches of the validation runs: error per branch", fontsize=10)
    fig.tight_layout()
    p = out / "unloading_errors.png"
    fig.savefig(p, dpi=DPI)
    plt.close(fig)
    return p


def _representative(rows: list[UnloadingRow]) -> list[UnloadingRow]:
    """The branch at h_max/R ≈ 0.1 and 0.3 of a flat, a rigid sphere and a pair, and the worst law branch."""
    pick = []
    for prefix in ("flat", "rsphere", "two"):
        for target in (0.1, 0.3):
            cand = [r for r in rows if r.run.startswith(prefix) and abs(math.log(r.h_over_R / target)) < 0.2]
            if cand:
                pick.append(max(cand, key=lambda r: r.F_err["law"]))
    worst = max(rows, key=lambda r: r.F_err["law"])
    if worst not in pick:
        pick.append(worst)
    return pick[:7]


def _branches_chart(rows: list[UnloadingRow], out: Path) -> Path:
    plt = pyplot()
    from matplotlib.ticker import MaxNLocator

    pick = _representative(rows)
    n = len(pick)
    cols = min(n, 4)
    nr = math.ceil(n / cols)
    fig, axes = plt.subplots(nr, cols, figsize=(3.3 * cols, 3.0 * nr), squeeze=False)
    for ax, r in zip(axes.ravel(), pick, strict=False):
        c = r.curve
        x = (c.h_max - c.h) / c.h_max
        ax.plot(x, c.f, "k-", lw=2.0, label="FE")
        for m in (m for m in METHODS if m in r.branches):
            ax.plot(x, r.branches[m], ls="--" if m in ("law", "model") else ":", color=COLORS[m],
                    lw=1.2, label=m)
        ax.set_title(f"{r.run[:34]}\nh_max/R = {r.h_over_R:.3g}", fontsize=7)
        ax.set_xlabel("(h_max − h)/h_max", fontsize=8)
        ax.set_ylabel("F/F_max (FE)", fontsize=8)
        ax.set_xlim(0.0, max(1.05 * (1.0 - r.h_res_fe), 1e-3))
        ax.set_ylim(-0.02, 1.1)
        ax.tick_params(labelsize=7)
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    axes.ravel()[0].legend(fontsize=6)
    fig.tight_layout()
    p = out / "unloading_branches.png"
    fig.savefig(p, dpi=DPI)
    plt.close(fig)
    return p


def _restitution_chart(rows: list[UnloadingRow], out: Path) -> Path | None:
    first = [r for r in rows if math.isfinite(r.e_fe) and math.isfinite(r.e_model)]
    if not first:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(4.2, 4.0))
    ax.scatter([r.e_fe for r in first], [r.e_model for r in first], s=14, color="tab:blue")
    ax.plot([0, 1], [0, 1], color="0.5", lw=0.8)
    ax.set_xlabel("e FE (first cycle)")
    ax.set_ylabel("e model")
    ax.set_title("Quasi-static restitution coefficient", fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    p = out / "unloading_restitution.png"
    fig.savefig(p, dpi=DPI)
    plt.close(fig)
    return p


def unloading_section(rows: list[UnloadingRow], F_limit: float, h_res_limit: float,
                      out) -> tuple[list[str], list[Path]]:
    """Markdown lines and charts of the unloading section."""
    out = Path(out)
    md = ["## Unloading and reloading", ""]
    if not rows:
        return md + ["No validation run holds unloading cycles.", ""], []
    fails = unloading_failures(rows, F_limit, h_res_limit)
    e = [(r.e_fe, r.e_model) for r in rows if math.isfinite(r.e_fe)]
    de = max((abs(a - b) for a, b in e), default=math.nan)
    md += [f"{len(rows)} unloading branches of {len({r.run for r in rows})} runs. The reloading retraces "
           "the unloading in the FE and in the model, so one branch is compared. Methods "
           "(`validation/unloading.py`): **law** — the model's unloading law given the FE's peak "
           "state (the acceptance quantity, thresholds `[unloading]`); **model** — the whole model, "
           "loading to the FE's h_max (its loading error at the peak included); Thornton (1997) — "
           "Hertz from the FE's peak; Etsion, Kligerman & Kadin (2005) — their FE fit for an "
           "elastic–plastic sphere on a rigid flat, the residual in the form Jackson, Chusoipin & Green "
           "(2007) quote, with the FE's F_max (‡: a cycle outside its fitted range 1 ≤ ω* ≤ 110); "
           "LAMMPS mdr — its stored unloading after its own loading to "
           "the FE run's last h_max, where mdr applies (its loading error included).", "",
           summary_table(rows, F_limit, h_res_limit), "",
           "Each published law on the branches inside its own stated range (`validation/unloading.py`), "
           "with the model's law and the whole model on the same branches (max |ΔF|/F_max and "
           "|Δh_res|/h_max, median / max over the branches, %):", "",
           range_table(rows), "",
           f"Acceptance (law): max |ΔF|/F_max ≤ {pct(F_limit, 0)} % along each branch and "
           f"|Δh_res| ≤ {pct(h_res_limit, 0)} % of h_max: "
           + (f"**{len(fails)} of {len(rows)} branches exceed it**." if fails
              else "**all branches within**."),
           ""]
    if fails:
        md += [f"* {f}" for f in fails] + [""]
    md += [f"Restitution coefficient of the first cycle (quasi-static, `model/cycle.py`): largest "
           f"|e_model − e_FE| = {de:.3f} over {len(e)} runs.", "",
           "Per run: the worst branch of each method (F error / largest h_res error, %).", "",
           run_rows(rows), ""]
    pngs = [_error_chart(rows, F_limit, out), _branches_chart(rows, out)]
    p = _restitution_chart(rows, out)
    if p is not None:
        pngs.append(p)
    md += [f"![{p.stem}]({p.name})" for p in pngs] + [""]
    return md, pngs
