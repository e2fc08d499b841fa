"""The validation report: tables, charts, speed–accuracy and stability → ``OUT/index.md`` + PNGs."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fem.io import START_TRANSIENT
from ..model import Coefficients, default_coefficients
from .cases import Case
from .charts import curves_chart, error_chart, representative
from .compare import W_ACCEPT, Comparison, compare_case
from .config import Thresholds
from .goal import goal_rows, goal_section
from .increments_report import small_contact_section
from .mdr_report import mdr_section
from .stability import (
    extreme_section,
    increment_section,
    locking_section,
    model_probes,
    penalty_section,
    probes_section,
)
from .studies import mdr_points, reference, speed_accuracy, speed_accuracy_chart, speed_accuracy_table
from .tables import class_matrix, class_tables, failures, level_table, pct, range_tables, run_table
from .unloading import unloading_failures, unloading_rows
from .unloading_report import unloading_section

__all__ = ["ReportResult", "build_report", "worst_point"]


@dataclass
class ReportResult:
    path: Path
    comparisons: list
    failures: list
    pngs: list
    goal_misses: list = field(default_factory=list)  # labels of the runs that miss ``[goal]``


def worst_point(comp: Comparison, q: str) -> str:
    """Where the model's |error| of q peaks in the acceptance window: sign, h/R, level."""
    e = comp.model.errors.get(q)
    if e is None:
        return "—"
    m = comp.masks[W_ACCEPT] & np.isfinite(e)
    if not np.any(m):
        return "—"
    i = np.flatnonzero(m)[np.argmax(np.abs(e[m]))]
    where = f"Level {'I' * int(comp.level[i])}"
    if comp.labels[i] == "large":
        where += ", large deformation"
    return f"{100 * e[i]:+.1f} % at h/R {comp.h_over_R[i]:.3g} ({where}, Λ {comp.Lambda[i]:.3g})"


def _rel(path: Path, out: Path) -> str:
    return path.relative_to(out).as_posix()


def _header(source: str, coeffs: Coefficients, coeff_path: str, th: Thresholds, th_path: str,
            validation: list[Case], studies: list[Case], skipped: list[str]) -> list[str]:
    stopped = [c.label for c in validation if c.status != "converged"]
    lines = [
        "# Validation: the closed-form model and published contact laws against FE",
        "",
        f"* FE data: `{source}` — {len(validation)} validation runs"
        + (f" ({len(stopped)} stopped early: {', '.join(stopped)})" if stopped else "")
        + f", {len(studies)} study runs.",
        f"* Model coefficients: `{coeff_path}` (source: {coeffs.source}); Λ_I = {coeffs.Lambda_I:.3g}, "
        f"Λ_III = {coeffs.Lambda_III:.4g}.",
        f"* Thresholds: `{th_path}` — max |F error| ≤ {pct(th.F_max, 0)} %, max |a error| ≤ "
        f"{pct(th.a_max, 0)} % per run, from the end of Level I to h/R = {th.h_over_R_max:g}.",
    ]
    transient = [c for c in validation if not np.array_equal(c.reference, c.loading)]
    if transient:
        lines.append(f"* FE increments: {len(transient)} of the runs began with a first step larger than "
                     f"today's solver takes, across first yield; their increments below "
                     f"{START_TRANSIENT:g}× that step (its transient, `fem.io.reference_mask`, "
                     "data/README.md) are left out of every comparison.")
    if skipped:
        lines.append(f"* Not compared (no converged curve): {', '.join(skipped)}.")
    return lines


