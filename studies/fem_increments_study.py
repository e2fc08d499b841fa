"""Increment convergence of stored reference curves where the contact is still small.

Checks: how far the stored campaign curves lie from their first loading re-run with increments
also bounded by the approach, dh ≤ r h (``spherecontact.fem.increments.rerun``): ln(stored/new)
of F and a per decade of h, largest and mean, at the stored loading increments after the first
ones. The default window is the validation set's, up to the campaign's first unloading approach
h = 0.01 of the smaller radius, r = 0.03 (the numbers ``spherecontact campaign increments``
stores as data for the validation report); ``--h-end 0.3 --relative-step 0 --strain-increment
0.0025 --name increments_window.json`` checks the whole loading window with the strain bound
halved instead.

Writes: ``python studies/fem_increments_study.py --db data/reference_v2.h5 --set validation
--out reports/fem [--name increments_validation.json]`` → ``OUT/NAME`` (JSON: ``date_utc``,
``db``, ``h_end``, ``note``, one entry per case with its deviations and re-run curve) and one
line per case on stdout.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from spherecontact.campaign.cli import rerun_arguments
from spherecontact.campaign.increments import collect, summary_line


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports/fem")
    rerun_arguments(ap)
    ap.add_argument("--name", default="increments_validation.json", help="file written in --out")
    args = ap.parse_args(argv)
    try:
        collect(args.db, Path(args.out) / args.name, set_name=args.set, cases=args.cases,
                relative_step=args.relative_step, h_end=args.h_end,
                strain_increment=args.strain_increment, workers=args.workers,
                on_case=lambda case, r: print(summary_line(case, r), flush=True))
    except ValueError as err:
        ap.error(str(err))
    return 0


if __name__ == "__main__":
    sys.exit(main())
