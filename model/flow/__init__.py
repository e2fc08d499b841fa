"""Flow curves σ_f(ε_p) as a family: one protocol (``FlowCurve``), one module per law, a registry.

Laws: ``ludwik`` σ_Y + K εⁿ, ``swift`` σ_Y (1 + ε/ε₀)ⁿ, ``voce`` σ_Y + Q σ_Y (1 − e^(−bε)),
``linear`` σ_Y + H ε, ``table`` (monotone, linear interpolation). Adding a law: one module with a
``FlowCurve`` dataclass and one ``register`` line in ``registry.py``.
"""

from .base import FlowCurve, check_parameter
from .linear import Linear
from .ludwik import Ludwik
from .registry import REGISTRY, flow_from_description, flow_from_spec, register
from .swift import Swift
from .table import Table
from .voce import Voce

__all__ = ["FlowCurve", "check_parameter", "Ludwik", "Swift", "Voce", "Linear", "Table", "REGISTRY",
           "register", "flow_from_spec", "flow_from_description"]
