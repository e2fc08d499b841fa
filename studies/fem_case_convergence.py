"""Mesh check of stored database runs: the same scene at mesh density 1 and 2.

``make verify-band`` checks the campaign's surface-band mesh on the standard scene (EPP
E/σY = 200). Where the model misses most (``calibration/README.md``, "The ceiling of smooth
terms") the scenes are others; this re-runs a stored case from its recorded inputs (material,
radii, mesh, element, solver options; no unloading cycles) at ``mesh_density`` 1 and 2 and
reads, at the approaches where the density-2 run's contact radius reaches ``A_OVER_R``, the
relative difference of F and a of the density-1 run and of the stored loading curve against
the density-2 run (linear interpolation in ln h). Results accumulate in
``case_convergence.json`` by case name.

    python studies/fem_case_convergence.py --case flat-pp-E1000-nu0.3 [...] --out reports/fem
"""

from __future__ import annotations

import argparse
import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from spherecontact.campaign.design import run_kwargs
from spherecontact.fem.io import run_indentation
from spherecontact.metrics import interp_loglog

__all__ = ["A_OVER_R", "rerun", "differences", "check_case", "main"]

#: contact radii (over R) at which the curves are compared
A_OVER_R = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7)


def rerun(inputs: dict, density: float, h_max: float | None = None) -> dict:
    """The stored run's scene (``Run.inputs`` of a one-body run) at mesh ``density``, without
    cycles; returns wall time, dofs, status and the curves h, F, a."""
    if inputs.get("scene") == "two_body":
        raise ValueError("rerun: one-body scenes only (flat or rigid sphere); got a two-body run")
    kw = run_kwargs(inputs, max_wall_s=math.inf)
    kw.update(density=density, unload_at=None, h_max=kw["h_max"] if h_max is None else h_max)
    t0 = time.perf_counter()
    res = run_indentation(**kw)
    return {"density": density, "status": res.status, "wall_s": time.perf_counter() - t0,
            "n_dofs": res.inputs["n_dofs"], "h": res.h.tolist(), "F": res.F.tolist(), "a": res.a.tolist()}


def differences(reference: dict, others: dict[str, dict], radius: float, at=A_OVER_R) -> dict:
    """{label: {"F@x", "a@x": relative difference against ``reference``}} at the approaches
    where the reference's contact radius is x·radius (x in ``at`` within its range)."""
    h, a = np.asarray(reference["h"]), np.asarray(reference["a"])
    x = np.array([v for v in at if a[0] <= v * radius <= a[-1]])
    h_at = np.exp(np.interp(np.log(x * radius), np.log(a), np.log(h)))
    ref = {q: interp_loglog(h_at, h, reference[q]) for q in ("F", "a")}
    out = {}
    for label, curve in others.items():
        row = {}
        for q in ("F", "a"):
            v = interp_loglog(h_at, curve["h"], curve[q]) / ref[q] - 1.0
            row.update({f"{q}@{xi:g}": float(d) for xi, d in zip(x, v, strict=True) if np.isfinite(d)})
        out[label] = row
    return out


def _stored_loading(run) -> dict:
    """The stored run's loading increments (``Run.reference``: no cycles, no first-step transient)."""
    keep = np.asarray(run.reference, bool)
    return {q: np.asarray(getattr(run, q))[keep].tolist() for q in ("h", "F", "a")}


def check_case(db_path, case: str, workers: int = 2) -> dict:
    """Density 1 and 2 of the stored ``case`` and their differences (module docstring)."""
    from spherecontact.data import Database

    found = Database(db_path).runs(status=None, where=lambda r: r.case == case)
    if not found:
        raise ValueError(f"case {case!r}: no such run in {db_path}")
    rec, run = found[0]
    with ProcessPoolExecutor(workers) as pool:
        d1, d2 = pool.map(rerun, [rec.inputs] * 2, [1.0, 2.0])
    diffs = differences(d2, {"density 1": d1, "stored": _stored_loading(run)}, float(rec.inputs["radius"]))
    brief = lambda d: {k: d[k] for k in ("status", "wall_s", "n_dofs")}  # noqa: E731
    return {"key": rec.key, "density 1": brief(d1), "density 2": brief(d2),
            "relative_to_density_2": diffs,
            "largest": {label: {q: max((abs(v) for k, v in row.items() if k.startswith(q)), default=None)
                                for q in ("F", "a")} for label, row in diffs.items()}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default="data/reference_v2.h5")
    ap.add_argument("--case", nargs="+", required=True, help="case names of one-body runs")
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    path = Path(args.out) / "case_convergence.json"
    report = json.loads(path.read_text()) if path.exists() else {}
    for case in args.case:
        report[case] = check_case(args.db, case, args.workers)
        print(case, {label: {q: f"{100 * v:.2f} %" for q, v in row.items()}
                     for label, row in report[case]["largest"].items()})
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(report, indent=1) + "\n")  # after every case: nothing lost
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
