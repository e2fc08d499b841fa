"""Study runs from the FE verification (``reports/fem/run_*.json``) when the database has none.

``make verify-fem`` saves each of its runs as JSON (curves, timings, residuals); their
inputs are those of ``spherecontact.fem.verification.plan`` (ν = 0.3, σ_Y = 1, R = 1,
rigid flat). The report uses them for the speed–accuracy chart and the stability
section only when the database holds no ``studies`` set, and says so. Runs used:

* ``standard``, ``standard_fine`` (mesh density 2), ``standard_dt2`` (strain increment
  0.0025): the refinement series of the standard case (E/σ_Y = 200, h/R = 0.3);
* ``lock_q4``, ``lock_q8r`` (and ``_fine``): the locking study (E/σ_Y = 10⁴);
* ``large_*``: runs to h/R = 0.5 (the extreme-h/R study).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .cases import Case

__all__ = ["STUDY_RUNS", "load_verification_runs"]

STUDY_RUNS = ("standard", "standard_fine", "standard_dt2", "lock_q4", "lock_q8r", "lock_q4_fine",
              "lock_q8r_fine", "large_epp50", "large_epp500", "large_ludwik")


def _inputs(spec: dict) -> dict:
    from ..fem.solver import SolverOptions
    from ..fem.verification import NU

    E = float(spec["E_over_sy"])
    material = {"E": E, "nu": NU, "sigma_y": 1.0, "K": float(spec.get("K", 0.0)),
                "n": float(spec.get("n", 1.0))}
    opts = {**SolverOptions().__dict__, **spec.get("options", {})}
    return {"material": material, "radius": 1.0, "indenter_radius": math.inf, "scene": "rigid_flat",
            "h_max": float(spec["h_max"]), "mesh_density": float(spec.get("density", 1.0)),
            "element": spec.get("element", "q8r"), "options": opts}


def load_verification_runs(directory) -> list[Case]:
    """Cases of the FE verification runs found in ``directory`` (empty list if none)."""
    from ..fem.verification import plan

    directory = Path(directory)
    specs = plan(quick=False)
    out = []
    for name in STUDY_RUNS:
        path = directory / f"run_{name}.json"
        if not path.is_file() or name not in specs:
            continue
        try:
            d = json.loads(path.read_text())
            curves = {k: np.asarray(v, dtype=float) for k, v in d["curves"].items()}
        except (OSError, ValueError, KeyError, TypeError):
            continue
        spec = specs[name]
        if spec.get("kind") == "elastic":
            continue
        inputs = _inputs(spec)
        wall = float(d.get("timings", {}).get("wall_s", math.nan))
        params = {"scene": "flat", "mesh_density": inputs["mesh_density"],
                  "strain_increment": inputs["options"]["strain_increment"],
                  "element": inputs["element"]}
        out.append(Case(key=f"verification:{name}", set="studies", name=name, params=params,
                        inputs=inputs, curves=curves, status=d.get("status", "converged"),
                        reason=d.get("reason", ""), wall_s=wall,
                        provenance={"timings": d.get("timings", {}), "wall_s": wall,
                                    "source": str(path)}))
    return out
