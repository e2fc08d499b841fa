"""LAMMPS ``mdr`` in a periodic lattice of equal spheres: the pair law's multi-contact peer.

Each contact of a sphere in a lattice under affine compression is a symmetry plane, so the
lattice is the scene of the 3D FE cell (:mod:`spherecontact.fem.cell`) and the place where a
pair law stops being enough. ``mdr`` (Zunker & Kamrin 2024, J. Mech. Phys. Solids 183:105492)
is the one DEM law with a multi-contact term: once a particle's free-surface fraction falls
below ψ_b, a bulk response stiffens all its contacts. This module runs it in the lattices of the
FE cell:

* ``sc``: simple cubic, one sphere per cell, 6 contacts along ±x, ±y, ±z;
* ``fcc``: face-centred cubic, 4 spheres per cubic cell, 12 contacts along ⟨110⟩;

``cells``³ cubic cells in a periodic box (2³: the box is wider than the neighbour cut-off), the
box deformed by ``fix deform … remap x`` so that every sphere moves affinely — loads
``isostatic`` (three box lengths alike) or ``die`` (z only, x and y held). The kinematics are
prescribed, as in :mod:`.lammps_mdr` (η = 0, no time integration), with the same input
settings (:class:`MdrSettings`: ψ_b, dt, approach per step).

Recorded per sample: the per-contact approach h = 2R − d of each contact family (``axial``: the
compressed direction; ``lateral``: the die's held directions), the mean force of the family and
its spread over the contacts (0 in an exact lattice), the mean contact area mdr reports
(``compute pair/local p13``), the relative density N·(4/3)πR³ / V_box (initial sphere volume),
and the cell stress from the virial (``compute pressure NULL virial``: mean, axial zz, lateral
xx; compression positive). Loading to ``h_max``, then unloading back to the initial box.
"""

from __future__ import annotations

import datetime
import json
import math
import platform
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .lammps_mdr import MdrScene, MdrSettings, _jsonable, _mdr_coeffs, _num, import_lammps, lammps_version

__all__ = ["LATTICES", "LOADS", "LatticeScene", "LatticeRun", "lattice_sites", "relative_density",
           "run_lattice"]

#: sites of one cubic cell in units of its side, and the nearest-neighbour distance over the side
LATTICES = {"sc": (np.zeros((1, 3)), 1.0),
            "fcc": (np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]), math.sqrt(0.5))}
LOADS = ("isostatic", "die")


@dataclass(frozen=True)
class LatticeScene:
    """Equal spheres (radius R, mdr material E, ν, Y) on a lattice under a load."""

    lattice: str
    load: str
    E: float
    nu: float
    Y: float
    R: float = 1.0
    cells: int = 2

    def __post_init__(self):
        if self.lattice not in LATTICES:
            raise ValueError(f"lattice must be one of {sorted(LATTICES)}, got {self.lattice!r}")
        if self.load not in LOADS:
            raise ValueError(f"load must be one of {LOADS}, got {self.load!r}")
        if self.lattice == "fcc" and self.load == "die":
            raise ValueError("lattice fcc: only the isostatic load (the die scene is simple cubic)")
        if not (self.R > 0 and self.cells >= 2):
            raise ValueError(f"R must be > 0 and cells >= 2, got R = {self.R}, cells = {self.cells}")

    @property
    def side0(self) -> float:
        """Side of the cubic cell with the spheres just touching."""
        return 2.0 * self.R / LATTICES[self.lattice][1]

    def box(self, h: float) -> tuple[float, float, float]:
        """Box lengths at per-contact approach h of the compressed direction(s)."""
        s = self.cells * self.side0 * (2.0 * self.R - h) / (2.0 * self.R)
        L0 = self.cells * self.side0
        return (s, s, s) if self.load == "isostatic" else (L0, L0, s)


def lattice_sites(scene: LatticeScene) -> np.ndarray:
    """(N, 3) sphere centres of the undeformed box (the cell's sites, shifted off the faces)."""
    base, _ = LATTICES[scene.lattice]
    n = scene.cells
    cells = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), -1).reshape(-1, 3)
    sites = (cells[:, None, :] + base[None, :, :] + 0.25).reshape(-1, 3)
    return sites * scene.side0


