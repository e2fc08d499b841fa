"""Charts of the validation report (matplotlib, Agg): curves per run, model error vs Λ and vs h/R.

The speed–accuracy and stability charts live with their sections (:mod:`.studies`,
:mod:`.stability`). Every function writes one PNG and returns its path.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .cases import CLASSES
from .compare import W_ACCEPT, Comparison
from .config import Thresholds

__all__ = ["pyplot", "slug", "representative", "curves_chart", "error_chart"]

DPI = 110
PEER_STYLE = {
    "Hertz": ("C2", "-."),
    "Jackson–Green 2005": ("C1", ":"),
    "Kogut–Etsion 2002": ("C3", (0, (5, 2))),
    "Thornton 1997": ("C4", (0, (1, 1))),
    "Johnson cavity": ("C5", (0, (3, 1, 1, 1))),
    "Biwa–Storåkers 1995": ("C6", (0, (6, 2, 1, 2))),
    "LAMMPS mdr": ("C9", "-"),
}
#: line width of a peer in the curve charts (default 1.1): the DEM law users run is drawn bolder
PEER_WIDTH = {"LAMMPS mdr": 1.6}


def pyplot():
    """matplotlib.pyplot with the file-only Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_").lower() or "run"


def representative(comps: list[Comparison]) -> list[Comparison]:
    """One run per class — converged before stopped, then the fewest classes (the purest
    example), then by name — and the run with the largest model error of F."""
    chosen: list[Comparison] = []

    def rank(c: Comparison):
        return (c.case.status != "converged", len(c.classes), c.case.label)

    for cls in CLASSES:
        members = sorted((c for c in comps if cls in c.classes), key=rank)
        pick = next((c for c in members if c not in chosen), None)
        if pick is not None:
            chosen.append(pick)
    scored = [c for c in comps if not c.model.summary(W_ACCEPT, "F").empty]
    if scored:
        worst = max(scored, key=lambda c: c.model.summary(W_ACCEPT, "F").max)
        if worst not in chosen:
            chosen.append(worst)
    return chosen


