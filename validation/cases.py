"""A validation case: one FE run from the reference database and the sphere pair it stands for.

The FE scenes (docs/design.md §4) and the pair the model is evaluated for:

* ``flat``: hemisphere R_1 on a rigid frictionless flat → Sphere(R_1, m_1) against
  Sphere(∞, rigid);
* ``rigid_sphere``: hemisphere R_1 under a rigid sphere R_2 → Sphere(R_1, m_1) against
  Sphere(R_2, rigid);
* ``two_body``: two deformable hemispheres, h = h_1 + h_2 → Sphere(R_1, m_1) against
  Sphere(R_2, m_2).

The flat scene is, by symmetry, one of two equal spheres: h is one body's approach
(the pair's mutual approach is 2h). The model gives the same body response for the
rigid-flat pair at h and for the equal pair at 2h (ρ = R in both), so the comparison
uses the scene the FE solved. The database is opened only through
``spherecontact.data.Database`` (:func:`load_cases`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..fem.io import loading_mask, reference_mask
from ..model import Material, Sphere
from ..model.run_inputs import spheres_from_inputs

__all__ = [
    "CLASSES",
    "Case",
    "scene_of",
    "spheres",
    "reference_radius",
    "classes",
    "is_perfectly_plastic",
    "case_from_run",
    "load_cases",
    "load_records",
]

#: validation classes, in report order (a run may belong to several)
CLASSES = ("equal spheres", "rigid indenter", "dissimilar radii", "dissimilar materials",
           "hardening levels")
SCENES = ("flat", "rigid_sphere", "two_body")


@dataclass(frozen=True, eq=False)
class Case:
    """One FE run with its database record.

    ``curves`` maps curve names (``h``, ``F``, ``a``, and ``h1``, ``h2`` for two-body
    runs, …) to 1-D arrays; ``inputs`` are the run's inputs (``material``, ``radius``,
    ``indenter_radius`` or ``radius2``/``material2``, ``mesh_density``, ``element``,
    ``options``); ``params`` the campaign's dimensionless parameters of the case.
    """

    key: str
    set: str
    name: str
    params: dict
    inputs: dict
    curves: dict
    status: str = "converged"
    reason: str = ""
    wall_s: float = math.nan
    provenance: dict = field(default_factory=dict)
    cycles: dict = field(default_factory=dict)  # per unloading branch (``fem.io`` ``cycles/*``)

    @property
    def label(self) -> str:
        """Short name for tables: the campaign's case name, else the key."""
        return self.name or self.key

    @property
    def loading(self) -> np.ndarray:
        """Mask of the loading increments (``branch`` 0); all True for runs without cycles."""
        return loading_mask(self.curves)

    @property
    def reference(self) -> np.ndarray:
        """Mask of the loading increments that are a reference: without the transient of an
        oversized first step (``fem.io.reference_mask``)."""
        return reference_mask(self.curves, self.inputs)

    @property
    def h(self) -> np.ndarray:
        """Approach on the loading curve (unloading and reloading increments and the transient
        of an oversized first step left out)."""
        return self.curve("h")

    @property
    def F(self) -> np.ndarray:
        return self.curve("F")

    @property
    def a(self) -> np.ndarray:
        return self.curve("a")

    def curve(self, name: str) -> np.ndarray | None:
        """A recorded curve on the reference loading increments (:attr:`reference`), or None
        when the run does not hold it (``raw_curve``: every increment, loading, unloading and
        reloading)."""
        c = self.raw_curve(name)
        return None if c is None else c[self.reference]

    def raw_curve(self, name: str) -> np.ndarray | None:
        """A recorded curve at every increment in the order computed, or None."""
        c = self.curves.get(name)
        return None if c is None else np.asarray(c, dtype=float)

    @property
    def scene(self) -> str:
        return scene_of(self.params, self.inputs)

    def option(self, name: str, default=None):
        """A solver option of the run: ``params`` first, then ``inputs['options']``."""
        if name in self.params:
            return self.params[name]
        return self.inputs.get("options", {}).get(name, default)


# ============================================================================ materials and scenes
#: the FE run's own scene names (``run.inputs["scene"]``) → scene of this module
FE_SCENES = {"rigid_flat": "flat", "rigid_sphere": "rigid_sphere", "two_body": "two_body",
             "equal_pair_symmetry": "two_body"}


