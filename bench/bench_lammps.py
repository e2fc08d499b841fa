"""Cost per contact per step in LAMMPS: pair_style spherecontact against pair_style granular with
the hertz/material and mdr normal models, on the same packing, one core.

The packing: examples/lammps/die_compaction (aluminium, radii 0.8 ... 1.2 mm, 1000 spheres) pressed
by spherecontact to a solid fraction of 0.65; its positions are then loaded into a fresh LAMMPS per
law, without walls and without time integration (no neighbour rebuild), and ``run STEPS`` is timed
(best of REPEATS, the laws taking turns): each step evaluates every neighbour pair once. Two
settings per law: normal force only, and with the tangential spring (friction 0.3; mdr and
hertz/material with their history tangential models). Cost per contact = time per step /
contacts (pairs with h > 0); the time per step includes LAMMPS' per-step overhead (the same for
all laws).

    python -m bench.run_all lammps        # -> bench/results/lammps.json
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "lammps" / "die_compaction"
N, PHI, STEPS, REPEATS = 1000, 0.65, 200, 7


def available() -> bool:
    """LAMMPS (the extra `lammps`) and the plugin (make lammps-plugin)."""
    try:
        from spherecontact.validation.lammps_mdr import import_lammps

        import_lammps()
    except ImportError:
        return False
    return (ROOT / "build" / "lammps" / "spherecontactplugin.so").is_file()


def _compaction():
    sys.path.insert(0, str(EXAMPLE))
    import compaction

    return compaction


def packed_state(workdir: Path):
    """Positions, radii and the die size of the packing pressed to PHI."""
    C = _compaction()
    p = C.Protocol(n=N, materials=("alu",), L=20e-3 * (N / 2000) ** (1 / 3), phi_max=PHI)
    tables = C.write_tables(workdir, p.materials)
    pk = C.packing(p)
    c = C.Compaction("spherecontact", pk, p, tables, log=str(workdir / "log.lammps"))
    c.wall_s, c.cpu_s, c.steps = 0.0, 0.0, 0
    c.set_timestep()
    c.lmp.command("run 0 post no")
    c.stroke(p.v_fill, p.phi_fill, "fill", log=lambda s: None)
    c.stroke(p.v_press, PHI, "press", log=lambda s: None)
    n = c.lmp.get_natoms()
    ids = c.lmp.numpy.extract_atom("id")[:n].copy()
    x = c.lmp.numpy.extract_atom("x")[:n].copy()
    z_top = c.z_top()
    c.close()
    order = np.argsort(ids)
    return x[order], pk.r, p.L, z_top, tables, C


def _contacts(x, r, skin):
    from scipy.spatial import cKDTree

    pairs = cKDTree(x).query_pairs(2 * r.max() + skin, output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    s = r[pairs[:, 0]] + r[pairs[:, 1]]
    return int((d < s).sum()), int((d < s + skin).sum())


def _commands(law, friction, x, r, L, z_top, tables, C):
    m = C.ALU
    G = m.E / (2 * (1 + m.nu))
    mu = 0.3 if friction else 0.0
    kt = 8 * G / (2 * (2 - m.nu)) * 0.05 * C.R_HI
    cmds = [f"plugin load {C.PLUGIN}"] if law == "spherecontact" else []
    cmds += ["units si", f"atom_style {'sphere 1' if law == 'mdr' else 'sphere'}", "atom_modify map array",
             "boundary f f f", "newton off", "comm_modify vel yes",
             f"region box block {-0.05 * L!r} {1.05 * L!r} {-0.05 * L!r} {1.05 * L!r} {-0.05 * L!r} "
             f"{z_top + 0.05 * L!r}", "create_box 1 box"]
    cmds += [f"create_atoms 1 single {float(x[i, 0])!r} {float(x[i, 1])!r} {float(x[i, 2])!r}"
             for i in range(len(r))]
    cmds += [f"set atom {i + 1} diameter {float(2 * r[i])!r} density 2700" for i in range(len(r))]
    if law == "spherecontact":
        cmds += [f"pair_style spherecontact friction {mu} damping 0.3",
                 f"pair_coeff 1 1 {tables[('alu', 'alu')]}"]
    elif law == "hertz/material":
        tang = (f"tangential mindlin NULL 0.0 {mu}" if friction
                else "tangential linear_nohistory 0.0 0.0")
        cmds += ["pair_style granular",
                 f"pair_coeff * * hertz/material {m.E!r} 0.3 {m.nu!r} {tang} damping tsuji"]
    else:
        tang = (f"tangential linear_history {kt!r} 0.0 {mu}" if friction
                else "tangential linear_nohistory 0.0 0.0")
        cmds += ["pair_style granular",
                 f"pair_coeff * * mdr {m.E!r} {m.nu!r} {m.sigma_y!r} 0 0.5 0.5 damping mdr 1 {tang}"]
    cmds += ["neighbor 1e-4 bin", "neigh_modify every 1 delay 0 check yes", "timestep 1e-8", "thermo 0",
             "run 0 post no"]
    return cmds


def main() -> dict:
    import tempfile

    from spherecontact.validation.lammps_mdr import import_lammps, lammps_version

    lammps = import_lammps()
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        x, r, L, z_top, tables, C = packed_state(Path(tmp))
        t_pack = time.perf_counter() - t0
        contacts, neighbours = _contacts(x, r, 1e-4)
        out = {"n_particles": int(len(r)), "solid_fraction": PHI, "contacts": contacts,
               "neighbour_pairs_within_skin": neighbours, "coordination": 2 * contacts / len(r),
               "steps": STEPS, "repeats": REPEATS, "packing_s": round(t_pack, 1),
               "versions": lammps_version(), "laws": {}}
        settings = [(law, friction) for friction in (False, True)
                    for law in ("spherecontact", "hertz/material", "mdr")]
        best = dict.fromkeys(settings, math.inf)
        for _ in range(REPEATS):  # round-robin, so that a change of the machine's load hits all laws
            for law, friction in settings:
                lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
                for cmd in _commands(law, friction, x, r, L, z_top, tables, C):
                    lmp.command(cmd)
                t = time.perf_counter()
                lmp.command(f"run {STEPS} pre no post no")
                best[law, friction] = min(best[law, friction], time.perf_counter() - t)
                lmp.close()
        for (law, friction), b in best.items():
            key = f"{law}{' +friction' if friction else ''}"
            out["laws"][key] = {"s_per_step": b / STEPS, "ns_per_contact": 1e9 * b / STEPS / contacts}
        for friction in ("", " +friction"):
            sc = out["laws"][f"spherecontact{friction}"]["s_per_step"]
            out[f"ratio{friction.replace(' +', '_')}"] = {
                "spherecontact/hertz_material": sc / out["laws"][f"hertz/material{friction}"]["s_per_step"],
                "spherecontact/mdr": sc / out["laws"][f"mdr{friction}"]["s_per_step"]}
    for k, v in out["laws"].items():
        print(f"  {k:28s} {v['s_per_step'] * 1e3:8.3f} ms/step  {v['ns_per_contact']:8.1f} ns/contact")
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(main(), indent=1))
