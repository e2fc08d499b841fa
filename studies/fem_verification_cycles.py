"""Verification of unloading and reloading cycles (one sphere on a rigid flat, ν = 0.3).

Runs (``--out`` gets ``cycles.md``, ``cycles_verification.json``, ``cycles.png``):

* elastic sphere, cycles at h/R = 0.001, 0.01, 0.1, 0.3: unloading must retrace loading
  (F within 0.1 %, also against a monotone run stepped to the unloading approaches, which
  needs no interpolation) and end at h_res = 0; its loading slope dF/dh is the elastic reference
  for the unloading stiffness of the plastic spheres;
* EPP E/σY = 200 and 1000, the same cycles: initial unloading stiffness S = dF/dh at h_max
  against Sneddon's 2E*a (any axisymmetric punch on a half-space; Sneddon 1965, Int. J.
  Eng. Sci. 3:47), E* = E/(1 − ν²) against a rigid flat, a the loaded contact radius;
  reloading elastic up to h_max (no dissipation), then back on the monotone curve;
  energy per cycle: work in − work returned = dissipation + change of stored energy;
* EPP E/σY = 200 monotone (cost of a cycle; the curve the reloads must rejoin);
* EPP E/σY = 200 to h/R = 0.1 on a 2× mesh and with half increments (loading strain
  increment and unloading increments): h_res and the unloading curves within 1 %; the same
  on the campaign's surface-band mesh (band 0.03) and its 2× mesh;
* two deformable bodies (exact contact): an elastic pair E₂ = 3E₁ (no dent, the split
  h₁/h = E₂'/(E₁' + E₂') along the unloading) and a plastic pair of yield ratio 3 (each
  body's share of the residual approach);
* Thornton (1997, J. Appl. Mech. 64:383): Hertzian unloading with the residual radius
  R_p = 4E*a_max³/(3F_max), h_res = h_max − (3F_max/(4E*√R_p))^{2/3},
  F = (4/3)E*√R_p (h − h_res)^{3/2}: a sanity check beside the FE, not a reference.

``python studies/fem_verification_cycles.py --out reports/fem`` (~10 min on 2 cores).
"""

from __future__ import annotations

import argparse
import json
import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from spherecontact.fem.io import run_indentation
from spherecontact.fem.solver import LOAD, RELOAD, UNLOAD, IndentationSolver, SolverOptions
from spherecontact.metrics import interp_loglog, scatter
from spherecontact.model.material import Material

NU = 0.3
CYCLES_AT = (0.001, 0.01, 0.1, 0.3)
#: the smooth configuration: segment-integrated penalty contact scaled with the approach
SMOOTH = {"penalty": 300.0, "segment_points": 8, "penalty_scale": "approach"}
#: name → (E/σY (inf: elastic), h_max, unload_at, mesh density, strain increment, unload increments,
#: edge band (0: the default mesh; 0.03: campaign v2's surface band)[, contact options])
RUNS = {
    "elastic": (math.inf, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.0),
    "elastic_band": (math.inf, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.03),
    "E200": (200.0, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.0),
    "E1000": (1000.0, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.0),
    "E200_monotone": (200.0, 0.3, None, 1.0, 0.005, 24, 0.0),
    "E200_mesh2": (200.0, 0.1, CYCLES_AT[:3], 2.0, 0.005, 24, 0.0),
    "E200_half_increment": (200.0, 0.1, CYCLES_AT[:3], 1.0, 0.0025, 48, 0.0),
    "E200_band": (200.0, 0.1, CYCLES_AT[:3], 1.0, 0.005, 24, 0.03),
    "E200_band_mesh2": (200.0, 0.1, CYCLES_AT[:3], 2.0, 0.005, 24, 0.03),
    "E1000_band": (1000.0, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.03),
    "elastic_smooth": (math.inf, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.03, SMOOTH),
    "E1000_smooth": (1000.0, 0.3, CYCLES_AT, 1.0, 0.005, 24, 0.03, SMOOTH),
}
#: the elastic runs whose unloading must retrace their loading
RETRACE_RUNS = ("elastic", "elastic_band", "elastic_smooth")
#: (base run, refined run): mesh and increment convergence of the unloading (default mesh: 2× mesh,
#: half increments; the campaign's band mesh: 2× mesh)
CONVERGENCE_PAIRS = (("E200", "E200_mesh2"), ("E200", "E200_half_increment"),
                     ("E200_band", "E200_band_mesh2"))
