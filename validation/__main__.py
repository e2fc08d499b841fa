"""``python -m spherecontact.validation``: the validation report from the reference database.

    python -m spherecontact.validation --db data/reference_v2.h5 \\
        --coefficients model/coefficients.json --thresholds validation/thresholds.toml \\
        --out reports/validation

Writes ``OUT/index.md`` and its PNG charts. Exit status: 0 when every validation run is
within the thresholds, 1 when some run exceeds them (the runs are named on stderr),
2 on bad input (missing database, no validation run, unreadable thresholds or
coefficients).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


def _parser() -> argparse.ArgumentParser:
    from .increments_report import DEFAULT_PATH as CONVERGED_FE

    p = argparse.ArgumentParser(prog="python -m spherecontact.validation",
                                description=__doc__.splitlines()[0])
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--coefficients", default=None,
                   help="model coefficient file (default: the model's default, model/coefficients.json)")
    p.add_argument("--thresholds", default="validation/thresholds.toml", help="thresholds (TOML)")
    p.add_argument("--out", default="reports/validation", help="output directory")
    p.add_argument("--set", default="validation", help="database set to validate on")
    p.add_argument("--studies-set", default="studies", help="database set of the FE studies")
    p.add_argument("--studies-fallback", default="",
                   help="directory of FE verification runs (run_*.json, e.g. reports/fem) added to the "
                        "study runs when the database has no studies set (default: none, so that the "
                        "report depends on the repository's files alone; verification runs are not "
                        "committed)")
    p.add_argument("--mdr", default="data/peers/mdr.json",
                   help="stored LAMMPS mdr curves (JSON; a missing file leaves mdr out)")
    p.add_argument("--converged-fe", default=str(CONVERGED_FE),
                   help="first loadings re-run with increments dh <= r h (make verify-increments; a "
                        "missing file leaves the section out)")
    p.add_argument("--study-runs", default="reports/validation/studies",
                   help="directory of the validation's own study runs (*.json), used with the fallback")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    t0 = time.perf_counter()
    from ..model import load_coefficients
    from .cases import load_cases, load_records
    from .config import load_thresholds
    from .report import build_report

    db = Path(args.db)
    try:
        if not db.is_file():
            raise FileNotFoundError(f"database {db} not found")
        th = load_thresholds(args.thresholds)
        coeffs = load_coefficients(args.coefficients) if args.coefficients else load_coefficients()
        validation = load_cases(db, args.set)
        if not validation:
            raise ValueError(f"{db}: no run in the set {args.set!r}")
        studies = load_cases(db, args.studies_set)
        studies_source = f"database set `{args.studies_set}`"
        if not studies and args.studies_fallback:
            from .fem_reports import load_fallback

            studies = load_fallback(args.studies_fallback, args.study_runs)
            studies_source = (f"FE verification runs `{args.studies_fallback}/run_*.json` and study runs "
                              f"`{args.study_runs}/*.json` (the database has no `{args.studies_set}` "
                              "set)")
        elif not studies:
            from .fem_reports import load_study_files

            studies = load_study_files(args.study_runs)
            studies_source = (f"study runs `{args.study_runs}/*.json` (the database has no "
                              f"`{args.studies_set}` set; `--studies-fallback reports/fem` adds the FE "
                              "verification runs on disk)")
        records = load_records(db, args.set)
        mdr = None
        if args.mdr and Path(args.mdr).is_file():
            from .mdr import load_store

            mdr = load_store(args.mdr)
        from .increments_report import load_converged

        converged = load_converged(args.converged_fe) if args.converged_fe else None
    except (OSError, ValueError) as err:
        print(f"validation: {err}", file=sys.stderr)
        return 2
    compared = {c.key for c in validation}
    skipped = [f"{r.case or r.key} ({r.status}: {r.reason})" for r in records if r.key not in compared]
    res = build_report(validation, studies, coeffs, th, args.out, source=str(db),
                       coeff_path=args.coefficients or "model default", th_path=args.thresholds,
                       skipped=skipped,
                       studies_source=studies_source, mdr=mdr, mdr_source=args.mdr,
                       converged=converged)
    dt = time.perf_counter() - t0
    print(f"validation: {len(res.comparisons)} runs, report {res.path} ({len(res.pngs)} charts), "
          f"{dt:.1f} s")
    if res.goal_misses:
        print(f"validation: the design goal ([goal]) is missed on {len(res.goal_misses)} of "
              f"{len(res.comparisons)} runs (reported, not the exit status; section \"The design goal\")")
    if res.failures:
        print(f"validation: {len(res.failures)} runs exceed the thresholds:", file=sys.stderr)
        for f in res.failures:
            print(f"  {f}", file=sys.stderr)
        return 1
    print("validation: all runs within the thresholds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
