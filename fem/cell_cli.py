"""``spherecontact fem cell``: one 3D cell run (a sphere among rigid flats) to an HDF5 run file.

Inputs are checked before the mesh is built (ValueError: one line on stderr, exit code 2 at the
top level); exit code 0 when the run reaches --h-max or --density-max, 3 when it stops early (the
converged part is written with status ``stopped`` and the reason).
"""

from __future__ import annotations

import argparse
import dataclasses
import signal
import sys

import numpy as np

from ..model.cli_args import material_from_args, output_path
from .cell import IncrementFailed, run_cell
from .cell_io import write_cell_run
from .cell_scene import scene

#: exit code of a run that stopped early (as ``fem run``)
EXIT_STOPPED = 3
MESH_DENSITY_RANGE = (0.5, 2.0)
#: the largest load approach a run may ask for, in units of R
H_MAX_LIMIT = 0.5


def check_cell_inputs(args: argparse.Namespace):
    """(scene, h grid, density target or None) from the arguments; ValueError naming the flag,
    its value and the allowed range."""
    sc = scene(args.lattice, args.load)
    R = args.radius
    if not (np.isfinite(R) and R > 0):
        raise ValueError(f"--radius must be finite and > 0, got {R!r}")
    lo, hi = MESH_DENSITY_RANGE
    if not lo <= args.mesh_density <= hi:
        raise ValueError(f"--mesh-density must lie in [{lo:g}, {hi:g}], got {args.mesh_density!r}")
    if not 0 < args.dh <= 0.05:
        raise ValueError(f"--dh must lie in (0, 0.05] (units of R), got {args.dh!r}")
    if not (args.tol > 0):
        raise ValueError(f"--tol must be > 0, got {args.tol!r}")
    if not 2 <= args.max_iterations <= 200:
        raise ValueError(f"--max-iterations must be an integer in [2, 200], got {args.max_iterations!r}")
    target = None
    if args.h_max is not None:
        if not 0 < args.h_max <= H_MAX_LIMIT:
            raise ValueError(f"--h-max must lie in (0, {H_MAX_LIMIT:g}] (units of R), got {args.h_max!r}")
        h_end = args.h_max
    else:
        d0 = sc.density(4 / 3 * np.pi * R**3, 0.0, R)
        if not d0 < args.density_max < 1:
            raise ValueError(f"--density-max must lie in ({d0:.4f}, 1) for {sc.name} (its density "
                             f"at contact is {d0:.4f}), got {args.density_max!r}")
        target = float(args.density_max)
        h_need = sc.approach_at_density(target, R) / R
        if h_need > H_MAX_LIMIT:
            raise ValueError(f"--density-max {target!r} needs an approach h ≈ {h_need:.3f} R for "
                             f"{sc.name}, beyond the limit {H_MAX_LIMIT:g} R")
        h_end = min(H_MAX_LIMIT, 1.1 * sc.approach_at_density(target, R) / R)
    n = int(np.ceil(h_end / args.dh - 1e-9))
    h = np.minimum(np.arange(1, n + 1) * args.dh, h_end) * R
    return sc, h, target


def pole_region(h_end: float, radius: float) -> float:
    """Radius (units of R) of the graded pole region: beyond the contact radius at the last
    approach, a ≈ 1.03 √(R h) on a flat (fem-031: 0.326 R at h/R 0.1), with a 15 % margin; at
    least the default 0.4, at most 0.7."""
    return float(np.clip(1.15 * np.sqrt(h_end / radius), 0.4, 0.7))


def _interrupt(signum, frame):
    """SIGTERM as Ctrl-C: the run stops and its converged increments are written."""
    raise KeyboardInterrupt


def _first_increments(result, n: int):
    """The result cut to its first n increments (an interrupt may fall between its appends)."""
    for f in dataclasses.fields(result):
        value = getattr(result, f.name)
        if isinstance(value, list):
            setattr(result, f.name, value[:n])
    return result