#: monotone elastic runs stepped exactly to the unloading approaches of another run (name →
#: that run): the loading F at those approaches, to compare without interpolating across the
#: kinks of F(h) where surface nodes close
SCHEDULED_RUNS = {"elastic_at_unloading": "elastic"}
#: the runs whose energy per cycle is checked
ENERGY_RUNS = ("elastic", "E200", "E1000", "E1000_smooth")
#: two deformable bodies (exact contact): name → (body 2 (E/σY₁, σY₂/σY₁; inf: elastic), h_max, unload_at)
PAIR_RUNS = {
    "pair_elastic_E3": ((600.0, math.inf), 0.01, (0.001, 0.01)),
    "pair_yield3": ((200.0, 3.0), 0.03, (0.01, 0.03)),
}
#: the runs of the unloading-stiffness table
STIFFNESS_RUNS = ("elastic", "E200", "E1000", "elastic_band", "E200_band", "E1000_band",
                  "elastic_smooth", "E1000_smooth")
LIMITS = {"elastic_retrace": 0.001, "energy": 0.01, "convergence": 0.01, "sneddon_small": 0.02,
          "cycle_cost": 0.20}


def _solver(name: str) -> IndentationSolver:
    """The solver of run ``name`` of :data:`RUNS` (material, mesh and options)."""
    ratio, _, _, density, strain_inc, n_unload, band, *contact = RUNS[name]
    material = Material(E=200.0, nu=NU, sigma_y=math.inf) if math.isinf(ratio) else \
        Material(E=ratio, nu=NU, sigma_y=1.0)
    return IndentationSolver(material, 1.0, density=density, edge_band=band,
                             options=SolverOptions(strain_increment=strain_inc, unload_increments=n_unload,
                                                   **(contact[0] if contact else {})))


def run_case(name: str) -> dict:
    """One FE run of :data:`RUNS`, as plain arrays."""
    _, h_max, unload, *_ = RUNS[name]
    solver = _solver(name)
    material = solver.material
    res = solver.run(h_max, unload_at=unload)
    keep = ("h", "F", "a", "a_ref", "branch", "dissipation", "work_external", "energy_elastic")
    return {"name": name, "E": material.E, "status": res.status, "wall_s": res.timings["wall_s"],
            "increments": res.timings["increments"], "n_dofs": solver.disc.n_dofs,
            "curves": {k: np.asarray(res.curves[k]).tolist() for k in keep},
            "cycles": {k: np.asarray(v).tolist() for k, v in res.cycles.items()
                       if not k.startswith("profile")}}


def unloading_approaches(run: dict) -> np.ndarray:
    """The distinct approaches > 0 of a run's unloading increments, increasing."""
    c = _arrays(run)
    h = c["h"][(c["branch"] == UNLOAD) & (c["h"] > 0)]
    return np.unique(h)


def run_scheduled_case(name: str, schedule) -> dict:
    """One monotone run of :data:`SCHEDULED_RUNS` (the mesh and options of its source run),
    stepped to the approaches ``schedule``."""
    solver = _solver(SCHEDULED_RUNS[name])
    sched = np.asarray(schedule, dtype=float)
    res = solver.run(float(sched[-1]), schedule=sched)
    return {"name": name, "E": solver.material.E, "status": res.status, "wall_s": res.timings["wall_s"],
            "increments": res.timings["increments"], "n_dofs": solver.disc.n_dofs,
            "curves": {k: np.asarray(res.curves[k]).tolist() for k in ("h", "F", "a", "branch")},
            "cycles": {}}


