"""Synthetic runs and databases for tests and demonstrations (no FE involved).

Checks: the calibration's reading and fitting on curves whose answer is known — Hertz curves must
give H̄ = 4Λ/(3π) and c² = 1/2, the model's own curves must give back its coefficients.
Writes: ``python studies/calibration_synthetic.py --out /tmp/synthetic.h5 [--hertz]`` a reference
database of such runs over the calibration grid (:data:`CALIBRATION_CASES`), which
``spherecontact calibrate --db /tmp/synthetic.h5`` reads like the FE database.

* :func:`hertz_result` — curves of exact Hertz contact (F = 4/3 E' √ρ h^{3/2}, a² = ρ h)
  for a given material and scene: the dataset must give H̄ = 4Λ/(3π) and c² = 1/2.
* :func:`model_result` — curves of the closed-form model with a given coefficient set:
  a fit must recover the coefficients.
* :func:`write_database` — such runs written through the reference-database writer
  (``spherecontact.data.append_run``), so the calibration reads them through the same
  reader API as the real FE data.

The results are ``fem.solver.RunResult`` objects with every curve a run file needs;
profiles and the final mesh are placeholders.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from spherecontact.calibration.check import quiet_range_warnings
from spherecontact.calibration.dataset import relative_radius
from spherecontact.fem.solver import RunResult
from spherecontact.model import Material, Sphere, contact
from spherecontact.model.coefficients import Coefficients

__all__ = ["CALIBRATION_CASES", "hertz_result", "model_result", "write_database"]

#: the calibration grid of campaign v1 (studies/campaign_v1.toml), as (case, material, R_i)
CALIBRATION_CASES: list[tuple[str, Material, float]] = (
    [(f"flat-E{E:g}", Material(E=E, nu=0.3, sigma_y=1.0), math.inf)
     for E in (10, 30, 100, 300, 1000, 3000, 10000)]
    + [(f"flat-E{E:g}-nu{nu:g}", Material(E=E, nu=nu, sigma_y=1.0), math.inf)
       for nu in (0.2, 0.45) for E in (100, 1000)]
    + [(f"flat-K2-n{n:g}-E{E:g}", Material(E=E, nu=0.3, sigma_y=1.0, K=2.0, n=n), math.inf)
       for n in (0.15, 0.3, 0.5) for E in (100, 1000)]
    + [(f"flat-K2-n0.3-E{E:g}", Material(E=E, nu=0.3, sigma_y=1.0, K=2.0, n=0.3), math.inf)
       for E in (30, 3000)]
    + [(f"sphere-E{E:g}", Material(E=E, nu=0.3, sigma_y=1.0), 1.0) for E in (100, 1000)]
    + [("sphere-K2-n0.3-E300", Material(E=300, nu=0.3, sigma_y=1.0, K=2.0, n=0.3), 1.0)]
)


def _inputs(material: Material, radius: float, indenter_radius: float, h_max: float) -> dict:
    m = {"E": float(material.E), "nu": float(material.nu), "sigma_y": float(material.sigma_y),
         "K": float(material.K), "n": float(material.n)}
    return {"material": m, "radius": float(radius), "indenter_radius": float(indenter_radius),
            "h_max": float(h_max), "mesh_density": 1.0, "element": "q8r", "options": {}}


def _result(material, radius, indenter_radius, h, F, a) -> RunResult:
    n = h.size
    zeros = np.zeros(n)
    curves = {"h": h, "F": F, "F_support": F, "a": a, "a_nodes": a, "a_ref": a, "a_raw": a,
              "a_ref_raw": a, "p_m": F / (math.pi * a * a), "eps_p_max": zeros,
              "work_external": zeros, "energy_elastic": zeros, "dissipation": zeros,
              "iterations": np.ones(n), "active_changes": zeros}
    X = np.array([[0.0, 1.0, 1.0, 0.0, 0.5, 1.0, 0.5, 0.0], [0.0, 0.0, 1.0, 1.0, 0.0, 0.5, 1.0, 0.5]])
    final = {"X": X, "u": np.zeros(16), "cells": np.arange(8)[None, :], "eps_p": np.zeros((1, 4))}
    return RunResult(inputs=_inputs(material, radius, indenter_radius, float(h[-1])), curves=curves,
                     residuals=[[1e-10]] * n, profile_r=np.zeros((n, 2)), profile_p=np.zeros((n, 2)),
                     profile_g=np.zeros((n, 2)), status="converged", reason="reached h_max",
                     timings={"wall_s": 0.0}, final=final)


def _h_grid(radius: float, h_max: float, n: int) -> np.ndarray:
    return radius * np.geomspace(1e-6, h_max / radius, n)


def hertz_result(material: Material, radius: float = 1.0, indenter_radius: float = math.inf,
                 h_max: float = 0.3, n: int = 300) -> RunResult:
    """Exact Hertz curves (whatever the yield stress): F = 4/3 E' √ρ h^{3/2}, a = √(ρ h)."""
    rho = relative_radius(radius, indenter_radius)
    h = _h_grid(radius, h_max, n)
    F = 4.0 / 3.0 * material.E_prime * math.sqrt(rho) * h**1.5
    return _result(material, radius, indenter_radius, h, F, np.sqrt(rho * h))


