"""The project's end-to-end job on one case: FE reference run against the closed-form model.

``python -m spherecontact.demo [--E-over-sy 200] [--h-max 0.1] [--out reports/demo]``

An elastic–perfectly plastic sphere (σ_Y = 1, R = 1, ν = 0.3) pressed on a rigid
flat — by symmetry one of two equal spheres in contact. The FE solver writes
its run file (``OUT/run.h5``); the closed-form model (coefficients from
``model/coefficients.json``), Hertz and Jackson & Green (2005) are evaluated at the
same approaches; ``OUT/index.md`` holds the table and ``OUT/curves.png`` the chart.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np


def main(argv: list[str] | None = None) -> int:
    from tqdm import tqdm

    from spherecontact.fem.io import run_indentation, write_run
    from spherecontact.model import Material, Sphere, contact
    from spherecontact.model.coefficients import load_coefficients
    from spherecontact.peers import hertz, jackson_green

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--E-over-sy", type=float, default=200.0, help="E/σ_Y (σ_Y = 1), > 1")
    parser.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio in (-1, 0.5)")
    parser.add_argument("--h-max", type=float, default=0.1, help="final approach h/R in (0, 0.8]")
    parser.add_argument("--out", default="reports/demo", help="output directory")
    args = parser.parse_args(argv)
    if not args.E_over_sy > 1:
        raise ValueError(f"--E-over-sy must be > 1, got {args.E_over_sy!r}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    material = Material(E=args.E_over_sy, nu=args.nu, sigma_y=1.0)

    t0 = time.perf_counter()
    with tqdm(total=args.h_max, desc="FE run", unit="R", bar_format="{l_bar}{bar}| h/R {n:.4f}/{total}") as bar:
        def progress(h):
            bar.update(h - bar.n)

        result = run_indentation(material, 1.0, args.h_max, progress=progress)
    t_fe = time.perf_counter() - t0
    write_run(out / "run.h5", result)
    h, F, a = result.h, result.F, result.a

    coeffs = load_coefficients()
    t1 = time.perf_counter()
    model = contact(Sphere(1.0, material), Sphere(math.inf, Material.rigid()), h)
    t_model = time.perf_counter() - t1
    Ep = material.E_prime
    hz = hertz(h, Ep, 1.0)
    jg = jackson_green(h, 1.0, Ep, 1.0, args.nu)

    rows = ["| h/R | F FE | F model | F J–G | F Hertz | a FE | a model | a J–G |", "|---|---|---|---|---|---|---|---|"]
    picks = np.unique(np.searchsorted(h, np.geomspace(h[0], h[-1], 10)).clip(0, h.size - 1))
    for i in picks:
        rows.append(f"| {h[i]:.4g} | {F[i]:.4g} | {model.F[i]:.4g} | {jg.F[i]:.4g} | {hz.F[i]:.4g} | "
                    f"{a[i]:.4f} | {model.a[i]:.4f} | {jg.a[i]:.4f} |")
    err_F = model.F / F - 1
    err_a = model.a / a - 1
    m = h >= 0.01 * args.h_max
    summary = (f"Model against FE for h/R in [{h[m][0]:.3g}, {h[-1]:.3g}]: F max {100 * np.abs(err_F[m]).max():.1f} %, "
               f"rms {100 * np.sqrt(np.mean(err_F[m] ** 2)):.1f} %; a max {100 * np.abs(err_a[m]).max():.1f} %, "
               f"rms {100 * np.sqrt(np.mean(err_a[m] ** 2)):.1f} % (coefficients: {coeffs.source}).")
    text = "\n".join([
        f"# FE against the closed-form model: EPP sphere on a rigid flat, E/σY = {args.E_over_sy:g}, ν = {args.nu:g}",
        "", f"FE run: {result.status} ({result.reason}), {result.timings['increments']} increments, "
        f"{result.timings['newton_iterations']} Newton iterations, {t_fe:.1f} s; file `run.h5`. "
        f"Model: {1e3 * t_model:.2f} ms for the {h.size} points.", "", summary, "", *rows, "",
        "![curves](curves.png)", ""])
    (out / "index.md").write_text(text)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for axis, key, fe, mo, pj, ph in ((ax[0], "F/(σ_Y R²)", F, model.F, jg.F, hz.F),
                                      (ax[1], "a/R", a, model.a, jg.a, hz.a)):
        axis.plot(h, fe, "k-", lw=2, label="FE")
        axis.plot(h, mo, "C0--", label=f"closed-form model ({coeffs.source})")
        axis.plot(h, pj, "C1:", label="Jackson & Green 2005")
        axis.plot(h, ph, "C2-.", lw=0.8, label="Hertz")
        axis.set_xlabel("h/R")
        axis.set_ylabel(key)
        axis.set_ylim(0, 1.3 * fe.max())
    ax[0].legend(fontsize=8)
    fig.suptitle(f"EPP sphere on a rigid flat, E/σY = {args.E_over_sy:g}")
    fig.tight_layout()
    fig.savefig(out / "curves.png", dpi=110)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
