"""Die compaction of a sphere packing in LAMMPS: the packing, the tables, the input and the driver.

Used by ``run.py`` (the example), ``checks.py`` (1 vs 2 MPI ranks, restart) and
``bench/bench_lammps.py`` (cost per contact). Units SI.

Protocol (``Protocol``): N spheres, radii uniform in [R_LO, R_HI], placed at random without overlap
(random sequential addition) at solid fraction ``phi0`` in a square die L x L; no gravity. The top
wall (punch) moves down at ``v_fill`` until the solid fraction reaches ``phi_fill`` (the punch gathers
the loose spheres into a packing), then at ``v_press`` to ``phi_max``, then back up at ``v_press``
until it has carried less than ``free_fraction`` of the peak pressure for ``hold_samples`` samples
(every sample_steps/10 steps) or moved up by 2 % of its height. Solid fraction = the
particles' volume (initial radii) over the die's volume L^2 (z_top - z_bottom); pressure = force on
the punch / L^2; coordination number = 2 x particle-particle contacts (h > 0 at the initial radii) /
N.

Laws: ``spherecontact`` (the plugin: pair_style spherecontact, fix wall/spherecontact on x, y and z,
the punch a zplane wall whose HI is the variable ``v_ztop``), ``mdr`` (pair_style granular with the
mdr normal model, walls by fix wall/gran/region, one material) and ``hertz`` (pair_style granular
hertz/material, used by the benchmark only).
"""

from __future__ import annotations

import math
import re
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from spherecontact.model import CalibrationRangeWarning, Material, Sphere
from spherecontact.model.dem_table import write_table2

ROOT = Path(__file__).resolve().parents[3]
PLUGIN = ROOT / "build" / "lammps" / "spherecontactplugin.so"

STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
DENSITY = {"steel": 7800.0, "alu": 2700.0}
MATERIAL = {"steel": STEEL, "alu": ALU}
R_LO, R_HI = 0.8e-3, 1.2e-3
#: slices of the ratio-range tables over R_LO/R_HI ... R_HI/R_LO (neighbours 2^(1/4) apart at most)
SLICES = 6


@dataclass
class Protocol:
    n: int = 2000
    materials: tuple = ("steel", "alu")      # type 1, type 2 (one entry: one material)
    steel_fraction: float = 0.5              # by number, two materials
    L: float = 20e-3                         # die side
    phi0: float = 0.33                       # random placement
    phi_fill: float = 0.50                   # end of the fast fill stroke
    phi_max: float = 0.86                    # end of the press stroke
    v_fill: float = 20.0                     # punch speeds (m/s)
    v_press: float = 3.0
    mu: float = 0.3                          # particle-particle friction
    mu_wall: float = 0.1                     # die wall friction (lubricated die)
    damping: float = 0.3                     # fraction of critical (spherecontact Eq. N)
    dt_fraction: float = 0.2                 # of the smallest critical time step the plugin prints
    dt: float | None = None                  # or a fixed time step
    sample_steps: int = 1000
    hold_samples: int = 20
    #: the punch has lost contact below this fraction of the peak pressure
    free_fraction: float = 1e-3
    seed: int = 1
    skin: float = 0.1e-3

    @property
    def ntypes(self) -> int:
        return len(self.materials)


# ---------------------------------------------------------------------------------------- tables

def write_tables(out: Path, materials=("steel", "alu")) -> dict:
    """Ratio-range tables of every type pair (body 1 = the lower type) over R_LO/R_HI ... R_HI/R_LO,
    and a table of each material on a rigid flat wall; existing files are kept."""
    out.mkdir(parents=True, exist_ok=True)
    ratios = np.geomspace(R_LO / R_HI, R_HI / R_LO, SLICES)
    files = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        for i, a in enumerate(materials):
            for b in materials[i:]:
                p = out / f"{a}_{b}.sct"
                if not p.is_file():
                    write_table2(p, Sphere(1e-3, MATERIAL[a]), Sphere(1e-3, MATERIAL[b]), ratios=ratios,
                                 probes=1)
                files[(a, b)] = p
            p = out / f"{a}_wall.sct"
            if not p.is_file():
                write_table2(p, Sphere(1e-3, MATERIAL[a]), Sphere(np.inf, Material.rigid()))
            files[(a, "wall")] = p
    return files


