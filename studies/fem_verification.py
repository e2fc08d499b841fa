"""Verification of the FE solver against independent references (docs/design.md §5, issue 3).

``python studies/fem_verification.py [--quick] [--out DIR]`` runs every case,
writes ``DIR/fem_verification.json`` (the figures), ``DIR/index.md`` and PNG charts.
Cases:

* ``hertz``: elastic hemisphere on a rigid flat. F against a within 1 % of
  F = 4E'a³/(3R) for a/R ∈ [0.02, 0.06] (Hertz 1882; a in the reference
  configuration, as in linear theory); the deformed radius differs by Hertz's
  radial surface displacement u_r(a)/a = −2(1−2ν)/(3π(1−ν)) a/R (Johnson 1985,
  eq. 3.41); F(h) above Hertz by the finite-sphere term (docs/design.md §2).
* ``jackson_green``: elastic–perfectly plastic E/σY = 200 and 1000 up to
  h = 100 ω_c against the Jackson & Green (2005) FE fit.
* ``mesh``: default against 2× refined mesh, F within 0.5 %, a within 1 % at
  h/R = 0.05 and 0.3; Newton's order of convergence from the residual histories.
* ``increments``: the same run with half the strain increment per step.
* ``locking``: fully plastic, small a/R (E/σY = 10⁴): mean pressure of the
  quadratic reduced-integration element against the bilinear fully integrated one, at the
  last increment and averaged over h/R 0.0006–0.0012 (a/R 0.04–0.057, where single
  increments step by ±1–2 % as surface nodes close); on the default mesh and on the
  surface-band mesh the campaigns run on (``CAMPAIGN_BAND``), each against its 2× refinement
  (the standard run on that mesh against its refinement: ``fem/band_convergence.py``).
* ``large``: EPP E/σY = 50 and 500 and a Ludwik K/σY = 2, n = 0.3 case to h/R = 0.5.
* ``energy`` and ``speed``: from the standard run (EPP E/σY = 200, ν = 0.3, h/R = 0.3).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.solver import IndentationSolver, SolverOptions
from spherecontact.metrics import local_fit_at
from spherecontact.model.material import Material

NU = 0.3
#: issue "FE reference v2": the standard run's wall time alone and its Newton iterations per increment
STANDARD_WALL_LIMIT_S = 25.0
MAX_ITERATIONS_PER_INCREMENT = 5.0


def _run(kind: str, E_over_sy: float, h_max: float, density: float = 1.0, element: str = "q8r",
         K: float = 0.0, n: float = 1.0, options: dict | None = None, name: str = "run",
         log_dir: str | None = None, edge_band: float = 0.0, schedule=None) -> dict:
    """One FE run (σ_Y = 1, R = 1; ``edge_band`` > 0: the surface-band mesh the campaigns run
    on; ``schedule``: the approaches to step to instead of the adaptive increments); returns
    curves, residual histories and timings."""
    mat = Material.elastic(E_over_sy, NU) if kind == "elastic" else Material(
        E=E_over_sy, nu=NU, sigma_y=1.0, K=K, n=n)
    solver = IndentationSolver(mat, 1.0, RigidObstacle(), density=density, element=element,
                               edge_band=edge_band, options=SolverOptions(**(options or {})))
    log = open(Path(log_dir) / f"progress_{name}.log", "w") if log_dir else None

    def progress(h):
        if log:
            print(f"{time.perf_counter() - t0:8.1f} s  h/R = {h:.5f}", file=log, flush=True)

    t0 = time.perf_counter()
    res = solver.run(h_max, progress=progress, schedule=schedule)
    if log:
        log.close()
    out = {"curves": {k: v.tolist() for k, v in res.curves.items()}, "status": res.status,
           "reason": res.reason, "timings": {k: float(v) for k, v in res.timings.items()},
           "residuals": [list(map(float, r)) for r in res.residuals],
           "n_dofs": int(solver.disc.n_dofs), "rejected": len(solver.rejected)}
    if log_dir:  # each run saves itself: nothing finished is lost if the caller fails
        save_run(log_dir, f"run_{name}.json", out)
    return out


def save_run(outdir, filename: str, run: dict) -> None:
    """Write one run's JSON atomically to ``outdir/filename`` (never half-written)."""
    tmp = Path(outdir) / f".{filename}.tmp"
    tmp.write_text(json.dumps(run))
    os.replace(tmp, Path(outdir) / filename)


