"""Campaign file: the FE design of experiments in dimensionless terms (TOML).

A campaign has optional ``[campaign]`` metadata, ``[defaults]`` for every case,
and one array of tables per set (``[[calibration]]``, ``[[validation]]``, any
other name). Every entry names a ``scene`` and parameters; a list-valued
parameter is a grid axis and an entry expands to the product of its lists::

    [defaults]
    h_max = 0.3
    mesh_density = 1.0

    [[calibration]]
    scene = "flat"
    E_over_sigma_y = [100, 1000]
    nu = [0.2, 0.45]           # -> 4 cases

Units: R1 = ``radius``, σY1 = ``sigma_y`` (both 1 by default); E, K and body 2's
properties are ratios. Every parameter is checked against its range, sets must
be disjoint, and each case gets a readable name (``flat-pp-E1000-nu0.3``).
Parameters and ranges are in :data:`PARAMETERS`; ``data/README.md`` documents
the format.

A case the FE cannot finish as designed is replaced in a ``[replace]`` table, by
its name, with a reason and the parameters that change (``h_max``, ``cycles``)::

    [replace."two-pp-E300-nu0.3-vs-sy2-f0.0015"]
    h_max = 0.18
    reason = "inverted element at h/R 0.186 (Lagrangian mesh at the contact edge)"

The original case leaves the campaign (its stored run becomes superseded) and the
replacement carries ``replaces`` = (original name, reason) into the reports.
"""

from __future__ import annotations

import itertools
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from ..data import input_key
from ..fem.assembly import ELEMENTS
from ..fem.mesh import BAND_FLOOR_RANGE, DENSITY_RANGE, EDGE_BAND_MAX, EDGE_BAND_MIN, check_band_floor
from ..fem.solver import SolverOptions
from ..model.flow.voce import Voce
from ..model.material import Material

__all__ = ["PARAMETERS", "SCENES", "Param", "Case", "Campaign", "load_campaign", "parse_campaign",
           "run_kwargs"]

SCENES = ("flat", "rigid_sphere", "two_body")
_TWO = ("two_body",)


@dataclass(frozen=True)
class Param:
    """One campaign parameter: allowed values, default, the scenes it applies to."""

    doc: str
    lo: float | None = None  # numeric bounds (None: unbounded)
    hi: float | None = None
    lo_open: bool = True
    hi_open: bool = False
    choices: tuple = ()  # allowed strings (string parameters)
    default: object = None  # None: required, or taken from another parameter (see _resolve)
    scenes: tuple = SCENES

    def check(self, name: str, value, where: str):
        """``value`` normalised (float or str); ValueError naming ``where``, the parameter and range."""
        if self.choices:
            if value not in self.choices:
                raise ValueError(f"{where}: {name} = {value!r} is not one of {list(self.choices)}")
            return value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{where}: {name} must be a number, got {value!r}")
        x = float(value)
        if math.isnan(x) or not self._inside(x):
            raise ValueError(f"{where}: {name} = {value!r} out of range: must lie in {self.range_text()}")
        return x

    def _inside(self, x: float) -> bool:
        lo = -math.inf if self.lo is None else self.lo
        hi = math.inf if self.hi is None else self.hi
        above = x > lo if self.lo_open else x >= lo
        below = x < hi if self.hi_open else x <= hi
        return above and below

    def range_text(self) -> str:
        if self.choices:
            return " | ".join(self.choices)
        lo = "-inf" if self.lo is None else f"{self.lo:g}"
        hi = "inf" if self.hi is None else f"{self.hi:g}"
        return f"{'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"


