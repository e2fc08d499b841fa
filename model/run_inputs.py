"""Run → model conversion: the closed-form model's material and sphere pair of an FE run's
stored ``inputs`` (the inverse of ``Material.describe()``), used by the FE, the database, the
calibration and the validation alike."""

from __future__ import annotations

import math

from .material import Material
from .sphere import Sphere

__all__ = ["spheres_from_inputs"]


def spheres_from_inputs(inputs: dict, scene: str) -> tuple[Sphere, Sphere]:
    """The closed-form model's sphere pair of an FE run's ``inputs`` (``Run.inputs``).

    Body 1 is the FE hemisphere (``radius``, ``material``); body 2 the partner of ``scene``:
    ``"two_body"`` the second deformable sphere (``radius2``, ``material2``; the first's where
    absent), ``"rigid_sphere"`` a rigid sphere of ``indenter_radius`` (``radius2`` where that
    is infinite), anything else a rigid flat.
    """
    s1 = Sphere(float(inputs["radius"]), Material.from_description(inputs["material"]))
    if scene == "two_body":
        m2 = inputs.get("material2", inputs["material"])
        return s1, Sphere(float(inputs.get("radius2", s1.radius)), Material.from_description(m2))
    if scene == "rigid_sphere":
        R2 = float(inputs.get("indenter_radius", math.inf))
        if not math.isfinite(R2):
            R2 = float(inputs["radius2"])
        return s1, Sphere(R2, Material.rigid())
    return s1, Sphere(math.inf, Material.rigid())