def saved_runs(outdir, names, prefix: str) -> dict:
    """Runs ``outdir/<prefix><name>.json`` already on disk (``--reuse``), by name."""
    paths = {n: Path(outdir) / f"{prefix}{n}.json" for n in names}
    return {n: json.loads(p.read_text()) for n, p in paths.items() if p.exists()}


#: the refined standard run stepped to the standard run's own approaches (mesh check without the
#: increments' share: the contact radius is a fit over neighbouring increments and moves with them)
SAME_STEPS = "standard_fine_same_steps"
#: the same pair of runs with the contact radius's edge exponent fitted (``edge_fit`` "fitted")
EDGE_FITTED = "standard_edge_fitted"
SAME_STEPS_FITTED = "standard_fine_same_steps_edge_fitted"
#: runs made after the pool, each stepped to the approaches of another: name → (case, its
#: options, the run whose approaches it takes)
AFTER_POOL = {SAME_STEPS: ("standard_fine", {}, "standard"),
              SAME_STEPS_FITTED: ("standard_fine", {"edge_fit": "fitted"}, EDGE_FITTED)}


def loading_approaches(run: dict) -> np.ndarray:
    """The approaches > 0 a monotone run converged at: another run's ``schedule``."""
    h = np.asarray(run["curves"]["h"], dtype=float)
    return h[h > 0]


def _at(run: dict, key: str, h: float) -> float:
    c = run["curves"]
    return float(np.interp(h, c["h"], c[key]))


def _jg_omega_c(E_over_sy: float) -> float:
    from spherecontact.peers import jackson_green_critical

    return jackson_green_critical(1.0, E_over_sy / (1 - NU**2), 1.0, NU)[0]


#: the surface band of the campaigns' meshes (``edge_band`` of data/campaign_v2.toml)
CAMPAIGN_BAND = 0.03
#: the window of h/R over which the locking runs' mean pressure is averaged
LOCK_WINDOW = (0.0006, 0.0012)


def plan(quick: bool) -> dict:
    """The FE runs of every case: name → keyword arguments of ``_run``."""
    d2 = 1.5 if quick else 2.0
    h_std = 0.1 if quick else 0.3
    runs = {
        "hertz": dict(kind="elastic", E_over_sy=200.0, h_max=0.01,
                      options=dict(dh_first=1e-4, dh_max=1e-4)),
        "jg200": dict(kind="epp", E_over_sy=200.0, h_max=100 * _jg_omega_c(200.0),
                      options=dict(dh_first=2e-5, dh_max=2e-4)),
        "jg1000": dict(kind="epp", E_over_sy=1000.0, h_max=100 * _jg_omega_c(1000.0),
                       options=dict(dh_first=1e-6, dh_max=2e-5)),
        "standard": dict(kind="epp", E_over_sy=200.0, h_max=h_std),
        "standard_fine": dict(kind="epp", E_over_sy=200.0, h_max=h_std, density=d2),
        EDGE_FITTED: dict(kind="epp", E_over_sy=200.0, h_max=h_std, options=dict(edge_fit="fitted")),
        "standard_dt2": dict(kind="epp", E_over_sy=200.0, h_max=h_std,
                             options=dict(strain_increment=0.0025)),
        "lock_q8r": dict(kind="epp", E_over_sy=1e4, h_max=0.0012,
                         options=dict(dh_first=2e-5, dh_max=1e-4)),
        "lock_q8r_fine": dict(kind="epp", E_over_sy=1e4, h_max=0.0012, density=d2,
                              options=dict(dh_first=2e-5, dh_max=1e-4)),
        "lock_q4": dict(kind="epp", E_over_sy=1e4, h_max=0.0012, element="q4",
                        options=dict(dh_first=2e-5, dh_max=1e-4)),
        "lock_q4_fine": dict(kind="epp", E_over_sy=1e4, h_max=0.0012, element="q4", density=d2,
                             options=dict(dh_first=2e-5, dh_max=1e-4)),
        "lock_band": dict(kind="epp", E_over_sy=1e4, h_max=0.0012, edge_band=CAMPAIGN_BAND,
                          options=dict(dh_first=2e-5, dh_max=1e-4)),
        "lock_band_fine": dict(kind="epp", E_over_sy=1e4, h_max=0.0012, edge_band=CAMPAIGN_BAND,
                               density=d2, options=dict(dh_first=2e-5, dh_max=1e-4)),
    }
    if not quick:
        limit = dict(max_wall_s=1200.0)
        runs.update({
            "large_epp50": dict(kind="epp", E_over_sy=50.0, h_max=0.5, options=limit),
            "large_epp500": dict(kind="epp", E_over_sy=500.0, h_max=0.5, options=limit),
            "large_ludwik": dict(kind="ludwik", E_over_sy=200.0, h_max=0.5, K=2.0, n=0.3, options=limit),
        })
    return runs