#: every parameter a campaign entry or [defaults] may set
PARAMETERS = {
    "scene": Param("flat: hemisphere on a rigid flat (= two equal spheres); rigid_sphere: on a rigid "
                   "sphere of indenter_radius; two_body: two deformable spheres", choices=SCENES),
    "E_over_sigma_y": Param("Young's modulus of body 1 over its yield stress, E1/σY1", lo=1, hi=1e7),
    "nu": Param("Poisson's ratio of body 1", lo=-1, hi=0.5, hi_open=True, default=0.3),
    "K_over_sigma_y": Param("Ludwik hardening modulus of body 1 over σY1 (0: perfectly plastic)",
                            lo=0, hi=1e4, lo_open=False, default=0.0),
    "n": Param("Ludwik hardening exponent of body 1 (ignored, stored as 1, when K = 0)", lo=0, hi=1,
               default=1.0),
    "h_max": Param("final approach in units of the smaller radius, min(R1, R2) (R2: the rigid "
                   "sphere's or body 2's radius; R1 on a flat)", lo=0, hi=0.8),
    "mesh_density": Param("mesh-density factor of the FE mesh", lo=DENSITY_RANGE[0], hi=DENSITY_RANGE[1],
                          lo_open=False, default=1.0),
    "edge_band": Param("surface element size per unit distance from the pole (0: default mesh)",
                       lo=0, hi=EDGE_BAND_MAX, lo_open=False, default=0.0),
    "band_floor": Param("smallest element size of the surface band in units of the smaller radius "
                        "(needs edge_band > 0)", lo=BAND_FLOOR_RANGE[0], hi=BAND_FLOOR_RANGE[1],
                        lo_open=False, default=EDGE_BAND_MIN),
    "Q_over_sigma_y": Param("Voce saturation of body 1 over σY1: σ_f = σY + K ε_p^n + Q(1 − e^(−b ε_p))",
                            lo=0, hi=1e4, lo_open=False, default=0.0),
    "b": Param("Voce saturation rate of body 1 (ignored when Q = 0)", lo=0, hi=1e5, default=1.0),
    "flow_curve": Param("name of a tabulated flow curve of body 1 in [flow_curves.<name>] "
                        "(replaces K, n, Q, b)", choices=None, default=""),
    "element": Param("finite element", choices=tuple(sorted(ELEMENTS)), default="q8r"),
    "max_wall_s": Param("wall-time limit of one run in seconds (the run is stored as stopped)",
                        lo=0, default=math.inf),
    "radius": Param("radius R1 of body 1 (the length unit)", lo=0, hi=1e12, hi_open=True, default=1.0),
    "sigma_y": Param("yield stress σY1 of body 1 (the stress unit)", lo=0, hi=1e15, hi_open=True,
                     default=1.0),
    "indenter_radius": Param("radius of the rigid sphere in units of R1", lo=0, hi=1e6,
                             scenes=("rigid_sphere",)),
    "radius2": Param("radius of body 2 in units of R1", lo=0, hi=1e3, default=1.0, scenes=_TWO),
    "E2_over_E1": Param("Young's modulus of body 2 over that of body 1", lo=0, hi=1e4, default=1.0,
                        scenes=_TWO),
    "nu2": Param("Poisson's ratio of body 2 (default: nu)", lo=-1, hi=0.5, hi_open=True, scenes=_TWO),
    "sigma_y2_over_sigma_y1": Param("yield stress of body 2 over σY1", lo=0, hi=1e4, default=1.0,
                                    scenes=_TWO),
    "K2_over_sigma_y1": Param("Ludwik modulus of body 2 over σY1 (default: K_over_sigma_y)", lo=0,
                              hi=1e4, lo_open=False, scenes=_TWO),
    "n2": Param("Ludwik exponent of body 2 (default: n)", lo=0, hi=1, scenes=_TWO),
}
#: body-2 parameters whose default is body 1's value
_FROM_BODY1 = {"nu2": "nu", "K2_over_sigma_y1": "K_over_sigma_y", "n2": "n"}
#: solver options a campaign may set in an ``options`` table (max_wall_s has its own key)
OPTION_NAMES = tuple(f.name for f in fields(SolverOptions) if f.name != "max_wall_s")
#: keys of an entry besides PARAMETERS
_ENTRY_KEYS = ("options", "cycles", "sample")
_SETS_RESERVED = ("campaign", "defaults", "flow_curves", "replace")
#: what a ``[replace]`` entry may change (besides its required ``reason``)
REPLACEABLE = ("h_max", "cycles")
#: significant digits of a tabulated Voce-type curve. The table is the run's input, hashed
#: into its key, and NumPy's SIMD exp/log/power differ in the last bit between CPUs (the
#: keys of campaign v2's 12 Voce runs changed on another machine with the same code and
#: NumPy); rounded, the same campaign gives the same keys everywhere (a last-bit change
#: crosses a 10-digit rounding boundary with probability ~1e-6 per value). The rounding
#: moves the curve by < 5e-11 relative.
TABLE_DIGITS = 10


