"""The validation's own FE study runs and the FE verification runs as validation cases.

Checks: how the model's error against the standard case (E/σ_Y = 200, ν = 0.3, h/R = 0.3, rigid
flat) moves with the FE's mesh density, strain increment, element, approach and contact penalty
(:data:`STUDY_VARIANTS`), i.e. the FE side of the validation report's speed–accuracy chart and
stability section.

Writes: ``python studies/validation_fem_reports.py --out data/validation_studies [NAME …]``
runs the missing variants one after another into ``OUT/<name>.json`` (``inputs``, ``curves``,
``status``, ``reason``, ``timings``), which ``spherecontact validate`` reads when the database
holds no ``studies`` set (``spherecontact.validation.study_runs``).
:func:`load_fallback` adds the runs of ``studies/fem_verification.py`` saved as
``run_<name>.json`` (``STUDY_RUNS``: the standard case's refinement series, the locking study,
the runs to h/R = 0.5) to them.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from spherecontact.validation.cases import Case
from spherecontact.validation.study_runs import load_study_files

__all__ = ["STUDY_RUNS", "STUDY_VARIANTS", "load_verification_runs", "load_fallback", "run_study_variants"]

STUDY_RUNS = ("standard", "standard_fine", "standard_dt2", "lock_q4", "lock_q8r", "lock_q4_fine",
              "lock_q8r_fine", "large_epp50", "large_epp500", "large_ludwik")


#: the validation's own study runs: name → (strain_increment, element, h_max, mesh density,
#: penalty or None for exact contact) of the standard case
STUDY_VARIANTS = {
    "standard_de0.005": (0.005, "q8r", 0.3, 1.0, None),
    "standard_de0.0025": (0.0025, "q8r", 0.3, 1.0, None),
    "standard_de0.01": (0.01, "q8r", 0.3, 1.0, None),
    "standard_de0.02": (0.02, "q8r", 0.3, 1.0, None),
    "standard_d0.5": (0.005, "q8r", 0.3, 0.5, None),
    "standard_d2": (0.005, "q8r", 0.3, 2.0, None),
    "standard_q4": (0.005, "q4", 0.3, 1.0, None),
    "standard_extreme0.6": (0.005, "q8r", 0.6, 1.0, None),
    "standard_penalty0.01": (0.005, "q8r", 0.3, 1.0, 0.01),
    "standard_penalty0.1": (0.005, "q8r", 0.3, 1.0, 0.1),
    "standard_penalty1": (0.005, "q8r", 0.3, 1.0, 1.0),
    "standard_penalty10": (0.005, "q8r", 0.3, 1.0, 10.0),
    "standard_penalty100": (0.005, "q8r", 0.3, 1.0, 100.0),
}


def _inputs(spec: dict) -> dict:
    from fem_verification import NU

    from spherecontact.fem.solver import SolverOptions

    E = float(spec["E_over_sy"])
    material = {"E": E, "nu": NU, "sigma_y": 1.0, "K": float(spec.get("K", 0.0)),
                "n": float(spec.get("n", 1.0))}
    opts = {**SolverOptions().__dict__, **spec.get("options", {})}
    return {"material": material, "radius": 1.0, "indenter_radius": math.inf, "scene": "rigid_flat",
            "h_max": float(spec["h_max"]), "mesh_density": float(spec.get("density", 1.0)),
            "element": spec.get("element", "q8r"), "options": opts}


def load_verification_runs(directory) -> list[Case]:
    """Cases of the FE verification runs found in ``directory`` (empty list if none)."""
    from fem_verification import plan

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


def _signature(c: Case) -> tuple:
    i = c.inputs
    m = i["material"]
    return (m["E"], m["nu"], m["sigma_y"], m.get("K", 0.0), m.get("n", 1.0), float(i["mesh_density"]),
            i.get("element", "q8r"), float(i["options"]["strain_increment"]), round(float(i["h_max"]), 6),
            i["options"].get("penalty"))


def load_fallback(verification_dir, study_dir) -> list[Case]:
    """Study files first, then the verification runs that no study file repeats."""
    own = load_study_files(study_dir)
    seen = {_signature(c) for c in own}
    return own + [c for c in load_verification_runs(verification_dir) if _signature(c) not in seen]


def run_study_variants(out_dir, names=None) -> list[Path]:
    """Run the missing :data:`STUDY_VARIANTS` one after another; write ``out_dir/<name>.json``."""
    import time

    from spherecontact.fem.io import run_indentation
    from spherecontact.fem.solver import SolverOptions
    from spherecontact.model import Material

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, (de, element, h_max, density, penalty) in STUDY_VARIANTS.items():
        path = out_dir / f"{name}.json"
        if (names and name not in names) or path.exists():
            continue
        t0 = time.perf_counter()
        res = run_indentation(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, h_max, element=element,
                              density=density,
                              options=SolverOptions(strain_increment=de, max_wall_s=1800.0,
                                                    penalty=penalty))
        timings = {k: float(v) for k, v in res.timings.items()}
        timings.setdefault("wall_s", time.perf_counter() - t0)
        inputs = json.loads(json.dumps(res.inputs, default=float))
        d = {"inputs": inputs, "curves": {k: np.asarray(v).tolist() for k, v in res.curves.items()},
             "status": res.status, "reason": res.reason, "timings": timings}
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(d))
        tmp.replace(path)
        written.append(path)
        print(f"{name}: {res.status} ({res.reason}), {timings['wall_s']:.0f} s", flush=True)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="data/validation_studies")
    parser.add_argument("names", nargs="*", help=f"subset of {', '.join(STUDY_VARIANTS)}")
    args = parser.parse_args(argv)
    run_study_variants(args.out, args.names)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
