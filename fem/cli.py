"""``spherecontact fem run``: one FE indentation run written to an HDF5 run file.

A thin layer over :func:`spherecontact.fem.io.run_indentation` and
:func:`spherecontact.fem.io.write_run`. Every input is validated before the
mesh is built; a ValueError becomes one line on stderr and exit code 2 (top
level). Exit code 0 when the run reaches h_max, 3 when it stops early (the
converged part is still written, flagged ``stopped`` with its reason).
"""

from __future__ import annotations

import argparse
import math
import sys
import textwrap
from dataclasses import replace
from pathlib import Path

from ..model.cli_args import (
    FLOW_HELP,
    material2_from_args,
    material_from_args,
    output_path,
    read_flow_table,
)
from .assembly import ELEMENTS
from .cell_cli import add_cell_parser
from .contact import EDGE_FITS
from .io import SCENES, check_inputs, run_checked, write_run
from .linsolve import METHODS as LINEAR_METHODS
from .mesh import BAND_FLOOR_RANGE, DENSITY_RANGE, EDGE_BAND_MAX, EDGE_BAND_MIN
from .solver import PENALTY_SCALES, SEGMENT_SCHEMES, SolverOptions

__all__ = ["register", "run_command", "render_command", "read_flow_table", "material_from_args",
           "options_from_args", "EXIT_STOPPED"]

#: exit code of a run that stopped before h_max (file written, status "stopped")
EXIT_STOPPED = 3
#: file names of a run file (HDF5)
RUN_SUFFIXES = (".h5", ".hdf5")
_DEFAULTS = SolverOptions()


def options_from_args(args: argparse.Namespace) -> SolverOptions:
    """Solver options from --dh-first/--dh-max/--dh-min/--max-iterations/--tol,
    --strain-increment, --max-wall-s, --no-line-search, --penalty, --segment-points,
    --segment-scheme, --penalty-scale, --linear-solver, --definite-shift and --edge-fit."""
    return SolverOptions(dh_first=args.dh_first, dh_max=args.dh_max, dh_min=args.dh_min,
                         max_iterations=args.max_iterations, tol=args.tol,
                         strain_increment=args.strain_increment, max_wall_s=args.max_wall_s,
                         line_search=not args.no_line_search, penalty=args.penalty,
                         segment_points=args.segment_points, segment_scheme=args.segment_scheme,
                         penalty_scale=args.penalty_scale, linear_solver=args.linear_solver,
                         definite_shift=args.definite_shift, edge_fit=args.edge_fit)


class _Progress:
    """tqdm bar over the largest h/h_max reached, on stderr (off with --quiet or when stderr is
    no TTY)."""

    def __init__(self, h_max: float, quiet: bool):
        from tqdm import tqdm

        disable = quiet or not sys.stderr.isatty()
        self.bar = tqdm(total=h_max, file=sys.stderr, disable=disable, desc="fem run",
                        bar_format="{desc}: {percentage:3.0f}%|{bar}| h = {n:.4g}/{total:.4g} "
                                   "[{elapsed}<{remaining}]")

    def __call__(self, h: float) -> None:
        self.bar.update(max(h - self.bar.n, 0.0))

    def close(self) -> None:
        self.bar.close()


def _summary(result, path: Path) -> str:
    """One line: status, increments, Newton iterations, wall time, final F and a, file."""
    t = result.timings
    n = len(result.curves["h"])
    last = (f"h = {result.h[-1]:.6g}, F = {result.F[-1]:.6g}, a = {result.a[-1]:.6g}" if n
            else "no converged increment")
    cyc = getattr(result, "cycles", None) or {}
    if cyc:
        last += "; h_res/h_max = " + ", ".join(f"{r / m:.4g}" for r, m in zip(cyc["h_res"], cyc["h_max"],
                                                                              strict=True))
    return (f"fem run {result.status}: {n} increments, {t.get('newton_iterations', 0)} Newton "
            f"iterations, wall {t.get('wall_s', float('nan')):.2f} s; {last} -> {path}")