def model_result(material: Material, coeffs: Coefficients, radius: float = 1.0,
                 indenter_radius: float = math.inf, h_max: float = 0.3, n: int = 300,
                 noise: float = 0.0, seed: int = 0) -> RunResult:
    """Curves of the model (body on a rigid flat or sphere) with ``coeffs``; optional
    multiplicative noise of relative size ``noise`` on F and a (fixed seed)."""
    h = _h_grid(radius, h_max, n)
    partner = Sphere(indenter_radius, Material.rigid())
    with quiet_range_warnings():  # made-up runs may leave the range of ``coeffs``
        st = contact(Sphere(radius, material), partner, h, coeffs=coeffs)
    F, a = np.asarray(st.F, dtype=float), np.asarray(st.a, dtype=float)
    if noise:
        rng = np.random.default_rng(seed)
        F = F * (1.0 + noise * rng.standard_normal(n))
        a = a * (1.0 + noise * rng.standard_normal(n))
    return _result(material, radius, indenter_radius, h, F, a)


def write_database(path, results: list[tuple[str, RunResult]], date_utc: str = "2026-01-01T00:00:00Z",
                   set_name: str = "calibration") -> None:
    """Append ``(case, result)`` pairs to the reference database ``path`` (created if missing)."""
    from spherecontact.data import Record, append_run, input_key
    from spherecontact.fem.io import provenance

    for case, res in results:
        prov = provenance(res)
        prov["date_utc"] = date_utc
        prov["hostname"] = "synthetic"
        key = input_key(res.inputs)
        m = res.inputs["material"]
        params = {"E_over_sigma_y": m["E"] / m["sigma_y"], "nu": m["nu"],
                  "K_over_sigma_y": m["K"] / m["sigma_y"], "n": m["n"]}
        rec = Record(key=key, set=set_name, case=case, status=res.status, reason=res.reason,
                     wall_s=0.0, inputs=res.inputs, params=params)
        append_run(path, rec, res, prov)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="database to write (HDF5; appended to when present)")
    p.add_argument("--hertz", action="store_true", help="Hertz curves instead of the model's")
    p.add_argument("--h-max", type=float, default=0.3, help="largest approach over the radius")
    args = p.parse_args(argv)
    from spherecontact.model import default_coefficients

    coeffs = default_coefficients()
    results = [(case, hertz_result(m, indenter_radius=Ri, h_max=args.h_max) if args.hertz
                else model_result(m, coeffs, indenter_radius=Ri, h_max=args.h_max))
               for case, m, Ri in CALIBRATION_CASES]
    write_database(args.out, results)
    print(f"wrote {len(results)} synthetic runs -> {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
