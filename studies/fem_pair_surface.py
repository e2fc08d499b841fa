"""Sawtooth of the contact surfaces in the stored two-body runs.

A smooth surface of curvature κ sampled at nodes Δs apart has second differences
z_{i+1} − 2 z_i + z_{i−1} ≈ κ Δs², the same at corner and at midside nodes of the quadratic
edges. A node-scale sawtooth adds ± the same amount at alternate nodes. Its size per body is the
**alternation**: half the difference between the mean second difference centred on corner nodes
and the mean centred on midside nodes, over the surface nodes within ``ZONE`` × the largest
contact radius, in the final state of the run. The rms second difference is reported beside it.

In two-pass nodal penalty contact both surfaces take the same sawtooth, corner nodes pressed into
each body and midside nodes standing out; surfaces of that shape that slide past each other ride
over each other's bumps, which frictionless contact should not have to do (fem/README.md, "Smoothness of
F"; data/README.md, "Surface band of the pairs").

The bodies' meshes are rebuilt from the run's inputs (gmsh is deterministic) to find the surface
nodes in the stored final mesh; a run whose stored mesh does not match is reported as such.

``python studies/fem_pair_surface.py --db data/reference_v2.h5 --out reports/fem``
→ ``sawtooth_pairs.json`` (about 15 s for campaign v2's 10 pairs). Campaign v1's nodal-penalty
pairs are in its database, which is in the git history only:
``git show 3667b84:data/reference.h5 > data/reference.h5``, then ``--db`` it too.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from spherecontact.data import Database
from spherecontact.fem.twobody import TwoBodySolver

#: the surface nodes within this fraction of the largest contact radius (reference radius)
ZONE = 0.8


def second_differences(z: np.ndarray) -> np.ndarray:
    """z_{i+1} − 2 z_i + z_{i−1} along a node sequence (the interior nodes)."""
    z = np.asarray(z, dtype=float)
    return z[2:] - 2.0 * z[1:-1] + z[:-2]


def alternation(z: np.ndarray, first_corner: bool = True) -> float:
    """Half the difference of the mean second difference centred on corner nodes and that centred
    on midside nodes (nodes alternate corner, midside, …; ``first_corner``: z[0] is a corner).
    Positive: the corners stand out (away from the body's inside, in z as given)."""
    d2 = second_differences(z)
    if d2.size < 2:
        raise ValueError(f"need at least 4 nodes for an alternation, got {np.size(z)}")
    # d2[k] is centred on node k + 1: a midside when z[0] is a corner and k is even
    mid, corner = (d2[0::2], d2[1::2]) if first_corner else (d2[1::2], d2[0::2])
    return 0.5 * float(corner.mean() - mid.mean())


def run_surfaces(run) -> dict:
    """Alternation and rms second difference of each body's surface z in the final state of a
    stored two-body ``run`` (``data.Database.run``), within ``ZONE`` × its largest contact radius."""
    inp = run.inputs
    solver = TwoBodySolver(run.material(), inp["radius"], run.material2(), inp["radius2"],
                           density=inp["mesh_density"], element=inp["element"],
                           edge_band=inp.get("edge_band", 0.0), band_floor=inp.get("band_floor"))
    return final_surfaces(solver, run.mesh["X"], run.mesh["u"], float(np.max(run.a)))


def final_surfaces(solver: TwoBodySolver, X: np.ndarray, u: np.ndarray, a_max: float) -> dict:
    """:func:`run_surfaces` on a final mesh (``RunResult.final``'s X (2, n) and u (2n,), both bodies
    in physical coordinates) and the bodies of the ``solver`` that made it."""
    u = np.asarray(u).reshape(-1, 2).T
    n1 = solver.bodies[0].hmesh.n_nodes
    if X.shape[1] != n1 + solver.bodies[1].hmesh.n_nodes:
        return {"mesh_matches": False}
    out: dict = {"mesh_matches": True, "a_max": a_max, "zone": ZONE}
    for i, body in enumerate(solver.bodies):
        nodes = body.hmesh.surface + (0 if i == 0 else n1)
        X0 = body.hmesh.X[:, body.hmesh.surface]
        if not np.allclose(np.abs(X[:, nodes]), np.abs(X0)):
            return {"mesh_matches": False}
        z = (X[1, nodes] + u[1, nodes]) * body.zsign  # in the body's own frame: z grows inwards
        inside = np.flatnonzero(X0[0] <= ZONE * a_max)
        if inside.size < 4:
            out[f"body{i + 1}"] = None
            continue
        zz = z[inside]
        out[f"body{i + 1}"] = {"alternation": alternation(zz),
                               "rms_second_difference": float(np.sqrt(np.mean(second_differences(zz) ** 2))),
                               "nodes": int(inside.size)}
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", nargs="+", default=["data/reference_v2.h5"],
                    help="reference databases whose two-body runs are read (default: campaign v2's)")
    ap.add_argument("--out", default="reports/fem")
    args = ap.parse_args(argv)
    rows = []
    for path in args.db:
        db = Database(path)
        for rec in db.records():
            run = db.run(rec.key)
            if run.scene != "two_body":
                continue
            options = run.solver_options()
            row = {"database": path, "set": rec.set, "case": rec.case, "key": rec.key,
                   "contact": "exact" if options.penalty is None else "penalty",
                   "segment_points": options.segment_points, **run_surfaces(run)}
            rows.append(row)
            bodies = [row.get(f"body{i}") for i in (1, 2)]
            text = "; ".join(f"body {i + 1} alternation {b['alternation']:+.1e} R, "
                             f"rms {b['rms_second_difference']:.1e} R"
                             for i, b in enumerate(bodies) if b) or "mesh does not match"
            print(f"{rec.case} ({row['contact']}): {text}", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sawtooth_pairs.json").write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
