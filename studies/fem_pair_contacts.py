"""Which split is right: equal-hardness pairs under five contact discretisations.

Two spheres of equal yield stress share the approach h = h₁ + h₂ in a way that the contact
discretisation can move where the interface slides (data/README.md, "Surface band of the
pairs"). Each scene is run with the approach-scaled penalty (P = 3000, no cycles) and

* ``nodal``: the two-pass nodal penalty of the reference runs;
* ``points``: 3 Gauss points per slave edge, each its own penalty, both bodies in turn
  (``segment_scheme`` "points");
* ``mortar``: one pass of the softer body's weighted gaps (``segment_scheme`` "mortar",
  2 points per half edge; :class:`~.twobody.MortarContactPass`);
* ``mortar, other slave``: the same with the other body's weighted gaps;
* ``mortar, Catmull-Rom master``: the softer body's weighted gaps against the Catmull–Rom curve
  of the other contacts instead of the master's own edges made C¹ (``segments.SMOOTH_EDGE``).

The scenes: campaign v1's pairs E₂ = 3E₁ and R₂ = 2R₁ on the surface band, and two equal-radius
pairs on the default mesh, E₂ = 1.05 E₁ and identical spheres. One-pass mortar's answer must not
depend on which body is the slave; where it does, the split is ill-conditioned. Recorded per
run: status, end, wall time, h₁/h and F at ``APPROACHES``, and the corner/midside sawtooth of
both final surfaces (:func:`~.pair_surface.final_surfaces`).

``python studies/fem_pair_contacts.py --out reports/fem`` → ``split_contacts.json``
(about 35 min on two cores). ``--mesh-density 2 --scenes 'E2 = 3 E1' --contacts points`` →
``split_contacts_density2.json``: whether the smooth split converges (about 18 min).
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from fem_pair_surface import final_surfaces

from spherecontact.fem.solver import SolverOptions
from spherecontact.fem.twobody import ContactPass, MortarContactPass, SegmentPairWarning, TwoBodySolver
from spherecontact.model.material import Material

#: relative penalty of the approach scaling (the bodies sink in by about h/P)
PENALTY = 3000.0
#: approaches (h/R of the smaller sphere) at which the split and F are read
APPROACHES = (0.01, 0.02, 0.04, 0.05, 0.1, 0.13, 0.15, 0.2)
CONTACTS = ("nodal", "points", "mortar", "mortar, other slave", "mortar, Catmull-Rom master")


@dataclass(frozen=True)
class Scene:
    """A pair of spheres of equal yield stress (body 1: E/σY 200, ν 0.3, R₁ = 1)."""

    name: str
    E2: float
    radius2: float
    edge_band: float
    h_max: float


SCENES = (
    # campaign v1's pairs two-pp-E200-nu0.3-vs-E600 and -vs-R2 on the band mesh
    Scene("E2 = 3 E1", 600.0, 1.0, 0.03, 0.2),
    Scene("R2 = 2 R1", 200.0, 2.0, 0.03, 0.15),
    Scene("E2 = 1.05 E1", 210.0, 1.0, 0.0, 0.2),
    Scene("E2 = E1", 200.0, 1.0, 0.0, 0.2),
)


def pair_solver(scene: Scene, contact: str, density: float = 1.0) -> TwoBodySolver:
    """The scene's solver with ``contact`` (one of :data:`CONTACTS`) on the mesh of ``density``."""
    seg = {"nodal": (0, "points"), "points": (3, "points")}.get(contact, (2, "mortar"))
    opts = SolverOptions(penalty=PENALTY, penalty_scale="approach", segment_points=seg[0],
                         segment_scheme=seg[1])
    m1 = Material(E=200.0, nu=0.3, sigma_y=1.0)
    m2 = Material(E=scene.E2, nu=0.3, sigma_y=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SegmentPairWarning)
        s = TwoBodySolver(m1, 1.0, m2, scene.radius2, density=density, options=opts,
                          edge_band=scene.edge_band)
    if contact == "mortar, other slave":
        s.slave, s.master = s.master, s.slave
        s.passes = [MortarContactPass(s.slave, s.master, s.n_dofs, 1.0, 2)]
    elif contact == "mortar, Catmull-Rom master":
        s.passes = [MortarContactPass(s.slave, s.master, s.n_dofs, 1.0, 2, smooth_edges=False)]
    s.contact = ContactPass(s.slave, s.master, s.n_dofs, 1.0)
    s.candidates = s.contact.candidates
    return s