def _rounded(values) -> np.ndarray:
    return np.array([float(f"{v:.{TABLE_DIGITS}g}") for v in np.asarray(values, dtype=float)])


#: strain points of the table a Voce-type curve is stored as (linear between them)
VOCE_STRAINS = tuple(_rounded([0.0, *np.geomspace(1e-5, 4.0, 90)]))
#: space-filling designs of a ``sample`` table (scipy.stats.qmc)
SAMPLERS = ("sobol", "lhs")
#: significant digits of a sampled parameter value (readable names, stable keys)
SAMPLE_DIGITS = 3


# ============================================================================ cases
def run_kwargs(inputs: dict, **options) -> dict:
    """Keyword arguments of ``fem.io.run_indentation`` for the inputs of a run: a campaign case's
    (:meth:`Case.run_kwargs`) or a stored run's (``Run.inputs``); ``options`` replace recorded
    solver options (e.g. ``max_wall_s``). Two bodies when the inputs name body 2's radius."""
    i = inputs
    kw = {"material": Material.from_description(i["material"]), "radius": i["radius"],
          "h_max": i["h_max"], "density": i["mesh_density"], "element": i["element"],
          "options": SolverOptions(**{**i["options"], **options}),
          "edge_band": i.get("edge_band", 0.0), "band_floor": i.get("band_floor"),
          "unload_at": i.get("unload_at")}
    if "radius2" in i:
        kw.update(radius2=i["radius2"], material2=Material.from_description(i["material2"]))
    else:
        kw["indenter_radius"] = i["indenter_radius"]
    return kw


@dataclass(frozen=True)
class Case:
    """One expanded campaign case: names, parameters, and the inputs of its FE run.

    ``inputs`` (dimensional, consistent units) are what the database key hashes:
    material, radius, h_max, mesh_density, element, options (those set by the
    campaign) and indenter_radius, or radius2 and material2 for two bodies.
    ``max_wall_s`` is a resource limit, not an input.
    """

    set: str
    name: str
    entry: str
    params: dict
    inputs: dict
    max_wall_s: float
    #: (name of the designed case this one replaces, reason), or () for a designed case
    replaces: tuple = ()
    key: str = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "key", input_key(self.inputs))

    @property
    def scene(self) -> str:
        return self.params["scene"]

    def run_kwargs(self) -> dict:
        """Keyword arguments of ``fem.io.run_indentation`` for this case."""
        return run_kwargs(self.inputs, max_wall_s=self.max_wall_s)


@dataclass(frozen=True)
class Campaign:
    """A parsed campaign: its text, source, metadata, set names and expanded cases."""

    text: str
    source: str
    meta: dict
    sets: tuple
    cases: tuple

    def select(self, sets=None, only: str | None = None) -> list[Case]:
        """Cases of the given sets (None: all) whose name contains ``only``."""
        return [c for c in self.cases
                if (sets is None or c.set in sets) and (not only or only in c.name)]


# ============================================================================ parsing
def _fmt(x: float) -> str:
    return f"{x:.10g}"


def _hardening(K: float, n: float) -> str:
    return "pp" if K == 0 else f"K{_fmt(K)}-n{_fmt(n)}"


