"""Closed-form unified contact model for two elastic–plastic spheres (DESIGN §1–3)."""

from .material import Material

__all__ = ["Material"]
