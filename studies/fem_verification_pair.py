"""Verification of the two-deformable-body scene (docs/design.md §4).

``python studies/fem_verification_pair.py [--quick] [--reuse] [--out DIR]``
runs the cases below, writes ``DIR/pair_verification.json``, ``DIR/pair.md`` and
``DIR/pair.png``. σ_Y = 1, R₁ = 1 throughout.

* ``equal``: an equal elastic–perfectly plastic pair (E/σY = 200, ν = 0.3) as two
  hemispheres against one hemisphere on a rigid flat (the symmetric scene), up
  to a per-body approach h/R = 0.3: F and a within 0.5 %. The pair uses the symmetric
  two-pass penalty contact and the flat the same penalty, with matched increments
  (see ``_cases``); the pair against the flat with exact contact, and an equal hardening
  pair with the exact one-pass contact, are reported alongside.
* ``hertz``: elastic E₂/E₁ = 3, R₂/R₁ = 2, ν = 0.3/0.2: F against the reference
  contact radius within 1 % of Hertz with E*, R* (Hertz 1882) for a/R₁ 0.01–0.05,
  and h₁/h₂ against E'₂/E'₁ (the half-space centre displacements
  π p₀ a/(2E'ᵢ); Johnson 1985 §4.2), within 2 % at small h. On the 2× mesh (density 2):
  the project's resolution rule admits contact radii from about seven pole elements on
  (``calibration.dataset.A_MIN_ELEMENTS``), a/R = 0.02 at density 1 and 0.01 at density 2;
  at density 1 the sub-element estimate of a ripples as surface nodes close, and F against
  Hertz's F(a) ∝ a³ swings between −1.15 % and 0 over a/R₁ 0.011–0.05 (−2 to −4 % below
  0.01). The same pair at density 1, the campaign's mesh, is reported beside as information.
* ``stiff``: a plastic body 1 (EPP E/σY = 200) against an elastic body 2 with
  E₂/E₁ = 1000, against the rigid-sphere scene (R₂ = R₁, stepped to the pair's
  approaches), to h/R = 0.3: within 1 %
  in F (both forces smoothed over increments like a: each scene's F(h) ripples by a few %
  at small h as single nodes close; the raw difference and that ripple are reported)
  and in a.
* ``plastic pairs``: the two-body runs of the reference database (``--db``, default campaign
  v2's), each with its contact method, the largest approach h/R_min it reached (runs with
  unloading cycles end below it) and its wall time; the pairs of :data:`REQUIRED_PAIRS` (yield-
  stress ratio 5, radius ratio 3, equal yield stress) must reach h/R_min = 0.3. Campaign v2
  replaced three pairs by shorter runs (``[replace]`` of ``data/campaign_v2.toml``).
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
from fem_verification import save_run, saved_runs

from spherecontact.data import Database
from spherecontact.fem.contact import smooth_contact_radius
from spherecontact.fem.io import run_indentation
from spherecontact.fem.solver import SolverOptions
from spherecontact.model.material import Material

NU = 0.3
EPP = Material(E=200.0, nu=NU, sigma_y=1.0, K=0.0, n=1.0)
HARD = Material(E=200.0, nu=NU, sigma_y=1.0, K=2.0, n=0.3)
#: relative penalty stiffness of the equal-pair check (0.08 % from exact contact in the work of a
#: plastic indentation, tests/test_fem_penalty.py)
PENALTY = 100.0
#: the elastic dissimilar pair of the Hertz check (mesh density given per run)
HERTZ_PAIR = dict(material=Material.elastic(200.0, 0.3), radius=1.0, h_max=0.004, radius2=2.0,
                  material2=Material.elastic(600.0, 0.2))


def _cases(quick: bool) -> dict:
    """name → keyword arguments of run_indentation (h_max shortened and meshes coarse in quick mode).

    The equal pair runs with the symmetric two-pass penalty contact; the flat scene then steps
    to the pair's per-body approaches (``schedule_of``: h/2 of that run), so that both take
    the same increments and the comparison measures the two-body method, not the path
    dependence of plasticity on the increment sequence (halving the strain increment alone
    moves F by 0.2–1 %, validation studies). The rigid-sphere scene steps to the stiff pair's
    approaches likewise.
    """
    d = 0.5 if quick else 1.0
    h_equal, h_stiff = (0.06, 0.06) if quick else (0.3, 0.3)
    base = SolverOptions(penalty=PENALTY)
    pair = SolverOptions(dh_first=2 * base.dh_first, dh_max=2 * base.dh_max, dh_min=2 * base.dh_min,
                         strain_increment=2 * base.strain_increment, penalty=PENALTY)  # h = 2 h₁
    return {
        "equal_two_body": dict(material=EPP, radius=1.0, h_max=2 * h_equal, radius2=1.0,
                               material2=EPP, scene="two_body", density=d, options=pair),
        "equal_flat": dict(material=EPP, radius=1.0, h_max=h_equal, density=d, options=base,
                           schedule_of=("equal_two_body", 0.5)),
        "equal_flat_exact": dict(material=EPP, radius=1.0, h_max=h_equal, density=d),
        "hard_two_body": dict(material=HARD, radius=1.0, h_max=2 * h_equal, radius2=1.0,
                              material2=HARD, scene="two_body", density=d),
        "hard_flat": dict(material=HARD, radius=1.0, h_max=h_equal, density=d),
        "hertz_d2": dict(HERTZ_PAIR, density=2 * d),
        "hertz": dict(HERTZ_PAIR, density=d),
        "stiff_two_body": dict(material=EPP, radius=1.0, h_max=h_stiff, radius2=1.0,
                               material2=Material.elastic(200.0 * 1000, NU), density=d),
        "stiff_rigid": dict(material=EPP, radius=1.0, h_max=h_stiff, indenter_radius=1.0, density=d,
                            schedule_of=("stiff_two_body", 1.0)),
    }


def _run(name: str, kwargs: dict, outdir: Path) -> dict:
    """One run, saved as JSON next to the report (nothing finished is lost). ``schedule_of``:
    (name, factor): step to factor × the approaches of that (already saved) run — half the
    equal pair's (h = 2 h₁), the stiff pair's own (its partner barely deforms), so that the two
    scenes compare at the same approaches, without the sampling of their node-closure ripple."""
    t0 = time.perf_counter()
    kwargs = dict(kwargs)
    source = kwargs.pop("schedule_of", None)
    if source is not None:
        source_name, factor = source
        h_src = np.asarray(saved_runs(outdir, [source_name], "pair_")[source_name]["curves"]["h"])
        kwargs["schedule"] = factor * h_src[h_src > 0]
    res = run_indentation(**kwargs)
    out = {"curves": {k: np.asarray(v).tolist() for k, v in res.curves.items()},
           "status": res.status, "reason": res.reason, "scene": res.inputs["scene"],
           "timings": {k: float(v) for k, v in res.timings.items()},
           "n_dofs": int(res.inputs["n_dofs"]), "wall_s": time.perf_counter() - t0}
    save_run(outdir, f"pair_{name}.json", out)
    return out


def _with_smooth_force(run: dict) -> dict:
    """The run with ``F_smooth``: F smoothed over increments like the contact radius."""
    c = dict(run["curves"])
    c["F_smooth"] = smooth_contact_radius(_curve(run, "h"), _curve(run, "F")).tolist()
    return {**run, "curves": c}


def _curve(run: dict, key: str) -> np.ndarray:
    return np.asarray(run["curves"][key], dtype=float)


def _rel_on(ref: dict, other: dict, key: str, x_ref: np.ndarray, x_other: np.ndarray,
            window: tuple[float, float]) -> np.ndarray:
    """Relative difference of ``other`` against ``ref`` in ``key``, at ref's points in the window."""
    xr, yr = x_ref, _curve(ref, key)
    sel = (xr >= window[0]) & (xr <= window[1]) & (yr > 0)
    return np.interp(xr[sel], x_other, _curve(other, key)) / yr[sel] - 1.0