def _convergence_order(residuals: list[list[float]]) -> float:
    """Median over the increments of Newton's order from its last three residuals,
    log(r_k+1/r_k) / log(r_k/r_k−1) (2 = quadratic; the constant C of r_k+1 = C r_k² cancels.
    The reading used before, log r_k+1 / log r_k = 2 + log C / log r_k, falls further below 2
    the earlier the tolerance stops Newton; it gave 1.83 on the standard run at tol 1e-8)."""
    orders = []
    for r in residuals:
        r = [x for x in r if x > 0]
        if len(r) >= 3 and r[-1] < r[-2] < r[-3] < 0.5:
            orders.append(math.log(r[-1] / r[-2]) / math.log(r[-2] / r[-3]))
    return float(np.median(orders)) if orders else float("nan")


def evaluate(runs: dict, quick: bool) -> dict:
    """Figures and pass/fail of every check from the finished runs."""
    from spherecontact.peers import jackson_green

    out: dict = {}
    # ---- Hertz
    r = runs["hertz"]
    c = {k: np.asarray(v) for k, v in r["curves"].items()}
    Ep = 200.0 / (1 - NU**2)
    a_F = (3 * c["F"] / (4 * Ep)) ** (1 / 3)
    sel = (a_F >= 0.02) & (a_F <= 0.06)
    err_ref = (c["F"][sel] / (4 * Ep * c["a_ref"][sel] ** 3 / 3) - 1)
    err_cur = (c["F"][sel] / (4 * Ep * c["a"][sel] ** 3 / 3) - 1)
    ur_fe = c["a"][sel] / c["a_ref"][sel] - 1
    ur_hertz = -2 * (1 - 2 * NU) / (3 * math.pi * (1 - NU)) * c["a_ref"][sel]
    FH = 4 / 3 * Ep * c["h"] ** 1.5
    out["hertz"] = {
        "F_vs_a_max_rel_err": float(np.abs(err_ref).max()),
        "F_vs_a_mean_rel_err": float(err_ref.mean()),
        "F_vs_a_deformed_mean_rel_err": float(err_cur.mean()),
        "radial_displacement_fe_vs_hertz_max_abs_diff": float(np.abs(ur_fe - ur_hertz).max()),
        "F_over_Hertz_at_h": {f"{h:g}": float(np.interp(h, c["h"], c["F"] / FH))
                              for h in (0.002, 0.005, 0.01)},
        "n_points": int(sel.sum()),
        "pass": bool(np.abs(err_ref).max() <= 0.01),
    }
    # ---- Jackson & Green
    out["jackson_green"] = {}
    for key, Es in (("jg200", 200.0), ("jg1000", 1000.0)):
        c = {k: np.asarray(v) for k, v in runs[key]["curves"].items()}
        wc = _jg_omega_c(Es)
        jg = jackson_green(c["h"], 1.0, Es / (1 - NU**2), 1.0, NU)
        ws = c["h"] / wc
        m = ws >= 1.0
        dev_F = c["F"][m] / jg.F[m] - 1
        dev_a = c["a"][m] / jg.a[m] - 1
        out["jackson_green"][f"E/sy={Es:g}"] = {
            "omega_c": wc,
            "F_dev_at_omega_star": {f"{w:g}": float(np.interp(w, ws, c["F"] / np.maximum(jg.F, 1e-300)) - 1)
                                    for w in (1, 2, 5, 10, 20, 50, 100)},
            "F_dev_max_abs": float(np.abs(dev_F).max()), "F_dev_rms": float(np.sqrt(np.mean(dev_F**2))),
            "a_dev_max_abs": float(np.abs(dev_a).max()), "a_dev_rms": float(np.sqrt(np.mean(dev_a**2))),
            "reached_h_max": runs[key]["status"] == "converged",
        }
    # ---- mesh and increment convergence, Newton rate
    std, fine, dt2 = runs["standard"], runs["standard_fine"], runs["standard_dt2"]
    hs = (0.05, 0.1) if quick else (0.05, 0.3)
    out["mesh"] = {"n_dofs_default": std["n_dofs"], "n_dofs_fine": fine["n_dofs"]}
    ok = True
    for h in hs:
        dF = _at(fine, "F", h) / _at(std, "F", h) - 1
        da = _at(fine, "a", h) / _at(std, "a", h) - 1
        out["mesh"][f"h/R={h:g}"] = {"F_rel_diff": dF, "a_rel_diff": da}
        ok &= abs(dF) <= 0.005 and abs(da) <= 0.01
    out["mesh"]["pass"] = bool(ok)
    # the same read on the local quadratic over 11 increments: the node-closing steps
    # (FE scatter ~2.6 % on the default mesh) averaged out of the comparison
    fit, h_fit = {}, ((0.05, 0.1) if quick else (0.05, 0.1, 0.3))
    for h in h_fit:
        fit[f"h/R={h:g}"] = {q + "_rel_diff": local_fit_at(fine["curves"]["h"], fine["curves"][q], h)
                             / local_fit_at(std["curves"]["h"], std["curves"][q], h) - 1 for q in ("F", "a")}
    fit["pass"] = all(abs(v) <= 0.005 for d in fit.values() for v in d.values())
    out["mesh_fit"] = fit
    for key, fine_key, base in (("mesh_same_steps", SAME_STEPS, std),
                                ("mesh_same_steps_edge_fitted", SAME_STEPS_FITTED, runs.get(EDGE_FITTED))):
        same = runs.get(fine_key)
        if same is None or base is None:
            continue
        # the 2× mesh on the default run's increments: the mesh's share alone
        out[key] = {
            f"h/R={h:g}": {q + "_rel_diff": _at(same, q, h) / _at(base, q, h) - 1 for q in ("F", "a")}
            | {q + "_fit_rel_diff": local_fit_at(same["curves"]["h"], same["curves"][q], h)
               / local_fit_at(base["curves"]["h"], base["curves"][q], h) - 1 for q in ("F", "a")}
            for h in h_fit}
    if EDGE_FITTED in runs:  # the fitted edge against the Hertz exponent's on the same states
        fitted = runs[EDGE_FITTED]
        out["edge_fitted_vs_hertz"] = {f"h/R={h:g}": local_fit_at(fitted["curves"]["h"], fitted["curves"]["a"], h)
                                       / local_fit_at(std["curves"]["h"], std["curves"]["a"], h) - 1
                                       for h in h_fit}
    out["increments"] = {f"h/R={h:g}": {"F_rel_diff": _at(dt2, "F", h) / _at(std, "F", h) - 1,
                                         "a_rel_diff": _at(dt2, "a", h) / _at(std, "a", h) - 1}
                         for h in hs}
    out["newton"] = {"convergence_order_median": _convergence_order(std["residuals"]),
                     "iterations_per_increment": std["timings"]["newton_iterations"]
                     / std["timings"]["increments"],
                     "rejected_increments": std["rejected"]}
    # ---- locking
    lock = {}
    for key in ("lock_q8r", "lock_q8r_fine", "lock_q4", "lock_q4_fine", "lock_band", "lock_band_fine"):
        c = {k: np.asarray(v) for k, v in runs[key]["curves"].items()}
        a = float(c["a"][-1])
        lock[key] = {"p_m_over_sy": float(c["p_m"][-1]), "a_over_R": a,
                     "p_m_window_mean": _window_mean(c["h"], c["p_m"], *LOCK_WINDOW),
                     "Lambda": 1e4 / (1 - NU**2) * a, "n_dofs": runs[key]["n_dofs"]}
    change = lambda fine, coarse, q: lock[fine][q] / lock[coarse][q] - 1  # noqa: E731
    lock["q8r_mesh_change"] = change("lock_q8r_fine", "lock_q8r", "p_m_over_sy")
    lock["q8r_mesh_change_window"] = change("lock_q8r_fine", "lock_q8r", "p_m_window_mean")
    lock["q4_over_q8r"] = change("lock_q4", "lock_q8r_fine", "p_m_over_sy")
    lock["band_mesh_change"] = change("lock_band_fine", "lock_band", "p_m_over_sy")
    lock["band_mesh_change_window"] = change("lock_band_fine", "lock_band", "p_m_window_mean")
    lock["window_h_over_R"] = list(LOCK_WINDOW)
    lock["pass"] = bool(abs(lock["q8r_mesh_change"]) <= 0.01)  # the default mesh
    lock["pass_band"] = bool(abs(lock["band_mesh_change_window"]) <= 0.01)  # the campaigns' mesh
    out["locking"] = lock
    # ---- large deformation
    if not quick:
        out["large"] = {k: {"status": runs[k]["status"], "reason": runs[k]["reason"],
                            "h_reached": runs[k]["curves"]["h"][-1], "F_end": runs[k]["curves"]["F"][-1],
                            "a_end": runs[k]["curves"]["a"][-1],
                            "eps_p_max_end": runs[k]["curves"]["eps_p_max"][-1],
                            "wall_s": runs[k]["timings"]["wall_s"]}
                        for k in ("large_epp50", "large_epp500", "large_ludwik")}
    # ---- energy and speed of the standard run
    c = {k: np.asarray(v) for k, v in std["curves"].items()}
    bal = (c["energy_elastic"] + c["dissipation"]) / c["work_external"] - 1
    m = c["h"] >= 0.01
    out["energy"] = {"balance_rel_err_max_h_ge_0.01": float(np.abs(bal[m]).max()),
                     "balance_rel_err_end": float(bal[-1]),
                     "balance_rel_err_max_all": float(np.abs(bal).max()),
                     "pass": bool(np.abs(bal[m]).max() <= 0.01)}
    t = std["timings"]
    out["speed"] = {k: t[k] for k in ("wall_s", "setup_s", "constitutive_s", "assembly_s", "solve_s",
                                      "contact_s", "increments", "newton_iterations")}
    out["speed"]["n_dofs"] = std["n_dofs"]
    out["speed"]["h_max"] = hs[-1]
    return out


