"""Command-line inputs shared by ``spherecontact model …`` and ``spherecontact fem run``.

Each body's material comes from the same flags in both stages (``--E --nu --sigma-y --K --n``,
``--sigma-y`` with ``--flow NAME:P=V,…``, or ``--flow-table``; ``--E2 … --flow2 --flow-table2`` for
body 2) and is checked once, by
:class:`~spherecontact.model.material.Material`. Output paths are checked before any work.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np

from .flow import REGISTRY, Table, flow_from_description, flow_from_spec
from .material import Material

__all__ = ["read_flow_table", "material_from_args", "material2_from_args", "output_path",
           "BODY2_FLAGS", "FLOW_HELP"]

#: body-2 flags of the command line (destination → flag); any of them makes a pair
BODY2_FLAGS = {"radius2": "--radius2", "E2": "--E2", "nu2": "--nu2", "sigma_y2": "--sigma-y2",
               "K2": "--K2", "n2": "--n2", "flow_table2": "--flow-table2",
               "flow2": "--flow2"}


def read_flow_table(path, flag: str = "--flow-table") -> tuple[np.ndarray, np.ndarray]:
    """Two-column CSV (eps_p, sigma); an optional header line and ``#`` comments allowed.

    Raises ValueError naming ``flag``, the file and the line of the problem.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as err:
        raise ValueError(f"{flag}: cannot read {path}: {err.strerror or err}") from None
    rows = []
    for lineno, row in enumerate(csv.reader(text.splitlines()), start=1):
        cells = [c.strip() for c in row if c.strip()]
        if not cells or cells[0].startswith("#"):
            continue
        if len(cells) != 2:
            raise ValueError(f"{flag} {path}, line {lineno}: expected two columns "
                             f"eps_p, sigma, got {len(cells)}")
        try:
            rows.append((float(cells[0]), float(cells[1])))
        except ValueError:
            if rows:  # only the first non-comment line may be a header
                raise ValueError(f"{flag} {path}, line {lineno}: not a number: "
                                 f"{','.join(cells)!r}") from None
    if not rows:
        raise ValueError(f"{flag} {path}: no data rows")
    table = np.array(rows)
    return table[:, 0], table[:, 1]


def _flow_names() -> str:
    return ", ".join(f"{name}:{','.join(f'{p}=V' for p in cls.parameter_names())}"
                     for name, cls in REGISTRY.items() if cls is not Table)


#: help of --flow / --flow2 (the laws and their parameters, from the registry)
FLOW_HELP = ("flow curve NAME:P=V,... with --sigma-y instead of --K/--n, one of " + _flow_names()
             + " (e.g. voce:Q=2,b=10)")


def _body(E, nu, sigma_y, K, n, flow_table, suffix: str, flow=None) -> Material:
    """One body's material; ``suffix`` is "" for body 1, "2" for body 2 (names the flags)."""
    if math.isinf(E) and E > 0:
        return Material.rigid(nu=nu)
    if flow_table is not None:
        given = [f"--{name}{suffix}" for name, v in (("sigma-y", sigma_y), ("K", K), ("n", n),
                                                     ("flow", flow)) if v is not None]
        if given:
            raise ValueError(f"--flow-table{suffix} replaces --sigma-y{suffix}/--K{suffix}/"
                             f"--n{suffix}/--flow{suffix}; drop {', '.join(given)}")
        eps, sigma = read_flow_table(flow_table, f"--flow-table{suffix}")
        try:
            return Material.from_table(E, nu, eps, sigma)
        except ValueError as err:
            raise ValueError(f"--flow-table{suffix} {flow_table}: {err}") from None
    if flow is not None:
        given = [f"--{name}{suffix}" for name, v in (("K", K), ("n", n)) if v is not None]
        if given:
            raise ValueError(f"--flow{suffix} gives the hardening; drop {', '.join(given)} (its "
                             f"parameters go into the spec, e.g. ludwik:K=2,n=0.3)")
        try:
            curve = flow_from_spec(flow, sigma_y)
        except ValueError as err:
            raise ValueError(f"--flow{suffix} {flow}: {err} (with --sigma-y{suffix}; laws: "
                             f"{_flow_names()})") from None
        try:
            return Material.with_flow(E, nu, curve)
        except ValueError as err:
            raise ValueError(f"body {suffix or '1'}: {err}") from None
    sy = math.inf if sigma_y is None else sigma_y
    if math.isinf(sy) and (K is not None or n is not None):
        raise ValueError(f"--K{suffix}/--n{suffix} need --sigma-y{suffix} (without a yield stress "
                         "the body is elastic and never hardens)")
    try:
        return Material(E=E, nu=nu, sigma_y=sy, K=0.0 if K is None else K, n=1.0 if n is None else n)
    except ValueError as err:
        raise ValueError(f"body {suffix or '1'}: {err}") from None