def build_report(validation: list[Case], studies: list[Case], coeffs: Coefficients | None,
                 th: Thresholds, out, *, source: str = "", coeff_path: str = "", th_path: str = "",
                 skipped: list[str] | None = None,
                 studies_source: str = "", mdr=None, mdr_source: str = "", converged=None) -> ReportResult:
    """Compare every validation run, run the studies, write ``out/index.md`` and the PNGs.

    ``mdr``: the stored LAMMPS mdr curves (:func:`.mdr.load_store`; None: mdr is not
    given), read from ``mdr_source``. ``converged``: the first loadings re-run with finer
    increments (:func:`.increments_report.load_converged`; None: the section says so).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("*.png"):
        old.unlink()
    cf = default_coefficients() if coeffs is None else coeffs
    comps = [compare_case(c, coeffs, th, mdr) for c in validation if c.h.size >= 2]
    fails = failures(comps, th)
    unload = unloading_rows(validation, coeffs, mdr)
    unload_fails = unloading_failures(unload, th.F_branch_max, th.h_res_max)
    pngs: list[Path] = []
    md = _header(source, cf, coeff_path, th, th_path, validation, studies, skipped or [])
    if studies_source:
        md.append(f"* Study runs (speed–accuracy, stability): {studies_source}.")
    if mdr is not None:
        md.append(f"* LAMMPS mdr: {len(mdr.curves)} stored curves `{mdr_source or mdr.path}` "
                  f"(LAMMPS {mdr.version}; section \"LAMMPS mdr\").")
    else:
        md.append(f"* LAMMPS mdr: no stored curves (`{mdr_source or 'data/peers/mdr.json'}` not found; "
                  "`make peers-mdr`).")

    # ------------------------------------------------------------------ verdict
    md += ["", "## Verdict", ""]
    if not comps:
        md.append("No validation run to compare.")
    elif fails:
        md.append(f"**FAIL** — {len(fails)} of {len(comps)} runs exceed the thresholds:")
        md.append("")
        by_key = {c.case.key: c for c in comps}
        for f in fails:
            c = by_key[f.key]
            md.append(f"* {f}. Largest F error {worst_point(c, 'F')}; largest a error "
                      f"{worst_point(c, 'a')}.")
    else:
        md.append(f"**PASS** — all {len(comps)} runs within the thresholds.")
    if unload:
        md += ["", (f"**FAIL (unloading)** — {len(unload_fails)} of {len(unload)} unloading branches "
                    "exceed the thresholds `[unloading]` (section \"Unloading and reloading\")."
                    if unload_fails else
                    f"**PASS (unloading)** — all {len(unload)} unloading branches within the thresholds.")]
    stopped = [c for c in comps if c.case.status != "converged"]
    if stopped:
        md += ["", "Runs that stopped early are checked over the part the FE reached: "
               + "; ".join(f"{c.case.label} to h/R = {c.h_over_R[-1]:.3g} ({c.case.reason})"
                           for c in stopped) + "."]
    warned = sorted({w for c in comps for w in c.model_warnings})
    md += ["", "Model warnings while evaluating the validation runs: "
           + ("; ".join(warned) if warned else "none") + "."]
    goals = goal_rows(comps)
    if comps:
        md += ["", "## The design goal", "", *goal_section(goals, th)]

    # ------------------------------------------------------------------ tables
    md += ["", f"## The model against each peer law, per class ({W_ACCEPT})", "",
           "Max |relative error| of F / of a in per cent, pooled over the runs of the class "
           "(a run can be in several classes); `[k/n]`: the law applies to k of the n runs; "
           "n/a: it applies to none (reasons in the class tables). Johnson's cavity model gives "
           "p_m only: its F column is the error of p_m at the FE contact radius, in its own range "
           "3 ≤ E'a/(σ_Y ρ) ≤ 40.", "",
           class_matrix(comps), "", "### Each peer in its own range",
           "", "The whole-window figures above score a law also where it does not claim to hold (Hertz "
           "far beyond first yield, a rigid–plastic law in the elastic–plastic range). Here each peer "
           "is scored on the resolved FE points from h = 0 to the window end that lie inside its own "
           "stated range (`spherecontact/peers.py`, in the law's own variable: ω/ω_c, δ/δ_y, E'a/(σ_Y ρ)), "
           "and the model on the same points; the model's whole-window figures are those of the "
           "tables above and below. Johnson's cavity model: error of p_m (its whole window is "
           "already its range).", "", range_tables(comps), "",
           "### Per class: max (RMS) errors and where a law does not apply",
           "", class_tables(comps), "", "## The model against FE, per run", "",
           "Max (RMS) relative error in per cent; h₁/h split: max absolute error of the fraction "
           "in percentage points. `to 0.5`: runs that go beyond the acceptance window. FE scatter: "
           "largest deviation of ln F (ln a) from a local quadratic over 11 increments — the noise "
           "of the FE curve itself, against which a max error is read.", "",
           run_table(comps, th), "", "## Per level (all runs pooled, every FE point)", "",
           "Level of a point: the model's level of the body furthest into plasticity; "
           f"`large deformation`: h/R > {th.large_deformation_from:g}. Max (RMS) error %.", "",
           "**F**", "", level_table(comps, "F"), "", "**a**", "", level_table(comps, "a"), ""]
    md += small_contact_section(comps, converged)

    # ------------------------------------------------------------------ charts
    if comps:
        md += ["", "## Curves of representative runs", "",
               "One run per class and the run with the largest F error. FE (black), model (blue "
               "dashed), peer laws where they apply; errors below; grey band: threshold; vertical "
               "lines: end of Level I (dotted) and the window end.", ""]
        for c in representative(comps):
            p = curves_chart(c, th, out)
            pngs.append(p)
            md += [f"![{c.case.label}]({_rel(p, out)})", ""]
        md += ["## Model error against Λ and h/R", ""]
        for x in ("Lambda", "h"):
            p = error_chart(comps, th, out, x, levels=(cf.Lambda_I, cf.Lambda_III))
            pngs.append(p)
            md += [f"![error vs {x}]({_rel(p, out)})", ""]

    # ------------------------------------------------------------------ LAMMPS mdr
    lines, mdr_pngs = mdr_section(comps, mdr, out, coeffs=coeffs, source=mdr_source)
    md += lines
    pngs += mdr_pngs

    # ------------------------------------------------------------------ unloading
    lines, unload_pngs = unloading_section(unload, th.F_branch_max, th.h_res_max, out)
    md += lines
    pngs += unload_pngs

    # ------------------------------------------------------------------ speed–accuracy
    md += ["## Speed and accuracy", ""]
    base = reference(studies, th)
    ref = None
    if base is None:
        md.append("No base run (default mesh and increment) in the studies set.")
    else:
        start = compare_case(base.base, coeffs, th).start
        ref, pts, models = speed_accuracy(studies, coeffs, th, start_h_over_R=start)
        models += mdr_points(ref, mdr)
        p = speed_accuracy_chart(pts, models, out)
        pngs.append(p)
        md += [f"Standard case `{ref.base.label}`; reference: {ref.how}, smoothed by a local quadratic "
               "in ln h over 11 increments (FE scatter removed). Errors over h/R "
               f"{start:.2g}–{th.h_over_R_max:g} against that reference; time per curve: FE "
               "wall time of the run on one core, model: one evaluation of the whole curve on the "
               "same approaches (best of three); LAMMPS mdr: its stored run (many small steps), and its "
               "cost per contact evaluation times the number of points.", "",
               speed_accuracy_table(pts, models), "",
               f"![speed and accuracy]({_rel(p, out)})", ""]

    # ------------------------------------------------------------------ stability
    md += ["## Stability: where methods fail", ""]
    sections = [
        ("Locking (bilinear fully integrated elements)", locking_section(studies, th, out)),
        ("Penalty contact", penalty_section(studies, th, out)),
        ("Oversized increments", increment_section(studies, ref, th, out)),
        ("Extreme h/R", extreme_section(studies, coeffs, th, out)),
    ]
    rng = cf.calibrated_range  # what the model warns outside of
    probes = model_probes(coeffs, rng)
    sections.append(("The model outside its calibrated range", probes_section(probes, rng, out)))
    for title, (text, png) in sections:
        md += [f"### {title}", "", text, ""]
        if title.startswith("The model"):
            md += [f"Calibrated range: {rng.describe()}.", "", _probe_summary(probes), ""]
        if png is not None:
            pngs.append(png)
            md += [f"![{title}]({_rel(png, out)})", ""]

    # ------------------------------------------------------------------ method
    md += ["## Method", "",
           "* Relative error e = prediction/FE − 1 at the FE approaches; max |e| and RMS = "
           "√(∫e² dh/∫dh) (trapezoid rule over the increments, so uniform in h). A class pools its "
           "runs as the max of the maxima and √(mean RMS²).",
           "* h/R uses the smaller deformable radius; the flat scene is one of two equal spheres "
           "(h is one body's approach) and the model is evaluated for the same scene (sphere on a "
           "rigid flat), which gives the same body response as the equal pair at 2h.",
           "* The acceptance window starts at the first FE point where the model leaves Level I "
           "(Λ > Λ_I for the body furthest into plasticity) and ends at h/R = "
           f"{th.h_over_R_max:g}. FE points with a/R < {th.a_min_over_R:g} (contact radius spanning "
           "fewer than about three pole elements of the standard mesh) are left out everywhere.",
           "* Peer laws: `validation/peer_scenes.py` states how each law is applied (E*, R*, total "
           "approach for pairs; yield stress and ν of the body that yields first; Johnson's cavity "
           "model as p_m in 3 ≤ E'a/(σ_Y ρ) ≤ 40; Biwa–Storåkers with a secant power law for non-power-law "
           "curves) and where a law does not apply.", ""]
    path = out / "index.md"
    path.write_text("\n".join(md))
    return ReportResult(path, comps, fails + [f"unloading: {f}" for f in unload_fails], pngs,
                        [r.label for r in goals if r.misses(th)])


def _probe_summary(probes) -> str:
    warned = [p.name for p in probes if p.warnings]
    bad = [p.name for p in probes if not (p.finite and p.monotone)]
    errs = [p.name for p in probes if p.error]
    over = [p.name for p in probes if p.a is not None and np.nanmax(p.a / p.R) > 1.0]
    parts = [
        "The model warned for: " + ", ".join(warned) + "." if warned else
        "**The model does not warn** when it is used outside its calibrated range: no probe "
        "raised a warning.",
        ("Non-finite or non-monotone F(h), a(h) for: " + ", ".join(bad) + ".") if bad else
        "F(h) and a(h) stay finite and increasing for every probe.",
    ]
    if errs:
        parts.append("The model raised an error for: " + ", ".join(errs) + ".")
    silent = [p.name for p in probes if p.name in over and not any("a/R" in w for w in p.warnings)]
    if over:
        parts.append("It returns a contact radius larger than the sphere (a > R), without clipping, "
                     "for: " + ", ".join(over) + "; " + (
                         "without a warning on a/R for: " + ", ".join(silent) + "." if silent else
                         "each time with a warning on a/R."))
    return " ".join(parts)

