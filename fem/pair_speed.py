"""Two bodies at the cost of one: the equal-hardness pairs with the approach-scaled penalty.

Two plastic spheres of equal yield stress need penalty contact (README, "Contact"). With the
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
phase (:func:`iteration_split`), which is where a pair's cost against the flat's is read.

``python -m spherecontact.fem.pair_speed --out reports/fem`` → ``approach_pairs.json`` (~4 min);
``--segment-points 3``: the same with the penalty at 3 Gauss points per edge (two passes, the
convention of campaign v2's pairs of equal yield stress) → ``approach_pairs_points3.json``. Their
smooth split differs from the stored nodal runs' by design (README, "Contact").
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..data import Database
from .design import load_campaign
from .io import run_indentation
from .reproduce import compare_loading
from .solver import PHASES, SolverOptions
from .verification_pair import HERTZ_PAIR, hertz_figures

#: the equal-hardness pairs of campaign v1 (penalty contact, default mesh, h/R 0.3)
CASES = ("two-pp-E200-nu0.3-vs-R2", "two-pp-E200-nu0.3-vs-R4", "two-pp-E200-nu0.3-vs-E600")
#: relative penalty of the approach scaling (the bodies sink in by about h/P, bounded)
PENALTY = 3000.0
#: the issue's target: a pair within this many times body 1's run on a flat
TARGET_RATIO = 3.0


def split_difference(stored: dict, new: dict, h_min: float) -> float:
    """Largest |h₁/h (new) − h₁/h (stored)| at the stored loading approaches in [h_min, new's end]."""
    h = np.asarray(stored["h"], dtype=float)
    on = (np.asarray(stored.get("branch", np.zeros(h.size))) == 0) & (h >= h_min) & (h <= new["h"][-1])
    mine = np.interp(h[on], new["h"], new["h1"] / new["h"])
    return float(np.max(np.abs(mine - np.asarray(stored["h1"])[on] / h[on])))


def pair_kwargs(case, penalty: float = PENALTY, segment_points: int = 0) -> dict:
    """The stored pair's run with the approach-scaled penalty (at the nodes, or at
    ``segment_points`` Gauss points per edge), without cycles or a wall limit."""
    kw = case.run_kwargs()
    kw["unload_at"] = None
    kw["options"] = replace(kw["options"], penalty=penalty, penalty_scale="approach",
                            linear_solver="cholesky", max_wall_s=math.inf,
                            segment_points=segment_points)
    return kw


def flat_kwargs(case) -> dict:
    """Body 1 of the pair alone on a rigid flat, same mesh, the solver's default options."""
    kw = case.run_kwargs()
    return {"material": kw["material"], "radius": kw["radius"], "h_max": kw["h_max"],
            "density": kw["density"], "element": kw["element"], "edge_band": kw["edge_band"],
            "band_floor": kw["band_floor"]}


def _timed(kw: dict):
    t0 = time.perf_counter()
    res = run_indentation(**kw)
    return res, time.perf_counter() - t0


def phase_split(timings: dict) -> dict:
    """Milliseconds per Newton iteration of each of :data:`~.solver.PHASES` the run timed (timings
    stored before a phase was split off lack it)."""
    n = max(timings["newton_iterations"], 1)
    return {k: round(1e3 * timings[f"{k}_s"] / n, 2) for k in PHASES if f"{k}_s" in timings}


def iteration_split(timings: dict) -> dict:
    """Milliseconds per Newton iteration: the whole and :func:`phase_split`."""
    n = max(timings["newton_iterations"], 1)
    return {"total": round(1e3 * timings["wall_s"] / n, 2), **phase_split(timings)}


def check_case(case, stored, flat_wall: float, penalty: float = PENALTY, segment_points: int = 0) -> dict:
    res, wall = _timed(pair_kwargs(case, penalty, segment_points))
    R = min(case.inputs["radius"], case.inputs["radius2"])
    cmp = compare_loading(stored.curves, res.curves, 0.01 * R)
    return {"case": case.name, "penalty": penalty, "segment_points": segment_points,
            "status": res.status, "reason": res.reason,
            "h_end": float(res.h[-1]), "wall_s": wall, "increments": res.timings["increments"],
            "newton_iterations": res.timings["newton_iterations"], "n_dofs": res.inputs["n_dofs"],
            "ms_per_iteration": iteration_split(res.timings),
            "wall_s_stored": float(stored.provenance.get("wall_s", np.nan)),
            "wall_over_body1_flat": wall / flat_wall, "target_ratio": TARGET_RATIO,
            "vs_stored": cmp, "split_max": split_difference(stored.curves, res.curves, 0.01 * R)}


def hertz_check(penalty: float = PENALTY, segment_points: int = 0) -> dict:
    """The elastic pair of ``make verify-pair``'s Hertz check (2× mesh) with the approach-scaled
    penalty, and its figures (``verification_pair.hertz_figures``)."""
    options = SolverOptions(penalty=penalty, penalty_scale="approach", segment_points=segment_points)
    res, wall = _timed({**HERTZ_PAIR, "density": 2.0, "options": options})
    run = {"curves": res.curves, "wall_s": wall, "n_dofs": res.inputs["n_dofs"]}
    return {"status": res.status, **hertz_figures(run)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default="data/reference.h5")
    ap.add_argument("--campaign", default="data/campaign.toml")
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--penalty", type=float, default=PENALTY)
    ap.add_argument("--segment-points", type=int, default=0, choices=range(0, 9), metavar="N",
                    help="Gauss points per surface edge for the penalty (0: at the nodes; 1-8)")
    args = ap.parse_args(argv)
    db = Database(args.db)
    cases = {c.name: c for c in load_campaign(args.campaign).cases}
    flats: dict[str, float] = {}  # body 1's flat run, once per distinct body 1 and mesh
    flat_split: dict[str, dict] = {}
    rows = []
    for name in CASES:
        case = cases[name]
        key = json.dumps({k: str(v) for k, v in flat_kwargs(case).items()}, sort_keys=True)
        if key not in flats:
            flat, flats[key] = _timed(flat_kwargs(case))
            flat_split[key] = {"newton_iterations": flat.timings["newton_iterations"],
                               "ms_per_iteration": iteration_split(flat.timings)}
            print(f"body 1 on a flat: {flats[key]:.1f} s ({flat.status})", flush=True)
        row = check_case(case, db.run(case.key), flats[key], args.penalty, args.segment_points)
        row["wall_s_body1_flat"] = flats[key]
        row["body1_flat"] = flat_split[key]
        rows.append(row)
        F, a = row["vs_stored"]["F"], row["vs_stored"]["a"]
        print(f"{name}: {row['status']} to h/R {row['h_end']:.3f} in {row['wall_s']:.1f} s "
              f"({row['wall_over_body1_flat']:.2f}x body 1's flat, stored run {row['wall_s_stored']:.0f} s); "
              f"F {100 * F['systematic']:+.2f} % (max {100 * F['max']:.2f}, scatter stored "
              f"{100 * F['stored_scatter']:.2f} / new {100 * F['new_scatter']:.2f}), a "
              f"{100 * a['systematic']:+.2f} %, split {100 * row['split_max']:.2f} points", flush=True)
    hz = hertz_check(args.penalty, args.segment_points)
    print(f"elastic pair vs Hertz (E*, R*): F against a within {hz['F_vs_a_max_pct']:.2f} % (mean "
          f"{hz['F_vs_a_mean_pct']:+.2f} %), h1/h2 within {hz['h1_over_h2_dev_pct_small_h']:.2f} % at "
          f"a/R <= 0.02 ({hz['h1_over_h2_dev_pct_all']:.2f} % over the run)", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    points = args.segment_points
    name = f"approach_pairs_points{points}.json" if points else "approach_pairs.json"
    (out / name).write_text(json.dumps({"pairs": rows, "hertz": hz}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