def _window_mean(h, y, lo: float, hi: float) -> float:
    """Mean of y over lo ≤ h ≤ hi (trapezoidal in h) of one run's increments."""
    h, y = np.asarray(h, dtype=float), np.asarray(y, dtype=float)
    m = (h >= lo) & (h <= hi)
    if np.count_nonzero(m) < 2:
        return float("nan")
    return float(np.trapezoid(y[m], h[m]) / (h[m][-1] - h[m][0]))


def _plots(runs: dict, figures: dict, outdir: Path) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from spherecontact.peers import jackson_green

    names = []
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    c = {k: np.asarray(v) for k, v in runs["hertz"]["curves"].items()}
    Ep = 200.0 / (1 - NU**2)
    ax[0].plot(c["h"], c["F"] / (4 / 3 * Ep * c["h"] ** 1.5), "o-", ms=3, label="FE / Hertz F(h)")
    ax[0].plot(c["a_ref"] ** 2, c["F"] / (4 * Ep * c["a_ref"] ** 3 / 3), ".", label="FE / Hertz F(a), a reference")
    ax[0].plot(c["a"] ** 2, c["F"] / (4 * Ep * c["a"] ** 3 / 3), ".", label="FE / Hertz F(a), a deformed")
    ax[0].axhline(1, color="k", lw=0.5)
    ax[0].set_xlabel("h/R  (or a²/R² for F(a))")
    ax[0].set_ylabel("ratio")
    ax[0].legend(fontsize=8)
    ax[0].set_title("Elastic hemisphere on a rigid flat")
    for key, Es in (("jg200", 200.0), ("jg1000", 1000.0)):
        c = {k: np.asarray(v) for k, v in runs[key]["curves"].items()}
        wc = _jg_omega_c(Es)
        jg = jackson_green(c["h"], 1.0, Es / (1 - NU**2), 1.0, NU)
        ax[1].loglog(c["h"] / wc, c["F"] / jg.F[0] * jg.F[0], "-", label=f"FE E/σY={Es:g}")
        ax[1].loglog(c["h"] / wc, jg.F, "--", label=f"Jackson–Green E/σY={Es:g}")
    ax[1].set_xlabel("ω/ω_c")
    ax[1].set_ylabel("F / (σ_Y R²)")
    ax[1].legend(fontsize=8)
    ax[1].set_title("Elastic–perfectly plastic, rigid flat")
    fig.tight_layout()
    fig.savefig(outdir / "hertz_jackson_green.png", dpi=110)
    names.append("hertz_jackson_green.png")
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for key, lab in (("standard", "default mesh"), ("standard_fine", "refined mesh"),
                     ("standard_dt2", "half strain increment")):
        c = runs[key]["curves"]
        ax[0].plot(c["h"], c["F"], label=lab)
        ax[1].plot(c["h"], c["a"], label=lab)
    for key in [k for k in runs if k.startswith("large_")]:
        c = runs[key]["curves"]
        ax[0].plot(c["h"], c["F"], "--", label=key)
        ax[1].plot(c["h"], c["a"], "--", label=key)
    ax[0].set_xlabel("h/R")
    ax[0].set_ylabel("F/(σ_Y R²)")
    ax[1].set_xlabel("h/R")
    ax[1].set_ylabel("a/R")
    ax[0].legend(fontsize=8)
    fig.suptitle("EPP E/σY = 200: convergence; large-deformation runs")
    fig.tight_layout()
    fig.savefig(outdir / "convergence_large.png", dpi=110)
    names.append("convergence_large.png")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(5, 4))
    for r in runs["standard"]["residuals"][::3]:
        ax.semilogy(range(len(r)), r, "-", color="C0", alpha=0.4)
    ax.set_xlabel("Newton iteration")
    ax.set_ylabel("relative residual")
    ax.set_title("Newton histories, standard run (every 3rd increment)")
    fig.tight_layout()
    fig.savefig(outdir / "newton.png", dpi=110)
    names.append("newton.png")
    plt.close(fig)
    return names


