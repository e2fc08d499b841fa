"""Does the current solver reproduce the stored reference curves? (one run per scene)

Re-runs campaign cases of ``data/reference_v2.h5`` with their stored inputs (the solver's
numerics may have changed since: factorisation, Newton steps) and compares F and a with
the stored curves at the stored approaches h/R ≥ 0.01 of the loading increments (unloading
cycles left out; log–log interpolation of the new curve): the systematic difference is the
median of ln(new/stored), the largest one the maximum, beside the stored curve's own FE
scatter (max |ln y − local quadratic| over 11 increments). Two noisy curves may differ by up
to the sum of their scatters.

``python studies/fem_reproduce.py --out reports/fem`` → ``reproduce.json`` (``--cases``
re-runs some cases and keeps the others' earlier rows; ``--edge-fit fitted --name F`` re-runs them
with the contact radius's edge exponent fitted, ``contact.contact_edge``). Campaign v1's cases
(``flat-pp-E200-nu0.35``, ``rsphere2-pp-E200-nu0.3``, ``two-pp-E200-nu0.3-vs-sy3``): ``--campaign
studies/campaign_v1.toml --db data/reference.h5 --cases …`` after restoring that database from the
git history (``git show 3667b84:data/reference.h5 > data/reference.h5``).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from spherecontact.campaign.design import load_campaign
from spherecontact.data import Database
from spherecontact.fem.contact import EDGE_FITS
from spherecontact.fem.io import loading_mask, run_indentation
from spherecontact.metrics import interp_loglog, scatter

#: one validation case of campaign v2 per scene: a flat, a rigid sphere, two bodies (exact contact)
CASES = ("flat-pp-E250-nu0.3", "rsphere2-pp-E300-nu0.3", "two-pp-E200-nu0.3-vs-sy5")


def compare(h_old, y_old, h_new, y_new, h_min: float) -> dict:
    sel = (h_old >= h_min) & (h_old <= h_new.max()) & (y_old > 0)
    dev = np.log(interp_loglog(h_old[sel], h_new[h_new > 0], y_new[h_new > 0]) / y_old[sel])
    return {"systematic": float(np.median(dev)), "max": float(np.max(np.abs(dev))),
            "stored_scatter": scatter(h_old, y_old, h_old >= h_min),
            "new_scatter": scatter(h_new, y_new, h_new >= h_min)}


def compare_loading(old: dict, new: dict, h_min: float) -> dict:
    """:func:`compare` of F and of a between two runs' curves on their loading increments (the
    unloading and reloading of cycles left out, ``io.loading_mask``)."""
    on_old, on_new = loading_mask(old), loading_mask(new)
    h_old, h_new = np.asarray(old["h"])[on_old], np.asarray(new["h"])[on_new]
    return {q: compare(h_old, np.asarray(old[q])[on_old], h_new, np.asarray(new[q])[on_new], h_min)
            for q in ("F", "a")}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default="data/reference_v2.h5")
    ap.add_argument("--campaign", default="data/campaign_v2.toml")
    ap.add_argument("--out", default="reports/fem")
    ap.add_argument("--cases", nargs="*", default=list(CASES))
    ap.add_argument("--edge-fit", choices=tuple(EDGE_FITS), default=None,
                    help="the contact radius's edge fit of the new runs (default: the stored runs' own)")
    ap.add_argument("--name", default="reproduce.json", help="file name of the report in --out")
    args = ap.parse_args(argv)
    db = Database(args.db)
    by_name = {c.name: c for c in load_campaign(args.campaign).cases}
    results = []
    for name in args.cases:
        case = by_name[name]
        stored = db.run(case.key)
        R = min(case.inputs["radius"], case.inputs.get("radius2", np.inf))
        kw = case.run_kwargs()
        if args.edge_fit is not None:
            kw["options"] = replace(kw["options"], edge_fit=args.edge_fit)
        new = run_indentation(**kw)
        row = {"case": name, "status": new.status, "edge_fit": new.inputs["options"]["edge_fit"],
               "wall_s_new": new.timings["wall_s"],
               "wall_s_stored": float(stored.provenance.get("wall_s", np.nan)),
               **compare_loading(stored.curves, new.curves, 0.01 * R)}
        results.append(row)
        F = row["F"]
        print(f"{name}: F systematic {100 * F['systematic']:+.2f} %, max {100 * F['max']:.2f} % "
              f"(stored scatter {100 * row['F']['stored_scatter']:.2f} %); a systematic "
              f"{100 * row['a']['systematic']:+.2f} %, max {100 * row['a']['max']:.2f} %; "
              f"{row['wall_s_new']:.0f} s (stored {row['wall_s_stored']:.0f} s)", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / args.name
    earlier = json.loads(path.read_text()) if path.exists() else []
    rerun = {row["case"] for row in results}
    kept = [row for row in earlier if row["case"] not in rerun]  # cases not re-run this time
    path.write_text(json.dumps(kept + results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