def _hardening1(p: dict) -> str:
    """Body 1's flow-curve tag: a named table, Ludwik, Voce or both."""
    if p.get("flow_curve"):
        return p["flow_curve"]
    tag = _hardening(p["K_over_sigma_y"], p["n"])
    if p.get("Q_over_sigma_y", 0.0) > 0:
        voce = f"voceQ{_fmt(p['Q_over_sigma_y'])}-b{_fmt(p['b'])}"
        tag = voce if tag == "pp" else f"{tag}-{voce}"
    return tag


def _name(p: dict, defaults: dict) -> str:
    """Readable case name from the resolved parameters."""
    scene = {"flat": "flat", "rigid_sphere": f"rsphere{_fmt(p.get('indenter_radius', 0))}",
             "two_body": "two"}[p["scene"]]
    parts = [scene, _hardening1(p), f"E{_fmt(p['E_over_sigma_y'])}",
             f"nu{_fmt(p['nu'])}"]
    if p["scene"] == "two_body":
        other = []
        if p["radius2"] != 1:
            other.append(f"R{_fmt(p['radius2'])}")
        if p["E2_over_E1"] != 1:
            other.append(f"E{_fmt(p['E2_over_E1'] * p['E_over_sigma_y'])}")
        if p["nu2"] != p["nu"]:
            other.append(f"nu{_fmt(p['nu2'])}")
        if p["sigma_y2_over_sigma_y1"] != 1:
            other.append(f"sy{_fmt(p['sigma_y2_over_sigma_y1'])}")
        if (p["K2_over_sigma_y1"], p["n2"]) != (p["K_over_sigma_y"], p["n"]):
            other.append(_hardening(p["K2_over_sigma_y1"], p["n2"]))
        parts += ["vs", *(other or ["same"])]
    for key, tag in (("h_max", "h"), ("mesh_density", "d"), ("edge_band", "c"), ("band_floor", "f")):
        if p[key] != defaults.get(key, PARAMETERS[key].default):
            parts.append(f"{tag}{_fmt(p[key])}")
    if p["element"] != defaults.get("element", PARAMETERS["element"].default):
        parts.append(p["element"])
    return "-".join(parts)


def _check_options(options, where: str) -> dict:
    """A table of solver options: known names, valid values (SolverOptions.validate)."""
    if not isinstance(options, dict):
        raise ValueError(f"{where}: options must be a table of solver options, got {options!r}")
    unknown = sorted(set(options) - set(OPTION_NAMES))
    if unknown:
        hint = " (max_wall_s is a parameter of its own)" if "max_wall_s" in unknown else ""
        raise ValueError(f"{where}: unknown solver option {unknown[0]!r}{hint}; "
                         f"known: {', '.join(OPTION_NAMES)}")
    try:
        SolverOptions(**options).validate()
    except (TypeError, ValueError) as err:
        raise ValueError(f"{where}: options: {err}") from None
    return dict(options)


def _check_keys(table: dict, where: str) -> None:
    unknown = [k for k in table if k not in PARAMETERS and k not in _ENTRY_KEYS]
    if unknown:
        raise ValueError(f"{where}: unknown parameter {unknown[0]!r}; known: "
                         f"{', '.join([*PARAMETERS, *_ENTRY_KEYS])}")


