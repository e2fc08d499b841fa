"""Calibration of H̄(Λ), c²(Λ) and the large-deformation terms from FE (DESIGN §2)."""