def _equal_pair(two: dict, flat: dict) -> dict:
    """An equal pair as two bodies against one body on a flat at the per-body approach h₁."""
    h_end = _curve(flat, "h")[-1]
    win = (0.01, h_end)
    dF = _rel_on(flat, two, "F", _curve(flat, "h"), _curve(two, "h1"), win)
    da = _rel_on(flat, two, "a", _curve(flat, "h"), _curve(two, "h1"), win)
    h1, h2 = _curve(two, "h1"), _curve(two, "h2")
    return {"window_h_over_R": list(win), "F_max_pct": 100 * float(np.abs(dF).max()),
            "F_rms_pct": 100 * float(np.sqrt(np.mean(dF**2))),
            "a_max_pct": 100 * float(np.abs(da).max()),
            "a_rms_pct": 100 * float(np.sqrt(np.mean(da**2))),
            "h1_h2_max_dev_pct": 100 * float(np.abs(h1[h2 > 0] / h2[h2 > 0] - 1).max()),
            "h1_end": float(h1[-1]), "status_two_body": two["status"],
            "wall_two_body_s": two["wall_s"], "wall_flat_s": flat["wall_s"],
            "dofs_two_body": two["n_dofs"], "dofs_flat": flat["n_dofs"]}


def hertz_figures(hz: dict) -> dict:
    """F against the reference contact radius vs Hertz with E*, R* over a/R₁ 0.01–0.05, and
    h₁/h₂ against E'₂/E'₁ (at a/R₁ ≤ 0.02 and over the whole run), of the elastic pair."""
    m1, m2 = HERTZ_PAIR["material"], HERTZ_PAIR["material2"]
    Es = 1.0 / (1.0 / m1.E_prime + 1.0 / m2.E_prime)
    Rs = 1.0 / (1.0 / HERTZ_PAIR["radius"] + 1.0 / HERTZ_PAIR["radius2"])
    F, a_ref, a = _curve(hz, "F"), _curve(hz, "a_ref"), _curve(hz, "a")
    sel = (a_ref >= 0.01) & (a_ref <= 0.05)
    ratio_F = F[sel] / (4.0 * Es * a_ref[sel] ** 3 / (3.0 * Rs))
    target = m2.E_prime / m1.E_prime
    rh = _curve(hz, "h1") / _curve(hz, "h2") / target
    small = a <= 0.02
    return {"E_star": Es, "R_star": Rs, "a_window": [0.01, 0.05],
            "F_vs_a_max_pct": 100 * float(np.abs(ratio_F - 1).max()),
            "F_vs_a_mean_pct": 100 * float(np.mean(ratio_F - 1)),
            "h1_over_h2_target": target,
            "h1_over_h2_dev_pct_small_h": 100 * float(np.abs(rh[small] - 1).max()),
            "h1_over_h2_dev_pct_all": 100 * float(np.abs(rh - 1).max()),
            "a_small_h_max": 0.02, "wall_s": hz["wall_s"], "n_dofs": hz["n_dofs"]}


