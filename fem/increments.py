"""Increment convergence of stored reference curves where the contact is still small.

The loading increments are bounded by the strain per step, dh ≤ strain_increment · a
(``SolverOptions``), which allows dh/h ≈ 0.01 c² R/a: about 0.6 at a/R = 0.02, ten increments a
decade of h across the elastic–plastic transition of a stiff sphere. The plastic path taken
over such steps differs from the converged one. This re-runs the first loading of stored
cases, up to the campaign's first unloading approach (``H_END`` of the smaller radius), with
the increments also bounded by the approach, dh ≤ r · h (``SolverOptions.relative_step``), and
compares F and a with the stored curve at its own approaches (loading increments after the
first ones, ``io.reference_mask``; log–log interpolation of the new curve), per decade of h.

``python -m spherecontact.fem.increments --db data/reference_v2.h5 --out reports/fem`` →
``increments_validation.json``: every converged one-body run of the set (``--set``, default
validation; ``--cases`` picks some), with the re-run curves, which the validation report reads
(``validation/increments_report.py``); ~8 min for the 30 validation runs on two workers.
``--h-end 0.3 --relative-step 0 --strain-increment 0.0025 --name …`` checks the whole loading
window instead: the strain bound halved, no bound by the approach (each decade's mean of
ln(stored/new) beside its largest, which a surface node closing at another increment sets).
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from ..data import Database
from ..metrics import interp_loglog
from ..model.run_inputs import material_from_description
from .io import loading_mask, run_indentation
from .solver import SolverOptions

#: the re-run ends at the campaign's first unloading approach (units of the smaller radius)
H_END = 0.01
RELATIVE_STEP = 0.03
#: a is compared where the contact spans several elements, a ≥ A_RESOLVED × the smaller radius
#: (the calibration's filter on the default mesh): below, the fitted edge lies within a pole element
A_RESOLVED = 0.01


def smaller_radius(inputs: dict) -> float:
    """The body's radius or its rigid partner's, the smaller: the length of ``H_END``."""
    return min(float(inputs["radius"]), float(inputs.get("indenter_radius", math.inf)))


def read_reruns(path) -> tuple[dict, dict]:
    """``(key → re-run case, header)`` of a file :func:`main` wrote; the header holds ``h_end``,
    ``date_utc``, ``db`` and ``note`` (what the calibration's ``--converged-fe`` and the validation's
    small-contact section read)."""
    d = json.loads(Path(path).read_text())
    return {c["key"]: c for c in d.pop("cases")}, d


def rerun(inputs: dict, relative_step: float | None, h_end: float = H_END,
          strain_increment: float | None = None):
    """The first loading of a stored one-body case to ``h_end`` (units of the smaller radius),
    increments dh ≤ ``relative_step`` · h (None: no such bound) and dh ≤ ``strain_increment`` · a
    (None: the solver's)."""
    strain = {} if strain_increment is None else {"strain_increment": strain_increment}
    return run_indentation(material_from_description(inputs["material"]), float(inputs["radius"]),
                           h_end * smaller_radius(inputs),
                           indenter_radius=float(inputs.get("indenter_radius", math.inf)),
                           edge_band=float(inputs.get("edge_band", 0.0)),
                           band_floor=inputs.get("band_floor"),
                           options=SolverOptions(relative_step=relative_step, **strain))


def by_decade(h_old, y_old, h_new, y_new, length: float) -> dict:
    """ln(stored/new) of y at the stored approaches, largest |·| per decade of h/``length``
    (keys: the decade's lower end) and over all."""
    dev = np.log(y_old / interp_loglog(h_old, h_new, y_new))
    k = np.floor(np.log10(h_old / length) + 1e-12).astype(int)
    out = {f"1e{d}": float(dev[k == d][np.argmax(np.abs(dev[k == d]))]) for d in np.unique(k)}
    out["largest"] = float(dev[np.argmax(np.abs(dev))])
    out["mean"] = {f"1e{d}": float(dev[k == d].mean()) for d in np.unique(k)}
    return out


def measure(db: Database, case: str, relative_step: float | None, h_end: float = H_END,
            strain_increment: float | None = None) -> dict:
    rec = next(r for r in db.records() if r.case == case)
    run = db.run(rec.key)
    old = {"h": np.asarray(run.h), "F": np.asarray(run.F), "a": np.asarray(run.a)}
    keep = np.asarray(run.reference)  # loading increments without a first step's transient
    L = smaller_radius(rec.inputs)
    t = time.perf_counter()
    new = rerun(rec.inputs, relative_step, h_end, strain_increment)
    wall = time.perf_counter() - t
    keep &= (old["h"] >= new.h[0]) & (old["h"] <= new.h[-1])
    ka = keep & (old["a"] >= A_RESOLVED * L)
    return {"case": case, "key": rec.key, "relative_step": relative_step,
            "strain_increment": strain_increment, "wall_s": round(wall, 1),
            "stored_increments": int(np.count_nonzero(old["h"][loading_mask(run.curves)] <= h_end * L)),
            "new_increments": int(new.h.size),
            "F": by_decade(old["h"][keep], old["F"][keep], new.h, new.F, L),
            "a": by_decade(old["h"][ka], old["a"][ka], new.h, new.a, L) if ka.any() else None,
            "curve": {q: [float(f"{v:.8g}") for v in getattr(new, q)] for q in ("h", "F", "a")}}


def _measure_in_worker(args: tuple) -> dict:
    db_path, case, *steps = args
    return measure(Database(db_path), case, *steps)


def one_body_cases(db: Database, set_name: str) -> list[str]:
    """The cases of ``set_name`` with one deformable body (rigid flat or sphere), sorted."""
    return sorted(r.case for r in db.records(set=set_name)
                  if r.inputs.get("scene") in ("rigid_flat", "rigid_sphere") and r.status == "converged")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default="data/reference_v2.h5")
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--set", default="validation", help="every converged one-body case of this set")
    ap.add_argument("--cases", nargs="*", default=None, help="these cases instead of --set")
    ap.add_argument("--relative-step", type=float, default=RELATIVE_STEP,
                    help=f"increments dh <= this * h (default {RELATIVE_STEP:g}; 0: no such bound)")
    ap.add_argument("--h-end", type=float, default=H_END,
                    help=f"approach the re-runs end at, in units of the smaller radius (default {H_END:g})")
    ap.add_argument("--strain-increment", type=float, default=None,
                    help="increments dh <= this * a (default: the solver's)")
    ap.add_argument("--workers", type=int, default=2, help="processes (one case each at a time)")
    ap.add_argument("--name", default="increments_validation.json", help="file written in --out")
    args = ap.parse_args(argv)
    if not 0.0 <= args.relative_step <= 10.0:
        ap.error(f"--relative-step must lie in [0, 10] (0: no bound), got {args.relative_step:g}")
    if not 0.0 < args.h_end <= 0.5:
        ap.error(f"--h-end must lie in (0, 0.5] (units of the smaller radius), got {args.h_end:g}")
    relative_step = args.relative_step or None
    db = Database(args.db)
    cases = args.cases if args.cases else one_body_cases(db, args.set)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {"date_utc": datetime.now(UTC).strftime("%Y-%m-%d"), "db": args.db, "h_end": args.h_end,
               "note": "ln(stored/new) per decade of h over the smaller radius, largest |.| (and the "
                       "decade's mean under 'mean'), at the stored loading increments after the first "
                       "ones (a: where a >= 0.01 of the smaller radius); new: increments dh <= "
                       "relative_step h (null: no such bound) and dh <= strain_increment a (null: "
                       "the solver's)", "cases": []}
    work = [(args.db, c, relative_step, args.h_end, args.strain_increment) for c in cases]
    with ProcessPoolExecutor(max(1, args.workers), mp_context=multiprocessing.get_context("fork")) as pool:
        done = pool.map(_measure_in_worker, work)
        for case, r in zip(cases, done, strict=True):
            results["cases"].append(r)
            _print(case, r)
            (out / args.name).write_text(json.dumps(results, separators=(",", ":")) + "\n")
    return 0


def _print(case: str, r: dict) -> None:
    a = f"{100 * r['a']['largest']:+.2f} %" if r["a"] else "—"
    print(f"{case}: F {100 * r['F']['largest']:+.2f} %, a {a} "
          f"({r['stored_increments']} → {r['new_increments']} increments, {r['wall_s']:.0f} s)", flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