def retrace_at_same_approach(run: dict, loading: dict) -> list[dict]:
    """Per cycle of an elastic run: the largest |F_unloading/F_loading − 1| over its unloading
    increments with F > 5 % F_max, F_loading from ``loading``, a monotone run stepped to exactly
    those approaches (:data:`SCHEDULED_RUNS`): no interpolation."""
    el, elc = _arrays(run), run["cycles"]
    mono = _arrays(loading)
    out = []
    for i, hm in enumerate(elc["h_max"]):
        _, unl = _branch(el, elc, i)
        unl = unl[(el["F"][unl] > 0.05 * elc["F_max"][i]) & (el["h"][unl] > 0)]
        j = np.searchsorted(mono["h"], el["h"][unl])
        j = np.clip(j, 0, mono["h"].size - 1)
        hit = np.abs(mono["h"][j] - el["h"][unl]) <= 1e-12 * el["h"][unl]
        if not np.any(hit):
            continue
        dev = np.abs(el["F"][unl][hit] / mono["F"][j[hit]] - 1.0)
        out.append({"h_max": hm, "F_max_dev": float(np.max(dev)), "points": int(hit.sum()),
                    "h_res_over_h_max": elc["h_res"][i] / hm})
    return out


def run_pair_case(name: str) -> dict:
    """One two-body run of :data:`PAIR_RUNS` (body 1: EPP E/σY 200, or elastic for the elastic pair)."""
    (E2, sy2), h_max, unload = PAIR_RUNS[name]
    elastic = math.isinf(sy2)
    m1 = Material(E=200.0, nu=NU, sigma_y=math.inf if elastic else 1.0)
    m2 = Material(E=E2, nu=NU, sigma_y=sy2)
    res = run_indentation(m1, 1.0, h_max, radius2=1.0, material2=m2, scene="two_body", unload_at=list(unload))
    keep = ("h", "F", "a", "h1", "h2", "branch", "dissipation_1", "dissipation_2")
    return {"name": name, "E": 200.0, "E2": E2, "status": res.status, "wall_s": res.timings["wall_s"],
            "increments": res.timings["increments"], "n_dofs": res.inputs["n_dofs"],
            "curves": {k: np.asarray(res.curves[k]).tolist() for k in keep},
            "cycles": {k: np.asarray(v).tolist() for k, v in res.cycles.items()
                       if not k.startswith("profile")}}


def analyse_pairs(runs: dict) -> list[dict]:
    """Per cycle of the two-body runs: h_res/h_max, each body's share of the residual approach,
    the elastic split h₁/h on unloading against E₂'/(E₁' + E₂'), energy per cycle."""
    out = []
    for name in PAIR_RUNS:
        if name not in runs:
            continue
        c, cyc = _arrays(runs[name]), runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"]):
            _, unl = _branch(c, cyc, i)
            ie = unl[-1]
            row = {"run": name, "h_max": hm, "h_res_over_h_max": cyc["h_res"][i] / hm,
                   "h1_share_of_h_res": float(c["h1"][ie] / c["h"][ie]) if c["h"][ie] > 0 else math.nan,
                   "energy_error": abs(cyc["work_in"][i] - cyc["work_returned"][i] - cyc["dissipation"][i]
                                       - cyc["elastic_energy_change"][i]) / cyc["work_in"][i]}
            if name == "pair_elastic_E3":
                sel = unl[c["F"][unl] > 0.2 * cyc["F_max"][i]]
                row["split_on_unloading_max_dev"] = float(np.max(np.abs(c["h1"][sel] / c["h"][sel] - 0.75)))
            out.append(row)
    return out


def _arrays(run: dict) -> dict:
    return {k: np.asarray(v) for k, v in run["curves"].items()}


def _branch(c: dict, cyc: dict, i: int):
    """(loading part, unloading part) of cycle i as index arrays."""
    i0, ip, ie = (int(cyc[k][i]) for k in ("increment_start", "increment_peak", "increment_end"))
    return np.arange(i0, ip + 1), np.arange(ip, ie + 1)