def _check_curves(doc: dict) -> dict:
    """The ``[flow_curves.<name>]`` tables: eps_p from 0 increasing, sigma_over_sigma_y from 1
    non-decreasing, and a source. Returns {name: (eps_p, sigma_over_sigma_y)}."""
    curves = doc.get("flow_curves", {})
    if not isinstance(curves, dict):
        raise ValueError("[flow_curves] must hold tables [flow_curves.<name>]")
    out = {}
    for name, table in curves.items():
        where = f"[flow_curves.{name}]"
        if not isinstance(table, dict) or not {"eps_p", "sigma_over_sigma_y", "source"} <= set(table):
            raise ValueError(f"{where} needs eps_p, sigma_over_sigma_y (lists) and source (text)")
        eps, sig = table["eps_p"], table["sigma_over_sigma_y"]
        try:
            Material.from_table(1e3, 0.3, eps, sig)  # the shape alone: E/σ_Y 1000 is in range
        except (TypeError, ValueError) as err:
            raise ValueError(f"{where}: {err}") from None
        if sig[0] != 1:
            raise ValueError(f"{where}: sigma_over_sigma_y must start at 1 (σ/σY at ε_p = 0), "
                             f"got {sig[0]!r}")
        out[name] = (tuple(float(x) for x in eps), tuple(float(x) for x in sig))
    return out


def _check_cycles(value, where: str) -> tuple:
    """``cycles``: increasing approaches in (0, 0.8], in the unit of h_max."""
    if not isinstance(value, list) or not value or not all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise ValueError(f"{where}: cycles must be a non-empty list of approaches, got {value!r}")
    x = [float(v) for v in value]
    if any(not 0 < v <= 0.8 for v in x) or any(b <= a for a, b in zip(x, x[1:], strict=False)):
        raise ValueError(f"{where}: cycles must increase and lie in (0, 0.8] (units of h_max's "
                         f"length), got {value!r}")
    return tuple(x)


def _resolve(raw: dict, defaults: dict, where: str, curves: dict | None = None) -> tuple[dict, dict]:
    """One grid point (entry over defaults) → (checked parameters, options)."""
    curves = curves or {}
    scene = PARAMETERS["scene"].check("scene", raw.get("scene", defaults.get("scene")), where)
    for name in raw:
        if name in PARAMETERS and scene not in PARAMETERS[name].scenes:
            raise ValueError(f"{where}: parameter {name} applies to scene "
                             f"{' | '.join(PARAMETERS[name].scenes)} only, not {scene!r}")
    p = {"scene": scene}
    for name, spec in PARAMETERS.items():
        if name == "scene" or scene not in spec.scenes:
            continue
        value = raw.get(name, defaults.get(name, spec.default))
        if value is None and name in _FROM_BODY1:
            value = p[_FROM_BODY1[name]]
        if name == "flow_curve":
            if value and value not in curves:
                raise ValueError(f"{where}: flow_curve = {value!r} is not a table of [flow_curves]; "
                                 f"known: {', '.join(curves) or 'none'}")
            p[name] = value
            continue
        if value is None:
            raise ValueError(f"{where}: parameter {name} is required ({spec.doc}; range "
                             f"{spec.range_text()})")
        p[name] = spec.check(name, value, where)
    if p["flow_curve"] and (p["K_over_sigma_y"] or p["Q_over_sigma_y"]):
        raise ValueError(f"{where}: flow_curve {p['flow_curve']!r} replaces K_over_sigma_y and "
                         "Q_over_sigma_y: leave those at 0")
    if p["Q_over_sigma_y"] == 0:
        p["b"] = 1.0  # no saturation term: b has no effect
    if p["K_over_sigma_y"] == 0:
        p["n"] = 1.0  # perfectly plastic: n has no effect
    if scene == "two_body" and p["K2_over_sigma_y1"] == 0:
        p["n2"] = 1.0
    if scene == "two_body" and p["K_over_sigma_y"] == 0 and "n2" not in raw and "n2" not in defaults \
            and p["K2_over_sigma_y1"] != 0:
        raise ValueError(f"{where}: body 2 hardens (K2_over_sigma_y1 = {p['K2_over_sigma_y1']:g}) "
                         "but body 1 is perfectly plastic: give n2")
    options = {**defaults.get("options", {}), **raw.get("options", {})}
    cycles = raw.get("cycles", defaults.get("cycles"))
    p["cycles"] = _check_cycles(cycles, where) if cycles is not None else ()
    return p, _check_options(options, where)