def curves_chart(comp: Comparison, th: Thresholds, out: Path) -> Path:
    """F–h and a–h (FE, model, peers), model and peer errors below; the split h₁/h for pairs."""
    plt = pyplot()
    c = comp.case
    hR = comp.h_over_R
    two = comp.model.h1 is not None and c.curve("h1") is not None
    ncol = 3 if two else 2
    fig, ax = plt.subplots(2, ncol, figsize=(5.0 * ncol, 7.5), squeeze=False)
    top = {"F": ax[0, 0], "a": ax[0, 1]}
    bottom = {"F": ax[1, 0], "a": ax[1, 1]}
    ok = (hR > 0) & comp.resolved
    lo_x = hR[ok][:1]
    if not lo_x.size:  # no resolved point: draw them all
        ok = hR > 0
        lo_x = hR[ok][:1]
    x_lo = float(lo_x[0])
    x_hi = float(hR[-1])
    for q in ("F", "a"):
        fe = c.F if q == "F" else c.a
        top[q].loglog(hR[ok], fe[ok], "k-", lw=2.2, label="FE")
        top[q].loglog(hR[ok], getattr(comp.model, q)[ok], "C0--", lw=1.8, label="model")
        e_model = 100 * comp.model.errors[q]
        bottom[q].semilogx(hR[ok], e_model[ok], "C0-", lw=1.8, label="model")
        for name, me in comp.peers.items():
            pred = getattr(me, q)
            if not me.applies or pred is None:
                continue
            color, ls = PEER_STYLE[name]
            lw = PEER_WIDTH.get(name, 1.1)
            mask = ok if me.mask is None else ok & me.mask
            top[q].plot(hR[mask], pred[mask], color=color, ls=ls, lw=lw, label=name)
            bottom[q].plot(hR[mask], 100 * me.errors[q][mask], color=color, ls=ls, lw=lw - 0.1,
                           label=name)
        inside = ok & (hR >= x_lo)
        top[q].set_ylim(0.7 * np.nanmin(fe[inside]), 1.6 * np.nanmax(fe[inside]))
        top[q].set_ylabel("F / (σ_Y1 R²)" if q == "F" else "a / R")
        lim = th.F_max if q == "F" else th.a_max
        bottom[q].axhspan(-100 * lim, 100 * lim, color="0.9", zorder=0, label=f"±{100 * lim:g} %")
        worst = np.nanmax(np.abs(e_model[comp.masks[W_ACCEPT]]), initial=0.0)
        span = min(100.0, max(2.5 * 100 * lim, 1.15 * worst))
        bottom[q].set_ylim(-span, span)
        bottom[q].set_ylabel(f"{q} relative error %")
        bottom[q].set_xlabel("h / R")
        for a_ in (top[q], bottom[q]):
            a_.set_xlim(x_lo, 1.05 * x_hi)
            if x_lo < th.h_over_R_max < x_hi:
                a_.axvline(th.h_over_R_max, color="0.6", lw=0.8)
            if np.isfinite(comp.start) and comp.start > x_lo:
                a_.axvline(comp.start, color="0.8", lw=0.8, ls=":")
    top["F"].legend(fontsize=7, loc="upper left")
    if two:
        h = c.h
        with np.errstate(divide="ignore", invalid="ignore"):
            ax[0, 2].plot(hR, c.curve("h1") / h, "k-", lw=2.2, label="FE h₁/h")
            ax[0, 2].plot(hR, comp.model.h1 / h, "C0--", lw=1.8, label="model h₁/h")
        ax[0, 2].set_xscale("log")
        ax[0, 2].set_xlim(x_lo, 1.05 * x_hi)
        ax[1, 2].set_xscale("log")
        ax[1, 2].set_xlim(x_lo, 1.05 * x_hi)
        ax[0, 2].set_ylim(0, 1)
        ax[0, 2].set_ylabel("h₁ / h")
        ax[0, 2].legend(fontsize=7)
        worst = 10.0
        for q, style in (("h1", "C0-"), ("h2", "C9-")):
            if q in comp.model.errors:
                e = 100 * comp.model.errors[q]
                ax[1, 2].plot(hR, e, style, label=f"model {q}")
                worst = max(worst, 1.15 * np.nanmax(np.abs(e[comp.masks[W_ACCEPT]]), initial=0.0))
        ax[1, 2].set_ylim(-min(worst, 100.0), min(worst, 100.0))
        ax[1, 2].set_ylabel("relative error %")
        ax[1, 2].set_xlabel("h / R")
        ax[1, 2].legend(fontsize=7)
    fig.suptitle(f"{c.label}: {', '.join(comp.classes)} (h/R, R = {comp.R_ref:g})", fontsize=10)
    fig.tight_layout()
    path = out / f"curves_{slug(c.label)}.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def error_chart(comps: list[Comparison], th: Thresholds, out: Path, x: str,
                levels: tuple[float, float] | None = None) -> Path:
    """Model relative error of F and a for every run against Λ (``x="Lambda"``) or h/R.

    ``levels`` = (Λ_I, Λ_III) draws the level boundaries on the Λ chart.
    """
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, comp in enumerate(comps):
        xs = comp.Lambda if x == "Lambda" else comp.h_over_R
        color = f"C{i % 10}"
        ls = "-" if i < 10 else "--"
        for k, q in enumerate(("F", "a")):
            e = 100 * comp.model.errors[q]
            ok = (xs > 0) & comp.resolved
            ax[k].plot(xs[ok], e[ok], color=color, ls=ls, lw=1.2,
                       label=comp.case.label if k == 0 else None)
    for k, q in enumerate(("F", "a")):
        lim = 100 * (th.F_max if q == "F" else th.a_max)
        ax[k].axhspan(-lim, lim, color="0.9", zorder=0)
        ax[k].axhline(0, color="0.5", lw=0.6)
        ax[k].set_ylabel(f"model {q} relative error %")
        if x == "Lambda":
            ax[k].set_xscale("log")
            ax[k].set_xlabel("Λ (model, body furthest into plasticity)")
            for lam in levels or ():
                ax[k].axvline(lam, color="0.6", lw=0.8, ls=":")
        else:
            ax[k].axvline(th.h_over_R_max, color="0.6", lw=0.8)
            ax[k].set_xlabel("h / R")
        lo, hi = ax[k].get_ylim()
        ax[k].set_ylim(max(lo, -100), min(hi, 150))
    ax[0].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    path = out / f"error_vs_{'lambda' if x == 'Lambda' else 'h'}.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
