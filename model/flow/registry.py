"""The flow-curve laws by name: ``REGISTRY``, ``register``, and the two ways in — a command-line
spec ``"voce:Q=2,b=10"`` (σ_Y apart) and a description dict (``FlowCurve.describe()``, or the
``Material.describe()`` of a stored run: Ludwik keys or a table without a "flow" key)."""

from __future__ import annotations

import math
from importlib import import_module

from .base import FlowCurve
from .ludwik import Ludwik
from .table import Table

__all__ = ["REGISTRY", "LAWS", "register", "flow_from_spec", "flow_from_description"]

#: registry name → law (a ``FlowCurve`` subclass)
REGISTRY: dict[str, type[FlowCurve]] = {}


def register(cls: type[FlowCurve]) -> type[FlowCurve]:
    """Add the law ``cls`` under ``cls.name`` (usable as a class decorator); returns ``cls``."""
    if not (isinstance(cls, type) and issubclass(cls, FlowCurve)) or not cls.name:
        raise ValueError(f"register: {cls!r} is not a FlowCurve subclass with a name")
    REGISTRY[cls.name] = cls
    return cls


#: the law modules of this package, each defining one ``FlowCurve`` subclass: adding a law is one
#: module in ``model/flow/`` and its name here
LAWS = ("ludwik", "swift", "voce", "linear", "table")


def _law_of(module) -> type[FlowCurve]:
    """The one ``FlowCurve`` subclass a law module defines."""
    found = [v for v in vars(module).values() if isinstance(v, type) and issubclass(v, FlowCurve)
             and v.__module__ == module.__name__]
    if len(found) != 1:
        raise ImportError(f"{module.__name__} must define exactly one FlowCurve subclass, found {len(found)}")
    return found[0]


for _name in LAWS:
    register(_law_of(import_module(f".{_name}", __package__)))


def _law(name: str, where: str) -> type[FlowCurve]:
    try:
        return REGISTRY[name]
    except KeyError:
        raise ValueError(f"{where}unknown flow curve {name!r}; known: "
                         f"{', '.join(sorted(REGISTRY))}") from None


def _allowed(cls: type[FlowCurve]) -> str:
    return ", ".join(("sigma_y", *cls.parameter_names()))


def flow_from_spec(spec: str, sigma_y: float | None = None) -> FlowCurve:
    """The curve of ``spec`` = ``NAME`` or ``NAME:P=V,P=V`` (e.g. ``"voce:Q=2,b=10"``) with initial
    yield stress ``sigma_y`` (or ``sigma_y=…`` inside the spec).

    Raises ValueError naming the spec and the known names, or the law's parameters.
    """
    name, _, rest = str(spec).strip().partition(":")
    cls = _law(name.strip().lower(), f"{spec!r}: ")
    if cls is Table:
        raise ValueError(f"{spec!r}: a flow table has no parameters; give it as a CSV file")
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, value = (s.strip() for s in item.partition("="))
        if not eq:
            raise ValueError(f"{spec!r}: expected P=V, got {item!r} (parameters of {cls.name}: "
                             f"{_allowed(cls)})")
        if key not in ("sigma_y", *cls.parameter_names()):
            raise ValueError(f"{spec!r}: unknown parameter {key!r} of {cls.name}; allowed: "
                             f"{_allowed(cls)}")
        try:
            params[key] = float(value)
        except ValueError:
            raise ValueError(f"{spec!r}: {key} = {value!r} is not a number") from None
    if "sigma_y" in params and sigma_y is not None and params["sigma_y"] != sigma_y:
        raise ValueError(f"{spec!r}: sigma_y given twice ({params['sigma_y']:g} and {sigma_y:g})")
    params.setdefault("sigma_y", math.nan if sigma_y is None else sigma_y)
    if math.isnan(params["sigma_y"]):
        raise ValueError(f"{spec!r}: needs the initial yield stress sigma_y")
    try:
        return cls(**params)
    except TypeError:
        missing = [p for p in cls.parameter_names() if p not in params]
        raise ValueError(f"{spec!r}: {cls.name} needs {', '.join(missing)} (parameters: "
                         f"{_allowed(cls)})") from None


def flow_from_description(d: dict) -> FlowCurve:
    """Inverse of ``FlowCurve.describe()`` and of the flow part of ``Material.describe()``
    (no "flow" key: a table if "eps_table" is there, else Ludwik with missing σ_Y = inf
    (elastic), K = 0, n = 1). Other keys (E, nu) are ignored."""
    name = d.get("flow")
    if name is None:
        name = "table" if "eps_table" in d else "ludwik"
    cls = _law(name, "")
    if cls is Ludwik:
        return Ludwik(sigma_y=float(d.get("sigma_y", math.inf)), K=float(d.get("K", 0.0)),
                      n=float(d.get("n", 1.0)))
    if cls is Table:
        return Table(d["eps_table"], d["sigma_table"])
    keys = ("sigma_y", *cls.parameter_names())
    missing = [k for k in keys if k not in d]
    if missing:
        raise ValueError(f"flow {name!r}: description lacks {', '.join(missing)}")
    return cls(**{k: float(d[k]) for k in keys})