def run_command(args: argparse.Namespace) -> int:
    """CLI handler of ``fem run``: check the inputs once (:func:`.io.check_inputs`), run them
    (:func:`.io.run_checked`), write, summarise; return the exit code."""
    material = material_from_args(args)
    options = options_from_args(args)
    out = output_path(args.out, RUN_SUFFIXES)
    material2 = material2_from_args(args, material)
    radius2 = args.radius2
    if material2 is not None and radius2 is None:
        radius2 = args.radius
    checked = check_inputs(material, args.radius, args.h_max, args.indenter_radius,
                           args.mesh_density, args.element, options, radius2=radius2,
                           material2=material2, scene=args.scene.replace("-", "_"),
                           unload_at=args.unload_at, edge_band=args.edge_band,
                           band_floor=args.band_floor)
    print(f"scene: {checked.scene} ({SCENES[checked.scene]})", file=sys.stderr)
    bar = _Progress(checked.h_max, args.quiet)
    try:
        result = run_checked(replace(checked, progress=bar))
    finally:
        bar.close()
    extra = {"entry_point": "spherecontact fem run",
             "flow_table": "" if args.flow_table is None else str(args.flow_table)}
    write_run(out, result, extra_provenance=extra)
    if result.status != "converged":
        print(f"spherecontact fem run: stopped early: {result.reason}", file=sys.stderr)
    print(_summary(result, out))
    return 0 if result.status == "converged" else EXIT_STOPPED


# ============================================================================ argparse
def _add_material(add) -> None:
    """Material options (``add(group_title, *flags, **kw)`` adds one option)."""
    grp = "material (consistent units: stresses in the unit of E)"
    add(grp, "--E", type=float, required=True, help="Young's modulus E, > 0")
    add(grp, "--nu", type=float, default=0.3, help="Poisson's ratio, in (-1, 0.5) (default 0.3)")
    add(grp, "--sigma-y", type=float, default=None,
        help="initial yield stress sigma_Y, > 0 (default inf: purely elastic)")
    add(grp, "--K", type=float, default=None,
        help="Ludwik hardening modulus K >= 0 in sigma_f = sigma_Y + K eps_p^n "
             "(default 0: perfectly plastic)")
    add(grp, "--n", type=float, default=None, help="Ludwik hardening exponent n >= 0 (default 1)")
    add(grp, "--flow-table", metavar="FILE.csv", default=None,
        help="tabulated flow curve instead of --sigma-y/--K/--n: two CSV columns eps_p, sigma "
             "(optional header, '#' comments); eps_p starts at 0 and increases strictly, "
             "sigma > 0 non-decreasing; extrapolated with the last slope")
    add(grp, "--flow", metavar="NAME:P=V,...", default=None, help=FLOW_HELP)


def _approach_list(text: str) -> list[float]:
    """``--unload-at``: comma-separated approaches."""
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--unload-at takes comma-separated numbers, e.g. 0.01,0.03, got {text!r}") from None