def scene_of(params: dict, inputs: dict) -> str:
    """``flat``, ``rigid_sphere`` or ``two_body``: the campaign's ``scene``, else the run's."""
    s = params.get("scene")
    if s in SCENES:
        return s
    if inputs.get("scene") in FE_SCENES:
        return FE_SCENES[inputs["scene"]]
    if "material2" in inputs and not math.isinf(float(inputs["material2"].get("E", 0.0))):
        return "two_body"
    if math.isfinite(float(inputs.get("indenter_radius", math.inf))):
        return "rigid_sphere"
    return "flat"


def spheres(case: Case) -> tuple[Sphere, Sphere]:
    """The sphere pair of the FE scene (body 1 is the FE hemisphere of ``radius``;
    ``fem.io.spheres_from_inputs``)."""
    return spheres_from_inputs(case.inputs, case.scene)


def reference_radius(case: Case) -> float:
    """R used in h/R: the smallest radius of a deformable body (R_1 in the rigid scenes)."""
    s1, s2 = spheres(case)
    if s2.is_rigid or s2.is_flat:
        return s1.radius
    return min(s1.radius, s2.radius)


def _hardens(m: Material) -> bool:
    return not m.is_elastic and m.flow.hardens()


def is_perfectly_plastic(m: Material) -> bool:
    """Elastic–perfectly plastic: finite yield stress, no hardening."""
    return not m.is_rigid and math.isfinite(m.sigma_y) and not _hardens(m)


def classes(case: Case) -> tuple[str, ...]:
    """Validation classes of a case (see :data:`CLASSES`)."""
    s1, s2 = spheres(case)
    out = set()
    scene = case.scene
    if scene == "flat":
        out.add("equal spheres")
    elif scene == "rigid_sphere" or s2.is_rigid:
        out.add("rigid indenter")
    else:
        if s1.radius != s2.radius:
            out.add("dissimilar radii")
        if s1.material != s2.material:
            out.add("dissimilar materials")
        if not out:
            out.add("equal spheres")
    if any(_hardens(s.material) for s in (s1, s2)):
        out.add("hardening levels")
    return tuple(c for c in CLASSES if c in out)


# ============================================================================ loading
def _wall(record_wall, prov: dict) -> float:
    for v in (record_wall, prov.get("wall_s"), prov.get("timings", {}).get("wall_s")):
        try:
            f = float(v)
        except (TypeError, ValueError):
            continue
        if math.isfinite(f) and f > 0:
            return f
    return math.nan


def case_from_run(run, key: str = "", set: str = "", name: str = "", params: dict | None = None,
                  status: str | None = None, reason: str | None = None,
                  wall_s: float | None = None) -> Case:
    """A :class:`Case` from a ``spherecontact.fem.io.Run`` (and optionally its record's fields)."""
    prov = dict(getattr(run, "provenance", {}) or {})
    return Case(key=key, set=set, name=name, params=dict(params or {}), inputs=dict(run.inputs),
                curves={k: np.asarray(v, dtype=float) for k, v in run.curves.items()},
                status=run.status if status is None else status,
                reason=run.reason if reason is None else reason,
                wall_s=_wall(wall_s, prov), provenance=prov,
                cycles={k: np.asarray(v) for k, v in (getattr(run, "cycles", None) or {}).items()})


def load_cases(db_path, set_name: str, statuses=("converged", "stopped")) -> list[Case]:
    """Every run of ``set_name`` with one of ``statuses``, through the database reader API."""
    from spherecontact.data import Database

    db = Database(db_path)
    out = []
    for status in statuses:
        for rec, run in db.runs(set=set_name, status=status):
            out.append(case_from_run(run, key=rec.key, set=rec.set, name=rec.case,
                                     params=rec.params, status=rec.status, reason=rec.reason,
                                     wall_s=rec.wall_s))
    return sorted(out, key=lambda c: (c.label, c.key))


def load_records(db_path, set_name: str) -> list:
    """All records of a set (any status, including failed runs without curves)."""
    from spherecontact.data import Database

    return list(Database(db_path).records(set=set_name))