def evaluate(runs: dict, quick: bool) -> dict:
    """The figures of the three checks."""
    fig = {}
    # equal pair: two bodies (h = 2 × per-body approach) against the symmetric scene
    fig["equal"] = _equal_pair(runs["equal_two_body"], runs["equal_flat"])
    if "equal_flat_exact" in runs:  # the same pair against the flat with exact contact
        ex = _equal_pair(runs["equal_two_body"], runs["equal_flat_exact"])
        fig["equal"]["vs_exact_flat"] = {k: ex[k] for k in ("F_max_pct", "F_rms_pct", "a_max_pct",
                                                             "a_rms_pct", "wall_flat_s")}
    if "hard_two_body" in runs:  # exact one-pass contact, a hardening equal pair
        fig["hard"] = _equal_pair(runs["hard_two_body"], runs["hard_flat"])
    # elastic dissimilar pair against Hertz with E*, R*: on the 2× mesh, and at density 1 (info)
    fig["hertz"] = hertz_figures(runs["hertz_d2"])
    if "hertz" in runs:
        fig["hertz_density1"] = hertz_figures(runs["hertz"])
    # stiff elastic body 2 against the rigid-sphere scene. F(h) of both scenes ripples by a few %
    # as single nodes close at small h; the method difference is measured on F smoothed like a
    # (local power-law fit over 7 increments, contact.smooth_contact_radius), raw figures kept.
    st, rg = runs["stiff_two_body"], runs["stiff_rigid"]
    win = (0.005, _curve(rg, "h")[-1])
    dF_raw = _rel_on(rg, st, "F", _curve(rg, "h"), _curve(st, "h"), win)
    st_s, rg_s = _with_smooth_force(st), _with_smooth_force(rg)
    dF = _rel_on(rg_s, st_s, "F_smooth", _curve(rg, "h"), _curve(st, "h"), win)
    da = _rel_on(rg, st, "a", _curve(rg, "h"), _curve(st, "h"), win)
    hr = _curve(rg, "h")
    ripple = _curve(rg, "F")[hr >= win[0]] / _curve(rg_s, "F_smooth")[hr >= win[0]] - 1.0
    fig["stiff"] = {"window_h_over_R": list(win), "F_max_pct": 100 * float(np.abs(dF).max()),
                    "F_rms_pct": 100 * float(np.sqrt(np.mean(dF**2))),
                    "F_raw_max_pct": 100 * float(np.abs(dF_raw).max()),
                    "F_ripple_rigid_max_pct": 100 * float(np.abs(ripple).max()),
                    "a_max_pct": 100 * float(np.abs(da).max()),
                    "h2_over_h_end": float(_curve(st, "h2")[-1] / _curve(st, "h")[-1]),
                    "wall_two_body_s": st["wall_s"], "wall_rigid_s": rg["wall_s"]}
    limits = {"equal": 0.5, "hertz": 1.0, "stiff": 1.0}
    e, hz, st = fig["equal"], fig["hertz"], fig["stiff"]
    fig["pass"] = {
        "equal": bool(max(e["F_max_pct"], e["a_max_pct"]) <= limits["equal"]
                      and e["h1_end"] >= 0.99 * e["window_h_over_R"][1]),
        "hertz": hz["F_vs_a_max_pct"] <= limits["hertz"] and hz["h1_over_h2_dev_pct_small_h"] <= 2.0,
        "stiff": max(st["F_max_pct"], st["a_max_pct"]) <= limits["stiff"]}
    fig["quick"] = quick
    return fig