def _body1(p: dict, curves: dict) -> Material:
    """Body 1's material: a named table, Ludwik, or Ludwik plus Voce saturation
    (``model.flow.voce``), tabulated at ``VOCE_STRAINS``."""
    sy = p["sigma_y"]
    E = p["E_over_sigma_y"] * sy
    if p.get("flow_curve"):
        eps, sig = curves[p["flow_curve"]]
        return Material.from_table(E, p["nu"], eps, [s * sy for s in sig])
    lud = Material(E=E, nu=p["nu"], sigma_y=sy, K=p["K_over_sigma_y"] * sy, n=p["n"])
    if p.get("Q_over_sigma_y", 0.0) == 0:
        return lud
    eps = np.array(VOCE_STRAINS)
    sig = lud.flow_stress(eps) + Voce(sy, p["Q_over_sigma_y"], p["b"]).saturation(eps)
    return Material.from_table(E, p["nu"], eps, _rounded(sig))


def _inputs(p: dict, options: dict, curves: dict | None = None) -> dict:
    """Dimensional inputs of the FE run (what the key hashes). The keys a default run leaves
    out (edge_band 0, the band's default floor, no cycles) are left out, so older runs keep their keys."""
    R, sy = p["radius"], p["sigma_y"]
    E = p["E_over_sigma_y"] * sy
    mat = _body1(p, curves or {}).describe()
    inputs = {"material": mat, "radius": R, "mesh_density": p["mesh_density"],
              "element": p["element"], "options": dict(options)}
    if p["scene"] == "two_body":
        R2 = p["radius2"] * R
        inputs.update(h_max=p["h_max"] * min(R, R2), radius2=R2, material2=Material(
            E=p["E2_over_E1"] * E, nu=p["nu2"], sigma_y=p["sigma_y2_over_sigma_y1"] * sy,
            K=p["K2_over_sigma_y1"] * sy, n=p["n2"]).describe())
    else:
        R_ind = p["indenter_radius"] * R if p["scene"] == "rigid_sphere" else math.inf
        inputs.update(h_max=p["h_max"] * min(R, R_ind), indenter_radius=R_ind)
    if p.get("edge_band", 0.0) > 0:
        inputs["edge_band"] = p["edge_band"]
    floor = check_band_floor(p.get("band_floor", EDGE_BAND_MIN), p.get("edge_band", 0.0))
    if floor != EDGE_BAND_MIN:
        inputs["band_floor"] = floor
    if p.get("cycles"):
        unit = inputs["h_max"] / p["h_max"]
        inputs["unload_at"] = [float(f"{c * unit:.12g}") for c in p["cycles"]
                              if c * unit <= inputs["h_max"] * (1 + 1e-12)]
    return inputs


