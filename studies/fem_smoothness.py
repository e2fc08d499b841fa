"""Cost against smoothness of the FE force: scatter of F(h) and a(h) per contact discretisation.

The FE scatter of a curve is max |ln y − local quadratic in ln h| over 11 increments
(``spherecontact.metrics.scatter``), here over the points with a/R ≥ 0.01 up to h/R = 0.3,
and per band of a/R. A node closing at the contact edge adds a ring of nearly full
plastic pressure, a step of about 2 Δs/a in F (Δs the surface node spacing), so the
scatter falls with the surface element size at the edge. Compared here, on one body
pressed by a rigid flat or sphere (EPP, ν = 0.3):

* the default mesh with exact (Lagrange-multiplier) nodal contact;
* ``edge_band`` c: surface elements of size c × the distance from the pole;
* penalty contact with the pressure integrated at Gauss points of each edge;
* the same scaled with the approach (``penalty_scale = "approach"``, k_N = P p_m/h): the
  obstacle presses in by about h/P, so an edge that closes takes its pressure over that
  penetration instead of at once; F is read against the body's own shortening.

``--only i j …`` runs those cases and keeps the other cases' earlier figures. Each record
carries the date, the Newton tolerance and the predictor it was measured with: at E/σY 10⁴ the
scatter moves with them (fem/README.md, "Smoothness of F").

Writes ``smoothness.json`` and ``smoothness.png`` (scatter of F against wall time).
``python studies/fem_smoothness.py --out reports/fem`` (~85 min on one core).
"""

from __future__ import annotations

import argparse
import json
import math
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.solver import IndentationSolver, SolverOptions
from spherecontact.metrics import scatter
from spherecontact.model.material import Material