#: reference-database pairs that must reach h/R_min = 0.3 (docs/design.md §4): name suffix → description
#: (campaign v2's; v1 required ``vs-sy3`` and ``vs-R4``)
REQUIRED_PAIRS = {"vs-sy5": "yield-stress ratio 5, equal radii", "vs-R3-sy2": "radius ratio 3",
                  "vs-E99.9": "equal yield stress (penalty contact), E ratio 1/3"}


def database_pairs(db_path) -> list[dict]:
    """The two-body runs of the reference database: case, contact, status, the largest approach
    h/R_min reached (a run with unloading cycles ends below it), wall."""
    db = Database(db_path)
    rows = []
    for rec in sorted(db.records(status=None), key=lambda r: (r.set, r.case)):
        if rec.status == "failed" or "radius2" not in rec.inputs:
            continue
        run = db.run(rec.key)
        r_min = min(rec.inputs["radius"], rec.inputs["radius2"])
        options = rec.inputs["options"]
        penalty, points = options.get("penalty"), options.get("segment_points") or 0
        contact = "exact one-pass" if not penalty else f"two-pass penalty {penalty:g}" + (
            f", {points} Gauss points" if points else "")
        rows.append({"set": rec.set, "case": rec.case, "status": rec.status, "contact": contact,
                     "h_end_over_R_min": float(np.max(run.h) / r_min), "wall_s": rec.wall_s,
                     "n_dofs": int(rec.inputs.get("n_dofs", 0)), "reason": rec.reason})
    return rows


def _pairs_pass(rows: list[dict]) -> bool:
    """Every REQUIRED_PAIRS case is in the database and reached h/R_min = 0.3."""
    done = {r["case"] for r in rows if r["status"] == "converged"
            and r["h_end_over_R_min"] >= 0.3 * (1 - 1e-9)}
    return all(any(c.endswith(s) for c in done) for s in REQUIRED_PAIRS)


def _pairs_rows(rows: list[dict]) -> list[str]:
    lines = ["## Plastic pairs of the reference database", "",
             "Must reach h/R_min = 0.3: " + "; ".join(f"`…-{s}` ({d})" for s, d in REQUIRED_PAIRS.items())
             + ". Wall times with both cores busy (two campaign runs at a time).", "",
             "| set | case | contact | status | reached h/R_min | wall [s] | dofs |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['set']} | {r['case']} | {r['contact']} | {r['status']} | {r['h_end_over_R_min']:.3f} "
              f"| {r['wall_s']:.0f} | {r['n_dofs']} |" for r in rows]
    return lines + [""]


