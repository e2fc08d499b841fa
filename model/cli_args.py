"""Command-line inputs shared by ``spherecontact model …`` and ``spherecontact fem run``.

Each body's material comes from the same flags in both stages (``--E --nu --sigma-y --K --n``
or ``--flow-table``; ``--E2 … --flow-table2`` for body 2) and is checked once, by
:class:`~spherecontact.model.material.Material`. Output paths are checked before any work.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np

from .material import Material

__all__ = ["read_flow_table", "material_from_args", "material2_from_args", "output_path",
           "BODY2_FLAGS"]

#: body-2 flags of the command line (destination → flag); any of them makes a pair
BODY2_FLAGS = {"radius2": "--radius2", "E2": "--E2", "nu2": "--nu2", "sigma_y2": "--sigma-y2",
               "K2": "--K2", "n2": "--n2", "flow_table2": "--flow-table2"}


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


def _body(E, nu, sigma_y, K, n, flow_table, suffix: str) -> Material:
    """One body's material; ``suffix`` is "" for body 1, "2" for body 2 (names the flags)."""
    if math.isinf(E) and E > 0:
        return Material.rigid(nu=nu)
    if flow_table is not None:
        given = [f"--{name}{suffix}" for name, v in (("sigma-y", sigma_y), ("K", K), ("n", n))
                 if v is not None]
        if given:
            raise ValueError(f"--flow-table{suffix} replaces --sigma-y{suffix}/--K{suffix}/"
                             f"--n{suffix}; drop {', '.join(given)}")
        eps, sigma = read_flow_table(flow_table, f"--flow-table{suffix}")
        try:
            return Material.from_table(E, nu, eps, sigma)
        except ValueError as err:
            raise ValueError(f"--flow-table{suffix} {flow_table}: {err}") from None
    sy = math.inf if sigma_y is None else sigma_y
    if math.isinf(sy) and (K is not None or n is not None):
        raise ValueError(f"--K{suffix}/--n{suffix} need --sigma-y{suffix} (without a yield stress "
                         "the body is elastic and never hardens)")
    try:
        return Material(E=E, nu=nu, sigma_y=sy, K=0.0 if K is None else K, n=1.0 if n is None else n)
    except ValueError as err:
        raise ValueError(f"body {suffix or '1'}: {err}") from None


def material_from_args(args: argparse.Namespace) -> Material:
    """Body 1 from --E/--nu and either --sigma-y/--K/--n (no --sigma-y: elastic) or --flow-table."""
    return _body(args.E, args.nu, args.sigma_y, args.K, args.n, args.flow_table, "")


def material2_from_args(args: argparse.Namespace, material: Material) -> Material | None:
    """Body 2 from --E2/--nu2/--sigma-y2/--K2/--n2 or --flow-table2, each missing value body 1's;
    None when no body-2 flag is given. --E2 inf makes body 2 rigid."""
    given = {k: getattr(args, k, None) for k in BODY2_FLAGS}
    if all(v is None for v in given.values()):
        return None
    E2 = args.E if given["E2"] is None else given["E2"]
    nu2 = args.nu if given["nu2"] is None else given["nu2"]
    plastic = [given[k] for k in ("sigma_y2", "K2", "n2")]
    if math.isinf(E2) and E2 > 0:
        return Material.rigid(nu=nu2)
    if given["flow_table2"] is None and all(v is None for v in plastic) and material.is_tabulated:
        return Material.from_table(E2, nu2, material.eps_table, material.sigma_table)
    ludwik1 = not (material.is_rigid or material.is_tabulated) and math.isfinite(material.sigma_y)
    if given["flow_table2"] is None and ludwik1:  # each missing value is body 1's
        plastic = [own if v is None else v for v, own in
                   zip(plastic, (material.sigma_y, material.K, material.n), strict=True)]
    return _body(E2, nu2, *plastic, given["flow_table2"], "2")


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
