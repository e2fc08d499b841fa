"""Axisymmetric large-deformation elastic–plastic FE solver for sphere contact (docs/design.md §4)."""

from .io import Run, read_run, run_indentation, write_run

__all__ = ["Run", "read_run", "run_indentation", "write_run"]
