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

from spherecontact.campaign.increments import collect, summary_line
from spherecontact.fem.increments import H_END, RELATIVE_STEP


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