def _plot(runs: dict, outdir: Path) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    two, flat = runs["equal_two_body"], runs["equal_flat"]
    ax[0].plot(_curve(flat, "h"), _curve(flat, "F"), "k-", label="one hemisphere on a flat")
    ax[0].plot(_curve(two, "h1"), _curve(two, "F"), "r--", label="two hemispheres (h₁)")
    ax[0].set(xlabel="per-body approach h/R", ylabel="F/(σY R²)", title="equal pair, EPP E/σY = 200")
    hz = runs["hertz_d2"]
    ax[1].plot(_curve(hz, "a"), _curve(hz, "h1") / _curve(hz, "h2"), "b.-", label="FE h₁/h₂")
    ax[1].axhline(HERTZ_PAIR["material2"].E_prime / HERTZ_PAIR["material"].E_prime, color="k", ls=":",
                  label="E'₂/E'₁")
    ax[1].set(xlabel="a/R₁", ylabel="h₁/h₂", title="elastic E₂/E₁ = 3, R₂/R₁ = 2")
    st, rg = runs["stiff_two_body"], runs["stiff_rigid"]
    ax[2].plot(_curve(rg, "h"), _curve(rg, "F"), "k-", label="rigid sphere")
    ax[2].plot(_curve(st, "h"), _curve(st, "F"), "r--", label="elastic, E₂/E₁ = 1000")
    ax[2].set(xlabel="h/R", ylabel="F/(σY R²)", title="stiff partner")
    for a in ax:
        a.legend()
        a.grid(alpha=0.3)
    fig.tight_layout()
    path = outdir / "pair.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.name


def _extra_equal_rows(fig: dict) -> list[str]:
    """Report rows: the penalty pair against exact flat contact, and the exact one-pass pair."""
    rows = []
    x = fig["equal"].get("vs_exact_flat")
    if x:
        rows.append(f"| same pair against the flat with exact contact (increments not matched) | F max "
                    f"{x['F_max_pct']:.2f} % (rms {x['F_rms_pct']:.2f} %), a max {x['a_max_pct']:.2f} % "
                    f"(rms {x['a_rms_pct']:.2f} %) | — | info |")
    hd = fig.get("hard")
    if hd:
        rows.append(f"| equal hardening pair (K/σY = 2, n = 0.3), exact one-pass contact, vs one on a flat "
                    f"(exact) | F max {hd['F_max_pct']:.2f} % (rms {hd['F_rms_pct']:.2f} %), a max "
                    f"{hd['a_max_pct']:.2f} % (rms {hd['a_rms_pct']:.2f} %); h₁/h₂ − 1 up to "
                    f"{hd['h1_h2_max_dev_pct']:.2f} %; reached h₁/R = {hd['h1_end']:.3g} | — | info |")
    return rows


def _hertz_density1_rows(fig: dict) -> list[str]:
    """Report row: the Hertz pair on the campaign's mesh (density 1), for information."""
    h1 = fig.get("hertz_density1")
    if not h1:
        return []
    return [f"| same pair at density 1 ({h1['n_dofs']} dofs; the contact-radius estimate ripples as "
            f"nodes close) | F vs a max {h1['F_vs_a_max_pct']:.2f} %, mean "
            f"{h1['F_vs_a_mean_pct']:+.2f} %; h₁/h₂ max "
            f"{h1['h1_over_h2_dev_pct_small_h']:.2f} % (whole run {h1['h1_over_h2_dev_pct_all']:.2f} %) "
            "| — | info |"]


