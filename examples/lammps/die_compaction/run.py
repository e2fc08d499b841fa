"""Die compaction of a steel/aluminium powder in LAMMPS with pair_style spherecontact.

    make lammps-plugin
    .venv/bin/python examples/lammps/die_compaction/run.py --out runs/die
    # one material, spherecontact and LAMMPS' mdr on the same packing and protocol (frictionless:
    # mdr's history-dependent tangential spring ends in NaN forces on unloading in this LAMMPS):
    .venv/bin/python examples/lammps/die_compaction/run.py --out runs/die_mdr --materials alu \
        --laws spherecontact mdr --n 1000 --mu 0 --mu-wall 0

2000 spheres (radii 0.8 ... 1.2 mm, half steel and half aluminium by number) placed at random in a
20 mm square die, gathered by the punch (20 m/s) to a solid fraction of 0.5, pressed at 3 m/s to
0.86 and unloaded (compaction.py: the protocol). Writes into DIR: the tables (steel_steel.sct,
steel_alu.sct, alu_alu.sct over R2/R1 = 2/3 ... 3/2, steel_wall.sct and alu_wall.sct on a rigid
die), die.json (the figures and every sample), die_compaction.png (punch pressure and coordination
number against solid fraction) and the LAMMPS logs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import compaction as C  # noqa: E402


def _json(x):
    if isinstance(x, dict):
        return {str(k): _json(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for k, (name, r) in enumerate(results.items()):
        s = r["samples"]
        keep = np.isin(np.array(s["stage"]), ["press", "unload"])  # the fast fill stroke is not plotted
        phi, pt, pb, Z = (np.array(s[c], dtype=float)[keep] for c in ("phi", "p_top", "p_bottom", "Z"))
        col = f"C{k}"
        ax1.plot(phi, pt / 1e6, "-", color=col, lw=1.2, label=f"{name}: punch")
        if np.isfinite(pb).any():
            ax1.plot(phi, pb / 1e6, ":", color=col, lw=1.0, label=f"{name}: bottom")
        sb = r["summary"]["phi_after_unload"]
        if sb is not None:
            ax1.axvline(sb, color=col, lw=0.6, ls="--")
        load = np.array(s["stage"])[keep] != "unload"
        ax2.plot(phi[load], Z[load], "-", color=col, lw=1.2, label=f"{name}: loading")
        ax2.plot(phi[~load], Z[~load], "--", color=col, lw=1.0, label=f"{name}: unloading")
    ax1.set_xlabel("solid fraction")
    ax1.set_ylabel("pressure (MPa)")
    ax1.legend(fontsize=7)
    ax1.set_title("pressing and unloading; dashed: solid fraction after unloading", fontsize=9)
    ax2.set_xlabel("solid fraction")
    ax2.set_ylabel("coordination number (h > 0)")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("runs/die"))
    ap.add_argument("--laws", nargs="+", default=["spherecontact"], choices=["spherecontact", "mdr"])
    ap.add_argument("--materials", nargs="+", default=["steel", "alu"], choices=["steel", "alu"])
    ap.add_argument("--n", type=int, default=2000, help="number of spheres")
    ap.add_argument("--phi-max", type=float, default=0.86)
    ap.add_argument("--v-press", type=float, default=3.0)
    ap.add_argument("--mu", type=float, default=0.3, help="particle-particle friction")
    ap.add_argument("--mu-wall", type=float, default=0.1, help="die wall friction")
    ap.add_argument("--dt", type=float, default=None,
                    help="time step (default: 0.2 of the smallest critical step spherecontact prints)")
    ap.add_argument("--reuse", action="store_true",
                    help="keep the laws already in DIR/die.json (same number of spheres), run the others")
    ap.add_argument("--plot-only", action="store_true", help="plot DIR/die.json again")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args(argv)
    if "spherecontact" in args.laws and not C.PLUGIN.is_file():
        raise SystemExit(f"{C.PLUGIN} is missing: make lammps-plugin")
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    if args.plot_only:
        plot(json.loads((out / "die.json").read_text())["results"], out / "die_compaction.png")
        return None
    p = C.Protocol(n=args.n, materials=tuple(args.materials), L=20e-3 * (args.n / 2000) ** (1 / 3),
                   phi_max=args.phi_max, v_press=args.v_press, mu=args.mu, mu_wall=args.mu_wall)
    t0 = time.perf_counter()
    tables = C.write_tables(out, p.materials)
    t_tables = time.perf_counter() - t0
    t0 = time.perf_counter()
    pk = C.packing(p)
    t_pack = time.perf_counter() - t0
    print(f"tables {t_tables:.1f} s, packing {p.n} spheres at phi {p.phi0} in {t_pack:.1f} s "
          f"(die {p.L * 1e3:.2f} mm, height {pk.H * 1e3:.2f} mm)")
    results, dt = {}, args.dt
    old = out / "die.json"
    if args.reuse and old.is_file():
        prev = json.loads(old.read_text())["results"]
        results = {k: v for k, v in prev.items() if k in args.laws and v["summary"]["n"] == p.n}
        dt = dt or next((v["summary"]["dt"] for v in results.values()), None)
    for law in args.laws:
        if law in results:
            print(f"{law}: kept from {old}")
            continue
        print(f"{law}:")
        t0 = time.perf_counter()
        proto = C.Protocol(**{**p.__dict__, "dt": dt})
        c = C.Compaction(law, pk, proto, tables, log=str(out / f"log_{law}.lammps"))
        s = c.protocol()
        c.close()
        dt = dt or c.dt  # the other laws run at spherecontact's time step
        s["total_s"] = round(time.perf_counter() - t0, 1)
        results[law] = {"summary": s, "samples": c.rec.__dict__}
        doc = {"tables": {f"{a}-{b}": str(v.name) for (a, b), v in tables.items()},
               "table_s": round(t_tables, 1), "packing_s": round(t_pack, 1), "results": results}
        (out / "die.json").write_text(json.dumps(_json(doc), indent=1) + "\n")
        print(f"  phi_max {s['phi_max']:.4f} at {s['p_max_MPa']:.4g} MPa, after unloading "
              f"{s['phi_after_unload']:.4f}; Z {s['Z_at_phi_max']:.2f}; {s['steps']} steps, "
              f"{s['wall_s']:.0f} s in LAMMPS ({s['s_per_step'] * 1e3:.3g} ms/step), "
              f"total {s['total_s']:.0f} s")
    if not args.no_plot:
        plot(results, out / "die_compaction.png")
        print(f"plot: {out / 'die_compaction.png'}")
    return doc


if __name__ == "__main__":
    main()