def cell_command(args: argparse.Namespace) -> int:
    """CLI handler of ``fem cell``: check, run, write, summarise; return the exit code."""
    from tqdm import tqdm

    material = material_from_args(args)
    sc, h, target = check_cell_inputs(args)
    out = output_path(args.out, (".h5", ".hdf5"))
    disable = args.quiet or not sys.stderr.isatty()
    total = target if target is not None else float(h[-1])
    bar = tqdm(total=total, file=sys.stderr, disable=disable, desc="fem cell",
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} [{elapsed}<{remaining}]")

    done = {}

    def progress(res):
        done["result"], done["n"] = res, len(res.h)
        now = res.density[-1] if target is not None else res.h[-1]
        bar.update(max(now - bar.n, 0.0))

    stop = None if target is None else (lambda res: res.density[-1] >= target)
    status, reason = "converged", ""
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        result = run_cell(sc, material, h, density=args.mesh_density, radius=args.radius,
                          mesh_options={"pole_region": pole_region(float(h[-1]), args.radius)},
                          tol=args.tol, max_iterations=args.max_iterations, progress=progress,
                          stop=stop)
    except IncrementFailed as err:
        if len(err.args) < 2:
            raise
        result, status, reason = err.args[1], "stopped", str(err.args[0])
    except KeyboardInterrupt:
        if "result" not in done:
            raise
        result = _first_increments(done["result"], done["n"])
        status, reason = "stopped", "interrupted (Ctrl-C or SIGTERM); the converged increments kept"
    finally:
        signal.signal(signal.SIGTERM, previous)
        bar.close()
    if status == "converged" and target is not None and (not result.density
                                                        or result.density[-1] < target):
        status, reason = "stopped", f"density {target:g} not reached by h = {h[-1]:g}"
    inputs = {"material": material.describe(), "radius": args.radius, "lattice": args.lattice,
              "load": args.load, "mesh_density": args.mesh_density, "dh": args.dh, "tol": args.tol,
              "max_iterations": args.max_iterations,
              "h_max": np.nan if args.h_max is None else args.h_max,
              "density_max": np.nan if target is None else target}
    write_cell_run(out, result, inputs, status, reason,
                   provenance={"entry_point": "spherecontact fem cell"})
    if status != "converged":
        print(f"spherecontact fem cell: stopped early: {reason}", file=sys.stderr)
    n = len(result.h)
    last = (f"h = {result.h[-1]:.5g}, density = {result.density[-1]:.4f}, F = "
            + ", ".join(f"{f:.5g}" for f in result.F[-1])) if n else "no converged increment"
    print(f"fem cell {sc.name} {status}: {n} increments, {sum(result.newton)} Newton iterations, "
          f"CPU {result.cpu_s:.1f} s; {last} -> {out}")
    return 0 if status == "converged" else EXIT_STOPPED


def add_cell_parser(cmds, add_material) -> None:
    """Add ``fem cell`` to the ``fem`` sub-commands; ``add_material(add)`` adds the material
    flags of ``fem run``."""
    p = cmds.add_parser(
        "cell", help="one 3D cell run: a sphere among rigid flats (lattice, isostatic or die)",
        description="Compress one elastic-plastic sphere of a lattice (simple cubic or face-centred "
                    "cubic) between rigid frictionless flats (its contact planes, symmetry planes "
                    "of the packing) up to --h-max or --density-max, and write per-contact "
                    "approach, force, contact area and the relative density to --out.",
        epilog="Exit codes: 0 reached h-max / density-max; 2 bad input (nothing computed); "
               "3 stopped early (file written with status 'stopped' and the reason).")
    groups: dict = {}

    def add(title, *flags, **kw):
        if title not in groups:
            groups[title] = p.add_argument_group(title)
        groups[title].add_argument(*flags, **kw)

    add_material(add)
    g = "cell and loading (lengths in the unit of --radius)"
    add(g, "--lattice", choices=("sc", "fcc"), required=True, help="simple cubic or face-centred cubic")
    add(g, "--load", choices=("isostatic", "die"), default="isostatic",
        help="isostatic (every contact approaches by h; default) or die (sc only: the z contacts "
             "approach by h, the lateral walls stay)")
    stop = p.add_mutually_exclusive_group(required=True)
    stop.add_argument("--h-max", type=float, default=None,
                      help=f"final per-contact approach h of the moving contacts, in (0, {H_MAX_LIMIT:g}] R")
    stop.add_argument("--density-max", type=float, default=None,
                      help="stop at this relative density, between the density at contact and 1")
    add(g, "--radius", type=float, default=1.0, help="sphere radius R, finite > 0 (default 1)")
    add(g, "--dh", type=float, default=0.0025, help="increment of h in units of R, in (0, 0.05] "
        "(default 0.0025; cut in half where Newton fails)")
    lo, hi = MESH_DENSITY_RANGE
    add(g, "--mesh-density", type=float, default=1.0,
        help=f"mesh-density factor in [{lo:g}, {hi:g}]; element sizes scale as 1/density (default 1)")
    add(g, "--tol", type=float, default=1e-4,
        help="Newton tolerance: largest free residual / largest nodal reaction, > 0 (default 1e-4)")
    add(g, "--max-iterations", type=int, default=25,
        help="Newton iterations per increment before a cut, integer in [2, 200] (default 25)")
    add("output", "--out", required=True, metavar="FILE.h5", help="HDF5 run file to write (atomically)")
    add("output", "--quiet", action="store_true", help="no progress bar (also off when stderr is no TTY)")
    p.set_defaults(func=cell_command)