def _report(fig: dict, png: str, outdir: Path, wall: float, reused: int = 0) -> None:
    e, hz, st = fig["equal"], fig["hertz"], fig["stiff"]
    reuse = f" (--reuse: {reused} stored runs)" if reused else ""
    ok = {k: "pass" if v else "FAIL" for k, v in fig["pass"].items()}
    lines = [
        "# FE verification: two deformable spheres", "",
        f"`python studies/fem_verification_pair.py{' --quick' if fig['quick'] else ''}`, "
        f"{wall:.0f} s{reuse}. Figures in `pair_verification.json`.", "",
        "| check | figure | limit | result |", "|---|---|---|---|",
        f"| equal EPP pair as two bodies (symmetric two-pass penalty {PENALTY:g}) vs one on a flat "
        f"(same penalty, stepping to the pair's approaches), h/R {e['window_h_over_R'][0]:g}–"
        f"{e['window_h_over_R'][1]:g} | F max {e['F_max_pct']:.3f} % (rms {e['F_rms_pct']:.3f} %), "
        f"a max {e['a_max_pct']:.2f} % (rms {e['a_rms_pct']:.2f} %); h₁/h₂ − 1 ≤ "
        f"{e['h1_h2_max_dev_pct']:.1e} %; reached h₁/R = {e['h1_end']:.3g} | 0.5 % | {ok['equal']} |",
        *_extra_equal_rows(fig),
        f"| elastic E₂/E₁ = 3, R₂/R₁ = 2, ν 0.3/0.2, 2× mesh ({hz['n_dofs']} dofs): F vs a (reference "
        f"config.) against Hertz with E*, R*, a/R₁ 0.01–0.05 | max {hz['F_vs_a_max_pct']:.2f} %, mean "
        f"{hz['F_vs_a_mean_pct']:+.2f} % | 1 % | {ok['hertz']} |",
        f"| same: h₁/h₂ against E'₂/E'₁ = {hz['h1_over_h2_target']:.4f} at a/R₁ ≤ 0.02 | max "
        f"{hz['h1_over_h2_dev_pct_small_h']:.2f} % (whole run {hz['h1_over_h2_dev_pct_all']:.2f} %) "
        f"| 2 % | {ok['hertz']} |",
        *_hertz_density1_rows(fig),
        f"| EPP body 1 vs elastic body 2 with E₂/E₁ = 1000 against the rigid-sphere scene, "
        f"h/R {st['window_h_over_R'][0]:g}–{st['window_h_over_R'][1]:g} | F max "
        f"{st['F_max_pct']:.2f} % (rms {st['F_rms_pct']:.2f} %) on F smoothed over 7 increments "
        f"(raw {st['F_raw_max_pct']:.2f} %, while the rigid scene's own node-closure ripple is "
        f"±{st['F_ripple_rigid_max_pct']:.1f} %), a max {st['a_max_pct']:.2f} %; h₂/h at the end "
        f"{st['h2_over_h_end']:.1e} | 1 % | {ok['stiff']} |", "",
        "Wall times (one core each, the other core busy): equal pair two bodies "
        f"{e['wall_two_body_s']:.0f} s ({e['dofs_two_body']} dofs) vs one on a flat "
        f"{e['wall_flat_s']:.0f} s ({e['dofs_flat']} dofs); stiff partner two bodies "
        f"{st['wall_two_body_s']:.0f} s vs rigid sphere {st['wall_rigid_s']:.0f} s.", "",
        f"![pair checks]({png})", ""]
    if fig.get("database_pairs"):
        lines += _pairs_rows(fig["database_pairs"])
    (outdir / "pair.md").write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="studies/fem_verification_pair.py",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="reports/fem", help="output directory")
    p.add_argument("--quick", action="store_true", help="coarse meshes and short runs (~1 min)")
    p.add_argument("--reuse", action="store_true", help="reuse DIR/pair_<case>.json runs")
    p.add_argument("--workers", type=int, default=2, help="parallel runs (default 2)")
    p.add_argument("--db", default="data/reference_v2.h5",
                   help="reference database whose two-body runs are tabulated ('' to skip)")
    args = p.parse_args(argv)
    outdir = Path(args.out)
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    cases = _cases(args.quick)
    runs = saved_runs(outdir, cases, "pair_") if args.reuse else {}
    reused = len(runs)
    todo = [n for n in cases if n not in runs]
    first = [n for n in todo if "schedule_of" not in cases[n]]  # then the runs that follow them
    for batch in (first, [n for n in todo if n not in first]):
        with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
            futures = {pool.submit(_run, n, cases[n], outdir): n for n in batch}
            for fut in as_completed(futures):
                runs[futures[fut]] = fut.result()
                print(f"{futures[fut]}: {runs[futures[fut]]['status']}, "
                      f"{runs[futures[fut]]['wall_s']:.0f} s", flush=True)
    fig = evaluate(runs, args.quick)
    if args.db:
        fig["database_pairs"] = database_pairs(args.db)
        fig["pass"]["plastic_pairs"] = _pairs_pass(fig["database_pairs"])
    (outdir / "pair_verification.json").write_text(json.dumps(fig, indent=2))
    _report(fig, _plot(runs, outdir), outdir, time.perf_counter() - t0, reused)
    print(json.dumps(fig["pass"]))
    return 0 if all(fig["pass"].values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
