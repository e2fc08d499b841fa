"""Run in.two_particles (steel R1 = 1 mm on aluminium R2 = 2 mm, load / unload / reload) with
pair_style spherecontact and plot the LAMMPS force against ContactLaw(..., beyond="table").

    make lammps-plugin
    .venv/bin/python examples/lammps/two_particles/run.py [--out DIR]

Writes DIR/steel_alu.sct (and the same-material tables the input needs), DIR/forces.txt (step, h,
F from LAMMPS) and DIR/two_particles.png, and prints the largest |F_LAMMPS - F_model| / F_max.
The tables are what `spherecontact model table` writes, e.g.

    spherecontact model table --E 210e9 --nu 0.3 --sigma-y 400e6 --K 600e6 --n 0.3 --radius 1e-3 \
        --E2 70e9 --nu2 0.33 --sigma-y2 100e6 --K2 200e6 --n2 0.5 --radius2 2e-3 --out steel_alu.sct
"""

import argparse
import os
import warnings
from pathlib import Path

import numpy as np

from spherecontact.model import CalibrationRangeWarning, Material, Sphere
from spherecontact.model.dem_table import calibrated_law, write_table2
from spherecontact.validation.lammps_mdr import import_lammps

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
PLUGIN = ROOT / "build" / "lammps" / "spherecontactplugin.so"
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
R1, R2, H, N = 1e-3, 2e-3, 4e-5, 3000


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("runs/lammps_two_particles"))
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args(argv)
    if not PLUGIN.is_file():
        raise SystemExit(f"{PLUGIN} is missing: make lammps-plugin")
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    s1, s2 = Sphere(R1, STEEL), Sphere(R2, ALU)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        law = calibrated_law(s1, s2)
        write_table2(out / "steel_alu.sct", s1, s2, laws=[law])
        for name, s in (("steel_steel", s1), ("alu_alu", s2)):
            write_table2(out / f"{name}.sct", s, s, laws=[calibrated_law(s, s)])

    lammps = import_lammps()
    cwd = os.getcwd()
    os.chdir(out)  # fix print writes forces.txt here
    try:
        var = {"plugin": PLUGIN, "table": out / "steel_alu.sct", "table_ss": out / "steel_steel.sct",
               "table_aa": out / "alu_alu.sct", "R1": R1, "R2": R2, "H": H, "N": N}
        cmd = ["-log", "log.lammps", "-screen", "none", "-nocite"]
        for k, v in var.items():
            cmd += ["-var", k, str(v)]
        lmp = lammps.lammps(cmdargs=cmd)
        lmp.file(str(HERE / "in.two_particles"))
        lmp.close()
    finally:
        os.chdir(cwd)

    step, h, F = np.loadtxt(out / "forces.txt", unpack=True)
    hm = np.maximum.accumulate(np.concatenate([[0.0], h[:-1]])).clip(min=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        F_ref = law.force(h, hm)[0]
    err = np.abs(F - F_ref).max() / np.abs(F_ref).max()
    print(f"{h.size} steps, F_max {np.abs(F_ref).max():.4g} N: max |F_LAMMPS - F_model| / F_max = {err:.2g}")
    if not args.no_plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(h * 1e6, F_ref, "k-", lw=2.5, alpha=0.35, label="ContactLaw(..., beyond='table')")
        ax.plot(h * 1e6, F, "C3-", lw=0.8, label="LAMMPS pair_style spherecontact")
        ax.set_xlabel("overlap h (µm)")
        ax.set_ylabel("normal force F (N)")
        ax.set_title(f"steel R {R1 * 1e3:g} mm / aluminium R {R2 * 1e3:g} mm; max diff {err:.1g} F_max",
                     fontsize=9)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "two_particles.png", dpi=120)
        print(f"plot: {out / 'two_particles.png'}")
    return err


if __name__ == "__main__":
    main()
