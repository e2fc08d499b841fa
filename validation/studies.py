"""FE accuracy studies of one standard case, and the speed–accuracy chart.

The ``studies`` set holds variants of one case (elastic–perfectly plastic, E/σ_Y = 200,
ν = 0.3, rigid flat, h/R = 0.3): mesh density, strain increment per step, element
(``q4``), penalty contact, and an extreme run to large h/R. A run's variant is read
from ``Record.params`` first, then from its inputs.

**Reference.** The best estimate combines the two refinements, assuming the mesh and
the increment errors add: F_ref = F_finest mesh · F_smallest increment / F_base (the same
for a), where ``base`` is the run at the default mesh and increment. Every FE variant
and the model are compared with F_ref on the base run's approaches (log–log
interpolation between increments), over the model's acceptance window (end of Level I
to ``h_over_R_max``).

**Cost.** FE: wall time of the run (one core; the solver is single-threaded), from the
run's provenance. Model: the best of three wall times of one exact evaluation of the
curve on the same grid (``contact``), and of building the tabulated law
(``ContactLaw``) plus evaluating it on the grid. LAMMPS mdr (:func:`mdr_points`, from
its stored curves): the wall time of its LAMMPS run, and its cost per contact
evaluation times the number of points of the curve.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..metrics import Summary, interp_loglog, relative_error, smooth_loglog, summarise, trapezoid_weights
from ..model import Coefficients, ContactLaw, contact
from .cases import Case, reference_radius, spheres
from .charts import DPI, pyplot
from .config import Thresholds
from .tables import markdown_table, pct

__all__ = ["DEFAULTS", "variant", "Variant", "Reference", "standard_runs", "reference", "FEPoint",
           "ModelPoint", "speed_accuracy", "mdr_points", "speed_accuracy_chart", "speed_accuracy_table",
           "energy_balance"]

#: solver defaults of the standard case
DEFAULTS = {"mesh_density": 1.0, "strain_increment": 0.005, "element": "q8r", "penalty": None}


@dataclass(frozen=True)
class Variant:
    kind: str            # "refinement", "locking", "penalty", "extreme"
    mesh_density: float
    strain_increment: float
    element: str
    penalty: float | None
    h_max: float


def _param(case: Case, name: str, default):
    if name in case.params and case.params[name] is not None:
        return case.params[name]
    if name == "mesh_density":
        return case.inputs.get("mesh_density", case.inputs.get("density", default))
    if name == "element":
        return case.inputs.get("element", default)
    return case.inputs.get("options", {}).get(name, default)


def variant(case: Case, th: Thresholds) -> Variant:
    """What a study run varies (``Record.params`` first, then the run's inputs)."""
    d = float(_param(case, "mesh_density", 1.0))
    de = float(_param(case, "strain_increment", DEFAULTS["strain_increment"]))
    el = str(_param(case, "element", "q8r"))
    pen = _param(case, "penalty", None)
    pen = None if pen is None or (isinstance(pen, float) and not math.isfinite(pen)) else float(pen)
    h_max = float(case.inputs.get("h_max", case.h[-1] if case.h.size else 0.0))
    h_max /= float(case.inputs.get("radius", 1.0))
    if el != "q8r":
        kind = "locking"
    elif pen is not None:
        kind = "penalty"
    elif h_max > 1.5 * th.h_over_R_max:
        kind = "extreme"
    else:
        kind = "refinement"
    return Variant(kind, d, de, el, pen, h_max)


def _is_default(v: Variant, field: str) -> bool:
    return math.isclose(getattr(v, field), DEFAULTS[field])


@dataclass
class Reference:
    """The best-estimate FE curves on the base run's grid and how they were built."""

    base: Case
    h: np.ndarray
    F: np.ndarray
    a: np.ndarray
    how: str
    window: np.ndarray    # mask of the acceptance window on h
    weights: np.ndarray


def standard_runs(cases: list[Case], th: Thresholds) -> tuple[Case | None, list[Case]]:
    """The base run (default mesh and increment, h_max nearest the acceptance window) and the
    refinement runs of the same material and h_max (base included)."""
    ref = [c for c in cases if variant(c, th).kind == "refinement"]
    defaults = [c for c in ref if _is_default(variant(c, th), "mesh_density")
                and _is_default(variant(c, th), "strain_increment")]
    if not defaults:
        return None, []
    base = min(defaults, key=lambda c: abs(variant(c, th).h_max - th.h_over_R_max))
    hb = variant(base, th).h_max
    same = [c for c in ref if c.inputs.get("material") == base.inputs.get("material")
            and math.isclose(variant(c, th).h_max, hb, rel_tol=0.05)]
    return base, same


def reference(cases: list[Case], th: Thresholds, start_h_over_R: float = 0.0) -> Reference | None:
    """The composite reference of the refinement runs (module docstring); None without a base run."""
    base, ref = standard_runs(cases, th)
    if base is None:
        return None
    mesh = [c for c in ref if _is_default(variant(c, th), "strain_increment")]
    incr = [c for c in ref if _is_default(variant(c, th), "mesh_density")]
    fine = max(mesh, key=lambda c: variant(c, th).mesh_density)
    small = min(incr, key=lambda c: variant(c, th).strain_increment)
    h = base.h
    out = {}
    for q in ("F", "a"):
        y = getattr(base, q).copy()
        if fine is not base:
            y = interp_loglog(h, fine.h, getattr(fine, q))
        if small is not base:
            y = y * interp_loglog(h, small.h, getattr(small, q)) / getattr(base, q)
        out[q] = smooth_loglog(h, y)
    parts = []
    if fine is not base:
        parts.append(f"mesh density {variant(fine, th).mesh_density:g} ({fine.label})")
    if small is not base:
        parts.append(f"strain increment {variant(small, th).strain_increment:g} ({small.label})")
    how = ("finest mesh × smallest increment / base: " + ", ".join(parts)) if len(parts) == 2 \
        else (parts[0] if parts else f"base run {base.label} (no refined run)")
    hR = h / reference_radius(base)
    window = ((hR >= start_h_over_R) & (hR <= th.h_over_R_max * (1 + 1e-9))
              & (base.a / reference_radius(base) >= th.a_min_over_R))
    return Reference(base, h, out["F"], out["a"], how, window, trapezoid_weights(h))


def _against(ref: Reference, h, y, q: str) -> Summary:
    yy = interp_loglog(ref.h, h, y)
    return summarise(relative_error(yy, getattr(ref, q)), ref.window, ref.weights)


def energy_balance(case: Case) -> float:
    """|W_ext − (E_el + D)|/W_ext at the end of the run (NaN without the energy curves)."""
    W, E, D = (case.curve(k) for k in ("work_external", "energy_elastic", "dissipation"))
    if W is None or E is None or D is None or W.size == 0 or W[-1] <= 0:
        return math.nan
    return abs(W[-1] - E[-1] - D[-1]) / W[-1]


@dataclass
class FEPoint:
    case: Case
    variant: Variant
    time_s: float
    F: Summary
    a: Summary
    energy: float
    increments: int
    iterations: int


@dataclass
class ModelPoint:
    name: str
    time_s: float
    F: Summary
    a: Summary
    color: str = "C3"
    marker: str = ""     # "" : the next of the model's markers


def _newton(case: Case) -> tuple[int, int]:
    it = case.curve("iterations")
    return int(case.h.size), int(it.sum()) if it is not None else -1


def speed_accuracy(cases: list[Case], coeffs: Coefficients | None, th: Thresholds,
                   start_h_over_R: float = 0.0):
    """FE variants and the model against the reference: (reference, FE points, model points)."""
    ref = reference(cases, th, start_h_over_R)
    if ref is None:
        return None, [], []
    pts = []
    for c in standard_runs(cases, th)[1]:
        v = variant(c, th)
        inc, its = _newton(c)
        pts.append(FEPoint(c, v, c.wall_s, _against(ref, c.h, c.F, "F"), _against(ref, c.h, c.a, "a"),
                           energy_balance(c), inc, its))
    s1, s2 = spheres(ref.base)
    h = ref.h[ref.h > 0]
    st = contact(s1, s2, ref.h, coeffs)
    t_exact = min(_timed(lambda: contact(s1, s2, h, coeffs)) for _ in range(3))

    def table():
        return ContactLaw(s1, s2, coeffs=coeffs)(h)

    t_table = min(_timed(table) for _ in range(3))
    tab = table()
    models = [ModelPoint("model (exact solve)", t_exact, _against(ref, ref.h, st.F, "F"),
                         _against(ref, ref.h, st.a, "a")),
              ModelPoint("model (tabulated ContactLaw, incl. setup)", t_table,
                         _against(ref, h, tab.F, "F"), _against(ref, h, tab.a, "a"))]
    return ref, pts, models


def mdr_points(ref: Reference | None, store) -> list[ModelPoint]:
    """LAMMPS mdr on the standard case against the reference (:mod:`.mdr`, stored curves).

    Two times: the wall time of its stored LAMMPS run (an incremental law walks the whole
    path in small steps), and its cost per contact evaluation (the store's lattice
    benchmark) times the number of points of the reference curve — the basis of the
    model's time per curve.
    """
    from .mdr import mdr_scene

    if ref is None or store is None:
        return []
    scene = mdr_scene(ref.base)
    c = store.find(scene) if isinstance(scene, dict) else None
    if c is None:
        return []
    F, a = _against(ref, c.h, c.F, "F"), _against(ref, c.h, c.a, "a")
    pts = [ModelPoint(f"LAMMPS mdr (its run: {c.steps:,} steps)", c.wall_s, F, a, "C9", "o")]
    cost = store.doc.get("cost", {}).get("mdr", {}).get("s_per_contact")
    if cost:
        n = int(np.sum(ref.h > 0))
        pts.append(ModelPoint(f"LAMMPS mdr ({n} contact evaluations)", cost * n, F, a, "C9", "^"))
    return pts


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def speed_accuracy_table(pts: list[FEPoint], models: list[ModelPoint]) -> str:
    rows = []
    for p in sorted(pts, key=lambda p: p.time_s):
        v = p.variant
        rows.append([p.case.label, f"{v.mesh_density:g}", f"{v.strain_increment:g}",
                     f"{p.time_s:.1f}", p.increments, p.iterations, f"{pct(p.F.max, 2)} ({pct(p.F.rms, 2)})",
                     f"{pct(p.a.max, 2)} ({pct(p.a.rms, 2)})", pct(p.energy, 2)])
    for m in models:
        rows.append([m.name, "", "", f"{m.time_s:.2g}", "", "", f"{pct(m.F.max, 2)} ({pct(m.F.rms, 2)})",
                     f"{pct(m.a.max, 2)} ({pct(m.a.rms, 2)})", ""])
    return markdown_table(["curve", "mesh density", "strain increment", "time per curve s",
                           "increments", "Newton iterations", "F max (rms) %", "a max (rms) %",
                           "energy balance miss %"], rows)


def speed_accuracy_chart(pts: list[FEPoint], models: list[ModelPoint], out: Path) -> Path:
    """Error against time per curve: FE mesh and increment series, the model."""
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.4))
    floor = 1e-4  # per cent; errors below are drawn on the floor
    for k, q in enumerate(("F", "a")):
        axis = ax[k]
        for series, field, color, short in (("mesh density", "mesh_density", "C0", "d"),
                                            ("strain increment", "strain_increment", "C1", "Δε")):
            other = "strain_increment" if field == "mesh_density" else "mesh_density"
            sel = sorted([p for p in pts if _is_default(p.variant, other)],
                         key=lambda p: p.time_s)
            if not sel:
                continue
            t = [p.time_s for p in sel]
            e = [max(100 * getattr(p, q).max, floor) for p in sel]
            r = [max(100 * getattr(p, q).rms, floor) for p in sel]
            axis.plot(t, e, "o-", color=color, label=f"FE, {series}: max")
            axis.plot(t, r, "o--", color=color, mfc="none", lw=0.8, label=f"FE, {series}: RMS")
            for p, ti, ei in zip(sel, t, e, strict=True):
                if p.variant.kind == "refinement" and _is_default(p.variant, field):
                    continue  # the base run is labelled once, below
                axis.annotate(f"{short} {getattr(p.variant, field):g}", (ti, ei), fontsize=7,
                              xytext=(4, 4), textcoords="offset points", color=color)
        for p in pts:
            if _is_default(p.variant, "mesh_density") and _is_default(p.variant, "strain_increment"):
                axis.annotate("base", (p.time_s, max(100 * getattr(p, q).max, floor)), fontsize=7,
                              xytext=(-22, 6), textcoords="offset points")
        default = iter(("s", "D", "p", "h"))
        for m in models:
            marker = m.marker or next(default)
            axis.plot([m.time_s], [max(100 * getattr(m, q).max, floor)], marker, color=m.color,
                      ms=8 if marker == "s" else 6, label=f"{m.name}: max")
            axis.plot([m.time_s], [max(100 * getattr(m, q).rms, floor)], marker, color=m.color,
                      mfc="none", ms=8 if marker == "s" else 6)
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("time per curve s (one core)")
        axis.set_ylabel(f"{q} error % vs best FE estimate (filled: max, open: RMS)")
        axis.grid(True, which="both", alpha=0.3)
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    path = out / "speed_accuracy.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
