"""Where methods fail: FE locking, penalty contact, oversized increments, extreme h/R; the model
outside its calibrated range.

Evidence is taken from the ``studies`` set (variants of the standard case, see
:mod:`.studies`) and from probes of the model:

* **Locking**: a run with bilinear fully integrated elements (``q4``) against the
  quadratic reduced-integration run (``q8r``) of the same material and mesh density.
* **Penalty contact**: runs with penalty contact at several relative stiffnesses
  against the exact (active-set) run.
* **Oversized increments**: the strain-increment series against the best FE estimate,
  and each run's energy balance.
* **Extreme h/R**: a run beyond the acceptance window: how far it got, its Newton
  effort per increment, and the model against it there.
* **Model outside its calibrated range**: the model evaluated for materials, pairs and
  approaches outside the calibration set; finite? monotone? does it warn?
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..metrics import Summary, interp_loglog, relative_error, summarise, trapezoid_weights
from ..model import Coefficients, Material, Sphere, contact
from ..model.calibrated_range import CalibratedRange, CalibrationRangeWarning
from ..model.material import E_OVER_SIGMA_Y_RANGE
from .cases import Case, reference_radius, spheres
from .charts import DPI, pyplot
from .config import Thresholds
from .studies import DEFAULTS, Reference, energy_balance, standard_runs, variant
from .tables import markdown_table, pct

__all__ = ["pair_error", "locking_section", "penalty_section", "increment_section",
           "extreme_section", "Probe", "model_probes",
           "probes_section"]


def _same_material(a: Case, b: Case) -> bool:
    return a.inputs.get("material") == b.inputs.get("material")


def pair_error(case: Case, other: Case, q: str, lo_frac: float = 0.0) -> tuple[Summary, np.ndarray]:
    """Relative error of ``case`` against ``other`` on ``other``'s grid (overlap, h ≥ lo_frac·h_end)."""
    y = interp_loglog(other.h, case.h, getattr(case, q) if q != "p_m" else _pm(case))
    ref = getattr(other, q) if q != "p_m" else _pm(other)
    e = relative_error(y, ref)
    mask = other.h >= lo_frac * min(case.h[-1], other.h[-1])
    return summarise(e, mask, trapezoid_weights(other.h)), e


def _pm(c: Case) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(c.a > 0, c.F / (math.pi * c.a**2), np.nan)


def _partner(case: Case, cases: list[Case], th: Thresholds) -> Case | None:
    """The exact-contact q8r run of the same material closest in mesh density, increment, h_max."""
    v = variant(case, th)
    cands = [c for c in cases if c is not case and _same_material(c, case)
             and variant(c, th).element == "q8r" and variant(c, th).penalty is None]
    if not cands:
        return None

    def dist(c):
        w = variant(c, th)
        return (abs(math.log(w.mesh_density / v.mesh_density)),
                abs(math.log(w.strain_increment / v.strain_increment)),
                abs(w.h_max - v.h_max))

    return min(cands, key=dist)


def _count(x) -> str:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return "—"
    return f"{v:g}" if math.isfinite(v) else "—"


def _status(c: Case) -> str:
    return c.status if c.status == "converged" else f"{c.status}: {c.reason}"


