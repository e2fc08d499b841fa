"""``spherecontact calibrate``: the calibration stage's command (thin layer over :func:`pipeline.calibrate`).

Exit codes: 0 done; 2 bad input (missing, unreadable or empty database); 3 no candidate
form passed the monotonicity check (nothing written).
"""

from __future__ import annotations

import argparse
import sys
import time

from .crossval import FOLD_NFEV, FOLD_TOL, FoldSolve
from .forms import CANDIDATES, FORMS
from .workers import DEFAULT_WORKERS


def _add_arguments(p: argparse.ArgumentParser) -> argparse.ArgumentParser:
    p.description = ("Fit H_bar(Lambda), c2(Lambda), the level boundaries, beta and the "
                     "large-deformation terms to the FE calibration runs; choose the Level II "
                     "form by cross-validation over five folds of held-out materials; write the "
                     "coefficient file and the report.")
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--out", default="model/coefficients.json", help="coefficient file to write")
    p.add_argument("--report", default="reports/calibration", metavar="DIR",
                   help="report directory (index.md + PNG); '' for none")
    p.add_argument("--forms", default=",".join(CANDIDATES),
                   help=f"candidate forms, comma-separated (known: {', '.join(FORMS)})")
    p.add_argument("--workers", type=int, default=DEFAULT_WORKERS,
                   help="processes for the independent fits (folds, variants); the result does "
                        f"not depend on it (default {DEFAULT_WORKERS})")
    p.add_argument("--fold-nfev", type=int, default=FOLD_NFEV, metavar="N",
                   help="evaluations per cross-validation fold fit, 1-10000 (default "
                        f"{FOLD_NFEV}; 100 with --fold-tol 1e-8 solves the folds further: slower, see "
                        "calibration/README.md)")
    p.add_argument("--fold-tol", type=float, default=FOLD_TOL, metavar="TOL",
                   help=f"stopping tolerance of a fold fit, 1e-15-1e-2 (default {FOLD_TOL:g})")
    p.add_argument("--converged-fe", default=None, metavar="JSON",
                   help="replace each run's first loading by its re-run with finer increments "
                        "(spherecontact campaign increments --set calibration); default: the runs as "
                        "stored")
    p.add_argument("--converged-only", action="store_true",
                   help="leave out runs that stopped before h_max (default: fit their converged "
                        "increments)")
    return p


def build_parser() -> argparse.ArgumentParser:
    """The ``calibrate`` options on a parser of their own (tests parse with it)."""
    return _add_arguments(argparse.ArgumentParser(prog="spherecontact calibrate"))


def register(subparsers) -> None:
    """Add the ``calibrate`` command to the top-level parser."""
    p = subparsers.add_parser("calibrate", help="calibrate the model from the reference database")
    _add_arguments(p).set_defaults(func=calibrate_command)


def calibrate_command(args: argparse.Namespace) -> int:
    forms = tuple(f for f in args.forms.split(",") if f)
    unknown = [f for f in forms if f not in FORMS]
    if unknown or not forms:
        print(f"calibrate: error: unknown form(s) {unknown}; known: {', '.join(FORMS)}",
              file=sys.stderr)
        return 2
    try:
        folds = FoldSolve(args.fold_nfev, args.fold_tol)
    except ValueError as err:
        print(f"calibrate: error: {err}", file=sys.stderr)
        return 2
    from .pipeline import calibrate

    t0 = time.perf_counter()
    try:
        cal = calibrate(args.db, out=args.out, report_dir=args.report or None,
                        include_stopped=not args.converged_only, candidates=forms,
                        workers=args.workers, folds=folds, converged_fe=args.converged_fe)
    except FileNotFoundError as err:
        print(f"calibrate: error: reference database not found: {err.filename or args.db}",
              file=sys.stderr)
        return 2
    except ValueError as err:
        code = 3 if "monotone" in str(err) else 2
        print(f"calibrate: error: {err}", file=sys.stderr)
        return code
    s = cal.best.summary()
    print(f"calibrate: {len(cal.dataset.curves)} runs, {cal.dataset.size} points; form "
          f"'{cal.chosen}'; RMS H_bar {100 * s['H_bar']['rms']:.2f} % (max {100 * s['H_bar']['max']:.2f} %), "
          f"RMS c2 {100 * s['c2']['rms']:.2f} % (max {100 * s['c2']['max']:.2f} %); "
          f"F(h) {100 * s['F']['rms']:.2f} % (max {100 * s['F']['max']:.2f} %), "
          f"a(h) {100 * s['a']['rms']:.2f} % (max {100 * s['a']['max']:.2f} %); "
          f"{time.perf_counter() - t0:.1f} s")
    print(f"calibrate: wrote {args.out}" + (f" and {args.report}/index.md" if args.report else ""))
    return 0
