"""spherecontact: contact force and area between two elastic–plastic spheres.

Stages (docs/design.md): ``fem`` (reference FE solver) → ``data`` → ``calibration``
→ ``model`` (closed-form unified law) ← ``validation``.
"""

__version__ = "0.1.0"