# ============================================================================ locking
def locking_section(cases: list[Case], th: Thresholds, out: Path):
    """q4 runs against their q8r partners: (markdown, chart path or None)."""
    pairs = [(c, _partner(c, cases, th)) for c in cases if variant(c, th).kind == "locking"]
    pairs = [(c, p) for c, p in pairs if p is not None]
    if not pairs:
        return "No run with the locking element (`q4`) in the studies set.", None
    rows, notes = [], []
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, (c, p) in enumerate(pairs):
        sF, _ = pair_error(c, p, "F", 0.1)
        sa, _ = pair_error(c, p, "a", 0.1)
        spm, _ = pair_error(c, p, "p_m", 0.1)
        m = c.inputs["material"]
        notes.append(f"`{c.label}` (q4) against `{p.label}` (q8r): final mean pressure "
                     f"{100 * (_pm(c)[-1] / _pm(p)[-1] - 1):+.0f} %, F up to {pct(sF.max)} % and a up "
                     f"to {pct(sa.max)} % apart (over h ≥ 0.1 h_end).")
        rows.append([c.label, p.label, f"{m['E'] / m['sigma_y']:g}", f"{variant(c, th).mesh_density:g}",
                     f"{c.h[-1] / reference_radius(c):.3g}", f"{pct(sF.max)} ({pct(sF.rms)})",
                     f"{pct(sa.max)} ({pct(sa.rms)})", f"{pct(spm.max)}",
                     f"{_pm(c)[-1] / m['sigma_y']:.3g} / {_pm(p)[-1] / m['sigma_y']:.3g}", _status(c)])
        for run, ls in ((c, "-"), (p, "--")):
            R = reference_radius(run)
            lab = f"{run.label} ({variant(run, th).element}, d={variant(run, th).mesh_density:g})"
            ax[0].plot(run.a / R, _pm(run) / m["sigma_y"], ls, color=f"C{i}", label=lab)
            ax[1].plot(run.h / R, run.F, ls, color=f"C{i}", label=lab)
    ax[0].set_xlabel("a / R")
    ax[0].set_ylabel("p_m / σ_Y")
    ax[1].set_xlabel("h / R")
    ax[1].set_ylabel("F / (σ_Y R²)")
    ax[0].legend(fontsize=7)
    fig.suptitle("locking: bilinear fully integrated (q4, solid) against quadratic reduced (q8r, dashed)",
                 fontsize=10)
    fig.tight_layout()
    path = out / "stability_locking.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    table = markdown_table(["q4 run", "against q8r run", "E/σ_Y", "mesh density", "h/R end",
                            "F max (rms) %", "a max (rms) %", "p_m max %", "final p_m/σ_Y q4 / q8r",
                            "status"], rows)
    return " ".join(notes) + "\n\n" + table, path


# ============================================================================ penalty
def penalty_section(cases: list[Case], th: Thresholds, out: Path):
    """Penalty-contact runs against the exact-contact run: (markdown, chart path or None)."""
    pen = sorted([c for c in cases if variant(c, th).kind == "penalty"],
                 key=lambda c: variant(c, th).penalty)
    if not pen:
        return "No penalty-contact run in the studies set.", None
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    rows, notes = [], []
    for i, c in enumerate(pen):
        p = _partner(c, cases, th)
        v = variant(c, th)
        if p is None:
            rows.append([f"{v.penalty:g}", c.label, "—", "—", "—", "—", "—", _status(c)])
            continue
        sF, eF = pair_error(c, p, "F", 0.0)
        sa, ea = pair_error(c, p, "a", 0.0)
        its = c.curve("iterations")
        its_p = p.curve("iterations")
        pen_curve = next((c.curve(k) for k in ("penetration", "gap_min", "penetration_max")
                          if c.curve(k) is not None), None)
        pen_txt = "—" if pen_curve is None else f"{np.nanmax(np.abs(pen_curve)):.2g}"
        rows.append([f"{v.penalty:g}", c.label, f"{pct(sF.max, 2)} ({pct(sF.rms, 2)})",
                     f"{pct(sa.max, 2)} ({pct(sa.rms, 2)})", pen_txt,
                     f"{int(its.sum()) if its is not None else '—'} / "
                     f"{int(its_p.sum()) if its_p is not None else '—'}",
                     f"{c.wall_s:.0f} / {p.wall_s:.0f}", _status(c)])
        notes.append(f"penalty {v.penalty:g}: F {pct(sF.max, 2)} %, a {pct(sa.max, 2)} % "
                     f"({_status(c)})")
        R = reference_radius(p)
        for k, e in enumerate((eF, ea)):
            ax[k].plot(p.h / R, 100 * e, color=f"C{i}", label=f"penalty {v.penalty:g}")
    path = _save_error_chart(plt, fig, ax, "relative to exact contact", out / "stability_penalty.png")
    table = markdown_table(["penalty (relative stiffness)", "run", "F max (rms) % vs exact",
                            "a max (rms) % vs exact", "max penetration / R",
                            "Newton iterations (penalty / exact)", "wall s (penalty / exact)",
                            "status"], rows)
    text = ("Largest difference from the exact (active-set) contact over the run: " + "; ".join(notes)
            + ".") if notes else ""
    return text + "\n\n" + table, path