# --------------------------------------------------------------------------------------- packing

@dataclass
class Packing:
    x: np.ndarray        # (n, 3)
    r: np.ndarray        # (n,)
    t: np.ndarray        # (n,) type 1 or 2
    L: float
    H: float             # initial punch position (bottom at 0)

    @property
    def volume(self) -> float:
        return float(np.sum(4.0 / 3.0 * np.pi * self.r**3))


def packing(p: Protocol) -> Packing:
    """Random sequential addition of p.n spheres at solid fraction p.phi0 in [0, L]^2 x [0, H]."""
    rng = np.random.default_rng(p.seed)
    r = rng.uniform(R_LO, R_HI, p.n)
    r = np.sort(r)[::-1].copy()  # large first: the placement succeeds at higher fractions
    vol = float(np.sum(4.0 / 3.0 * np.pi * r**3))
    H = vol / (p.phi0 * p.L**2)
    x = np.zeros((p.n, 3))
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([p.L, p.L, H])
    for i in range(p.n):
        for _attempt in range(2000):
            c = rng.uniform(lo + r[i], hi - r[i], (64, 3))
            if i:
                d2 = np.sum((c[:, None, :] - x[None, :i, :]) ** 2, axis=2)
                ok = np.all(d2 >= (r[i] + r[:i]) ** 2, axis=1)
            else:
                ok = np.ones(64, dtype=bool)
            if ok.any():
                x[i] = c[int(np.argmax(ok))]
                break
        else:
            raise RuntimeError(f"random placement failed at sphere {i} (phi0 {p.phi0} too high)")
    perm = rng.permutation(p.n)
    x, r = x[perm], r[perm]
    if p.ntypes == 1:
        t = np.ones(p.n, dtype=int)
    else:
        t = np.where(rng.uniform(size=p.n) < p.steel_fraction, 1, 2)
    return Packing(x=x, r=r, t=t, L=p.L, H=H)


# ---------------------------------------------------------------------------------------- inputs

def _n(v: float) -> str:
    return repr(float(v))


def _atoms(pk: Packing, p: Protocol) -> list[str]:
    cmds = []
    for i in range(len(pk.r)):
        cmds.append(f"create_atoms {int(pk.t[i])} single {_n(pk.x[i, 0])} {_n(pk.x[i, 1])} {_n(pk.x[i, 2])}")
    for i in range(len(pk.r)):
        cmds.append(f"set atom {i + 1} diameter {_n(2 * pk.r[i])} density "
                    f"{DENSITY[p.materials[int(pk.t[i]) - 1]]}")
    return cmds