def _sample(entry: dict, where: str) -> list[dict]:
    """Points of a ``sample = {method, n, seed}`` table over the parameters given as ranges,
    ``{range = [lo, hi]}`` (uniform) or ``{log = [lo, hi]}`` (uniform in log): a scrambled
    Sobol sequence (n a power of 2) or a Latin hypercube, seeded, values rounded to
    ``SAMPLE_DIGITS`` significant digits."""
    spec = entry.get("sample")
    ranged = {k: v for k, v in entry.items() if isinstance(v, dict) and k not in _ENTRY_KEYS}
    if spec is None:
        if ranged:
            raise ValueError(f"{where}: parameter {next(iter(ranged))} is a range but the entry has "
                             "no sample = {method, n, seed} table")
        return [{}]
    if not isinstance(spec, dict) or set(spec) != {"method", "n", "seed"}:
        raise ValueError(f"{where}: sample must be a table {{method, n, seed}}, got {spec!r}")
    method, n, seed = spec["method"], spec["n"], spec["seed"]
    if method not in SAMPLERS:
        raise ValueError(f"{where}: sample.method must be one of {list(SAMPLERS)}, got {method!r}")
    if not (isinstance(n, int) and n >= 1) or (method == "sobol" and n & (n - 1)):
        raise ValueError(f"{where}: sample.n must be an integer >= 1 (a power of 2 for sobol), got {n!r}")
    if not isinstance(seed, int):
        raise ValueError(f"{where}: sample.seed must be an integer, got {seed!r}")
    if not ranged:
        raise ValueError(f"{where}: sample needs parameters given as {{range = [lo, hi]}} or "
                         "{log = [lo, hi]}")
    bounds = []
    for name, r in ranged.items():
        kind = next(iter(r)) if len(r) == 1 else None
        lims = r.get(kind) if kind in ("range", "log") else None
        if not (isinstance(lims, list) and len(lims) == 2 and all(
                isinstance(x, int | float) and not isinstance(x, bool) for x in lims) and lims[0] < lims[1]
                and (kind == "range" or lims[0] > 0)):
            raise ValueError(f"{where}: parameter {name} must be {{range = [lo, hi]}} or {{log = [lo, hi]}} "
                             f"with lo < hi (lo > 0 for log), got {r!r}")
        bounds.append((name, kind, float(lims[0]), float(lims[1])))
    d = len(bounds)
    engine = qmc.Sobol(d, scramble=True, seed=seed) if method == "sobol" else qmc.LatinHypercube(d, seed=seed)
    unit = engine.random(n)
    points = []
    for row in unit:
        pt = {}
        for u, (name, kind, lo, hi) in zip(row, bounds, strict=True):
            x = math.exp(math.log(lo) + u * math.log(hi / lo)) if kind == "log" else lo + u * (hi - lo)
            pt[name] = float(f"{x:.{SAMPLE_DIGITS}g}")
        points.append(pt)
    return points


def _expand(entry: dict, where: str) -> list[dict]:
    """Grid expansion: list-valued parameters → their product (entry order, last fastest),
    times the points of a ``sample`` table (:func:`_sample`)."""
    axes = []
    for name, value in entry.items():
        if name in _ENTRY_KEYS or isinstance(value, dict):
            continue
        if isinstance(value, list):
            if not value:
                raise ValueError(f"{where}: parameter {name} is an empty list")
            if any(isinstance(v, list | dict) for v in value):
                raise ValueError(f"{where}: parameter {name}: grid values must be single values")
            axes.append([(name, v) for v in value])
        else:
            axes.append([(name, value)])
    fixed = {k: v for k, v in entry.items() if k in _ENTRY_KEYS and k != "sample"}
    return [{**dict(point), **sampled, **fixed}
            for point in itertools.product(*axes) for sampled in _sample(entry, where)]


def _cases_of_set(set_name: str, entries, defaults: dict, curves: dict | None = None,
                  replace: dict | None = None) -> list[Case]:
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        hint = "; parameters go in [defaults] or in entries" if set_name in PARAMETERS else ""
        raise ValueError(f"top-level key {set_name!r} must be a set, an array of tables "
                         f"([[{set_name}]]){hint}")
    cases = []
    for i, entry in enumerate(entries, start=1):
        where = f"[[{set_name}]] entry {i}"
        _check_keys(entry, where)
        if "options" in entry and not isinstance(entry["options"], dict):
            raise ValueError(f"{where}: options must be a table of solver options")
        for point in _expand(entry, where):
            p, options = _resolve(point, defaults, where, curves)
            name, replaces = _name(p, defaults), ()
            if name in (replace or {}):
                change = {k: v for k, v in replace[name].items() if k != "reason"}
                p, options = _resolve({**point, **change}, defaults, f"[replace.{name!r}]", curves)
                replaces = (name, replace[name]["reason"])
                name = _name(p, defaults)
            wall = p.pop("max_wall_s")
            cases.append(Case(set=set_name, name=name, entry=where, params=p,
                              inputs=_inputs(p, options, curves), max_wall_s=wall, replaces=replaces))
    return cases


