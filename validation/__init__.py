"""Validation of the closed-form model and peer laws against FE runs (DESIGN §5)."""