def _report(figures: dict, pngs: list[str], outdir: Path, wall: float, quick: bool) -> None:
    h = figures["hertz"]
    lines = [f"# FE solver verification{' (quick)' if quick else ''}", "",
             f"Made by `python studies/fem_verification.py{' --quick' if quick else ''}` "
             f"in {wall:.0f} s; its {figures.get('_runs', 0)} runs took {figures.get('_runs_wall_s', 0):.0f} s "
             f"of wall time in all ({figures.get('_reused', 0)} reused from earlier with --reuse); "
             "figures in `fem_verification.json`.", "",
             "| check | target | measured | pass |", "|---|---|---|---|",
             f"| Hertz F vs a (a/R 0.02–0.06, reference a) | ≤ 1 % | max {100 * h['F_vs_a_max_rel_err']:.2f} %, "
             f"mean {100 * h['F_vs_a_mean_rel_err']:+.2f} % | {h['pass']} |",
             "| Hertz F(h): finite sphere | a few % above Hertz | "
             + ", ".join(f"h/R={k}: {100 * (v - 1):+.1f} %" for k, v in h["F_over_Hertz_at_h"].items())
             + " | — |"]
    for key, v in figures["jackson_green"].items():
        lines.append(f"| Jackson–Green {key}, ω* ≥ 1 to 100 | few % scatter of the fit | F max {100 * v['F_dev_max_abs']:.1f} %, "
                     f"rms {100 * v['F_dev_rms']:.1f} %; a max {100 * v['a_dev_max_abs']:.1f} % | — |")
    for key, v in figures["mesh"].items():
        if key.startswith("h/R"):
            lines.append(f"| mesh 2× at {key} | F ≤ 0.5 %, a ≤ 1 % | F {100 * v['F_rel_diff']:+.2f} %, "
                         f"a {100 * v['a_rel_diff']:+.2f} % | "
                         f"{abs(v['F_rel_diff']) <= 0.005 and abs(v['a_rel_diff']) <= 0.01} |")
    for key, v in figures.get("mesh_fit", {}).items():
        if key.startswith("h/R"):
            lines.append(f"| mesh 2× at {key}, on the local quadratic over 11 increments | F, a ≤ 0.5 % | "
                         f"F {100 * v['F_rel_diff']:+.2f} %, a {100 * v['a_rel_diff']:+.2f} % | "
                         f"{abs(v['F_rel_diff']) <= 0.005 and abs(v['a_rel_diff']) <= 0.005} |")
    for fig, what in (("mesh_same_steps", ""),
                      ("mesh_same_steps_edge_fitted", ", contact radius with the edge exponent fitted")):
        for key, v in figures.get(fig, {}).items():
            lines.append(f"| mesh 2× on the default run's increments at {key}{what}: pointwise; on the "
                         f"local quadratic | — | F {100 * v['F_rel_diff']:+.2f} %, a {100 * v['a_rel_diff']:+.2f} %; "
                         f"F {100 * v['F_fit_rel_diff']:+.2f} %, a {100 * v['a_fit_rel_diff']:+.2f} % | — |")
    if "edge_fitted_vs_hertz" in figures:
        lines.append("| contact radius with the edge exponent fitted against the Hertz exponent's, standard "
                     "run, local quadratic | — | " + ", ".join(
                         f"{k} {100 * v:+.2f} %" for k, v in figures["edge_fitted_vs_hertz"].items()) + " | — |")
    for key, v in figures["increments"].items():
        lines.append(f"| half strain increment at {key} | — | F {100 * v['F_rel_diff']:+.2f} %, "
                     f"a {100 * v['a_rel_diff']:+.2f} % | — |")
    n = figures["newton"]
    lines.append(f"| Newton order (log(r_k+1/r_k) / log(r_k/r_k−1)); iterations per increment | 2; "
                 f"≤ {MAX_ITERATIONS_PER_INCREMENT:g} | median {n['convergence_order_median']:.2f}, {n['iterations_per_increment']:.2f} it/increment | "
                 f"{n['iterations_per_increment'] <= MAX_ITERATIONS_PER_INCREMENT} |")
    lk = figures["locking"]
    lo, hi = lk["window_h_over_R"]
    lines.append(f"| locking, EPP E/σY=10⁴, Λ ≈ {lk['lock_q8r']['Lambda']:.0f}, default mesh | p_m mesh-converged (≤ 1 %) | "
                 f"Q8R p_m/σY {lk['lock_q8r']['p_m_over_sy']:.3f} → {lk['lock_q8r_fine']['p_m_over_sy']:.3f} "
                 f"({100 * lk['q8r_mesh_change']:+.2f} %; mean over h/R {lo:g}–{hi:g} "
                 f"{100 * lk['q8r_mesh_change_window']:+.2f} %); Q4 full integration {lk['lock_q4']['p_m_over_sy']:.3f} → "
                 f"{lk['lock_q4_fine']['p_m_over_sy']:.3f} ({100 * lk['q4_over_q8r']:+.1f} % vs Q8R) | {lk['pass']} |")
    b, bf = lk["lock_band"], lk["lock_band_fine"]
    lines.append(f"| locking, the same on the campaigns' surface-band mesh ({CAMPAIGN_BAND:g}) | p_m mean over "
                 f"h/R {lo:g}–{hi:g} mesh-converged (≤ 1 %) | {b['p_m_window_mean']:.3f} → "
                 f"{bf['p_m_window_mean']:.3f} ({100 * lk['band_mesh_change_window']:+.2f} %; last increment "
                 f"{b['p_m_over_sy']:.3f} → {bf['p_m_over_sy']:.3f}, {100 * lk['band_mesh_change']:+.2f} %; "
                 f"{b['n_dofs']} → {bf['n_dofs']} dofs) | {lk['pass_band']} |")
    e = figures["energy"]
    lines.append(f"| energy W = E_el + D (h/R ≥ 0.01) | ≤ 1 % | max {100 * e['balance_rel_err_max_h_ge_0.01']:.2f} %, "
                 f"end {100 * e['balance_rel_err_end']:+.2f} % | {e['pass']} |")
    s = figures["speed"]
    lines.append(f"| standard run EPP 200 to h/R={s['h_max']:g} (the other core busy here; alone: `make bench`) "
                 f"| ≤ {STANDARD_WALL_LIMIT_S:g} s | {s['wall_s']:.1f} s "
                 f"({s['increments']} increments, {s['newton_iterations']} iterations; constitutive "
                 f"{s['constitutive_s']:.1f} s, assembly {s['assembly_s']:.1f} s, solve {s['solve_s']:.1f} s) | "
                 f"{s['wall_s'] <= STANDARD_WALL_LIMIT_S} |")
    for key, v in figures.get("large", {}).items():
        lines.append(f"| {key} to h/R = 0.5 | reach or say why | {v['status']}: h/R = {v['h_reached']:.3f}, "
                     f"{v['wall_s']:.0f} s; {v['reason']} | {v['status'] == 'converged'} |")
    lines += ["", *[f"![{p}]({p})" for p in pngs], ""]
    (outdir / "index.md").write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="coarser, shorter runs (CI)")
    parser.add_argument("--out", default="reports/fem", help="output directory")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--reuse", action="store_true", help="reuse finished runs (OUT/run_*.json)")
    args = parser.parse_args(argv)
    outdir = Path(args.out)
    outdir.mkdir(parents=True, exist_ok=True)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    t0 = time.perf_counter()
    cases = plan(args.quick)
    order = sorted(cases, key=lambda k: cases[k]["h_max"] * cases[k].get("density", 1.0) ** 2)
    from tqdm import tqdm

    runs = saved_runs(outdir, order, "run_") if args.reuse else {}
    todo = [k for k in order if k not in runs]
    failed: dict[str, str] = {}
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        futures = {pool.submit(_run, **cases[k], name=k, log_dir=str(outdir)): k for k in todo}
        for fut in tqdm(as_completed(futures), total=len(futures), desc="FE verification runs", unit="run"):
            try:
                runs[futures[fut]] = fut.result()
            except Exception as err:  # keep the other runs; the report names the failure
                failed[futures[fut]] = f"{type(err).__name__}: {err}"
    if failed:
        raise SystemExit(f"verification runs failed: {failed}")
    runs |= saved_runs(outdir, list(AFTER_POOL), "run_") if args.reuse else {}
    made = len(todo) + sum(name not in runs for name in AFTER_POOL)
    for name, (case, options, steps_of) in AFTER_POOL.items():
        if name in runs:
            continue
        # after the pool: it steps to another run's approaches
        print(f"FE verification: {name} (the 2x mesh on {steps_of}'s increments)", flush=True)
        kw = cases[case] | {"options": (cases[case].get("options") or {}) | options}
        runs[name] = _run(**kw, name=name, log_dir=str(outdir), schedule=loading_approaches(runs[steps_of]))
    figures = evaluate(runs, args.quick)
    pngs = _plots(runs, figures, outdir)
    wall = time.perf_counter() - t0
    figures["_wall_s"] = wall
    figures["_runs"] = len(runs)
    figures["_runs_wall_s"] = float(sum(r["timings"]["wall_s"] for r in runs.values()))
    figures["_reused"] = len(runs) - made
    (outdir / "fem_verification.json").write_text(json.dumps(figures, indent=2) + "\n")
    _report(figures, pngs, outdir, wall, args.quick)
    print((outdir / "index.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
