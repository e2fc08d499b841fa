"""FE speed: the standard run (EPP, E/σY = 200, ν = 0.3, rigid flat, h/R = 0.3, default mesh).

Wall time, increments, Newton iterations and the split between constitutive
update, tangent/force assembly and linear solve (issue 3 target: under 30 s).
"""

from __future__ import annotations

from spherecontact.fem.solver import IndentationSolver
from spherecontact.model import Material


def main() -> dict:
    solver = IndentationSolver(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0)
    res = solver.run(0.3)
    t = res.timings
    return {
        "case": "EPP E/sigma_Y=200, nu=0.3, rigid flat, h/R=0.3, default mesh",
        "status": res.status,
        "n_dofs": solver.disc.n_dofs,
        "n_elements": solver.disc.n_elements,
        **{k: (round(v, 3) if isinstance(v, float) else v) for k, v in t.items()},
        "iterations_per_increment": round(t["newton_iterations"] / t["increments"], 2),
        "ms_per_iteration": round(1e3 * t["wall_s"] / t["newton_iterations"], 1),
        "rejected_increments": len(solver.rejected),
        "F_end": float(res.F[-1]),
        "a_end": float(res.a[-1]),
        "target_wall_s": 30.0,
    }