def _loglog_interp(x, xp, yp):
    """:func:`spherecontact.metrics.interp_loglog` for points given in any order."""
    order = np.argsort(xp)
    return interp_loglog(x, xp[order], yp[order])


def unloading_stiffness(h: np.ndarray, F: np.ndarray) -> float:
    """dF/dh at the first point of an unloading branch: quadratic through its first 4 points."""
    p = np.polyfit(h[:4] - h[0], F[:4], 2)
    return float(p[1])


def mesh_label(name: str) -> str:
    """The mesh and contact of run ``name`` (:data:`RUNS`) as the report names them."""
    band, contact = RUNS[name][6], RUNS[name][7:]
    if not band:
        return "default mesh"
    return f"edge band {band:g}" + (", penalty scaled with the approach" if contact else "")


def stiffness_small(stiff: list[dict], a_max: float = 0.05) -> dict:
    """Per mesh, the largest |S/(2E*a) − 1| of the unloading branches with a/R ≤ ``a_max``
    (Sneddon's limit of a small contact, limit ``LIMITS["sneddon_small"]``)."""
    out = {}
    for mesh in dict.fromkeys(s["mesh"] for s in stiff):
        small = [s for s in stiff if s["mesh"] == mesh and s["a_over_R"] <= a_max]
        if small:
            dev = max(abs(s["S_over_2Ea"] - 1.0) for s in small)
            own = max(abs(s["S_over_2Ea"] / s["elastic_sphere_dFdh_over_2Ea"] - 1.0) for s in small)
            out[mesh] = {"max_dev": dev, "branches": len(small), "within_limit": bool(dev <= LIMITS["sneddon_small"]),
                         "max_dev_from_elastic_sphere": own}
    return out


def elastic_slope(c: dict) -> tuple[np.ndarray, np.ndarray]:
    """(a/R, dF/dh) along the monotone loading of the elastic run (d ln F/d ln h · F/h)."""
    load = np.flatnonzero((c["branch"] == LOAD) & (c["h"] > 0))
    h, F, a = c["h"][load], c["F"][load], c["a"][load]
    slope = np.gradient(np.log(F), np.log(h)) * F / h
    return a, slope


def thornton(h_max: float, F_max: float, a_max: float, E_star: float, h: np.ndarray):
    """Thornton (1997): (h_res, F on unloading at h)."""
    Rp = 4.0 * E_star * a_max**3 / (3.0 * F_max)
    h_res = h_max - (3.0 * F_max / (4.0 * E_star * math.sqrt(Rp))) ** (2.0 / 3.0)
    return h_res, 4.0 / 3.0 * E_star * math.sqrt(Rp) * np.maximum(h - h_res, 0.0) ** 1.5


def retrace(run: dict) -> list[dict]:
    """Per cycle of an elastic run: the largest |F_unloading/F_loading − 1| at the loading
    increments the unloading spans (F > 5 % F_max), and h_res/h_max."""
    el, elc = _arrays(run), run["cycles"]
    out = []
    for i, hm in enumerate(elc["h_max"]):
        load, unl = _branch(el, elc, i)
        # the (finely stepped) unloading curve read at the loading increments it spans
        on = unl[el["F"][unl] > 0]
        sel = load[(el["F"][load] > 0.05 * elc["F_max"][i]) & (el["h"][load] >= el["h"][on].min())]
        down = _loglog_interp(el["h"][sel], el["h"][on], el["F"][on])
        out.append({"h_max": hm, "F_max_dev": float(np.max(np.abs(down / el["F"][sel] - 1))),
                    "h_res_over_h_max": elc["h_res"][i] / hm})
    return out