def _check_replace(doc: dict) -> dict:
    """The ``[replace]`` table: case name → {reason, and h_max and/or cycles}."""
    table = doc.get("replace", {})
    if not isinstance(table, dict):
        raise ValueError("[replace] must be a table of case names")
    for name, entry in table.items():
        where = f"[replace.{name!r}]"
        if not isinstance(entry, dict):
            raise ValueError(f"{where} must be a table (reason, and {' or '.join(REPLACEABLE)})")
        if not (isinstance(entry.get("reason"), str) and entry["reason"].strip()):
            raise ValueError(f"{where}: a replacement needs a reason (a non-empty string)")
        unknown = sorted(set(entry) - {"reason", *REPLACEABLE})
        if unknown:
            raise ValueError(f"{where}: {unknown[0]!r} cannot be replaced; allowed: "
                             f"{', '.join(REPLACEABLE)}")
        if len(entry) == 1:
            raise ValueError(f"{where}: nothing to replace; give {' or '.join(REPLACEABLE)}")
        if "cycles" in entry:
            _check_cycles(entry["cycles"], where)
    return {k: dict(v) for k, v in table.items()}


def _check_unique(cases: list[Case]) -> None:
    """No case twice (same key or same name), in one set or across sets."""
    by_key: dict = {}
    by_name: dict = {}
    for c in cases:
        prev = by_key.setdefault(c.key, c)
        if prev is not c:
            what = "appears in both sets" if prev.set != c.set else "appears twice"
            raise ValueError(f"case {c.name} {what}: {prev.entry} and {c.entry} have the same "
                             "inputs (sets must be disjoint, cases unique)")
        prev = by_name.setdefault(c.name, c)
        if prev is not c:
            raise ValueError(f"{prev.entry} and {c.entry} both give a case named {c.name} with "
                             "different inputs (solver options?); make them differ in a named "
                             "parameter")


def parse_campaign(text: str, source: str = "<campaign>") -> Campaign:
    """Parse and validate campaign TOML text; ValueError naming the entry and parameter."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{source}: not valid TOML: {err}") from None
    try:
        meta = doc.get("campaign", {})
        if not isinstance(meta, dict):
            raise ValueError("[campaign] must be a table (title, description)")
        defaults = doc.get("defaults", {})
        if not isinstance(defaults, dict):
            raise ValueError("[defaults] must be a table")
        _check_keys(defaults, "[defaults]")
        for name, value in defaults.items():
            if name == "cycles":
                _check_cycles(value, "[defaults]")
                continue
            if name == "flow_curve":
                continue
            if isinstance(value, list):
                raise ValueError(f"[defaults]: {name} must be a single value (grids go in entries)")
            if name != "options":
                PARAMETERS[name].check(name, value, "[defaults]")
        if "options" in defaults:
            _check_options(defaults["options"], "[defaults]")
        curves = _check_curves(doc)
        sets = [k for k in doc if k not in _SETS_RESERVED]
        if not sets:
            raise ValueError("no sets: add entries such as [[calibration]] and [[validation]]")
        replace = _check_replace(doc)
        cases = []
        for name in sets:
            if not name.replace("_", "").replace("-", "").isalnum():
                raise ValueError(f"set name {name!r} must be letters, digits, '_' or '-'")
            cases += _cases_of_set(name, doc[name], defaults, curves, replace)
        used = {c.replaces[0] for c in cases if c.replaces}
        unused = [n for n in replace if n not in used]
        if unused:
            raise ValueError(f"[replace.{unused[0]!r}]: no case of the campaign has that name")
        _check_unique(cases)
    except ValueError as err:
        raise ValueError(f"{source}: {err}") from None
    return Campaign(text=text, source=source, meta=dict(meta), sets=tuple(sets),
                    cases=tuple(sorted(cases, key=lambda c: (c.set, c.name))))


def load_campaign(path) -> Campaign:
    """Read and validate the campaign file ``path``."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as err:
        raise ValueError(f"{path}: cannot read the campaign file: {err.strerror or err}") from None
    return parse_campaign(text, source=str(path))