def run_one(scene: Scene, contact: str, density: float = 1.0) -> dict:
    """One scene with one contact: the figures of the module docstring."""
    s = pair_solver(scene, contact, density)
    t0 = time.perf_counter()
    res = s.run(scene.h_max)
    wall = time.perf_counter() - t0
    h, F, h1 = (np.asarray(res.curves[k], dtype=float) for k in ("h", "F", "h1"))
    at = [x for x in APPROACHES if x <= h[-1] * (1 + 1e-3)]  # h_max itself, reached to round-off
    return {"scene": scene.name, "contact": contact, "status": res.status, "reason": res.reason,
            "h_end": float(h[-1]), "wall_s": wall, "slave": res.inputs["slave_body"],
            "mesh_density": density, "n_dofs": s.n_dofs,
            "approaches": at, "split": [float(np.interp(x, h, h1 / h)) for x in at],
            "F": [float(np.interp(x, h, F)) for x in at],
            "surfaces": final_surfaces(s, res.final["X"], res.final["u"], float(np.max(res.a)))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--mesh-density", type=float, default=1.0,
                    help="mesh density (2: every size halved); not 1: written to "
                         "split_contacts_density<D>.json (at 1, a subset of scenes or contacts "
                         "goes to split_contacts_subset.json, the full report is kept)")
    ap.add_argument("--scenes", help="comma-separated scene names (default: all), e.g. 'E2 = 3 E1'")
    ap.add_argument("--contacts", help=f"comma-separated contacts (default: all of {', '.join(CONTACTS)})")
    args = ap.parse_args(argv)
    names = {s.name for s in SCENES}
    scenes = [s.strip() for s in args.scenes.split(",")] if args.scenes else sorted(names)
    contacts = [c.strip() for c in args.contacts.split(",")] if args.contacts else list(CONTACTS)
    for given, allowed, what in ((scenes, names, "--scenes"), (contacts, CONTACTS, "--contacts")):
        bad = [x for x in given if x not in allowed]
        if bad:
            ap.error(f"{what}: unknown {bad[0]!r} (allowed: {', '.join(sorted(allowed))})")
    if not args.mesh_density > 0.0:
        ap.error(f"--mesh-density must be > 0, got {args.mesh_density}")
    jobs = [(scene, c) for scene in SCENES for c in CONTACTS if scene.name in scenes and c in contacts]
    rows = []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        futures = [pool.submit(run_one, *job, args.mesh_density) for job in jobs]
        for done, fut in enumerate(as_completed(futures), 1):
            row = fut.result()
            rows.append(row)
            split = " ".join(f"{x:g}:{v:.3f}" for x, v in zip(row["approaches"], row["split"], strict=True))
            print(f"[{done}/{len(jobs)}] {row['scene']}, {row['contact']}: {row['status']} to h/R "
                  f"{row['h_end']:.3f} in {row['wall_s']:.0f} s; h1/h {split}", flush=True)
    order = {job: i for i, job in enumerate((s.name, c) for s, c in jobs)}
    rows.sort(key=lambda r: order[(r["scene"], r["contact"])])
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    subset = len(jobs) < len(SCENES) * len(CONTACTS)
    name = ("split_contacts" + (f"_density{args.mesh_density:g}" if args.mesh_density != 1.0 else
                                "_subset" if subset else "") + ".json")
    (out / name).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