def _add_geometry(add) -> None:
    """Geometry and loading options."""
    grp = "geometry and loading (lengths in the unit of --radius)"
    add(grp, "--radius", type=float, default=1.0, help="sphere radius R, finite > 0 (default 1)")
    add(grp, "--h-max", type=float, required=True,
        help="final approach h = h1 + h2 (shortening between the two bodies' equatorial "
             "planes), in (0, 0.8 min(R, R2)] (equal pairs: (0, 1.6 R])")
    add(grp, "--unload-at", type=_approach_list, default=None, metavar="H1,H2,...",
        help="unload fully (until the force vanishes) at each of these increasing approaches in "
             "(0, h-max], then reload; e.g. 0.01,0.03,0.1,0.3 (default: monotone loading)")
    add(grp, "--indenter-radius", type=float, default=math.inf, metavar="R2",
        help="radius of a rigid spherical indenter, > 0 (default inf: rigid flat, i.e. two "
             "equal spheres by symmetry)")
    grp2 = "body 2 (any of these makes a pair; each defaults to body 1's value)"
    add(grp2, "--radius2", type=float, default=None,
        help="radius of body 2, > 0 (inf: a flat, which must then be rigid)")
    add(grp2, "--E2", type=float, default=None, help="Young's modulus of body 2, > 0 (inf: rigid)")
    add(grp2, "--nu2", type=float, default=None, help="Poisson's ratio of body 2, in (-1, 0.5)")
    add(grp2, "--sigma-y2", type=float, default=None, help="yield stress of body 2, > 0")
    add(grp2, "--K2", type=float, default=None, help="Ludwik hardening modulus of body 2, >= 0")
    add(grp2, "--n2", type=float, default=None, help="Ludwik hardening exponent of body 2, >= 0")
    add(grp2, "--flow-table2", metavar="FILE.csv", default=None,
        help="tabulated flow curve of body 2 instead of --sigma-y2/--K2/--n2 (format of --flow-table)")
    add(grp2, "--flow2", metavar="NAME:P=V,...", default=None,
        help="flow curve of body 2 (as --flow; --sigma-y2 defaults to body 1's)")
    add(grp2, "--scene", choices=("auto", "two-body"), default="auto",
        help="auto (default): the cheapest exact scene (rigid partner: one hemisphere on a rigid "
             "flat or sphere; equal bodies: one hemisphere on a flat by symmetry; otherwise two "
             "hemispheres); two-body: always two deformable hemispheres")