def material_from_args(args: argparse.Namespace) -> Material:
    """Body 1 from --E/--nu and either --sigma-y/--K/--n (no --sigma-y: elastic), --sigma-y with
    --flow NAME:P=V,..., or --flow-table."""
    return _body(args.E, args.nu, args.sigma_y, args.K, args.n, args.flow_table, "",
                 getattr(args, "flow", None))


def material2_from_args(args: argparse.Namespace, material: Material) -> Material | None:
    """Body 2 from --E2/--nu2/--sigma-y2/--K2/--n2, --flow2 or --flow-table2, each missing value
    body 1's (its flow curve, or its law with the parameters given for body 2 replaced); None when
    no body-2 flag is given. --E2 inf makes body 2 rigid."""
    given = {k: getattr(args, k, None) for k in BODY2_FLAGS}
    if all(v is None for v in given.values()):
        return None
    E2 = args.E if given["E2"] is None else given["E2"]
    nu2 = args.nu if given["nu2"] is None else given["nu2"]
    if math.isinf(E2) and E2 > 0:
        return Material.rigid(nu=nu2)
    sy2, K2, n2, table2, flow2 = (given[k] for k in ("sigma_y2", "K2", "n2", "flow_table2", "flow2"))
    own = material.flow
    inherit = not material.is_elastic and table2 is None
    if flow2 is not None and sy2 is None and inherit:
        sy2 = own.sigma_y
    if not inherit or flow2 is not None or (isinstance(own, Table) and (sy2, K2, n2) != (None,) * 3):
        return _body(E2, nu2, sy2, K2, n2, table2, "2", flow2)
    changes = {k: v for k, v in (("sigma_y", sy2), ("K", K2), ("n", n2)) if v is not None}
    if not changes:
        try:
            return Material.with_flow(E2, nu2, own)
        except ValueError as err:
            raise ValueError(f"body 2: {err}") from None
    wrong = [k for k in changes if k != "sigma_y" and k not in own.parameter_names()]
    if wrong:
        raise ValueError(f"--{wrong[0]}2 is not a parameter of body 1's flow curve {own.name} "
                         f"(parameters: sigma_y, {', '.join(own.parameter_names())}); give --flow2")
    merged = {"flow": own.name, "sigma_y": own.sigma_y, **own.parameters(), **changes}
    try:
        return Material.with_flow(E2, nu2, flow_from_description(merged))
    except ValueError as err:
        raise ValueError(f"body 2: {err}") from None


def output_path(out, suffixes: tuple[str, ...] = (), flag: str = "--out") -> Path:
    """The output file ``out``, checked before any work: its directory exists, it is not a
    directory, and (when ``suffixes`` are given) it ends in one of them. Raises ValueError."""
    path = Path(out)
    if suffixes and path.suffix.lower() not in suffixes:
        raise ValueError(f"{flag} {out}: the file name must end in {' or '.join(suffixes)}")
    if path.is_dir():
        raise ValueError(f"{flag} {out} is a directory; give a file name")
    if not path.parent.is_dir():
        raise ValueError(f"{flag} {out}: directory {path.parent} does not exist; create it first")
    return path