def input_commands(law: str, pk: Packing, p: Protocol, tables: dict | None = None,
                   plugin: Path = PLUGIN) -> list[str]:
    """Setup commands: box, atoms, contact law, die walls with the punch at v_ztop, integrator.
    The time step is set by the driver."""
    L, H = pk.L, pk.H
    atom_style = "sphere 1" if law in ("mdr",) else "sphere"
    cmds = [] if law != "spherecontact" else [f"plugin load {plugin}"]
    cmds += ["units si", f"atom_style {atom_style}", "atom_modify map array", "boundary f f f",
             "newton off", "comm_modify vel yes",
             f"region box block {_n(-0.05 * L)} {_n(1.05 * L)} {_n(-0.05 * L)} {_n(1.05 * L)} "
             f"{_n(-0.05 * L)} {_n(H + 0.05 * L)}",
             f"create_box {p.ntypes} box"]
    cmds += _atoms(pk, p)
    for k, m in enumerate(p.materials):
        cmds.append(f"group {m} type {k + 1}")
    cmds += ["variable z0 equal " + _n(H), "variable vel equal 0.0", "variable t0 equal 0.0",
             "variable ztop equal v_z0-v_vel*(time-v_t0)"]
    if law == "spherecontact":
        cmds.append(f"pair_style spherecontact friction {p.mu} damping {p.damping}")
        for i, a in enumerate(p.materials):
            for j, b in enumerate(p.materials[i:], start=i):
                cmds.append(f"pair_coeff {i + 1} {j + 1} {tables[(a, b)]}")
        for m in p.materials:
            w = tables[(m, "wall")]
            opts = f"friction {p.mu_wall} damping {p.damping}"
            cmds += [f"fix wx_{m} {m} wall/spherecontact xplane 0.0 {_n(L)} {w} {opts}",
                     f"fix wy_{m} {m} wall/spherecontact yplane 0.0 {_n(L)} {w} {opts}",
                     f"fix wz_{m} {m} wall/spherecontact zplane 0.0 v_ztop {w} {opts}"]
    elif law in ("mdr", "hertz"):
        if p.ntypes != 1:
            raise ValueError(f"{law}: one material")
        m = MATERIAL[p.materials[0]]
        G = m.E / (2 * (1 + m.nu))

        def granular(mu):
            if law == "mdr" and mu == 0.0:
                return (f"mdr {_n(m.E)} {_n(m.nu)} {_n(m.sigma_y)} 0 0.5 0.5 damping mdr 1 "
                        "tangential linear_nohistory 0.0 0.0")
            if law == "mdr":
                # E, nu, Y, surface energy 0, psi_b 0.5, damping eta 0.5 (mdr's own damping); the
                # tangential spring linear with k_t of Mindlin's 8 G* a at a = 0.05 R_HI
                return (f"mdr {_n(m.E)} {_n(m.nu)} {_n(m.sigma_y)} 0 0.5 0.5 damping mdr 1 "
                        f"tangential linear_history {_n(8 * G / (2 * (2 - m.nu)) * 0.05 * R_HI)} 0.0 {mu}")
            return (f"hertz/material {_n(m.E)} {p.damping} {_n(m.nu)} tangential mindlin NULL 0.0 {mu} "
                    "damping tsuji")

        coeff, wcoeff = granular(p.mu), granular(p.mu_wall)
        cmds += ["pair_style granular", f"pair_coeff * * {coeff}",
                 f"region die block 0.0 {_n(L)} 0.0 {_n(L)} 0.0 {_n(10 * H)} side in",
                 "region punch plane 0.0 0.0 0.0 0.0 0.0 -1.0 side in move NULL NULL v_ztop",
                 f"fix wdie all wall/gran/region granular {wcoeff} region die",
                 f"fix wtop all wall/gran/region granular {wcoeff} region punch contacts"]
    else:
        raise ValueError(f"unknown law {law!r}")
    cmds += ["fix nve all nve/sphere", f"neighbor {_n(p.skin)} bin", "neigh_modify every 1 delay 0 check yes",
             "thermo 0"]
    return cmds


# ---------------------------------------------------------------------------------------- driver

@dataclass
class Record:
    step: list = field(default_factory=list)
    time: list = field(default_factory=list)
    stage: list = field(default_factory=list)
    z_top: list = field(default_factory=list)
    phi: list = field(default_factory=list)
    p_top: list = field(default_factory=list)      # Pa
    p_bottom: list = field(default_factory=list)
    Z: list = field(default_factory=list)
    h_over_R_max: list = field(default_factory=list)
    h_over_R_p99: list = field(default_factory=list)


