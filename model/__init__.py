"""Closed-form unified contact model for two elastic–plastic spheres (docs/design.md §1–3).

Public API::

    from spherecontact.model import Material, Sphere, contact
    st = contact(Sphere(1e-3, m), Sphere(math.inf, Material.rigid()), h)
    st.F, st.a, st.h1, st.h2, st.stiffness
    st = contact(s1, s2, h, h_max=hm)       # unloading/reloading below the largest approach hm
    residual_approach(s1, s2, hm); cycle(s1, s2, hm).restitution

``ContactLaw`` is the tabulated fast path for many contacts of one sphere pair.

Inputs outside the range the coefficients were calibrated on give a
``CalibrationRangeWarning`` (a ``UserWarning``; ``Coefficients.calibrated_range``).
"""

from .calibrated_range import CalibratedRange, CalibrationRangeWarning
from .coefficients import Coefficients, default_coefficients, load_coefficients
from .contact import ContactState, contact, contact_from_radius, residual_approach
from .cycle import Cycle, cycle
from .fast import ContactLaw, contact_table
from .material import Material
from .sphere import Sphere

__all__ = [
    "Material",
    "Sphere",
    "contact",
    "contact_from_radius",
    "residual_approach",
    "cycle",
    "Cycle",
    "ContactState",
    "ContactLaw",
    "contact_table",
    "Coefficients",
    "load_coefficients",
    "default_coefficients",
    "CalibratedRange",
    "CalibrationRangeWarning",
]