def _save_error_chart(plt, fig, ax, against: str, path: Path) -> Path:
    """Label the F and a error panels against h/R ("<q> <against> %"), save and close."""
    for k, q in enumerate(("F", "a")):
        ax[k].set_xlabel("h / R")
        ax[k].set_ylabel(f"{q} {against} %")
        ax[k].axhline(0, color="0.5", lw=0.6)
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


# ============================================================================ increments
def increment_section(cases: list[Case], ref: Reference | None, th: Thresholds, out: Path):
    """Strain-increment series against the reference: (markdown, chart path or None)."""
    runs = sorted([c for c in standard_runs(cases, th)[1]
                   if math.isclose(variant(c, th).mesh_density, 1.0)],
                  key=lambda c: variant(c, th).strain_increment)
    if len(runs) < 2 or ref is None:
        return "Fewer than two strain-increment sizes in the studies set.", None
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    rows, worst = [], []
    R = reference_radius(ref.base)
    for i, c in enumerate(runs):
        v = variant(c, th)
        out_q = {}
        for k, q in enumerate(("F", "a")):
            y = interp_loglog(ref.h, c.h, getattr(c, q))
            e = relative_error(y, getattr(ref, q))
            out_q[q] = summarise(e, ref.window, ref.weights)
            ax[k].plot(ref.h / R, 100 * e, color=f"C{i}", label=f"Δε = {v.strain_increment:g}")
        its = c.curve("iterations")
        rej = c.provenance.get("timings", {}).get("rejected_increments", math.nan)
        rows.append([f"{v.strain_increment:g}", c.label, c.h.size,
                     int(its.sum()) if its is not None else "—", _count(rej),
                     f"{c.wall_s:.0f}", f"{pct(out_q['F'].max, 2)} ({pct(out_q['F'].rms, 2)})",
                     f"{pct(out_q['a'].max, 2)} ({pct(out_q['a'].rms, 2)})",
                     pct(energy_balance(c), 2), _status(c)])
        worst.append((v.strain_increment, out_q["F"], out_q["a"], energy_balance(c), c))
    path = _save_error_chart(plt, fig, ax, "relative to best FE estimate", out / "stability_increments.png")
    table = markdown_table(["strain increment Δε", "run", "increments", "Newton iterations",
                            "rejected increments", "wall s", "F max (rms) %", "a max (rms) %",
                            "energy balance miss %", "status"], rows)
    de, sF, sa, eb, c = worst[-1]
    if de <= DEFAULTS["strain_increment"] * (1 + 1e-9):
        return (f"No run with a strain increment above the default Δε = "
                f"{DEFAULTS['strain_increment']:g} in the studies; the series:\n\n" + table, path)
    text = (f"The largest increment, Δε = {de:g}: F up to {pct(sF.max, 2)} % and a up to "
            f"{pct(sa.max, 2)} % from the best estimate, energy balance missed by {pct(eb, 2)} % "
            f"({_status(c)}); the smallest, Δε = {worst[0][0]:g}: F {pct(worst[0][1].max, 2)} %.")
    return text + "\n\n" + table, path


