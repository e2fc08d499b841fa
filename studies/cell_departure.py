"""Where the pair law stops: a 3D FE cell run against pair laws at the same per-contact approach.

For a cell run (``spherecontact fem cell``) of one material and scene, the force of each moving
contact F_cell(h) is set beside, at the same per-contact approach h:

* the axisymmetric FE flat run of the same material (``spherecontact fem run``): a sphere pair
  at approach h is the hemisphere on a flat at h/2, so F_pair = F_ax(h/2);
* the model, ``contact(s, s, h)`` for two equal spheres;
* LAMMPS' ``mdr`` in the same lattice (``data/peers/mdr_lattice.json``, EPP materials only).

Departure: the relative density from which on |F_cell/F_pair − 1| stays above 5 % (20 %) to the
end of the loading (the mesh's node-closing scatter crosses 5 % briefly at small patches).
Writes ``<out>/<name>.md`` and ``<name>.png``::

    python studies/cell_departure.py --cell runs/cells/sc_iso.h5 --flat runs/flat_epp200.h5 \\
        --mdr data/peers/mdr_lattice.json --mdr-material epp200 --name sc_isostatic_epp200
"""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from spherecontact.fem import read_run  # noqa: E402
from spherecontact.model import Material, Sphere, contact  # noqa: E402

THRESHOLDS = (0.05, 0.20)


def departure(density, ratio, thr: float) -> float | None:
    """Density from which on |ratio − 1| > thr to the end (NaN ratios ignored); None if never."""
    r = np.asarray(ratio, float)
    ok = np.flatnonzero(np.isfinite(r))
    inside = ok[np.abs(r[ok] - 1.0) <= thr]
    last_in = inside[-1] if inside.size else -1
    after = ok[ok > last_in]
    return float(density[after[0]]) if after.size else None


def _material(inputs: dict) -> Material:
    m = inputs["material"]
    return Material.from_description(m) if hasattr(Material, "from_description") else Material(**m)


def references(cell, flat_path: str | None, mdr_path: str | None, mdr_material: str | None) -> dict:
    """Pair forces at the cell's per-contact approach of its first moving contact."""
    h = cell.h[:, 0]
    out = {}
    if flat_path:
        ax = read_run(flat_path)
        ok = h / 2 <= ax.h[-1]
        out["axisymmetric FE"] = np.where(ok, np.interp(h / 2, ax.h, ax.F), np.nan)
    s = Sphere(cell.inputs.get("radius", 1.0), _material(cell.inputs))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out["model"] = np.asarray(contact(s, s, np.maximum(h, 1e-12)).F)
    if mdr_path and mdr_material:
        doc = json.loads(Path(mdr_path).read_text())
        lattice, load = cell.scene.split("-")
        for run in doc["runs"]:
            sc = run["scene"]
            if run["material"] == mdr_material and sc["lattice"] == lattice and sc["load"] == load:
                k = run["i_max"] + 1
                hm, Fm = np.array(run["family"]["axial"]["h"][:k]), np.array(run["family"]["axial"]["F"][:k])
                inside = (h >= hm[0]) & (h <= hm[-1])
                out["mdr (lattice)"] = np.where(inside, np.interp(h, hm, Fm), np.nan)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cell", required=True, help="cell run file (spherecontact fem cell)")
    ap.add_argument("--flat", help="axisymmetric flat run of the same material (spherecontact fem run)")
    ap.add_argument("--mdr", help="mdr lattice store (spherecontact peers mdr-lattice)")
    ap.add_argument("--mdr-material", help="its material key (epp200, epp1000)")
    ap.add_argument("--name", required=True)
    ap.add_argument("--out", default="reports/cells")
    a = ap.parse_args(argv)
    cell = read_run(a.cell)
    loading = np.arange(len(cell.density))
    if "h" in cell.curves:  # loading part only: up to the largest approach
        loading = loading[: int(np.argmax(cell.h_load)) + 1]
    rho, F = cell.density[loading], cell.F[loading, 0]
    refs = {k: v[loading] for k, v in references(cell, a.flat, a.mdr, a.mdr_material).items()}
    rows = []
    for name, Fp in refs.items():
        r = F / Fp
        rows.append((name, departure(rho, r, 0.05), departure(rho, r, 0.20), r))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for name, _, _, r in rows:
        ax.plot(rho, r, label=name)
    for y in (0.8, 0.95, 1.05, 1.2):
        ax.axhline(y, color="0.8", lw=0.8, zorder=0)
    ax.set_xlabel("relative density")
    ax.set_ylabel("F_cell / F_pair (same per-contact h)")
    ax.set_title(f"{a.name}: 3D FE cell against pair laws", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / f"{a.name}.png", dpi=130)
    fmt = lambda x: "—" if x is None else f"{x:.3f}"  # noqa: E731
    lines = [f"# {a.name}: the 3D FE cell against pair laws", "",
             f"Cell run `{a.cell}` (scene {cell.scene}, mesh density "
             f"{cell.inputs.get('mesh_density', '?')}, status {cell.status}: {cell.reason}); density "
             f"{rho[0]:.3f} … {rho[-1]:.3f}. Pair laws at the same per-contact approach h: "
             + ", ".join(refs) + ". Departure: the density from which on |F_cell/F_pair − 1| "
             "stays above 5 % / 20 % to the end of the loading.", "",
             f"![ratio]({a.name}.png)", "",
             "| pair law | 5 % | 20 % | F_cell/F_pair at the last density |", "|---|---|---|---|"]
    for name, d5, d20, r in rows:
        lines.append(f"| {name} | {fmt(d5)} | {fmt(d20)} | {r[-1]:.3f} |")
    (out / f"{a.name}.md").write_text("\n".join(lines) + "\n")
    for name, d5, d20, r in rows:
        print(f"{a.name}: {name}: 5 % at {fmt(d5)}, 20 % at {fmt(d20)}, last ratio {r[-1]:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
