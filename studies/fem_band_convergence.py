"""Mesh convergence of the surface-band mesh that campaign v2 uses (``edge_band`` = 0.03).

The standard scene (EPP E/σY = 200, ν = 0.3, rigid flat, h/R = 0.3) on the band mesh at
density 1 and 2 (everything, the band included, twice finer), on the default mesh at
density 1, and on the band mesh at density 1 with segment-integrated penalty contact scaled
with the approach (``penalty_scale = "approach"``, P = 300). At h/R = 0.05, 0.1 and 0.3 it
reports F and a read at the increment-wise curve (linear interpolation in ln h, as
``make verify-fem``) and read on the local quadratic in ln h through the 11 increments
nearest to h, which averages the node-closing steps (the FE scatter) out of the comparison;
the stored curves are not changed. Writes ``band_convergence.json``.
``python studies/fem_band_convergence.py --out reports/fem [--keep LABEL …]``.
"""

from __future__ import annotations

import argparse
import json
import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from spherecontact.fem.io import run_indentation
from spherecontact.fem.solver import SolverOptions
from spherecontact.metrics import local_fit_at, scatter
from spherecontact.model.material import Material

CHECK_H = (0.05, 0.1, 0.3)
#: label → (edge band, mesh density, solver options); the reference is band 0.03 at density 2
APPROACH_PENALTY = {"penalty": 300.0, "segment_points": 8, "penalty_scale": "approach"}
MESHES = {"band 0.03, density 1": (0.03, 1.0, {}), "band 0.03, density 2": (0.03, 2.0, {}),
          "default, density 1": (0.0, 1.0, {}),
          "band 0.03, density 1, approach penalty 300": (0.03, 1.0, APPROACH_PENALTY)}
WINDOW = 11


def one(label: str) -> dict:
    band, density, options = MESHES[label]
    res = run_indentation(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, 0.3, density=density,
                          edge_band=band, options=SolverOptions(**options))
    h, F, a = res.h, res.F, res.a
    m = a >= 0.01
    out = {"label": label, "edge_band": band, "density": density, "options": options,
           "status": res.status,
           "wall_s": res.timings["wall_s"], "increments": res.timings["increments"],
           "n_dofs": res.inputs["n_dofs"], "scatter_F": scatter(h, F, m), "scatter_a": scatter(h, a, m)}
    for x in CHECK_H:
        out[f"F@{x:g}"] = float(np.exp(np.interp(math.log(x), np.log(h), np.log(F))))
        out[f"a@{x:g}"] = float(np.exp(np.interp(math.log(x), np.log(h), np.log(a))))
        out[f"F_fit@{x:g}"] = local_fit_at(h, F, x, WINDOW)
        out[f"a_fit@{x:g}"] = local_fit_at(h, a, x, WINDOW)
    return out


def compare(runs: dict) -> dict:
    """Relative differences of each mesh against the band mesh at density 2."""
    ref = runs["band 0.03, density 2"]
    table = {}
    for label, r in runs.items():
        if r is ref:
            continue
        table[label] = {f"{k}": r[k] / ref[k] - 1.0 for k in r if "@" in k}
    return table


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", nargs="*", default=[], metavar="LABEL",
                    help="runs to take from the earlier band_convergence.json instead of running "
                         "them again (e.g. the 2x reference, ~1 h)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    earlier = out / "band_convergence.json"
    stored = json.loads(earlier.read_text())["runs"] if args.keep and earlier.exists() else {}
    missing = [label for label in args.keep if label not in stored]
    if missing:
        ap.error(f"--keep: no stored run {missing} in {earlier}")
    runs = {label: stored[label] for label in args.keep}
    todo = [label for label in MESHES if label not in runs]
    with ProcessPoolExecutor(args.workers) as pool:
        runs.update(zip(todo, pool.map(one, todo), strict=True))
    runs = {label: runs[label] for label in MESHES}
    report = {"runs": runs, "relative_to_band_density_2": compare(runs)}
    out.mkdir(parents=True, exist_ok=True)
    (out / "band_convergence.json").write_text(json.dumps(report, indent=1) + "\n")
    for label, diffs in report["relative_to_band_density_2"].items():
        print(label, {k: f"{100 * v:+.2f} %" for k, v in diffs.items()})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