def relative_density(scene: LatticeScene, h) -> np.ndarray:
    """N (4/3)π R³ / V_box at per-contact approach h (the initial sphere volume)."""
    n_sites = len(LATTICES[scene.lattice][0]) * scene.cells ** 3
    h = np.asarray(h, float)
    Lx, Ly, Lz = scene.box(0.0)
    scale = (2.0 * scene.R - h) / (2.0 * scene.R)
    V = Lx * Ly * Lz * (scale ** 3 if scene.load == "isostatic" else scale)
    return n_sites * 4.0 / 3.0 * math.pi * scene.R ** 3 / V


@dataclass
class LatticeRun:
    """Samples of one lattice run (loading then unloading); per family the contact values."""

    scene: LatticeScene
    settings: MdrSettings
    h: list = field(default_factory=list)          # approach of the compressed direction
    density: list = field(default_factory=list)
    family: dict = field(default_factory=dict)     # name -> {"h", "F", "F_spread", "A", "n"}
    stress: dict = field(default_factory=lambda: {"mean": [], "axial": [], "lateral": []})
    i_max: int = 0
    steps: int = 0
    wall_s: float = 0.0
    script: list = field(default_factory=list)

    def record(self) -> dict:
        return {"scene": asdict(self.scene), "settings": asdict(self.settings), "h": self.h,
                "density": self.density, "family": self.family, "stress": self.stress,
                "i_max": self.i_max, "steps": self.steps, "wall_s": self.wall_s, "script": self.script}


def _input(scene: LatticeScene, st: MdrSettings) -> list[str]:
    Lx, Ly, Lz = scene.box(0.0)
    mat = MdrScene("pair", scene.R, scene.R, scene.E, scene.nu, scene.Y)
    cmds = ["units lj", "atom_style sphere 1", "atom_modify map array sort 0 0.0", "boundary p p p",
            "newton off", "comm_modify vel yes",
            f"region box block 0 {_num(Lx)} 0 {_num(Ly)} 0 {_num(Lz)}", "create_box 1 box"]
    cmds += [f"create_atoms 1 single {_num(x)} {_num(y)} {_num(z)}" for x, y, z in lattice_sites(scene)]
    cmds += [f"set atom * diameter {_num(2 * scene.R)}", "set atom * density 1.0",
             "pair_style granular", f"pair_coeff * * {_mdr_coeffs(mat, st)}",
             f"neighbor {_num(0.5 * scene.R)} bin", "neigh_modify every 1 delay 0 check no",
             f"timestep {_num(st.dt)}", "thermo 0",
             "compute pairs all pair/local dist force p13",  # p13: the mdr contact area A_c
             "compute stress all pressure NULL virial", "run 0 post no"]
    return cmds


def _families(scene: LatticeScene, dist: np.ndarray, h_axial: float) -> dict[str, np.ndarray]:
    """Pairs of each family, by centre distance (die: axial 2R − h, lateral 2R)."""
    if scene.load == "isostatic":
        return {"axial": np.ones(dist.size, bool)}
    d_ax, d_lat = 2.0 * scene.R - h_axial, 2.0 * scene.R
    axial = np.abs(dist - d_ax) < np.abs(dist - d_lat)
    return {"axial": axial, "lateral": ~axial}


def run_lattice(scene: LatticeScene, h_max: float, *, settings: MdrSettings | None = None,
                samples: int = 60, unload_samples: int = 20, log=None) -> LatticeRun:
    """Compress the lattice to per-contact approach ``h_max`` (``samples`` equal steps of h), then
    expand it back to the initial box (``unload_samples``); one LAMMPS run per sample."""
    if not 0.0 < h_max < 2.0 * scene.R:
        raise ValueError(f"h_max must lie in (0, 2R) = (0, {2 * scene.R:g}), got {h_max}")
    st = settings or MdrSettings()
    lammps = import_lammps()
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    run = LatticeRun(scene, st)

    def cmd(line: str) -> None:
        run.script.append(line)
        lmp.command(line)

    t0 = time.perf_counter()
    try:
        for line in _input(scene, st):
            cmd(line)
        path = np.concatenate([np.linspace(0.0, h_max, samples + 1)[1:],
                               np.linspace(h_max, 0.0, unload_samples + 1)[1:]])
        run.i_max = samples - 1
        h_prev = 0.0
        for h in path:
            Lx, Ly, Lz = scene.box(float(h))
            steps = max(1, round(abs(h - h_prev) / (st.step_over_R * scene.R)))
            cmd(f"fix squeeze all deform 1 x final 0 {_num(Lx)} y final 0 {_num(Ly)} "
                f"z final 0 {_num(Lz)} remap x")
            cmd(f"run {steps} post no")
            cmd("unfix squeeze")
            run.steps += steps
            h_prev = float(h)
            _sample(lmp, scene, run, float(h))
            if log:
                log(f"  h {h:.4f}  density {run.density[-1]:.4f}  F {run.family['axial']['F'][-1]:.5g}")
    finally:
        lmp.close()
    run.wall_s = time.perf_counter() - t0
    return run


