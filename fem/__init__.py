"""Axisymmetric large-deformation elastic–plastic FE solver for sphere contact (docs/design.md §4),
and the 3D cell solver of one sphere among rigid flats (fem/cell.py)."""

from .io import Run, run_indentation, write_run
from .runfile import read_run

__all__ = ["Run", "read_run", "run_indentation", "write_run"]
