"""Scenes of the 3D cell solver: the rigid frictionless flats around one sphere (issue 62).

In a lattice of equal spheres every contact plane is a symmetry plane, so each contact is the
sphere against a rigid frictionless flat. A flat k has the outward unit normal n_k (the
direction of the neighbour) and sits at n_k · x = R − h_k/2: h_k is the contact's approach
(2R − d for a neighbour at distance d), the flat's travel h_k/2. Only the octant x, y, z ≥ 0 is
modelled, so only the flats whose pole lies in it are listed; a contact whose pole lies on s of
the symmetry planes is cut into 2^s pieces by them, its force is ``multiplicity`` = 2^s × the
octant's reaction.

Relative density (solid volume over cell volume), V = 8 ∫ J dV₀ the current solid volume:

- simple cubic, isostatic:   V / (2R − h)³
- simple cubic, closed die:  V / ((2R)² (2R − h))
- face-centred cubic:        V / (d³/√2),  d = 2R − h (the rhombohedral primitive cell's volume)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_S2 = 1.0 / np.sqrt(2.0)


@dataclass(frozen=True)
class Flat:
    """A rigid frictionless flat: outward unit ``normal``; ``moves``: its approach is the load's
    h (True) or stays 0, touching the undeformed sphere (False, the lateral walls of a die)."""

    normal: tuple[float, float, float]
    moves: bool = True

    @property
    def multiplicity(self) -> int:
        """2^(symmetry planes through the pole): the octant holds 1/multiplicity of the patch."""
        return 2 ** int(np.sum(np.abs(np.asarray(self.normal)) < 1e-12))


@dataclass(frozen=True)
class Scene:
    """Flats of a scene and the cell volume of its relative density (None: no cell)."""

    name: str
    flats: tuple[Flat, ...]
    cell: str | None

    @property
    def normals(self) -> np.ndarray:
        """(k, 3) unit normals of the flats."""
        return np.array([f.normal for f in self.flats], dtype=float)

    @property
    def moving(self) -> np.ndarray:
        return np.array([f.moves for f in self.flats], dtype=bool)

    @property
    def multiplicity(self) -> np.ndarray:
        return np.array([f.multiplicity for f in self.flats], dtype=float)

    def approaches(self, h: float) -> np.ndarray:
        """Per-contact approach h_k at the load's approach h."""
        return np.where(self.moving, float(h), 0.0)

    def cell_volume(self, h: float, radius: float) -> float:
        """Volume of the unit cell of one sphere at the load's approach h (nan: no cell)."""
        d = 2.0 * radius - h
        if self.cell == "sc":
            return d**3
        if self.cell == "die":
            return (2.0 * radius) ** 2 * d
        if self.cell == "fcc":
            return d**3 / np.sqrt(2.0)
        return float("nan")

    def approach_at_density(self, density: float, radius: float) -> float:
        """The load approach h at which the relative density reaches ``density`` if the solid
        volume stays 4π/3 R³ (plastic flow conserves it; elastic compression makes the actual h
        slightly larger)."""
        v = 4.0 / 3.0 * np.pi * radius**3 / density
        if self.cell == "sc":
            return 2.0 * radius - v ** (1.0 / 3.0)
        if self.cell == "die":
            return 2.0 * radius - v / (2.0 * radius) ** 2
        if self.cell == "fcc":
            return 2.0 * radius - (np.sqrt(2.0) * v) ** (1.0 / 3.0)
        raise ValueError(f"scene {self.name!r} has no cell, hence no density")

    def density(self, volume: float, h: float, radius: float) -> float:
        """Relative density: solid volume ``volume`` over the cell volume (module docstring)."""
        return volume / self.cell_volume(h, radius)


SCENES = {
    "two-flats": Scene("two-flats", (Flat((0.0, 0.0, 1.0)),), None),
    "sc-isostatic": Scene("sc-isostatic", (Flat((1.0, 0.0, 0.0)), Flat((0.0, 1.0, 0.0)),
                                           Flat((0.0, 0.0, 1.0))), "sc"),
    "sc-die": Scene("sc-die", (Flat((1.0, 0.0, 0.0), moves=False), Flat((0.0, 1.0, 0.0), moves=False),
                               Flat((0.0, 0.0, 1.0))), "die"),
    "fcc-isostatic": Scene("fcc-isostatic", (Flat((_S2, _S2, 0.0)), Flat((_S2, 0.0, _S2)),
                                             Flat((0.0, _S2, _S2))), "fcc"),
}


def scene(lattice: str, load: str = "isostatic") -> Scene:
    """The scene of a lattice ('sc', 'fcc'; 'two-flats') under a load ('isostatic', 'die')."""
    name = lattice if lattice == "two-flats" else f"{lattice}-{load}"
    if name not in SCENES:
        allowed = ", ".join(repr(k) for k in SCENES)
        raise ValueError(f"lattice/load {lattice!r}/{load!r} is not a scene; one of {allowed}")
    return SCENES[name]