def analyse(runs: dict) -> dict:
    out = {"limits": LIMITS, "runs": {n: {k: r[k] for k in ("status", "wall_s", "increments", "n_dofs")}
                                      for n, r in runs.items()}}
    E_star = {n: r["E"] / (1 - NU**2) for n, r in runs.items()}
    # 1. elastic retrace and h_res, on each mesh
    out["elastic"] = []
    for name in RETRACE_RUNS:
        if name in runs:
            out["elastic"] += [{"run": name, "mesh": mesh_label(name), **e} for e in retrace(runs[name])]
    out["elastic_same_approach"] = []
    for name, source in SCHEDULED_RUNS.items():
        if name in runs and source in runs:
            out["elastic_same_approach"] += [{"run": source, "mesh": mesh_label(source), **e}
                                             for e in retrace_at_same_approach(runs[source], runs[name])]
    el = _arrays(runs["elastic"])
    # 2. unloading stiffness against Sneddon, beside the elastic sphere's own slope
    a_el, S_el = elastic_slope(el)
    order = np.argsort(a_el)
    stiff = []
    for name in (n for n in STIFFNESS_RUNS if n in runs):
        c, cyc = _arrays(runs[name]), runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"]):
            _, unl = _branch(c, cyc, i)
            S = unloading_stiffness(c["h"][unl], c["F"][unl])
            a = c["a"][unl[0]]
            sneddon = 2.0 * E_star[name] * a
            own = float(np.interp(a, a_el[order], S_el[order])) / (2.0 * E_star["elastic"] * a)
            stiff.append({"run": name, "mesh": mesh_label(name), "h_max": hm, "a_over_R": float(a),
                          "S_over_2Ea": S / sneddon, "elastic_sphere_dFdh_over_2Ea": own})
    out["stiffness"] = stiff
    out["stiffness_small"] = stiffness_small(stiff)
    # 3. reloading: elastic until h_max, then the monotone curve
    mono = _arrays(runs["E200_monotone"])
    noise = scatter(mono["h"], mono["F"], mono["h"] >= 0.01)
    reload = []
    for name in ("E200", "E1000"):
        c, cyc = _arrays(runs[name]), runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"][:-1]):
            _, unl = _branch(c, cyc, i)
            rel = np.arange(unl[-1] + 1, c["h"].size)
            rel = rel[:np.argmax(np.append(c["branch"][rel] != RELOAD, True))]  # this cycle's reload
            if rel.size < 3:
                continue
            up = c["F"][rel]
            down = np.interp(c["h"][rel], c["h"][unl][::-1], c["F"][unl][::-1])
            top = (c["F"][rel] > 0.05 * cyc["F_max"][i])
            entry = {"run": name, "h_max": hm,
                     "reload_vs_unload_max_dev_over_F_max": float(np.max(np.abs(up - down)[top]) / cyc["F_max"][i]),
                     "reload_dissipation_over_cycle": float((c["dissipation"][rel[-1]] - c["dissipation"][rel[0]])
                                                            / max(cyc["dissipation"][i], 1e-300))}
            if name == "E200":
                after = np.flatnonzero((c["branch"] == LOAD) & (c["h"] > hm * 1.05)
                                       & (c["h"] < (cyc["h_max"][i + 1] if i + 1 < len(cyc["h_max"]) else 1)))
                if after.size:
                    ref = _loglog_interp(c["h"][after], mono["h"][mono["h"] > 0], mono["F"][mono["h"] > 0])
                    entry["rejoin_max_dev"] = float(np.max(np.abs(c["F"][after] / ref - 1)))
                    entry["monotone_scatter"] = noise
            reload.append(entry)
    out["reload"] = reload
    # 4. energy per cycle
    energy = []
    for name in (n for n in ENERGY_RUNS if n in runs):
        cyc = runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"]):
            lhs = cyc["work_in"][i] - cyc["work_returned"][i]
            rhs = cyc["dissipation"][i] + cyc["elastic_energy_change"][i]
            energy.append({"run": name, "h_max": hm, "work_in": cyc["work_in"][i], "net_work": lhs,
                           "dissipation_plus_stored": rhs, "error_over_work_in": abs(lhs - rhs) / cyc["work_in"][i]})
    out["energy"] = energy
    # 5. mesh and increment convergence of h_res and of the unloading curves
    conv = []
    for base_name, name in CONVERGENCE_PAIRS:
        if base_name not in runs or name not in runs:
            continue
        base, bc = _arrays(runs[base_name]), runs[base_name]["cycles"]
        c, cyc = _arrays(runs[name]), runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"]):
            _, ub = _branch(base, bc, i)
            _, uc = _branch(c, cyc, i)
            Fi = np.interp(base["h"][ub][::-1], c["h"][uc][::-1], c["F"][uc][::-1])[::-1]
            # the shape of the unloading: F/F_max against (h − h_res)/(h_max − h_res)
            xb = (base["h"][ub] - bc["h_res"][i]) / (hm - bc["h_res"][i])
            xc = (c["h"][uc] - cyc["h_res"][i]) / (cyc["h_max"][i] - cyc["h_res"][i])
            shape = np.interp(xb[::-1], xc[::-1], c["F"][uc][::-1] / cyc["F_max"][i])[::-1]
            conv.append({"run": name, "against": base_name, "h_max": hm, "h_res_dev": cyc["h_res"][i] / bc["h_res"][i] - 1,
                         "F_max_dev": cyc["F_max"][i] / bc["F_max"][i] - 1,
                         "unloading_F_max_dev_over_F_max":
                             float(np.max(np.abs(Fi - base["F"][ub])) / bc["F_max"][i]),
                         "unloading_shape_max_dev": float(np.max(np.abs(shape - base["F"][ub] / bc["F_max"][i])))})
    out["convergence"] = conv
    # 6. Thornton's residual approach and unloading curve beside the FE
    th = []
    for name in ("E200", "E1000"):
        c, cyc = _arrays(runs[name]), runs[name]["cycles"]
        for i, hm in enumerate(cyc["h_max"]):
            _, unl = _branch(c, cyc, i)
            h_res_t, F_t = thornton(hm, cyc["F_max"][i], cyc["a_max"][i], E_star[name], c["h"][unl])
            th.append({"run": name, "h_max": hm, "h_res_over_h_max_fe": cyc["h_res"][i] / hm,
                       "h_res_over_h_max_thornton": h_res_t / hm,
                       "F_max_dev_over_F_max": float(np.max(np.abs(F_t - c["F"][unl])) / cyc["F_max"][i])})
    out["thornton"] = th
    # 7. cost of the cycles
    w_cyc, w_mono = runs["E200"]["wall_s"], runs["E200_monotone"]["wall_s"]
    added = (w_cyc / w_mono - 1) / len(CYCLES_AT)
    out["cost"] = {"wall_with_4_cycles_s": w_cyc, "wall_monotone_s": w_mono, "added_per_cycle": added,
                   "within_limit": bool(added <= LIMITS["cycle_cost"])}
    return out