#: penalty contact integrated over the surface edges, scaled with the approach (P = 300)
APPROACH = {"penalty": 300.0, "segment_points": 8, "penalty_scale": "approach"}
#: (label, E/σY, indenter radius, edge band, solver options)
CASES = [
    ("flat E200, default mesh", 200.0, math.inf, 0.0, {}),
    ("flat E200, edge band 0.03", 200.0, math.inf, 0.03, {}),
    ("flat E200, edge band 0.02", 200.0, math.inf, 0.02, {}),
    ("flat E200, segment penalty 100, 8 points", 200.0, math.inf, 0.0,
     {"penalty": 100.0, "segment_points": 8}),
    ("flat E1000, default mesh", 1000.0, math.inf, 0.0, {}),
    ("flat E1000, edge band 0.02", 1000.0, math.inf, 0.02, {}),
    ("rigid sphere R2 = 2, E200, default mesh", 200.0, 2.0, 0.0, {}),
    ("rigid sphere R2 = 2, E200, edge band 0.02", 200.0, 2.0, 0.02, {}),
    ("flat E10, band 0.03, approach penalty 300", 10.0, math.inf, 0.03, APPROACH),
    ("flat E200, band 0.03, approach penalty 300", 200.0, math.inf, 0.03, APPROACH),
    ("flat E1000, band 0.03, approach penalty 300", 1000.0, math.inf, 0.03, APPROACH),
    ("flat E10000, band 0.03, approach penalty 300", 10000.0, math.inf, 0.03, APPROACH),
    ("rigid sphere R2 = 2, E200, band 0.03, approach penalty 300", 200.0, 2.0, 0.03, APPROACH),
    ("rigid sphere R2 = 4, E200, band 0.03, approach penalty 300", 200.0, 4.0, 0.03, APPROACH),
    ("rigid sphere R2 = 0.25, E200, band 0.03, approach penalty 300", 200.0, 0.25, 0.03, APPROACH),
    ("flat E10000, band 0.02, approach penalty 300", 10000.0, math.inf, 0.02, APPROACH),
    ("flat E10000, band 0.03, approach penalty 100", 10000.0, math.inf, 0.03,
     {**APPROACH, "penalty": 100.0}),
    ("flat E10000, band 0.02, approach penalty 100", 10000.0, math.inf, 0.02,
     {**APPROACH, "penalty": 100.0}),
    ("flat E10000, band 0.015, approach penalty 300", 10000.0, math.inf, 0.015, APPROACH),
    ("flat E1000, band 0.02, approach penalty 300", 1000.0, math.inf, 0.02, APPROACH),
    ("flat E10000, band 0.02, approach penalty 300, Newton 1e-8", 10000.0, math.inf, 0.02,
     {**APPROACH, "tol": 1e-8}),
    ("flat E10000, band 0.02, approach penalty 300, Newton 1e-8, secant predictor", 10000.0,
     math.inf, 0.02, {**APPROACH, "tol": 1e-8, "predictor": "secant"}),
    # loading increments dh ≤ 0.1 h / 0.05 h (SolverOptions.relative_step), and the band's floor
    # 0.0002 of R instead of 0.0005 (the band is at its floor for a/R < 0.025 at 0.02)
    ("flat E10000, band 0.02, approach penalty 300, steps ≤ 0.1 h", 10000.0, math.inf, 0.02,
     {**APPROACH, "relative_step": 0.1}),
    ("flat E10000, band 0.02, approach penalty 300, steps ≤ 0.05 h", 10000.0, math.inf, 0.02,
     {**APPROACH, "relative_step": 0.05}),
    ("flat E10000, band 0.02 floor 0.0002, approach penalty 300, steps ≤ 0.1 h", 10000.0, math.inf,
     0.02, {**APPROACH, "relative_step": 0.1, "band_floor": 0.0002}),
    ("flat E1000, band 0.02, approach penalty 300, steps ≤ 0.1 h", 1000.0, math.inf, 0.02,
     {**APPROACH, "relative_step": 0.1}),
    # the increment-converged settings together: Newton 1e-8, the secant predictor, steps ≤ 0.1 h
    # and the band's floor 0.0002 of R; and a softer approach penalty under 1e-8 and the secant
    ("flat E10000, band 0.02 floor 0.0002, approach penalty 300, steps ≤ 0.1 h, Newton 1e-8, secant",
     10000.0, math.inf, 0.02,
     {**APPROACH, "relative_step": 0.1, "band_floor": 0.0002, "tol": 1e-8, "predictor": "secant"}),
    ("flat E10000, band 0.02, approach penalty 150, Newton 1e-8, secant", 10000.0, math.inf, 0.02,
     {**APPROACH, "penalty": 150.0, "tol": 1e-8, "predictor": "secant"}),
    # the same on a mesh refined 1.5× everywhere (``density``): the plastic zone under the
    # contact, not only the surface band, in smaller elements
    ("flat E10000, mesh density 1.5, band 0.02, approach penalty 150, Newton 1e-8, secant", 10000.0,
     math.inf, 0.02, {**APPROACH, "penalty": 150.0, "tol": 1e-8, "predictor": "secant", "density": 1.5}),
    # the same with the tangents Cholesky refuses factored shifted (``definite_shift``) instead of
    # by LDLᵀ: no increment fails, so none cuts the later steps down
    ("flat E10000, mesh density 1.5, band 0.02, approach penalty 150, Newton 1e-8, secant, refused "
     "tangents shifted 0.1", 10000.0, math.inf, 0.02,
     {**APPROACH, "penalty": 150.0, "tol": 1e-8, "predictor": "secant", "density": 1.5,
      "definite_shift": 0.1}),
]
BANDS = ((0.01, 0.03), (0.03, 0.1), (0.1, 0.3), (0.3, 1.2))