def _sample(lmp, scene: LatticeScene, run: LatticeRun, h: float) -> None:
    pairs = lmp.numpy.extract_compute("pairs", 2, 2)  # LMP_STYLE_LOCAL, LMP_TYPE_ARRAY
    pairs = np.zeros((0, 3)) if pairs is None else np.asarray(pairs).reshape(-1, 3)
    dist, F, A = pairs[:, 0], pairs[:, 1], pairs[:, 2]
    run.h.append(h)
    run.density.append(float(relative_density(scene, h)))
    for name, sel in _families(scene, dist, h).items():
        fam = run.family.setdefault(name, {"h": [], "F": [], "F_spread": [], "A": [], "n": []})
        d_nom = 2.0 * scene.R - (h if name == "axial" else 0.0)
        fam["h"].append(2.0 * scene.R - d_nom)
        fam["n"].append(int(sel.sum()))
        f = F[sel]
        fam["F"].append(float(f.mean()) if f.size else 0.0)
        fam["F_spread"].append(float(f.max() - f.min()) if f.size else 0.0)
        fam["A"].append(float(A[sel].mean()) if f.size else 0.0)
    p = lmp.numpy.extract_compute("stress", 0, 1)  # LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR: xx yy zz xy xz yz
    run.stress["mean"].append(float(np.mean(p[:3])))
    run.stress["axial"].append(float(p[2]))
    run.stress["lateral"].append(float(p[0]))


#: the issue's EPP materials (mdr is elastic–perfectly plastic: hardening materials do not apply)
MATERIALS = {"epp200": (200.0, 0.3, 1.0), "epp1000": (1000.0, 0.3, 1.0)}
#: scene -> the largest per-contact approach over R (relative density 0.95; the die to 0.80, where
#: its axial approach is already 0.69 R)
SCENES = {("sc", "isostatic"): 0.36, ("sc", "die"): 0.69, ("fcc", "isostatic"): 0.16}


def generate(out, *, settings: MdrSettings | None = None, samples: int = 60, log=print) -> dict:
    """Run every scene of :data:`SCENES` for every material of :data:`MATERIALS`, write ``out``
    (JSON) and return the document."""
    st = settings or MdrSettings()
    doc = {"schema": "spherecontact.peers.mdr_lattice", "schema_version": 1,
           "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
           "versions": lammps_version(), "platform": platform.platform(),
           "model": "pair_style granular, normal model mdr (Zunker & Kamrin 2024)",
           "settings": asdict(st),
           "conventions": {
               "h": "per-contact approach 2R - d of the family's contacts (d: centre distance)",
               "density": "N (4/3) pi R^3 / V_box, initial sphere volume",
               "F": "mean normal force of the family's contacts (compute pair/local force)",
               "F_spread": "largest minus smallest force over the family's contacts",
               "A": "mean contact area mdr reports (compute pair/local p13)",
               "stress": "virial stress of the box, compression positive: mean, zz, xx"},
           "runs": []}
    for name, (E, nu, Y) in MATERIALS.items():
        for (lattice, load), h_over_R in SCENES.items():
            scene = LatticeScene(lattice, load, E, nu, Y)
            run = run_lattice(scene, h_over_R * scene.R, settings=st, samples=samples)
            log(f"mdr lattice: {name} {lattice} {load}: {run.steps} steps, {run.wall_s:.0f} s, "
                f"density {run.density[run.i_max]:.3f}, F {run.family['axial']['F'][run.i_max]:.4g}")
            doc["runs"].append({"material": name, **run.record()})
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(_jsonable(doc), ensure_ascii=False) + "\n")
    return doc
