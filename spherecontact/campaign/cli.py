"""``spherecontact campaign run|design|increments``: the FE campaign from the command line.

``run`` runs a campaign file into the reference database (:func:`.driver.run_campaign`),
``design`` writes its design at a glance (:func:`.report.write_design`), ``increments`` stores
the increment-converged first loadings of a set as data (:func:`.increments.collect`).
"""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from ..fem.increments import H_END, RELATIVE_STEP

__all__ = ["register", "run_command", "design_command", "increments_command"]


def run_command(args: argparse.Namespace) -> int:
    """Exit 0 when every selected case is in the database and none failed, 1 otherwise."""
    from ..data import compact
    from .design import load_campaign
    from .driver import dry_run, format_summary, prune, run_campaign, select_sets

    if args.workers is not None and args.workers < 0:
        raise ValueError(f"--workers must be >= 0, got {args.workers}")
    if args.workers is not None and args.scheduler:
        raise ValueError("--workers applies to local runs; a Dask cluster brings its own workers")
    campaign = load_campaign(args.campaign)
    sets = select_sets(campaign, args.set)
    if args.dry_run:
        print(dry_run(campaign, args.db, sets, args.only))
        return 0
    if args.compact:
        before, after = compact(args.db)
        print(f"{args.db}: {before / 1e6:.2f} MB -> {after / 1e6:.2f} MB")
        return 0
    if args.prune:
        removed = prune(campaign, args.db)
        for r in removed:
            print(f"removed {r.set} {r.case} {r.key} ({r.status})")
        print(f"{len(removed)} superseded entries removed from {args.db}")
        return 0
    summary = run_campaign(campaign, args.db, sets=sets, only=args.only, workers=args.workers,
                           scheduler=args.scheduler, retry_failed=args.retry_failed,
                           retry_stopped=args.retry_stopped, refresh_start=args.refresh_start)
    print(format_summary(summary))
    if Path(args.db).exists():
        print(f"summary -> {args.db}.summary.json")
    bad = summary["total"]["failed"] + summary["total"]["missing"]
    return 0 if bad == 0 else 1


def design_command(args: argparse.Namespace) -> int:
    from .report import write_design

    cases = write_design(args.campaign, args.db, args.out)
    print(f"wrote {args.out}/design.md, design.json, design.png ({len(cases)} cases)")
    return 0


def increments_command(args: argparse.Namespace) -> int:
    from .. import __version__
    from .increments import collect, summary_line

    def echo(case: str, r: dict) -> None:
        print(summary_line(case, r), flush=True)

    argv = ["spherecontact", "campaign", "increments", "--db", str(args.db), "--out", str(args.out)]
    argv += ["--cases", *args.cases] if args.cases else ["--set", args.set]
    argv += ["--relative-step", f"{args.relative_step:g}", "--h-end", f"{args.h_end:g}"]
    if args.strain_increment is not None:
        argv += ["--strain-increment", f"{args.strain_increment:g}"]
    provenance = {"command": shlex.join(argv), "spherecontact": __version__}
    collect(args.db, args.out, set_name=args.set, cases=args.cases, relative_step=args.relative_step,
            h_end=args.h_end, strain_increment=args.strain_increment, workers=args.workers,
            on_case=echo, extra={"provenance": provenance})
    print(f"wrote {args.out}")
    return 0


def _run_parser(cmds) -> None:
    p = cmds.add_parser("run", help="run a campaign file into the reference database",
                        description="Run the FE campaign into the reference database: cases already there "
                                    "are skipped, the rest run in parallel and are appended as they finish.")
    p.add_argument("--campaign", default="data/campaign_v2.toml", help="campaign file (TOML)")
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--set", default="all", help="set to run: a set name of the campaign, or all")
    p.add_argument("--only", metavar="SUBSTRING", help="only cases whose name contains SUBSTRING")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: number of cores; 0: in this process)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                   help="run on this Dask scheduler instead of local processes")
    p.add_argument("--retry-failed", action="store_true", help="rerun cases recorded as failed")
    p.add_argument("--retry-stopped", action="store_true",
                   help="rerun cases stored as stopped (e.g. after raising max_wall_s) and replace them")
    p.add_argument("--refresh-start", action="store_true",
                   help="rerun stored runs whose first step was larger than today's solver takes "
                        "(their first increments are left out as a transient) and replace them "
                        "when the re-run converges")
    p.add_argument("--prune", action="store_true",
                   help="remove the database entries no case of the campaign produces (superseded "
                        "inputs or options), print them, and run nothing")
    p.add_argument("--compact", action="store_true",
                   help="rewrite the database with one copy of each mesh and the space of replaced "
                        "runs reclaimed, print the sizes, and run nothing")
    p.add_argument("--dry-run", action="store_true",
                   help="list the cases, their keys and whether they are in the database; run nothing")
    p.set_defaults(func=run_command)


def _design_parser(cmds) -> None:
    p = cmds.add_parser("design", help="the campaign's design: parameter planes and runs per set",
                        description="Write design.md, design.json and design.png of a campaign file.")
    p.add_argument("--campaign", default="data/campaign_v2.toml", help="campaign file (TOML)")
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--out", default="reports/campaign", help="output directory")
    p.set_defaults(func=design_command)


def _increments_parser(cmds) -> None:
    p = cmds.add_parser("increments", help="the increment-converged first loadings of a set, as data",
                        description="Re-run the first loading of every converged one-body run of a set "
                                    "with increments also bounded by the approach, dh <= r h, and write "
                                    "the curves (JSON).")
    p.add_argument("--out", default="data/increments_v2.json", help="file to write (JSON)")
    rerun_arguments(p)
    p.set_defaults(func=increments_command)


def rerun_arguments(p) -> None:
    """The options of an increment-converged re-run (``--db --set --cases --relative-step --h-end
    --strain-increment --workers``), shared with ``studies/fem_increments_study.py``."""
    p.add_argument("--db", default="data/reference_v2.h5", help="reference database (HDF5)")
    p.add_argument("--set", default="validation", help="every converged one-body case of this set")
    p.add_argument("--cases", nargs="*", default=None, help="these cases instead of --set")
    p.add_argument("--relative-step", type=float, default=RELATIVE_STEP,
                   help=f"increments dh <= this * h (default {RELATIVE_STEP:g}; 0: no such bound)")
    p.add_argument("--h-end", type=float, default=H_END,
                   help=f"approach the re-runs end at, in units of the smaller radius (default {H_END:g})")
    p.add_argument("--strain-increment", type=float, default=None,
                   help="increments dh <= this * a (default: the solver's)")
    p.add_argument("--workers", type=int, default=2, help="processes (one case each at a time)")


def register(subparsers) -> None:
    """Add the ``campaign`` stage and its ``run``, ``design`` and ``increments`` commands."""
    stage = subparsers.add_parser("campaign", help="FE campaign into the reference database",
                                  description="The FE campaign: run it, show its design, store the "
                                              "increment-converged first loadings of a set.")
    cmds = stage.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _run_parser(cmds)
    _design_parser(cmds)
    _increments_parser(cmds)


