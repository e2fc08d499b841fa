"""A sphere: radius (``math.inf`` for a flat) and material (``Material.rigid()`` if rigid)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .material import Material

__all__ = ["Sphere"]


@dataclass(frozen=True)
class Sphere:
    """Spherical body of radius R (> 0; ``math.inf`` is a flat) made of ``material``."""

    radius: float
    material: Material

    def __post_init__(self) -> None:
        try:
            R = float(self.radius)
        except (TypeError, ValueError) as err:
            raise ValueError(f"radius must be a number > 0 (inf for a flat), got {self.radius!r}") \
                from err
        if math.isnan(R) or R <= 0.0:
            raise ValueError(f"radius must be > 0 (inf for a flat), got {self.radius!r}")
        if not isinstance(self.material, Material):
            raise ValueError(
                f"material must be a spherecontact Material, got {type(self.material).__name__}"
            )
        object.__setattr__(self, "radius", R)

    @property
    def is_flat(self) -> bool:
        return math.isinf(self.radius)

    @property
    def is_rigid(self) -> bool:
        return self.material.is_rigid