def measure(E: float, indenter: float, band: float, options: dict, h_max: float = 0.3) -> dict:
    """One run and its scatter figures (h_max in units of the smaller radius); ``options``: the
    solver's, the band's smallest size ``band_floor`` (``mesh.build_mesh``) and the mesh
    ``density`` if given."""
    options = dict(options)
    floor = options.pop("band_floor", None)
    density = options.pop("density", 1.0)
    solver = IndentationSolver(Material(E=E, nu=0.3, sigma_y=1.0), 1.0, RigidObstacle(indenter),
                               density=density, edge_band=band, band_floor=floor,
                               options=SolverOptions(**options))
    res = solver.run(h_max * min(1.0, indenter))
    h, F, a = res.h, res.F, res.a
    m = a >= 0.01
    by_band = {}
    for lo, hi in BANDS:
        sel = m & (a >= lo) & (a < hi)
        by_band[f"{lo:g}-{hi:g}"] = scatter(h[sel], F[sel]) if sel.sum() >= 11 else None
    t = res.timings
    return {"date_utc": datetime.now(UTC).strftime("%Y-%m-%d"), "newton_tol": solver.options.tol,
            "predictor": solver.options.predictor, "definite_shift": solver.options.definite_shift,
            "linear": solver.linear.stats, "status": res.status, "n_dofs": solver.disc.n_dofs,
            "wall_s": t["wall_s"], "rejected_increments": t["rejected_increments"],
            "increments": t["increments"], "newton_iterations": t["newton_iterations"],
            "scatter_F": scatter(h, F, m), "scatter_a": scatter(h, a, m),
            "scatter_F_by_a_band": by_band, "F_end": float(F[-1]), "a_end": float(a[-1])}


def _method(r: dict) -> str:
    """The contact discretisation of a result, for the chart's legend."""
    band = f"band {r['edge_band']:g}" if r["edge_band"] else "default mesh"
    if r.get("density", 1.0) != 1.0:
        band = f"mesh {r['density']:g}×, {band}"
    if r.get("definite_shift"):
        band = f"{band}, refused tangents shifted"
    if r.get("penalty_scale") == "approach":
        return f"{band}, penalty over edges ∝ p_m/h"
    if r.get("penalty"):
        return f"{band}, penalty over edges ∝ E/ℓ"
    return f"{band}, exact nodal contact"


def _scene(r: dict) -> str:
    ind = r["indenter_radius"]
    where = "flat" if ind == "inf" else f"R₂={ind:g}"
    return f"{where}, E/σY {r['E_over_sigma_y']:g}"


def chart(results: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.5, 5.5))
    methods = sorted({_method(r) for r in results})
    markers = "osD^vP*X"
    for k, m in enumerate(methods):
        sel = [r for r in results if _method(r) == m]
        ax.scatter([r["wall_s"] for r in sel], [100 * r["scatter_F"] for r in sel], s=36,
                   marker=markers[k % len(markers)], label=m)
        for r in sel:
            ax.annotate(_scene(r), (r["wall_s"], 100 * r["scatter_F"]), fontsize=6.5,
                        xytext=(4, 2), textcoords="offset points")
    ax.axhline(0.5, color="grey", ls="--", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time to h/R = 0.3 [s]")
    ax.set_ylabel("FE scatter of F [%] (a/R ≥ 0.01)")
    ax.set_title("Smoothness of the FE force against its cost (dashed: 0.5 % target)")
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports/fem", help="output folder")
    ap.add_argument("--only", type=int, nargs="*", help="indices into CASES (default: all)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = []
    earlier = out / "smoothness.json"
    kept = {r["label"]: r for r in json.loads(earlier.read_text())} if args.only and earlier.exists() else {}
    for i, (label, E, ind, band, options) in enumerate(CASES):
        if args.only and i not in args.only:
            if label in kept:  # an earlier measurement of a case not run now
                results.append(kept[label])
            continue
        r = {"label": label, "E_over_sigma_y": E, "indenter_radius": ind if np.isfinite(ind) else "inf",
             "edge_band": band, "penalty": options.get("penalty"),
             "segment_points": options.get("segment_points", 0),
             "penalty_scale": options.get("penalty_scale", "modulus"),
             "band_floor": options.get("band_floor"), "relative_step": options.get("relative_step"),
             "density": options.get("density", 1.0),
             **measure(E, ind, band, options)}
        results.append(r)
        print(f"{label}: scatter F {100 * r['scatter_F']:.2f} %, a {100 * r['scatter_a']:.2f} %, "
              f"{r['wall_s']:.0f} s, {r['n_dofs']} dofs", flush=True)
        (out / "smoothness.json").write_text(json.dumps(results, indent=2) + "\n")
    # the kept cases listed after the last re-measured one
    (out / "smoothness.json").write_text(json.dumps(results, indent=2) + "\n")
    chart(results, out / "smoothness.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