# ============================================================================ extreme h/R
def extreme_section(cases: list[Case], coeffs: Coefficients | None, th: Thresholds, out: Path):
    """Runs beyond the acceptance window: (markdown, chart path or None)."""
    runs = [c for c in cases if variant(c, th).kind == "extreme"]
    if not runs:
        return "No run beyond the acceptance window in the studies set.", None
    plt = pyplot()
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    rows, notes = [], []
    for i, c in enumerate(runs):
        R = reference_radius(c)
        hR = c.h / R
        s1, s2 = spheres(c)
        with warnings.catch_warnings():  # beyond the calibrated h/R on purpose (said in the text)
            warnings.simplefilter("ignore", CalibrationRangeWarning)
            st = contact(s1, s2, c.h, coeffs)
        eF = relative_error(st.F, c.F)
        ea = relative_error(st.a, c.a)
        w = trapezoid_weights(c.h)
        beyond = hR > th.h_over_R_max
        its = c.curve("iterations")
        n = c.h.size
        tail = its[int(0.9 * n):] if its is not None and n else np.array([])
        head = its[: max(1, int(0.5 * n))] if its is not None and n else np.array([])
        rej = c.provenance.get("timings", {}).get("rejected_increments", math.nan)
        sF, sa = summarise(eF, beyond, w), summarise(ea, beyond, w)
        eb = energy_balance(c)
        rows.append([c.label, f"{variant(c, th).h_max:g}", f"{hR[-1]:.3g}", _status(c), n,
                     f"{head.mean():.1f} / {tail.mean():.1f}" if tail.size else "—", _count(rej),
                     f"{c.wall_s:.0f}", pct(eb, 2), f"{pct(sF.max)} ({pct(sF.rms)})",
                     f"{pct(sa.max)} ({pct(sa.rms)})"])
        notes.append(f"`{c.label}` reached h/R = {hR[-1]:.3g} of {variant(c, th).h_max:g} asked "
                     f"({_status(c)}) in {n} increments"
                     + (f", {head.mean():.1f} Newton iterations per increment in the first half and "
                        f"{tail.mean():.1f} in the last 10 %" if tail.size else "")
                     + f"; the model, which extrapolates there (it warns beyond its calibrated "
                       f"h/R), is off by up to {pct(sF.max)} % in F beyond h/R = {th.h_over_R_max:g}.")
        ax[0].plot(hR, c.F, "-", color=f"C{i}", lw=2, label=f"FE {c.label}")
        ax[0].plot(hR, st.F, "--", color=f"C{i}", label="model")
        ax[1].plot(hR, c.a / R, "-", color=f"C{i}", lw=2)
        ax[1].plot(hR, st.a / R, "--", color=f"C{i}")
        if its is not None:
            ax[2].plot(hR, its, ".", color=f"C{i}", ms=3)
    for a_ in ax:
        a_.axvline(th.h_over_R_max, color="0.6", lw=0.8)
        a_.set_xlabel("h / R")
    ax[0].set_ylabel("F / (σ_Y R²)")
    ax[1].set_ylabel("a / R")
    ax[2].set_ylabel("Newton iterations per increment")
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    path = out / "stability_extreme.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    table = markdown_table(["run", "h_max/R asked", "h/R reached", "status", "increments",
                            "iterations/increment (first half / last 10 %)", "rejected increments",
                            "wall s", "energy balance miss %",
                            f"model F max (rms) % beyond {th.h_over_R_max:g}",
                            f"model a max (rms) % beyond {th.h_over_R_max:g}"], rows)
    return " ".join(notes) + "\n\n" + table, path


# ============================================================================ model outside range
@dataclass
class Probe:
    name: str
    description: str
    h_over_R: np.ndarray
    F: np.ndarray | None
    a: np.ndarray | None
    stiffness: np.ndarray | None
    warnings: list
    error: str
    R: float
    sigma_y: float

    @property
    def finite(self) -> bool:
        return self.F is not None and bool(np.all(np.isfinite(self.F)) and np.all(np.isfinite(self.a)))

    @property
    def monotone(self) -> bool:
        return self.F is not None and bool(np.all(np.diff(self.F) > 0) and np.all(np.diff(self.a) > 0))

    def a_over_R_at(self, x: float) -> float:
        if self.a is None:
            return math.nan
        return float(np.interp(x, self.h_over_R, self.a / self.R))


