"""Run file of a 3D cell run (``spherecontact fem cell``; schema ``spherecontact.fem.cell``).

One HDF5 group ``cell_run`` (docs/formats.md, "Cell run file"): attributes (schema, version,
status, reason, scene, ``input.*``, ``provenance.*``), ``contacts/`` (one row per flat of the
octant: normal, multiplicity, moves) and ``curves/`` (one row per converged increment; the
per-contact curves one column per flat). Written atomically as :func:`.io.write_run`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from ..model.material import Material
from .cell import CellResult
from .cell_scene import SCENES
from .io import INPUT_PREFIX, PROVENANCE_PREFIX, _flatten, _python_value, _replacing, _unflatten

SCHEMA = "spherecontact.fem.cell"
SCHEMA_VERSION = 1
GROUP = "cell_run"
STATUSES = ("converged", "stopped")
#: per-increment curves (n,) and per-contact curves (n, k)
CURVES = ("h", "volume", "density", "work", "stored", "dissipation", "newton", "tension")
CONTACT_CURVES = ("hk", "F", "A", "a", "a_min", "a_max", "a_nodes")


def write_cell_run(path, result: CellResult, inputs: dict, status: str = "converged",
                   reason: str = "", provenance: dict | None = None) -> Path:
    """Write one cell run to ``path`` atomically (temporary sibling, fsync, rename)."""
    if status not in STATUSES:
        raise ValueError(f"status must be one of {STATUSES}, got {status!r}")
    path = Path(path)
    sc = SCENES[result.scene]
    arr = result.arrays()
    k = len(sc.flats)
    with _replacing(path) as tmp, h5py.File(tmp, "w") as f:
        g = f.create_group(GROUP)
        g.attrs.update({"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "status": status,
                        "reason": reason, "scene": result.scene})
        g.attrs.update(_flatten(INPUT_PREFIX, inputs))
        prov = dict(provenance or {})
        prov.update(wall_s=result.wall_s, cpu_s=result.cpu_s, n_nodes=result.n_nodes,
                    n_elements=result.n_elements)
        g.attrs.update(_flatten(PROVENANCE_PREFIX, prov))
        c = g.create_group("contacts")
        c.create_dataset("normal", data=sc.normals)
        c.create_dataset("multiplicity", data=sc.multiplicity)
        c.create_dataset("moves", data=sc.moving)
        cv = g.create_group("curves")
        n = len(result.h)
        for name in CURVES:
            cv.create_dataset(name, data=np.asarray(arr[name], dtype=float).reshape(n))
        for name in CONTACT_CURVES:
            cv.create_dataset(name, data=np.asarray(arr[name], dtype=float).reshape(n, k))
    return path


@dataclass
class CellRun:
    """A cell run read back: ``.h`` (n, k) per-contact approach, ``.F`` (n, k) per-contact force,
    ``.A`` (n, k) per-contact area, ``.density`` (n,); every curve in ``curves``."""

    scene: str
    inputs: dict
    curves: dict
    contacts: dict
    status: str
    reason: str
    provenance: dict = field(default_factory=dict)
    source: str = ""

    @property
    def h(self) -> np.ndarray:
        return self.curves["hk"]

    @property
    def h_load(self) -> np.ndarray:
        return self.curves["h"]

    @property
    def F(self) -> np.ndarray:
        return self.curves["F"]

    @property
    def A(self) -> np.ndarray:
        return self.curves["A"]

    @property
    def a(self) -> np.ndarray:
        return self.curves["a"]

    @property
    def density(self) -> np.ndarray:
        return self.curves["density"]

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def material(self) -> Material:
        return Material.from_description(self.inputs["material"])


def is_cell_file(f: h5py.File) -> bool:
    return GROUP in f


def cell_run_from_group(g: h5py.Group, source: str = "") -> CellRun:
    """Read and validate a ``cell_run`` group."""
    schema = _python_value(g.attrs.get("schema"))
    if schema != SCHEMA:
        raise ValueError(f"group {g.name!r} has schema {schema!r}, expected {SCHEMA!r}")
    version = _python_value(g.attrs.get("schema_version"))
    if version != SCHEMA_VERSION:
        raise ValueError(f"unsupported schema_version {version!r} in {g.name!r} "
                         f"(this reader knows {SCHEMA_VERSION})")
    for name in ("contacts", "curves"):
        if name not in g:
            raise ValueError(f"run group {g.name!r} lacks {name!r}")
    missing = [c for c in CURVES + CONTACT_CURVES if c not in g["curves"]]
    if missing:
        raise ValueError(f"cell run {g.name!r} lacks the curves {missing}")
    curves = {name: np.asarray(g["curves"][name]) for name in g["curves"]}
    contacts = {name: np.asarray(g["contacts"][name]) for name in g["contacts"]}
    n, k = curves["h"].shape[0], contacts["normal"].shape[0]
    bad = [c for c in CURVES if curves[c].shape != (n,)]
    bad += [c for c in CONTACT_CURVES if curves[c].shape != (n, k)]
    if bad:
        raise ValueError(f"cell run curves {bad} do not have the shape ({n},) or ({n}, {k})")
    return CellRun(scene=_python_value(g.attrs["scene"]), inputs=_unflatten(g.attrs, INPUT_PREFIX),
                   curves=curves, contacts=contacts, status=_python_value(g.attrs["status"]),
                   reason=_python_value(g.attrs["reason"]),
                   provenance=_unflatten(g.attrs, PROVENANCE_PREFIX), source=source)