def chart(runs: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, name in zip(axes, ("E200", "E1000"), strict=True):
        c = _arrays(runs[name])
        for b, col, lab in ((LOAD, "k", "load"), (UNLOAD, "tab:red", "unload"), (RELOAD, "tab:blue", "reload")):
            m = c["branch"] == b
            ax.plot(c["h"][m], c["F"][m], ".", ms=2, color=col, label=lab)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("h/R")
        ax.set_ylabel("F/(σY R²)")
        ax.set_title(f"EPP E/σY = {name[1:]}: cycles at h/R = {', '.join(f'{x:g}' for x in CYCLES_AT)}")
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _pct(x: float) -> str:
    return f"{100 * x:.2f}"


def report(res: dict) -> str:
    lines = ["# Unloading and reloading cycles (one sphere on a rigid flat, ν = 0.3)", "",
             "`python studies/fem_verification_cycles.py` — " + __doc__.splitlines()[0], ""]
    lines += ["## Runs", "", "| run | status | increments | dofs | wall s |", "|---|---|---|---|---|"]
    lines += [f"| {n} | {r['status']} | {r['increments']} | {r['n_dofs']} | {r['wall_s']:.0f} |"
              for n, r in res["runs"].items()]
    lines += ["", "Runs `*_smooth`: the surface band 0.03 with the penalty over the edges scaled with the "
              "approach (P = 300; `penalty_scale = \"approach\"`). Its stiffness stays at the peak's on "
              "unloading, so the obstacle gives way by about h_max/P, as much as a good part of the "
              "elastic recovery: compare their retrace and unloading stiffness with the exact "
              "contact's before using that contact for unloading branches."]
    lines += ["", "## Elastic sphere: unloading retraces loading", "",
              "| mesh | h_max/R | unloading vs loading F, max dev at the loading increments (F > 5 % F_max) % "
              "| h_res/h_max |", "|---|---|---|---|"]
    lines += [f"| {e.get('mesh', 'default mesh')} | {e['h_max']:g} | {_pct(e['F_max_dev'])} | "
              f"{e['h_res_over_h_max']:.2e} |" for e in res["elastic"]]
    if res.get("elastic_same_approach"):
        lines += ["", "The same comparison without interpolation: a monotone elastic run stepped to exactly "
                  "the unloading approaches (`" + "`, `".join(SCHEDULED_RUNS) + "`) gives the loading F at each "
                  "unloading increment with F > 5 % F_max. Interpolating the unloading curve at the loading "
                  "increments (the table above) crosses the kinks of F(h) where surface nodes close.", "",
                  "| mesh | h_max/R | unloading increments compared | unloading vs loading F at the same "
                  "approach, max dev % |", "|---|---|---|---|"]
        lines += [f"| {e['mesh']} | {e['h_max']:g} | {e['points']} | {100 * e['F_max_dev']:.1e} |"
                  for e in res["elastic_same_approach"]]
    lines += ["", "## Initial unloading stiffness against Sneddon's 2E*a", "",
              "S = dF/dh at h_max (quadratic through the first four unloading points); the elastic "
              "sphere's own loading slope at the same a/R beside it.", "",
              "| run | mesh | h_max/R | a/R | S/(2E*a) | elastic sphere dF/dh/(2E*a) |", "|---|---|---|---|---|---|"]
    lines += [f"| {s['run']} | {s['mesh']} | {s['h_max']:g} | {s['a_over_R']:.4f} | {s['S_over_2Ea']:.3f} | "
              f"{s['elastic_sphere_dFdh_over_2Ea']:.3f} |" for s in res["stiffness"]]
    lines += ["", f"Small contacts (a/R ≤ 0.05), max |S/(2E*a) − 1| per mesh (limit "
              f"{_pct(LIMITS['sneddon_small'])} %), and max |S / the elastic sphere's own dF/dh − 1| (the "
              "finite sphere is stiffer than Sneddon's half-space already at these a/R: its own loading "
              "slope is the column on the right):", ""]
    lines += [f"* {mesh}: {_pct(v['max_dev'])} % over {v['branches']} branches — "
              f"{'met' if v['within_limit'] else 'missed'}; against the elastic sphere's slope "
              f"{_pct(v['max_dev_from_elastic_sphere'])} %" for mesh, v in res.get("stiffness_small", {}).items()]
    lines += ["", "## Reloading", "",
              "| run | h_max/R | reload vs unload, max |ΔF|/F_max % | dissipation while reloading / cycle's | "
              "after h_max: max dev from the monotone run % (its scatter %) |", "|---|---|---|---|---|"]
    for r in res["reload"]:
        rej = (f"{_pct(r['rejoin_max_dev'])} ({_pct(r['monotone_scatter'])})" if "rejoin_max_dev" in r else "—")
        lines.append(f"| {r['run']} | {r['h_max']:g} | {_pct(r['reload_vs_unload_max_dev_over_F_max'])} | "
                     f"{r['reload_dissipation_over_cycle']:.2e} | {rej} |")
    lines += ["", "## Energy per cycle", "",
              "| run | h_max/R | work in − returned | dissipation + Δ stored | error / work in % |",
              "|---|---|---|---|---|"]
    lines += [f"| {e['run']} | {e['h_max']:g} | {e['net_work']:.4e} | {e['dissipation_plus_stored']:.4e} | "
              f"{_pct(e['error_over_work_in'])} |" for e in res["energy"]]
    lines += ["", "## Mesh and increment convergence (E/σY = 200)", "",
              "F_max differs by the loading's own path dependence and node-closure scatter; the "
              "shape column compares F/F_max against (h − h_res)/(h_max − h_res).", "",
              "| run | against | h_max/R | h_res % | F_max % | unloading F max |ΔF|/F_max % | "
              "unloading shape max dev % |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {c['run']} | {c['against']} | {c['h_max']:g} | {_pct(c['h_res_dev'])} | {_pct(c['F_max_dev'])} | "
              f"{_pct(c['unloading_F_max_dev_over_F_max'])} | {_pct(c['unloading_shape_max_dev'])} |"
              for c in res["convergence"]]
    lines += ["", "## Thornton (1997) beside the FE", "",
              "| run | h_max/R | h_res/h_max FE | Thornton | unloading F max |ΔF|/F_max % |", "|---|---|---|---|---|"]
    lines += [f"| {t['run']} | {t['h_max']:g} | {t['h_res_over_h_max_fe']:.3f} | {t['h_res_over_h_max_thornton']:.3f}"
              f" | {_pct(t['F_max_dev_over_F_max'])} |" for t in res["thornton"]]
    lines += ["", "## Two deformable bodies (exact contact, equal radii; body 1 EPP E/σY 200, elastic for the elastic pair)", "",
              "pair_elastic_E3: body 2 elastic with E₂ = 3E₁ (h₁/h = E₂'/(E₁' + E₂') = 0.75); pair_yield3: body 2 "
              "with σY₂ = 3σY₁. h₁ share: body 1's part of the residual approach.", "",
              "| run | h_max/R | h_res/h_max | h₁/h at h_res | energy error % | split on unloading, max dev from 0.75 |",
              "|---|---|---|---|---|---|"]
    for p in res.get("pairs", []):
        split = f"{p['split_on_unloading_max_dev']:.4f}" if "split_on_unloading_max_dev" in p else "—"
        lines.append(f"| {p['run']} | {p['h_max']:g} | {p['h_res_over_h_max']:.4f} | {p['h1_share_of_h_res']:.3f} | "
                     f"{_pct(p['energy_error'])} | {split} |")
    c = res["cost"]
    lines += ["", "## Cost", "", f"E/σY = 200 to h/R = 0.3: {c['wall_monotone_s']:.0f} s monotone, "
              f"{c['wall_with_4_cycles_s']:.0f} s with 4 cycles: {_pct(c['added_per_cycle'])} % per cycle "
              f"(limit {_pct(LIMITS['cycle_cost'])} %: {'met' if c['within_limit'] else 'missed'}).", "",
              "![cycles](cycles.png)", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--reuse", action="store_true", help="analyse the runs of the last call again")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(RUNS, key=lambda n: -RUNS[n][3] * RUNS[n][1])  # longest first
    cache = out / ".cycles_runs.json"  # the raw runs: --reuse runs only those missing
    runs = json.loads(cache.read_text()) if args.reuse and cache.exists() else {}
    todo = [n for n in names if n not in runs]
    pairs = [n for n in PAIR_RUNS if n not in runs]
    with ProcessPoolExecutor(args.workers) as pool:
        runs.update(zip(pairs, pool.map(run_pair_case, pairs), strict=True))
        runs.update(zip(todo, pool.map(run_case, todo), strict=True))
        scheduled = [n for n in SCHEDULED_RUNS if n not in runs]
        runs.update(zip(scheduled, pool.map(run_scheduled_case, scheduled,
                                            [unloading_approaches(runs[SCHEDULED_RUNS[n]]) for n in scheduled]),
                        strict=True))
    cache.write_text(json.dumps(runs))
    res = analyse(runs)
    res["pairs"] = analyse_pairs(runs)
    res["runs"].update({n: {k: runs[n][k] for k in ("status", "wall_s", "increments", "n_dofs")}
                        for n in PAIR_RUNS if n in runs})
    (out / "cycles_verification.json").write_text(json.dumps(res, indent=1) + "\n")
    chart(runs, out / "cycles.png")
    (out / "cycles.md").write_text(report(res))
    print(report(res))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
