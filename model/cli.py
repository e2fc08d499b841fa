"""``spherecontact model curve`` and ``model table``: the closed-form model from the command line.

``curve``: force–approach curve of two spheres, a thin layer over :func:`curve`, which tests
call directly. Body 2 defaults to a copy of body 1 (equal spheres); ``--radius2 inf`` gives a
flat, ``--E2 inf`` a rigid body. ``--unload`` appends the unloading branch from h_max to the
residual approach (column ``branch``: 0 load, 1 unload) and the cycle's residual approach,
energies and quasi-static restitution coefficient (``cycle.py``).

Body flags as ``fem run``'s (``cli_args.py``): ``--flow-table`` / ``--flow-table2`` for a
tabulated flow curve of either body.

``table``: the pair's contact law for a particle (DEM) code. ``.sct``: format v2
(``spherecontact-contact-table/2``, ``dem/FORMAT.md``, :mod:`.dem_table`): F, dF/dh, a, h_1/h with
the unloading/reloading history, a rule beyond the table, one radius ratio or a range of them
(``--ratio-range``), read by the C evaluator ``dem/spherecontact_table.c``. ``.npz``/``.txt``:
format v1, the fast path's arrays (``ContactLaw.tables``, :func:`write_table`).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from .cli_args import FLOW_HELP, material2_from_args, material_from_args, output_path
from .coefficients import default_coefficients, load_coefficients
from .contact import contact
from .cycle import cycle
from .dem_table import SLICE_STEP, strict_json, write_table2
from .fast import ContactLaw
from .sphere import Sphere

__all__ = ["register", "curve", "run_curve", "write_table", "run_table", "TABLE_FORMAT",
           "TABLE_SUFFIXES"]

#: format name of the ``model table`` file (its ``meta`` says how to evaluate it)
TABLE_FORMAT = "spherecontact-contact-table/1"
#: reference evaluations stored with a table, to check an implementation against
CHECK_POINTS = 16

COLUMNS = ("h", "F", "a", "h1", "h2", "stiffness")


def curve(s1: Sphere, s2: Sphere, h_max: float, points: int = 50, coeffs=None,
          unload: bool = False) -> dict:
    """Model curve at ``points`` approaches h = h_max·i/points, i = 1..points; with ``unload``
    then ``points`` more on the unloading branch from h_max down to the residual approach.

    Returns a dict of lists (``h``, ``F``, ``a``, ``h1``, ``h2``, ``stiffness``; with
    ``unload`` also ``branch``, 0 load / 1 unload, and ``cycle``: h_res, each body's share,
    work in and returned, dissipated work, restitution coefficient).
    """
    if not (math.isfinite(h_max) and h_max > 0.0):
        raise ValueError(f"--h-max must be a finite number > 0, got {h_max!r}")
    if points < 1:
        raise ValueError(f"--points must be >= 1, got {points!r}")
    h = h_max * np.arange(1, points + 1) / points
    st = contact(s1, s2, h, coeffs)
    out = {"h": h}
    out.update({k: getattr(st, k) for k in COLUMNS[1:]})
    if not unload:
        return {k: np.asarray(v, dtype=float).tolist() for k, v in out.items()}
    c = cycle(s1, s2, h_max, coeffs)
    hu = h_max - (h_max - float(c.h_res)) * np.arange(1, points + 1) / points
    su = contact(s1, s2, hu, coeffs, h_max=h_max)
    data = {k: np.concatenate([out[k], hu if k == "h" else getattr(su, k)]).tolist() for k in COLUMNS}
    data["branch"] = [0] * points + [1] * points
    data["cycle"] = {k: float(getattr(c, k)) for k in ("h_max", "F_max", "a_max", "h_res", "h1_res",
                                                        "h2_res", "work_in", "work_returned",
                                                        "dissipated", "restitution")}
    return data


def _pair(args: argparse.Namespace) -> tuple[Sphere, Sphere]:
    """The two spheres of the command line (body 2's missing values are body 1's)."""
    m1 = material_from_args(args)
    m2 = material2_from_args(args, m1) or m1
    s1 = Sphere(radius=args.radius, material=m1)
    return s1, Sphere(radius=args.radius if args.radius2 is None else args.radius2, material=m2)


def _coefficients(args: argparse.Namespace):
    """``--coefficients``: a file, ``literature`` (the uncalibrated set, by name) or the default."""
    return load_coefficients(args.coefficients) if args.coefficients else default_coefficients()


#: file formats of ``model table``, by suffix: v2 (``.sct``), v1 (``.npz``, ``.txt``)
TABLE_SUFFIXES = (".sct", ".npz", ".txt")
#: suffixes of the v1 writer :func:`write_table`
V1_SUFFIXES = (".npz", ".txt")


def write_table(s1: Sphere, s2: Sphere, path, h_max: float | None = None, coeffs=None) -> dict:
    """Write the pair's fast-path table to ``path`` and return what was written: a NumPy ``.npz``
    of the arrays below, or a ``.txt`` of the same numbers for codes without NumPy
    (:func:`_write_text`).

    Arrays: those of :meth:`ContactLaw.tables` (``ln_h``, ``ln_F_hermite``, ``recovery``, ``m``;
    the scalars ``h_elastic``, ``h_min``, ``h_max`` as 0-d arrays), the reference evaluations
    ``check_h``, ``check_h_max``, ``check_F``, ``check_dF_dh`` (``CHECK_POINTS`` loading contacts
    and as many half way down their peaks' elastic recovery, from ``ContactLaw.force``), and
    ``meta``: a standard JSON string (an infinite radius or modulus as the string "inf") with
    the format name, both bodies, the coefficient source, the table's measured error bounds and
    the evaluation recipe (the docstring of ``ContactLaw.tables``). Units are those of the inputs.
    """
    suffix = Path(path).suffix
    if suffix not in V1_SUFFIXES:
        raise ValueError(f"path must end in {' or '.join(V1_SUFFIXES)}, got {str(path)!r}")
    law = ContactLaw(s1, s2, h_max=h_max, coeffs=coeffs)
    tab = law.tables()
    hm = np.geomspace(max(law.h_min, 1e-6 * law.h_max), law.h_max, CHECK_POINTS)
    recovery = law._peaks(hm)[3]  # δ_e/h_max: each unloading point half way down its recovery
    check_hm = np.concatenate([hm, hm])
    check_h = np.concatenate([hm, hm * (1.0 - 0.5 * recovery)])  # loading, unloading
    F, dF = law.force(check_h, check_hm)
    desc = law.describe()
    meta = {"format": TABLE_FORMAT,
            "body1": {"radius": s1.radius, **s1.material.describe()},
            "body2": {"radius": s2.radius, **s2.material.describe()},
            "coefficients_source": law.pair.coeffs.source,
            "units": "consistent units of the inputs (F in those of E·R²)",
            "nodes": desc["nodes"], "error_bound": desc["error_bound"],
            "calibrated_range_warnings": desc["calibrated_range_warnings"],
            "evaluation": " ".join(ContactLaw.tables.__doc__.split())}
    meta = strict_json(meta)
    arrays = {k: np.asarray(v, dtype=float) for k, v in tab.items()}
    arrays.update(check_h=check_h, check_h_max=check_hm, check_F=F, check_dF_dh=dF,
                  meta=np.array(json.dumps(meta, allow_nan=False)))
    if suffix == ".txt":
        _write_text(path, arrays)
        return arrays
    with open(path, "wb") as fh:  # the name as given (np.savez would append .npz to a bare name)
        np.savez(fh, **arrays)
    return arrays


def _write_text(path, arrays: dict) -> None:
    """The table as text: ``#`` lines with the format, ``meta`` (one JSON line), the scalars
    ``h_elastic h_min h_max`` and the reference evaluations (``# check h h_max F dF/dh``), then
    one row per node j: ln_h, c₀ … c₃ of interval j (NaN on the last node), recovery, m. Every
    number in 17 significant digits (read back exactly)."""
    n = arrays["ln_h"].size
    cF = np.vstack([arrays["ln_F_hermite"], np.full((1, 4), np.nan)])
    rows = np.column_stack([arrays["ln_h"], cF, arrays["recovery"], arrays["m"]])
    lines = [f"# {TABLE_FORMAT} (text)", f"# meta: {arrays['meta']}",
             "# h_elastic h_min h_max: " + " ".join(f"{float(arrays[k]):.17g}"
                                                   for k in ("h_elastic", "h_min", "h_max")),
             "# check h h_max F dF/dh: reference evaluations of force(h, h_max)"]
    lines += [f"# check {h:.17g} {hm:.17g} {F:.17g} {k:.17g}" for h, hm, F, k in
              zip(arrays["check_h"], arrays["check_h_max"], arrays["check_F"], arrays["check_dF_dh"],
                  strict=True)]
    lines.append(f"# columns ({n} nodes): ln_h c0 c1 c2 c3 recovery m")
    lines += [" ".join(f"{v:.17g}" for v in row) for row in rows]
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")


def table_ratios(lo: float, hi: float, slices: int | None = None) -> np.ndarray:
    """Radius ratios R2/R1 of a ratio-range table: ``slices`` geometric from lo to hi (default:
    neighbours ``SLICE_STEP`` = 2^(1/4) apart or closer, at least 2). Raises ValueError naming
    ``--ratio-range`` or ``--slices`` and the allowed values."""
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise ValueError(f"--ratio-range LO HI needs finite 0 < LO < HI, got {lo!r} {hi!r}")
    if slices is None:
        slices = max(math.ceil(math.log(hi / lo) / math.log(SLICE_STEP) - 1e-9) + 1, 2)
    if slices < 2:
        raise ValueError(f"--slices must be >= 2 for a ratio range, got {slices!r}")
    return np.geomspace(lo, hi, slices)


def run_table(args: argparse.Namespace) -> int:
    """CLI handler of ``model table``."""
    output_path(args.out, TABLE_SUFFIXES)
    s1, s2 = _pair(args)
    if Path(args.out).suffix.lower() == ".sct":
        ratios = None
        if args.ratio_range is not None:
            if math.isinf(s2.radius):
                raise ValueError("--ratio-range: body 2 is a flat (--radius2 inf), which has no ratio")
            ratios = table_ratios(*args.ratio_range, args.slices)
        elif args.slices is not None:
            raise ValueError("--slices needs --ratio-range")
        meta = write_table2(args.out, s1, s2, ratios=ratios, h_max=args.h_max,
                            coeffs=_coefficients(args))
        sl = meta["slices"]
        msg = (f"wrote {args.out}: {len(sl)} slice(s), R2/R1 {sl[0]['ratio']} … {sl[-1]['ratio']}, "
               f"h_max {sl[0]['h_max']:.6g} (slice 0)")
        err = meta.get("ratio_interpolation_error")
        if err:
            msg += (f", measured ratio-interpolation error of F: loading {err['F_loading']:.2g}, "
                    f"unloading {err['F_unloading']:.2g} of F_max")
        sys.stdout.write(msg + "\n")
        return 0
    if args.ratio_range is not None or args.slices is not None:
        raise ValueError("--ratio-range and --slices need a .sct table (format v2)")
    arrays = write_table(s1, s2, args.out, args.h_max, _coefficients(args))
    meta = json.loads(str(arrays["meta"]))
    bound = meta["error_bound"].get("F", "n/a")
    sys.stdout.write(f"wrote {args.out}: {meta['nodes']} nodes, h {float(arrays['h_min']):.6g} … "
                     f"{float(arrays['h_max']):.6g}, error bound of F {bound}\n")
    return 0


def run_curve(args: argparse.Namespace) -> int:
    """CLI handler of ``model curve``."""
    if args.out:
        output_path(args.out)
    s1, s2 = _pair(args)
    m1, m2 = s1.material, s2.material
    coeffs = _coefficients(args)
    data = curve(s1, s2, args.h_max, args.points, coeffs, unload=args.unload)
    cyc = data.pop("cycle", None)
    cols = COLUMNS + (("branch",) if args.unload else ())
    meta = {
        "body1": {"radius": s1.radius, **m1.describe()},
        "body2": {"radius": s2.radius, **m2.describe()},
        "coefficients_source": coeffs.source,
        "units": "consistent units of the inputs",
        **({"cycle": cyc} if cyc else {}),
    }
    if args.json:
        text = json.dumps({"meta": meta, **data}, indent=1)
    else:
        lines = [f"# spherecontact model curve; coefficients: {coeffs.source}"]
        if cyc:
            lines.append("# cycle: " + ", ".join(f"{k} = {v:.6g}" for k, v in cyc.items()))
        lines.append(",".join(cols))
        lines += [",".join(f"{data[c][i]:.10g}" for c in cols) for i in range(len(data["h"]))]
        text = "\n".join(lines)
    if args.out:
        Path(args.out).write_text(text + "\n")
    else:
        sys.stdout.write(text + "\n")
    return 0


def _body_arguments(p) -> None:
    g1 = p.add_argument_group("body 1 (consistent units: stresses in the unit of E)")
    g1.add_argument("--E", type=float, required=True, help="Young's modulus (inf: rigid)")
    g1.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio (default 0.3)")
    g1.add_argument("--sigma-y", type=float, default=None,
                    help="yield stress (default: none, an elastic body)")
    g1.add_argument("--K", type=float, default=None, help="Ludwik hardening modulus (default 0)")
    g1.add_argument("--n", type=float, default=None, help="Ludwik hardening exponent (default 1)")
    g1.add_argument("--flow-table", metavar="FILE.csv", default=None,
                    help="tabulated flow curve instead of --sigma-y/--K/--n: two CSV columns eps_p, "
                         "sigma (optional header, '#' comments)")
    g1.add_argument("--flow", metavar="NAME:P=V,...", default=None, help=FLOW_HELP)
    g1.add_argument("--radius", type=float, required=True, help="radius (inf: flat)")
    g2 = p.add_argument_group("body 2 (defaults: same as body 1)")
    g2.add_argument("--E2", type=float)
    g2.add_argument("--nu2", type=float)
    g2.add_argument("--sigma-y2", type=float)
    g2.add_argument("--K2", type=float)
    g2.add_argument("--n2", type=float)
    g2.add_argument("--flow-table2", metavar="FILE.csv", help="tabulated flow curve of body 2")
    g2.add_argument("--flow2", metavar="NAME:P=V,...", help="flow curve of body 2 (as --flow)")
    g2.add_argument("--radius2", type=float)
    p.add_argument("--coefficients", metavar="FILE.json|literature",
                   help="coefficient file (default: the calibrated set shipped with the package); "
                        "'literature' for the uncalibrated literature set")


def register(subparsers) -> None:
    """Add the ``model`` stage and its ``curve`` and ``table`` commands to the top-level parser."""
    stage = subparsers.add_parser("model", help="closed-form unified contact model")
    cmds = stage.add_subparsers(dest="command", required=True, metavar="COMMAND")
    p = cmds.add_parser("curve", help="force-approach curve F(h), a(h), h1, h2, dF/dh")
    _body_arguments(p)
    p.add_argument("--h-max", type=float, required=True, help="largest approach h")
    p.add_argument("--points", type=int, default=50, help="number of points (default 50)")
    p.add_argument("--unload", action="store_true",
                   help="append the unloading branch to the residual approach and the cycle's energies")
    p.add_argument("--json", action="store_true", help="write JSON instead of CSV")
    p.add_argument("--out", help="output file (default: stdout)")
    p.set_defaults(func=run_curve)
    t = cmds.add_parser("table", help="the pair's contact law for a DEM code (.sct: format v2; "
                                      ".npz/.txt: v1 arrays)")
    _body_arguments(t)
    t.add_argument("--h-max", type=float, default=None,
                   help="largest approach of the table (default: .sct the model's calibrated "
                        "range; .npz/.txt half the smaller radius)")
    t.add_argument("--ratio-range", type=float, nargs=2, metavar=("LO", "HI"), default=None,
                   help=".sct: cover radius ratios R2/R1 from LO to HI (body 1's --radius is the "
                        "reference; --radius2 is then ignored)")
    t.add_argument("--slices", type=int, default=None,
                   help="ratios tabulated over --ratio-range (default: neighbours 2^(1/4) apart)")
    t.add_argument("--out", required=True,
                   help="output file: .sct (format v2, text), .npz or .txt (format v1)")
    t.set_defaults(func=run_table)
