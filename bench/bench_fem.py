"""FE speed: the standard run (EPP, E/σY = 200, ν = 0.3, rigid flat, h/R = 0.3, default mesh).

Runs it four times (the first twice, keeping the faster): as it stands (tangent predictor,
CHOLMOD's supernodal Cholesky reusing its symbolic analysis, Newton tolerance 1e-4), with
qdldl's LDLᵀ instead (the factorisation before Cholesky), with the previous predictor
(``predictor="secant"``), and with SuperLU alone (the solver before LDLᵀ), and reports for
each the wall time, increments, Newton iterations, the split per iteration (constitutive
update, assembly, contact, constraint setup, factorisation, triangular solves, line search)
and the FE scatter of
F and a over h/R ≥ 0.01 (max |ln y − local quadratic in ln h| over 11
increments). Target (issue "FE reference v2"): ≤ 25 s alone, ≤ 5 iterations
per increment. Then ``smooth``: the same scene on the surface-band mesh (0.03)
with the penalty over the edges scaled with the approach (P = 300): its cost beside its
scatter. ``cycles``: the standard run with unloading to F = 0 and reloading at
h/R = 0.001, 0.01, 0.1 and 0.3 (issue "FE: unloading and reloading cycles": a cycle adds
≤ 20 % to a monotone run's wall time), measured alone like the others. ``stiff``:
the same scene with E/σY = 10⁴ (target: ≤ 10 min to h/R = 0.3). ``rigid_sphere`` presses
the same sphere with a rigid sphere of radius 2R, beside the flat: curved obstacles take their own
code path (nodal frames), and until 2026-11-26 it ran without line search at 5× the flat's wall
time (149 s against 30 s) without any benchmark showing it. ``pair``: two plastic bodies of
equal yield stress, E₂ = 3E₁ (E/σY 200 and 600), R₂ = 2R₁, two-pass penalty contact (P = 100),
to h = 0.03 R₁, against body 1 alone on a rigid flat to the same approach (target: ≤ 3× its wall
time); ``pair_approach``: the same pair with the penalty scaled with the approach (P = 3000;
``studies/fem_pair_speed.py``, whose ``make verify-pair-speed`` times the campaign's pairs to h/R 0.3).
The pairs' split per iteration has the same phases (constraints: the penalty tangent's assembly
on its pattern) and the tangent predictor's (its triangular solves, its contact correction).
"""

from __future__ import annotations

import math

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.solver import IndentationSolver, SolverOptions, phase_split
from spherecontact.fem.twobody import TwoBodySolver
from spherecontact.metrics import scatter
from spherecontact.model import Material

#: the smooth configuration: surface band 0.03, penalty over the edges scaled with the approach
SMOOTH = {"edge_band": 0.03, "penalty": 300.0, "segment_points": 8, "penalty_scale": "approach"}


#: the unloading approaches of the ``cycles`` run
CYCLES_AT = (0.001, 0.01, 0.1, 0.3)


def linear_counts(timings: dict) -> dict:
    """The linear solver's counts of a run's ``timings`` (``linear_*``, prefix dropped)."""
    return {k[len("linear_"):]: v for k, v in timings.items() if k.startswith("linear_")}


def standard_run(linear_solver: str, edge_band: float = 0.0, unload_at=None, E: float = 200.0,
                 indenter: float = math.inf, **options) -> dict:
    solver = IndentationSolver(Material(E=E, nu=0.3, sigma_y=1.0), 1.0, RigidObstacle(indenter),
                               edge_band=edge_band,
                               options=SolverOptions(linear_solver=linear_solver, **options))
    res = solver.run(0.3, unload_at=unload_at)
    t = res.timings
    its = t["newton_iterations"]
    late = (res.h >= 0.01) & (res.curves["branch"] == 0)
    return {
        "status": res.status,
        "n_dofs": solver.disc.n_dofs,
        "wall_s": round(t["wall_s"], 2),
        "increments": t["increments"],
        "newton_iterations": its,
        "rejected_increments": t["rejected_increments"],
        "iterations_per_increment": round(its / t["increments"], 2),
        "ms_per_iteration": round(1e3 * t["wall_s"] / its, 1),
        "ms_per_iteration_split": phase_split(t),
        "linear": linear_counts(t),
        "F_end": float(res.F[-1]),
        "a_end": float(res.a[-1]),
        "scatter_F": round(scatter(res.h[late], res.F[late]), 5),
        "scatter_a": round(scatter(res.h[late], res.a[late]), 5),
    }


