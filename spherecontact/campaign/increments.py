"""The increment-converged first loadings of a database set, stored as data.

``spherecontact campaign increments --db data/reference_v2.h5 --set validation
--out data/increments_v2.json`` re-runs the first loading of every converged one-body run of
the set with the increments also bounded by the approach (:func:`spherecontact.fem.increments.rerun`)
and writes the re-run curves with their deviation from the stored ones per decade of h
(:func:`spherecontact.fem.increments.measure_run`); the validation's small-contact section
reads that file.
"""

from __future__ import annotations

import json
import multiprocessing
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

from ..data import Database
from ..fem.increments import H_END, RELATIVE_STEP, measure_run

__all__ = ["NOTE", "measure", "one_body_cases", "collect", "check_window", "summary_line"]

#: what the stored deviations mean (the file's ``note``)
NOTE = ("ln(stored/new) per decade of h over the smaller radius, largest |.| (and the "
        "decade's mean under 'mean'), at the stored loading increments after the first "
        "ones (a: where a >= 0.01 of the smaller radius); new: increments dh <= "
        "relative_step h (null: no such bound) and dh <= strain_increment a (null: "
        "the solver's)")


def measure(db: Database, case: str, relative_step: float | None, h_end: float = H_END,
            strain_increment: float | None = None) -> dict:
    """:func:`~spherecontact.fem.increments.measure_run` of the stored run of ``case``, with its
    case name and database key."""
    rec = next(r for r in db.records() if r.case == case)
    return {"case": case, "key": rec.key,
            **measure_run(rec.inputs, db.run(rec.key), relative_step, h_end, strain_increment)}


def _measure_in_worker(args: tuple) -> dict:
    db_path, case, *steps = args
    return measure(Database(db_path), case, *steps)


def one_body_cases(db: Database, set_name: str) -> list[str]:
    """The cases of ``set_name`` with one deformable body (rigid flat or sphere), sorted."""
    return sorted(r.case for r in db.records(set=set_name)
                  if r.inputs.get("scene") in ("rigid_flat", "rigid_sphere") and r.status == "converged")


def check_window(relative_step: float, h_end: float) -> None:
    """ValueError unless 0 ≤ ``relative_step`` ≤ 10 (0: no bound) and 0 < ``h_end`` ≤ 0.5."""
    if not 0.0 <= relative_step <= 10.0:
        raise ValueError(f"--relative-step must lie in [0, 10] (0: no bound), got {relative_step:g}")
    if not 0.0 < h_end <= 0.5:
        raise ValueError(f"--h-end must lie in (0, 0.5] (units of the smaller radius), got {h_end:g}")


def collect(db_path, out, set_name: str = "validation", cases=None, relative_step: float = RELATIVE_STEP,
            h_end: float = H_END, strain_increment: float | None = None, workers: int = 2,
            on_case: Callable[[str, dict], None] | None = None, extra: dict | None = None) -> dict:
    """Re-run the cases (``cases``, default every converged one-body case of ``set_name``) on
    ``workers`` processes and write the file ``out`` after each (``date_utc``, ``db``, ``h_end``,
    ``note``, the ``extra`` keys, ``cases``); ``relative_step`` 0 is no bound by the approach."""
    check_window(relative_step, h_end)
    db = Database(db_path)
    cases = list(cases) if cases else one_body_cases(db, set_name)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    results = {"date_utc": datetime.now(UTC).strftime("%Y-%m-%d"), "db": str(db_path), "h_end": h_end,
               "note": NOTE, **(extra or {}), "cases": []}
    work = [(str(db_path), c, relative_step or None, h_end, strain_increment) for c in cases]
    with ProcessPoolExecutor(max(1, workers), mp_context=multiprocessing.get_context("fork")) as pool:
        for case, r in zip(cases, pool.map(_measure_in_worker, work), strict=True):
            results["cases"].append(r)
            if on_case is not None:
                on_case(case, r)
            out.write_text(json.dumps(results, separators=(",", ":")) + "\n")
    return results


def summary_line(case: str, r: dict) -> str:
    """One line per re-run case: the largest deviations of F and a, the increments, the wall time."""
    a = f"{100 * r['a']['largest']:+.2f} %" if r["a"] else "—"
    return (f"{case}: F {100 * r['F']['largest']:+.2f} %, a {a} "
            f"({r['stored_increments']} → {r['new_increments']} increments, {r['wall_s']:.0f} s)")