class Compaction:
    """One LAMMPS instance running the protocol."""

    def __init__(self, law: str, pk: Packing, p: Protocol, tables: dict | None = None, log: str = "none",
                 cmdargs: list | None = None):
        from spherecontact.validation.lammps_mdr import import_lammps

        lammps = import_lammps()
        self.law, self.pk, self.p = law, pk, p
        self.log = log
        self.lmp = lammps.lammps(cmdargs=(cmdargs or []) + ["-log", log, "-screen", "none", "-nocite"])
        self.script = input_commands(law, pk, p, tables)
        for c in self.script:
            self.lmp.command(c)
        self.area = pk.L**2
        self.vs = pk.volume
        self.rec = Record()
        self.dt = p.dt
        self.r0 = None

    def set_timestep(self) -> float:
        """p.dt, or p.dt_fraction of the smallest critical time step the plugin prints."""
        if self.dt is None:
            if self.law != "spherecontact" or self.log == "none":
                raise ValueError("give Protocol.dt (the critical time step is read from the plugin's log)")
            self.lmp.command("timestep 1e-9")
            self.lmp.command("run 0 post no")
            self.lmp.flush_buffers() if hasattr(self.lmp, "flush_buffers") else None
            text = Path(self.log).read_text()
            dtc = [float(v) for v in re.findall(r"critical time step 2\*sqrt\([^)]*\) = ([0-9.eE+-]+)", text)]
            self.dtc = min(dtc)
            self.dt = self.p.dt_fraction * self.dtc
        self.lmp.command(f"timestep {_n(self.dt)}")
        return self.dt

    # -- measurements
    def z_top(self) -> float:
        return float(self.lmp.extract_variable("ztop"))

    def wall_forces(self) -> tuple[float, float]:
        """Force of the particles on the punch (+: pushed up) and on the bottom (+: pushed down)."""
        lmp = self.lmp
        if self.law == "spherecontact":
            top = sum(lmp.extract_fix(f"wz_{m}", 0, 1, 1) for m in self.p.materials)
            bot = -sum(lmp.extract_fix(f"wz_{m}", 0, 1, 0) for m in self.p.materials)
            return float(top), float(bot)
        c = lmp.numpy.extract_fix("wtop", 1, 2)
        top = -float(np.sum(c[:, 3])) if c is not None and len(c) else 0.0
        return top, float("nan")

    def geometry(self) -> tuple[float, float, float]:
        """Coordination number (particle-particle contacts with h > 0 at the initial radii), the
        largest overlap over the smaller radius and its 99th percentile over the contacts."""
        from scipy.spatial import cKDTree

        lmp = self.lmp
        n = lmp.get_natoms()
        ids = lmp.numpy.extract_atom("id")[:n]
        x = lmp.numpy.extract_atom("x")[:n]
        if self.r0 is None:
            self.r0 = self.pk.r  # atom ID k+1 has radius pk.r[k]
        r = self.r0[ids - 1]
        pairs = cKDTree(x).query_pairs(2 * R_HI, output_type="ndarray")
        if len(pairs) == 0:
            return 0.0, 0.0, 0.0
        d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
        h = r[pairs[:, 0]] + r[pairs[:, 1]] - d
        touch = h > 0
        hr = (h / np.minimum(r[pairs[:, 0]], r[pairs[:, 1]]))[touch]
        if not hr.size:
            return 0.0, 0.0, 0.0
        return 2.0 * touch.sum() / n, float(hr.max()), float(np.percentile(hr, 99))

    def sample(self, stage: str) -> None:
        lmp, R = self.lmp, self.rec
        z = self.z_top()
        ft, fb = self.wall_forces()
        Z, hr, h99 = self.geometry()
        R.step.append(int(lmp.get_thermo("step")))
        R.time.append(float(lmp.get_thermo("time")))
        R.stage.append(stage)
        R.z_top.append(z)
        R.phi.append(self.vs / (self.area * z))
        R.p_top.append(ft / self.area)
        R.p_bottom.append(fb / self.area)
        R.Z.append(Z)
        R.h_over_R_max.append(hr)
        R.h_over_R_p99.append(h99)

    # -- punch motion
    def _move(self, velocity: float) -> None:
        z = self.z_top()
        t = float(self.lmp.get_thermo("time"))
        self.lmp.command(f"variable z0 equal {_n(z)}")
        self.lmp.command(f"variable t0 equal {_n(t)}")
        self.lmp.command(f"variable vel equal {_n(velocity)}")

    def run(self, n: int) -> None:
        t0, c0 = time.perf_counter(), time.process_time()
        self.lmp.command(f"run {int(n)} pre no post no")
        self.wall_s += time.perf_counter() - t0
        self.cpu_s += time.process_time() - c0
        self.steps += int(n)

    def stroke(self, velocity: float, phi_end: float, stage: str, log=print) -> None:
        """Move the punch at velocity (down > 0) until the solid fraction is phi_end."""
        self._move(velocity)
        z_end = self.vs / (self.area * phi_end)
        n_total = int(math.ceil(abs(self.z_top() - z_end) / abs(velocity) / self.dt))
        done = 0
        while done < n_total:
            n = min(self.p.sample_steps, n_total - done)
            self.run(n)
            done += n
            self.sample(stage)
        R = self.rec
        log(f"  {stage}: step {R.step[-1]}, phi {R.phi[-1]:.4f}, p_top {R.p_top[-1] / 1e6:.4g} MPa, "
            f"Z {R.Z[-1]:.2f}, h/R max {R.h_over_R_max[-1]:.3f} p99 {R.h_over_R_p99[-1]:.3f}, "
            f"{self.steps} steps, {self.wall_s:.0f} s")

    def unload(self, velocity: float, max_travel: float, log=print) -> None:
        """Punch back up at velocity until it has carried no force for hold_samples samples."""
        self._move(-abs(velocity))
        z_start = self.z_top()
        free, p_max = 0, max(self.rec.p_top)
        n = max(1, self.p.sample_steps // 10)  # the compact springs back within a few samples
        while free < self.p.hold_samples and self.z_top() - z_start < max_travel:
            self.run(n)
            self.sample("unload")
            free = free + 1 if self.rec.p_top[-1] <= self.p.free_fraction * p_max else 0
        R = self.rec
        log(f"  unload: step {R.step[-1]}, phi {R.phi[-1]:.4f}, p_top {R.p_top[-1] / 1e6:.4g} MPa, "
            f"{self.wall_s:.0f} s")

    def protocol(self, log=print) -> dict:
        p = self.p
        self.wall_s, self.cpu_s, self.steps = 0.0, 0.0, 0
        self.failure = None
        self.set_timestep()
        self.lmp.command("run 0 post no")
        self.sample("start")
        try:
            self.stroke(p.v_fill, p.phi_fill, "fill", log)
            self.stroke(p.v_press, p.phi_max, "press", log)
            self.unload(p.v_press, 0.02 * self.z_top(), log)
        except Exception as err:  # LAMMPS stopped (an error of the contact law): keep what was run
            self.failure = {"stage": self.rec.stage[-1] if self.rec.stage else "start",
                            "step": self.rec.step[-1] if self.rec.step else 0,
                            "phi": self.rec.phi[-1] if self.rec.phi else None, "error": str(err)}
            log(f"  LAMMPS stopped after step {self.failure['step']} ({self.failure['stage']}, phi "
                f"{self.failure['phi']:.4f}): {err}")
        return self.summary()

    def summary(self) -> dict:
        R = self.rec
        phi = np.array(R.phi)
        pt = np.array(R.p_top)
        st = np.array(R.stage)
        i_max = int(np.argmax(phi))
        free = self.p.free_fraction * pt[i_max]
        un = np.flatnonzero((st == "unload") & (pt <= free))
        phi_spring = float(phi[un[0]]) if un.size else float("nan")
        # first unloading sample below free_fraction of the peak pressure, refined linearly
        # between it and the one before
        if un.size and un[0] > 0 and pt[un[0] - 1] > free:
            k = un[0]
            w = (pt[k - 1] - free) / (pt[k - 1] - pt[k])
            phi_spring = float(phi[k - 1] + w * (phi[k] - phi[k - 1]))
        return {"law": self.law, "materials": list(self.p.materials), "n": int(len(self.pk.r)),
                "dt": self.dt, "dt_critical": getattr(self, "dtc", None), "steps": self.steps,
                "wall_s": round(self.wall_s, 2), "s_per_step": self.wall_s / max(self.steps, 1),
                "cpu_s": round(self.cpu_s, 2), "cpu_s_per_step": self.cpu_s / max(self.steps, 1),
                "phi_max": float(phi[i_max]), "p_max_MPa": float(pt[i_max] / 1e6),
                "phi_after_unload": phi_spring,
                "springback_height_pct": 100.0 * (phi[i_max] / phi_spring - 1.0) if un.size else None,
                "Z_at_phi_max": float(R.Z[i_max]), "h_over_R_max": float(max(R.h_over_R_max)),
                "h_over_R_p99_at_phi_max": float(R.h_over_R_p99[i_max]),
                "failure": getattr(self, "failure", None),
                "protocol": asdict(self.p)}

    def close(self) -> None:
        self.lmp.close()