def _add_numerics(add) -> None:
    """Mesh and solver options."""
    lo, hi = DENSITY_RANGE
    grp = "mesh and solver"
    add(grp, "--mesh-density", type=float, default=1.0,
        help=f"mesh-density factor in [{lo:g}, {hi:g}]; element sizes scale as 1/density "
             "(default 1)")
    add(grp, "--edge-band", type=float, default=0.0,
        help=f"surface band where the contact edge travels: element size = edge-band x distance "
             f"from the pole, in [0, {EDGE_BAND_MAX:g}] (default 0: the default mesh; the reference "
             "campaigns use 0.03, FE scatter 0.7 %% instead of 2.6 %%)")
    add(grp, "--band-floor", type=float, default=None,
        help=f"smallest element size of the surface band in units of the smaller radius, in "
             f"[{BAND_FLOOR_RANGE[0]:g}, {BAND_FLOOR_RANGE[1]:g}] (default {EDGE_BAND_MIN:g}; "
             "campaign v2's two-body pairs whose partner crushes the finest pole elements take "
             "0.0015 or 0.003)")
    add(grp, "--element", choices=sorted(ELEMENTS), default="q8r",
        help="q8r: 8-node quads, 2x2 reduced integration (default, no locking); "
             "q4: bilinear quads, full integration (locks; for comparison)")
    add(grp, "--dh-first", type=float, default=_DEFAULTS.dh_first,
        help="first increment of h as a fraction of R, in [dh-min, dh-max] "
             f"(default {_DEFAULTS.dh_first:g})")
    add(grp, "--dh-max", type=float, default=_DEFAULTS.dh_max,
        help=f"largest increment of h as a fraction of R, > 0 (default {_DEFAULTS.dh_max:g})")
    add(grp, "--dh-min", type=float, default=_DEFAULTS.dh_min,
        help="smallest increment as a fraction of R; the run stops when a cut-back goes "
             f"below it (default {_DEFAULTS.dh_min:g})")
    add(grp, "--max-iterations", type=int, default=_DEFAULTS.max_iterations,
        help="Newton iterations per increment before a cut-back, integer in [2, 200] "
             f"(default {_DEFAULTS.max_iterations})")
    add(grp, "--tol", type=float, default=_DEFAULTS.tol,
        help="Newton tolerance: largest free residual / largest reaction, > 0 "
             f"(default {_DEFAULTS.tol:g})")
    add(grp, "--strain-increment", type=float, default=_DEFAULTS.strain_increment,
        help="bound on the strain per increment, dh <= strain-increment * a, > 0 "
             f"(default {_DEFAULTS.strain_increment:g})")
    add(grp, "--max-wall-s", type=float, default=_DEFAULTS.max_wall_s,
        help="stop after this many seconds, > 0; the converged part is written with "
             "status 'stopped' (default inf: no limit)")
    add(grp, "--no-line-search", action="store_true",
        help="full Newton steps (only the J > 0 guard); the default uses an energy line search")
    add(grp, "--penalty", type=float, default=None,
        help="penalty contact with stiffness penalty * E / (pole element length), > 0 (two "
             "bodies: symmetric two-pass, with E* of the pair); the default is exact contact "
             "(Lagrange multipliers)")
    add(grp, "--segment-points", type=int, default=0,
        help="with --penalty: integrate the contact pressure at this many Gauss points per surface "
             "edge, 1-64 (default 0: at the nodes); two bodies: see --segment-scheme, and the split "
             "of spheres of equal yield stress is nearly neutral with smooth surfaces (fem/README.md)")
    add(grp, "--segment-scheme", choices=SEGMENT_SCHEMES, default=_DEFAULTS.segment_scheme,
        help="two bodies with --segment-points: 'points' (default; each Gauss point its own "
             "penalty, both bodies in turn) or 'mortar' (one pass of the softer body's weighted "
             "nodal gaps, --segment-points Gauss points per half edge)")
    add(grp, "--penalty-scale", choices=PENALTY_SCALES, default=_DEFAULTS.penalty_scale,
        help="with --penalty: 'modulus' (default), stiffness penalty * E / (pole element "
             "length); 'approach', stiffness penalty * p_m / h, so the obstacle (or the other "
             "body) presses in by about h / penalty at every approach (one body: use with "
             "--segment-points; fem/README.md, 'Smoothness of F'). The curve h is then the bodies' own "
             "shortening and h_applied the travel of the equator(s)")
    add(grp, "--linear-solver", choices=LINEAR_METHODS, default=_DEFAULTS.linear_solver,
        help="sparse factorisation: 'cholesky' (CHOLMOD's supernodal Cholesky reusing its "
             "analysis, LDL^T where the tangent is not positive definite; default), 'ldl' (qdldl "
             "LDL^T reusing its ordering, SuperLU where it fails) or 'superlu'")
    add(grp, "--definite-shift", type=float, default=_DEFAULTS.definite_shift,
        help="one body, --linear-solver cholesky: where Cholesky refuses the tangent, factor it "
             "with its diagonal raised by this fraction of its magnitude (a damped Newton step; "
             "0.1 halves the increments of E/sigma_Y 1e4 runs); 0 (default): LDL^T of the tangent")
    add(grp, "--edge-fit", choices=tuple(EDGE_FITS), default=_DEFAULTS.edge_fit,
        help="contact radius between nodes: 'hertz' (default, the stored databases' estimate: the gap "
             "opening as (r - a)^1.5) or 'fitted' (its exponent fitted in [1, 2]: mesh-consistent at "
             "a plastic edge, 0.4-0.6 %% higher there on the surface-band mesh)")


def _add_output(add) -> None:
    """Output options."""
    add("output", "--out", required=True, metavar="FILE.h5",
        help="HDF5 run file to write (replaced atomically)")
    add("output", "--quiet", action="store_true",
        help="no progress bar (it is also off when stderr is not a terminal)")


