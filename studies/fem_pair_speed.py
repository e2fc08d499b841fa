"""Two bodies at the cost of one: the equal-hardness pairs with the approach-scaled penalty.

Two plastic spheres of equal yield stress need penalty contact (fem/README.md, "Contact"). With the
stiffness set by the modulus (k_N = P E*/ℓ, P = 100) the campaign's pairs took 20–35 min to
h/R 0.3; with k_N = P p_m/h (``penalty_scale`` "approach", bounded so that the bodies sink into
each other by at most ``twobody.APPROACH_DEPTH`` of a surface node spacing) the contact is
soft enough for Newton and stiff enough for the answer. For each equal-hardness pair of
campaign v1 (radius ratio 2 and 4, E ratio 3; default mesh, to h/R 0.3) this re-runs the pair
from its stored inputs with that penalty (no cycles) and body 1 alone on a rigid flat with the
solver's defaults (exact contact), one run at a time, and compares the pair with its stored
curve (``reproduce.compare_loading``: systematic and largest difference of F and a at the stored
approaches h/R ≥ 0.01, beside both curves' FE scatter; the split h₁/h, largest difference in
percentage points). Against an independent reference: the elastic dissimilar pair of
``make verify-pair`` (E₂/E₁ = 3, R₂ = 2R₁, ν 0.3 / 0.2, 2× mesh) with the same penalty, F against
the reference contact radius vs Hertz with E*, R* and h₁/h₂ vs E′₂/E′₁ (its limits: 1 % and 2 %).

Each pair's record and its flat run's carry the milliseconds per Newton iteration, whole and by
phase (:func:`~.solver.iteration_split`), which is where a pair's cost against the flat's is read.

The stored pairs are campaign v1's (design ``studies/campaign_v1.toml``); its database is in the
git history only: ``git show 3667b84:data/reference.h5 > data/reference.h5``, then ``--db
data/reference.h5``.

``python studies/fem_pair_speed.py --db data/reference.h5 --out reports/fem`` →
``approach_pairs.json`` (~4 min);
``--segment-points 3``: the same with the penalty at 3 Gauss points per edge (two passes, the
convention of campaign v2's pairs of equal yield stress) → ``approach_pairs_points3.json``. Their
smooth split differs from the stored nodal runs' by design (fem/README.md, "Contact").
``--edge-band 0.03``: the pairs and the flat run on the campaigns' surface-band mesh instead of the
stored default mesh (file name ``…_band0.03.json``); ``--interleave N``: each pair and its flat run
then alternately N times (:func:`interleaved`), the ratio a drifting machine reads fairly.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from fem_reproduce import compare_loading
from fem_verification_pair import HERTZ_PAIR, hertz_figures

from spherecontact.campaign.design import load_campaign
from spherecontact.data import Database
from spherecontact.fem.io import run_indentation
from spherecontact.fem.mesh import check_band_floor, check_edge_band
from spherecontact.fem.solver import SolverOptions, iteration_split

#: the equal-hardness pairs of campaign v1 (penalty contact, default mesh, h/R 0.3)
CASES = ("two-pp-E200-nu0.3-vs-R2", "two-pp-E200-nu0.3-vs-R4", "two-pp-E200-nu0.3-vs-E600")
#: relative penalty of the approach scaling (the bodies sink in by about h/P, bounded)
PENALTY = 3000.0
#: the issue's target: a pair within this many times body 1's run on a flat
TARGET_RATIO = 3.0
#: campaign v1's database, retired from the tree: the last commit that has it
V1_DATABASE = "git show 3667b84:data/reference.h5 > data/reference.h5"


def split_difference(stored: dict, new: dict, h_min: float) -> float:
    """Largest |h₁/h (new) − h₁/h (stored)| at the stored loading approaches in [h_min, new's end]."""
    h = np.asarray(stored["h"], dtype=float)
    on = (np.asarray(stored.get("branch", np.zeros(h.size))) == 0) & (h >= h_min) & (h <= new["h"][-1])
    mine = np.interp(h[on], new["h"], new["h1"] / new["h"])
    return float(np.max(np.abs(mine - np.asarray(stored["h1"])[on] / h[on])))


def _meshed(kw: dict, mesh: dict | None) -> dict:
    """``kw`` with the surface band of ``mesh`` ({"edge_band": …, "band_floor": …}; None: the
    stored run's mesh)."""
    return kw if mesh is None else {**kw, **mesh}


def pair_kwargs(case, penalty: float = PENALTY, segment_points: int = 0, mesh: dict | None = None) -> dict:
    """The stored pair's run with the approach-scaled penalty (at the nodes, or at
    ``segment_points`` Gauss points per edge), without cycles or a wall limit, on the stored
    mesh or on ``mesh`` (:func:`_meshed`)."""
    kw = _meshed(case.run_kwargs(), mesh)
    kw["unload_at"] = None
    kw["options"] = replace(kw["options"], penalty=penalty, penalty_scale="approach",
                            linear_solver="cholesky", max_wall_s=math.inf,
                            segment_points=segment_points)
    return kw


def flat_kwargs(case, mesh: dict | None = None) -> dict:
    """Body 1 of the pair alone on a rigid flat, same mesh, the solver's default options."""
    kw = _meshed(case.run_kwargs(), mesh)
    return {"material": kw["material"], "radius": kw["radius"], "h_max": kw["h_max"],
            "density": kw["density"], "element": kw["element"], "edge_band": kw["edge_band"],
            "band_floor": kw["band_floor"]}


def _timed(kw: dict):
    t0 = time.perf_counter()
    res = run_indentation(**kw)
    return res, time.perf_counter() - t0


def check_case(case, stored, flat_wall: float, penalty: float = PENALTY, segment_points: int = 0,
               mesh: dict | None = None) -> dict:
    res, wall = _timed(pair_kwargs(case, penalty, segment_points, mesh))
    R = min(case.inputs["radius"], case.inputs["radius2"])
    cmp = compare_loading(stored.curves, res.curves, 0.01 * R)
    return {"case": case.name, "penalty": penalty, "segment_points": segment_points,
            "edge_band": res.inputs.get("edge_band"), "band_floor": res.inputs.get("band_floor"),
            "status": res.status, "reason": res.reason,
            "h_end": float(res.h[-1]), "wall_s": wall, "increments": res.timings["increments"],
            "newton_iterations": res.timings["newton_iterations"], "n_dofs": res.inputs["n_dofs"],
            "ms_per_iteration": iteration_split(res.timings),
            "wall_s_stored": float(stored.provenance.get("wall_s", np.nan)),
            "wall_over_body1_flat": wall / flat_wall, "target_ratio": TARGET_RATIO,
            "vs_stored": cmp, "split_max": split_difference(stored.curves, res.curves, 0.01 * R)}


def interleaved(case, rounds: int, penalty: float = PENALTY, segment_points: int = 0,
                mesh: dict | None = None) -> dict:
    """The pair and body 1's flat run alternately, ``rounds`` times: the machine's speed drifts
    by 10–25 % within minutes, and a ratio of two runs made minutes apart carries that drift.
    Returns each round's walls and ratio, and the ratio of the sums."""
    rows = []
    for _ in range(rounds):
        flat = _timed(flat_kwargs(case, mesh))[1]
        pair = _timed(pair_kwargs(case, penalty, segment_points, mesh))[1]
        rows.append({"flat_s": round(flat, 2), "pair_s": round(pair, 2), "ratio": round(pair / flat, 3)})
    return {"rounds": rows, "ratio": sum(r["pair_s"] for r in rows) / sum(r["flat_s"] for r in rows)}


def hertz_check(penalty: float = PENALTY, segment_points: int = 0) -> dict:
    """The elastic pair of ``make verify-pair``'s Hertz check (2× mesh) with the approach-scaled
    penalty, and its figures (``verification_pair.hertz_figures``)."""
    options = SolverOptions(penalty=penalty, penalty_scale="approach", segment_points=segment_points)
    res, wall = _timed({**HERTZ_PAIR, "density": 2.0, "options": options})
    run = {"curves": res.curves, "wall_s": wall, "n_dofs": res.inputs["n_dofs"]}
    return {"status": res.status, **hertz_figures(run)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", required=True,
                    help="campaign v1's database with the stored pairs (data/reference.h5, in the git "
                         f"history only: {V1_DATABASE})")
    ap.add_argument("--campaign", default="studies/campaign_v1.toml")
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--penalty", type=float, default=PENALTY)
    ap.add_argument("--segment-points", type=int, default=0, choices=range(0, 9), metavar="N",
                    help="Gauss points per surface edge for the penalty (0: at the nodes; 1-8)")
    ap.add_argument("--edge-band", type=float, default=None, metavar="B",
                    help="surface band for the pairs and their flat runs (default: the stored runs' mesh)")
    ap.add_argument("--band-floor", type=float, default=0.003, metavar="L",
                    help="smallest surface element of the band, over R (with --edge-band; "
                         "the mesh's BAND_FLOOR_RANGE)")
    ap.add_argument("--interleave", type=int, default=0, metavar="N",
                    help="then run each pair and its flat run alternately N times (0-10)")
    args = ap.parse_args(argv)
    if not 0 <= args.interleave <= 10:
        ap.error(f"--interleave must be in [0, 10], got {args.interleave}")
    if args.edge_band is not None:  # the mesh's own checks, before any run
        try:
            if check_edge_band(args.edge_band) == 0.0:
                raise ValueError("edge_band 0 is the stored runs' mesh: leave --edge-band out")
        except ValueError as err:
            ap.error(f"--edge-band: {err}")
        try:
            check_band_floor(args.band_floor, args.edge_band)
        except ValueError as err:
            ap.error(f"--band-floor: {err}")
    if not Path(args.db).is_file():
        ap.error(f"--db {args.db}: no such file (campaign v1's database: {V1_DATABASE})")
    mesh = None if args.edge_band is None else {"edge_band": args.edge_band, "band_floor": args.band_floor}
    db = Database(args.db)
    cases = {c.name: c for c in load_campaign(args.campaign).cases}
    flats: dict[str, float] = {}  # body 1's flat run, once per distinct body 1 and mesh
    flat_split: dict[str, dict] = {}
    rows = []
    for name in CASES:
        case = cases[name]
        key = json.dumps({k: str(v) for k, v in flat_kwargs(case, mesh).items()}, sort_keys=True)
        if key not in flats:
            flat, flats[key] = _timed(flat_kwargs(case, mesh))
            flat_split[key] = {"newton_iterations": flat.timings["newton_iterations"],
                               "ms_per_iteration": iteration_split(flat.timings)}
            print(f"body 1 on a flat: {flats[key]:.1f} s ({flat.status})", flush=True)
        row = check_case(case, db.run(case.key), flats[key], args.penalty, args.segment_points, mesh)
        row["wall_s_body1_flat"] = flats[key]
        row["body1_flat"] = flat_split[key]
        rows.append(row)
        F, a = row["vs_stored"]["F"], row["vs_stored"]["a"]
        print(f"{name}: {row['status']} to h/R {row['h_end']:.3f} in {row['wall_s']:.1f} s "
              f"({row['wall_over_body1_flat']:.2f}x body 1's flat, stored run {row['wall_s_stored']:.0f} s); "
              f"F {100 * F['systematic']:+.2f} % (max {100 * F['max']:.2f}, scatter stored "
              f"{100 * F['stored_scatter']:.2f} / new {100 * F['new_scatter']:.2f}), a "
              f"{100 * a['systematic']:+.2f} %, split {100 * row['split_max']:.2f} points", flush=True)
        if args.interleave:
            row["interleaved"] = interleaved(case, args.interleave, args.penalty, args.segment_points, mesh)
            each = ", ".join(f"{r['ratio']:.2f}" for r in row["interleaved"]["rounds"])
            print(f"  interleaved {args.interleave}x: {row['interleaved']['ratio']:.2f}x body 1's flat "
                  f"({each})", flush=True)
    hz = hertz_check(args.penalty, args.segment_points)
    print(f"elastic pair vs Hertz (E*, R*): F against a within {hz['F_vs_a_max_pct']:.2f} % (mean "
          f"{hz['F_vs_a_mean_pct']:+.2f} %), h1/h2 within {hz['h1_over_h2_dev_pct_small_h']:.2f} % at "
          f"a/R <= 0.02 ({hz['h1_over_h2_dev_pct_all']:.2f} % over the run)", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    points = args.segment_points
    name = f"approach_pairs_points{points}" if points else "approach_pairs"
    name += "" if mesh is None else f"_band{args.edge_band:g}"
    name += ".json"
    (out / name).write_text(json.dumps({"pairs": rows, "hertz": hz}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