def model_probes(coeffs: Coefficients | None, rng: CalibratedRange, h_over_R_max: float = 1.0):
    """The model on materials, pairs and approaches outside ``rng`` (and one inside, for contrast)."""
    E_lo, E_hi = rng.E_over_sigma_y
    E_soft = max(E_lo / 4, E_OVER_SIGMA_Y_RANGE[0])  # below the calibrated range, still accepted
    flat = Sphere(math.inf, Material.rigid())
    pp = Material(E=200.0, nu=0.3, sigma_y=1.0)
    specs = [
        ("inside", f"E/σ_Y 200, ν 0.3, perfectly plastic, rigid flat (h/R > {rng.h_over_R_max:g} "
         "is outside)", Sphere(1.0, pp), flat),
        ("soft elastic limit", f"E/σ_Y {E_soft:g} (below {E_lo:g}; the smallest accepted)",
         Sphere(1.0, Material(E=E_soft, nu=0.3, sigma_y=1.0)), flat),
        ("very stiff", f"E/σ_Y {E_hi * 10:g} (above {E_hi:g})",
         Sphere(1.0, Material(E=E_hi * 10, nu=0.3, sigma_y=1.0)), flat),
        ("nearly incompressible", f"ν 0.49 (above {rng.nu[1]:g})",
         Sphere(1.0, Material(E=200.0, nu=0.49, sigma_y=1.0)), flat),
        ("linear hardening", f"Ludwik K/σ_Y 5, n 1 (above n {rng.hardening_n[1]:g})",
         Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=5.0, n=1.0)), flat),
        ("late hardening table", "flow table flat to ε 0.05, then to 3σ_Y at ε 0.5",
         Sphere(1.0, Material.from_table(200.0, 0.3, [0.0, 0.05, 0.5], [1.0, 1.0, 3.0])), flat),
        ("extreme pair", f"radius ratio 50, yield ratio 20, E ratio 10 (calibrated up to "
         f"{rng.radius_ratio_max:g}, {rng.yield_ratio_max:g}, {rng.E_ratio_max:g})",
         Sphere(1.0, pp), Sphere(50.0, Material(E=2000.0, nu=0.3, sigma_y=20.0))),
        ("plastic limit pair", "R₂ = 0.365 R₁, yield ratio 1.47, E ratio 1.56, perfectly plastic: "
         "the smaller sphere's collapse pressure meets the larger one's indentation pressure near "
         "h/R₂ 0.42 (R = R₂; model/README.md, Domain)",
         Sphere(1.0, Material(E=2143.12, nu=0.268349, sigma_y=1.0)),
         Sphere(0.365052, Material(E=3342.54, nu=0.247789, sigma_y=1.46889))),
    ]
    out = []
    for name, desc, s1, s2 in specs:
        R = s1.radius if s2.is_rigid or s2.is_flat else min(s1.radius, s2.radius)
        hR = np.geomspace(1e-5, h_over_R_max, 300)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                st = contact(s1, s2, hR * R, coeffs)
                F, a, k, err = (np.asarray(st.F), np.asarray(st.a), np.asarray(st.stiffness), "")
            except Exception as exc:  # the probe reports what the model does, errors included
                F = a = k = None
                err = f"{type(exc).__name__}: {exc}"
        out.append(Probe(name, desc, hR, F, a, k, sorted({str(w.message) for w in caught}), err, R,
                         s1.material.sigma_y))
    return out


def probes_section(probes: list[Probe], rng: CalibratedRange, out: Path):
    """Table and chart of the model probes: (markdown, chart path)."""
    rows = []
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, p in enumerate(probes):
        pos = "—" if p.stiffness is None else ("yes" if np.all(p.stiffness > 0) else "no")
        rows.append([p.name, p.description, "yes" if p.finite else "no",
                     "yes" if p.monotone else "no", pos, f"{p.a_over_R_at(rng.h_over_R_max):.3g}",
                     f"{p.a_over_R_at(p.h_over_R[-1]):.3g}",
                     "; ".join(p.warnings) if p.warnings else "none", p.error or "—"])
        if p.F is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                pm = p.F / (math.pi * p.a**2) / p.sigma_y
            ax[0].plot(p.h_over_R, pm, color=f"C{i}", label=p.name)
            ax[1].plot(p.h_over_R, p.a / p.R, color=f"C{i}", label=p.name)
    for a_ in ax:
        a_.axvspan(rng.h_over_R_max, probes[0].h_over_R[-1], color="0.92", zorder=0)
        a_.set_xscale("log")
        a_.set_xlabel("h / R (shaded: beyond the calibrated h/R)")
    ax[0].set_ylabel("p_m / σ_Y (model)")
    ax[0].set_yscale("log")
    ax[1].set_ylabel("a / R (model)")
    ax[1].axhline(1.0, color="k", lw=0.6)
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    path = out / "model_outside_range.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    h_last = probes[0].h_over_R[-1]
    table = markdown_table(["probe", "inputs", "finite", "F, a increasing", "dF/dh > 0",
                            f"a/R at h/R {rng.h_over_R_max:g}", f"a/R at h/R {h_last:g}",
                            "warnings", "error"], rows)
    return table, path