def _build_run_parser(cmds) -> list:
    """Add ``fem run``; return its options as (flags, help) for the stage overview."""
    run = cmds.add_parser(
        "run", help="one indentation run up to --h-max, written to an HDF5 file",
        description="Press an elastic-plastic hemisphere on a rigid obstacle up to --h-max and "
                    "write curves (h, F, a, p_m, energies, ...), Newton residual histories, "
                    "pressure profiles and the final mesh to --out. Units are consistent: "
                    "lengths in the unit of --radius, stresses in the unit of --E.",
        epilog="Exit codes: 0 reached h-max; 2 bad input (nothing computed); 3 stopped early "
               "(file written with status 'stopped' and the reason).")
    groups: dict = {}
    listed = []

    def add(title, *flags, **kw):
        if title not in groups:
            groups[title] = run.add_argument_group(title)
        groups[title].add_argument(*flags, **kw)
        listed.append((", ".join(flags), kw["help"]))

    for adder in (_add_material, _add_geometry, _add_numerics, _add_output):
        adder(add)
    run.set_defaults(func=run_command)
    return listed


def _option_table(listed, width: int = 79) -> str:
    """Two-column text: option flags, then the wrapped help."""
    col = max(len(f) for f, _ in listed) + 4
    lines = []
    for flags, text in listed:
        wrapped = textwrap.wrap(text, width - col) or [""]
        lines.append(f"  {flags:<{col - 2}}{wrapped[0]}")
        lines += [" " * col + w for w in wrapped[1:]]
    return "\n".join(lines)


def _build_render_parser(cmds) -> None:
    rp = cmds.add_parser(
        "render", help="final fields of a run file: VTU for ParaView and/or a PNG of plastic strain",
        description="Write the final deformed section of RUN with its displacement and equivalent "
                    "plastic strain to a VTU file (ParaView, via meshio) and/or render the plastic "
                    "strain off-screen to a PNG (needs pyvista: pip install '.[render]').")
    rp.add_argument("run", metavar="RUN", help="HDF5 run file written by 'fem run'")
    rp.add_argument("--png", metavar="FILE.png", help="picture of the equivalent plastic strain")
    rp.add_argument("--vtu", metavar="FILE.vtu", help="mesh and fields for ParaView")
    rp.add_argument("--reference", action="store_true",
                    help="write the VTU on the undeformed section (default: deformed)")
    rp.set_defaults(func=render_command)


def render_command(args: argparse.Namespace) -> int:
    """``fem render``: VTU and/or PNG of a run's final state; at least one output."""
    from .io import read_run
    from .render import export_vtu, render_png

    if not (args.png or args.vtu):
        raise ValueError("fem render: give --png FILE.png and/or --vtu FILE.vtu")
    run = read_run(args.run)
    if args.vtu:
        print(f"wrote {export_vtu(run, args.vtu, deformed=not args.reference)}")
    if args.png:
        print(f"wrote {render_png(run, args.png)}")
    return 0


def register(subparsers) -> None:
    """Add the ``fem`` stage and its ``run`` and ``render`` commands to the top-level parser."""
    fem = subparsers.add_parser(
        "fem", help="FE reference solver (one hemisphere on a rigid flat or sphere)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Axisymmetric large-deformation elastic-plastic FE solver: one hemisphere\n"
                    "pressed on a rigid flat (equal spheres by symmetry) or a rigid sphere.\n"
                    "'run' computes one force-approach curve into an HDF5 run file\n"
                    "(read it back with spherecontact.fem.read_run).")
    cmds = fem.add_subparsers(dest="command", required=True, metavar="COMMAND")
    listed = _build_run_parser(cmds)
    _build_render_parser(cmds)
    add_cell_parser(cmds, _add_material)
    fem.epilog = ("options of 'fem run' (lengths in the unit of --radius, stresses in the "
                  "unit of --E):\n" + _option_table(listed)
                  + "\n\nExit codes of 'fem run': 0 reached h-max; 2 bad input; 3 stopped early.")
