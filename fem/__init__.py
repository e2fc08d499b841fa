"""Axisymmetric large-deformation elastic–plastic FE solver for sphere contact (DESIGN §4)."""