#: the ``pair`` scene's approach
PAIR_H = 0.03


#: the ``pair_approach`` scene's penalty: k_N = P p_m/h, P as ``make verify-pair-speed`` runs it
#: (``studies/fem_pair_speed.py``: the bodies sink in by about h/P, bounded)
PAIR_SPEED_PENALTY = 3000.0
PAIR_APPROACH = {"penalty": PAIR_SPEED_PENALTY, "penalty_scale": "approach"}


def pair_run(**options) -> dict:
    """The ``pair`` scene (module docstring; ``options``: its contact, default the two-pass
    penalty 100 scaled with the modulus) and body 1 alone on a flat to the same approach."""
    body1 = Material(E=200.0, nu=0.3, sigma_y=1.0)
    options = options or {"penalty": 100.0}
    solver = TwoBodySolver(body1, 1.0, Material(E=600.0, nu=0.3, sigma_y=1.0), 2.0,
                           options=SolverOptions(**options))
    res = solver.run(PAIR_H)
    t = res.timings
    flat = IndentationSolver(body1, 1.0, RigidObstacle(math.inf)).run(PAIR_H).timings
    return {"case": f"EPP E/sigma_Y 200 and 600, R2 = 2 R1, two-pass penalty {options}, h = {PAIR_H} R1",
            "status": res.status, "n_dofs": solver.n_dofs, "wall_s": round(t["wall_s"], 2),
            "increments": t["increments"], "newton_iterations": t["newton_iterations"],
            "rejected_increments": t["rejected_increments"],
            "ms_per_iteration": round(1e3 * t["wall_s"] / t["newton_iterations"], 1),
            "ms_per_iteration_split": phase_split(t),
            "linear": linear_counts(t),
            "F_end": float(res.F[-1]), "h_end": float(res.h[-1]),
            "body1_flat_wall_s": round(flat["wall_s"], 2),
            "wall_over_body1_flat": round(t["wall_s"] / flat["wall_s"], 2),
            "target_wall_over_body1_flat": 3.0}


def main() -> dict:
    # the machine's speed drifts by 20-30 % within minutes: the headline run is the faster of two
    repeats = [standard_run("cholesky") for _ in range(2)]
    after = {**min(repeats, key=lambda r: r["wall_s"]), "wall_s_repeats": [r["wall_s"] for r in repeats]}
    ldl = standard_run("ldl")
    secant = standard_run("cholesky", predictor="secant")
    before = standard_run("superlu")
    smooth = standard_run("cholesky", **SMOOTH)
    cycles = standard_run("cholesky", unload_at=CYCLES_AT)
    stiff = standard_run("cholesky", E=10000.0)
    rigid = standard_run("cholesky", indenter=2.0)
    pair = pair_run()
    pair_approach = pair_run(**PAIR_APPROACH)
    per_cycle = (cycles["wall_s"] / after["wall_s"] - 1.0) / len(CYCLES_AT)
    return {
        "case": "EPP E/sigma_Y=200, nu=0.3, rigid flat, h/R=0.3, default mesh",
        "cholesky": after,
        "ldl": {**ldl, "wall_over_cholesky": round(ldl["wall_s"] / after["wall_s"], 2)},
        "superlu": before,
        "secant_predictor": {"case": "the standard run with the previous predictor (secant)", **secant,
                             "wall_over_tangent": round(secant["wall_s"] / after["wall_s"], 2)},
        "smooth": {"configuration": SMOOTH, **smooth},
        "cycles": {"unload_at": list(CYCLES_AT), **cycles,
                   "added_wall_per_cycle": round(per_cycle, 3), "target_added_wall_per_cycle": 0.20},
        "stiff": {"case": "EPP E/sigma_Y=1e4, nu=0.3, rigid flat, h/R=0.3, default mesh", **stiff,
                  "target_wall_s": 600.0},
        "rigid_sphere": {"case": "the standard run against a rigid sphere of radius 2R", **rigid,
                         "wall_over_flat": round(rigid["wall_s"] / after["wall_s"], 2)},
        "pair": pair,
        "pair_approach": pair_approach,
        "speedup": round(before["wall_s"] / after["wall_s"], 2),
        "same_answer_F_a": [abs(after[k] / before[k] - 1) for k in ("F_end", "a_end")],
        "target_wall_s": 25.0,
        "target_iterations_per_increment": 5.0,
    }
