"""Mesh convergence of the surface-band mesh that campaign v2 uses (``edge_band`` = 0.03).

The standard scene (EPP E/σY = 200, ν = 0.3, rigid flat, h/R = 0.3) on the band mesh at
density 1 and 2 (everything, the band included, twice finer) and on the default mesh at
density 1. At h/R = 0.05, 0.1 and 0.3 it reports F and a read at the increment-wise curve
(linear interpolation in ln h, as ``make verify-fem``) and read on the local quadratic in
ln h through the 11 increments nearest to h, which averages the node-closing steps (the
FE scatter) out of the comparison; the stored curves are not changed. Writes
``band_convergence.json``. ``python -m spherecontact.fem.band_convergence --out reports/fem``.
"""

from __future__ import annotations

import argparse
import json
import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from ..model.material import Material
from ..validation.metrics import local_fit_at, scatter
from .io import run_indentation

CHECK_H = (0.05, 0.1, 0.3)
MESHES = {"band 0.03, density 1": (0.03, 1.0), "band 0.03, density 2": (0.03, 2.0),
          "default, density 1": (0.0, 1.0)}
WINDOW = 11


def one(label: str) -> dict:
    band, density = MESHES[label]
    res = run_indentation(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, 0.3, density=density,
                          edge_band=band)
    h, F, a = res.h, res.F, res.a
    m = a >= 0.01
    out = {"label": label, "edge_band": band, "density": density, "status": res.status,
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
    args = ap.parse_args(argv)
    with ProcessPoolExecutor(args.workers) as pool:
        runs = dict(zip(MESHES, pool.map(one, MESHES), strict=True))
    report = {"runs": runs, "relative_to_band_density_2": compare(runs)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "band_convergence.json").write_text(json.dumps(report, indent=1) + "\n")
    for label, diffs in report["relative_to_band_density_2"].items():
        print(label, {k: f"{100 * v:+.2f} %" for k, v in diffs.items()})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
