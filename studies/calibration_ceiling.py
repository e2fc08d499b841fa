"""How much of the fitted model's misfit a smooth term in its own variables could take away.

The chosen form misses 3 % on about half the runs (``calibration/README.md``, "Where the
chosen form stops"). Before adding terms, this measures the most any term of the kind the
form is built from could give: corrections of ln H̄ and ln c² are fitted, by ridge least squares,
to the F and a errors at the calibration points (to first order
r_F = r_H + (d ln F/d ln h) r_c and r_a = (d ln a/d ln h) r_c, as in ``fit.log_errors``), each
correction a combination of cubic B-splines in

    ξ = a/R + s n        (s = ``SHIFT``: the FE's c² step lines up in ξ, below)

times the modifiers 1, n, ζ = z/(1 + z) and ln(E/σ_Y)/ln 10⁴ (n the effective exponent,
z = R/ρ − 1 of the rigid partner); ``extra`` adds more (``EXTRA``): the products of those three
(``pairs``), and the log-log curvature of the flow curve about the representative strain,
κ = [ln σ_f(4ε)/σ_f(ε) − ln σ_f(ε)/σ_f(ε/4)]/ln 4 at ε = ε_rep (``curvature``: 0 for a power
law, < 0 where a curve saturates). Scores: in-sample, held out
over the five folds of materials of the cross-validation (``crossval.material_folds``), and on
the validation set's single-body points with the correction fitted to all calibration points.
A term of this kind cannot do better than the in-sample figure; if the held-out one does not
move, the misfit is not a smooth function of these variables.

**The c² step** (:func:`step_positions`): on flats the FE's d ln a/d ln h dips (to 0.32 for a
stiff perfectly plastic sphere) where c² falls from its plateau; the dip's a/R is read as the
minimum over a/R 0.25–0.7 of runs that reach a/R 0.62 and dip to ``STEP_DEPTH`` or below, and
regressed on n (:func:`step_law`). ``python studies/calibration_ceiling.py`` writes
``reports/calibration/ceiling.json`` and ``ceiling.png``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from scipy.interpolate import BSpline

from spherecontact.calibration.crossval import FOLDS, material_folds
from spherecontact.calibration.dataset import Dataset
from spherecontact.calibration.fit import log_errors
from spherecontact.calibration.forms import point_inputs, predict, raw_curvature_ratio
from spherecontact.model.single import representative_strain

__all__ = ["SHIFT", "STEP_DEPTH", "EXTRA", "basis", "flow_curvature", "tensor_basis", "ceiling",
           "learning_curve", "step_positions", "step_law", "main"]

#: ξ = a/R + SHIFT·n: the FE's c² step at ξ ≈ 0.545 for every hardening (``step_law``, v2 database)
SHIFT = 0.67
#: a run's c² step counts when its d ln a/d ln h dips to this or below
STEP_DEPTH = 0.43
#: B-spline knots on ξ ∈ [0, XI_MAX]
XI_MAX = 0.9
#: ridge weight (the basis is a partition of unity: O(1) columns)
RIDGE = 1e-3
#: the run error the model's design goal asks for
TARGET = 0.03
#: modifier sets ``basis`` can add to (1, n, ζ, ln E/σ_Y) (module docstring)
EXTRA = ("pairs", "curvature")
#: ratio of the strains the flow curve's curvature is read over (ε/k, ε, kε)
CURVATURE_RATIO = 4.0


def flow_curvature(ds: Dataset, coeffs, k: float = CURVATURE_RATIO) -> np.ndarray:
    """κ = [ln σ_f(kε)/σ_f(ε) − ln σ_f(ε)/σ_f(ε/k)]/ln k at ε = ε_rep of every point (0 for a
    perfectly plastic body)."""
    eps = representative_strain(ds.x_rho, coeffs.beta, coeffs.beta_growth)[0]
    out = np.zeros(ds.size)
    for i, c in enumerate(ds.curves):
        if math.isinf(c.material.sigma_y):
            continue
        m = ds.run == i
        lo, mid, hi = (c.material.flow_stress(eps[m] * f) for f in (1.0 / k, 1.0, k))
        out[m] = np.log(hi * lo / mid ** 2) / math.log(k)
    return out


def _splines(v, lo: float, hi: float, inner: int, degree: int) -> np.ndarray:
    """B-splines of ``degree`` on [lo, hi] with ``inner`` equally spaced inner knots at v."""
    v = np.clip(v, lo, hi - 1e-12 * (hi - lo))
    t = np.r_[[lo] * (degree + 1), np.linspace(lo, hi, inner + 2)[1:-1], [hi] * (degree + 1)]
    return BSpline.design_matrix(v, t, degree).toarray()


def _variables(ds: Dataset, coeffs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n (the effective exponent), ζ = z/(1 + z) of the rigid partner and E'/σ_Y at every point."""
    n = point_inputs(ds, coeffs)[0]
    z = raw_curvature_ratio(ds)
    sy = np.asarray([c.material.sigma_y for c in ds.curves])[ds.run]
    return n, z / (1.0 + z), ds.E_prime / sy


def basis(ds: Dataset, coeffs, knots: int = 8, shift: float = SHIFT, extra=()) -> np.ndarray:
    """Design matrix (points × columns): cubic B-splines in ξ (module docstring), each times
    1, n, ζ and ln(E/σ_Y)/ln 10⁴, and the modifiers of ``extra`` (names from ``EXTRA``)."""
    unknown = set(extra) - set(EXTRA)
    if unknown:
        raise ValueError(f"extra must name modifiers among {EXTRA}, got {sorted(unknown)}")
    n, zeta, stiffness = _variables(ds, coeffs)
    B = _splines(ds.x_R + shift * n, 0.0, XI_MAX, knots, 3)
    lnE = np.log(stiffness) / math.log(1e4)
    mods = [np.ones_like(n), n, zeta, lnE]
    if "pairs" in extra:
        mods += [n * zeta, zeta * lnE, n * n, lnE * lnE, n * lnE]
    if "curvature" in extra:
        mods.append(flow_curvature(ds, coeffs))
    return np.hstack([B * m[:, None] for m in mods])


def _fit(ds: Dataset, r0: tuple, X: np.ndarray, keep: np.ndarray,
         ridge: float) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients of the ln H̄ and ln c² corrections fitted to the model's F and a errors
    ``r0`` = (r_F, r_a) at the points ``keep`` (ridge least squares)."""
    rF, ra = r0
    Xk, sF, sa = X[keep], ds.slope_F[keep, None], ds.slope_a[keep, None]
    A = np.block([[Xk, sF * Xk], [np.zeros_like(Xk), sa * Xk]])
    w = np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), A.T @ np.r_[rF[keep], ra[keep]])
    k = X.shape[1]
    return w[:k], w[k:]


def _held_out(cal: Dataset, r0: tuple, X: np.ndarray, ridge: float,
              folds: int = FOLDS) -> tuple[np.ndarray, np.ndarray]:
    """The ln H̄ and ln c² corrections at every point, each fold of materials
    (``crossval.material_folds``) predicted by the correction fitted to the others."""
    dH, dc = np.empty(cal.size), np.empty(cal.size)
    groups = np.asarray([c.group for c in cal.curves])[cal.run]
    for held in material_folds(cal.groups, folds):
        test = np.isin(groups, held)
        fH, fc = _fit(cal, r0, X, ~test, ridge)
        dH[test], dc[test] = X[test] @ fH, X[test] @ fc
    return dH, dc


def _corrected(ds: Dataset, model: tuple, dH=0.0, dc=0.0) -> tuple[np.ndarray, np.ndarray]:
    """r_F, r_a (``fit.log_errors``) of the model's p_m, c² = ``model`` with ln H̄ and ln c²
    corrected by −dH, −dc."""
    p, c = model
    return log_errors(ds, p * np.exp(-dH), c * np.exp(-dc))


def _scores(ds: Dataset, rF: np.ndarray, ra: np.ndarray, worst: int = 3) -> dict:
    """RMS and max in %, runs whose larger max exceeds ``TARGET`` and the ``worst`` runs (key,
    max %, a/R where it sits)."""
    pct = lambda v: round(100.0 * float(v), 2)  # noqa: E731
    big = np.maximum(np.abs(rF), np.abs(ra))
    runs = []
    for i, c in enumerate(ds.curves):
        m = np.flatnonzero(ds.run == i)
        j = m[np.argmax(big[m])]
        runs.append((float(big[j]), c.key, round(float(ds.x_R[j]), 3)))
    runs.sort(reverse=True)
    return {"F_rms_pct": pct(np.sqrt(np.mean(rF ** 2))), "F_max_pct": pct(np.abs(rF).max()),
            "a_rms_pct": pct(np.sqrt(np.mean(ra ** 2))), "a_max_pct": pct(np.abs(ra).max()),
            "runs": len(runs), "runs_above_target": sum(r[0] > TARGET for r in runs),
            "worst": [{"run": k, "max_pct": pct(v), "a_over_R": x} for v, k, x in runs[:worst]]}


def ceiling(cal: Dataset, coeffs, val: Dataset | None = None, knots: int = 8,
            ridge: float = RIDGE, extra=(), design=None) -> dict:
    """Scores (RMS and max of the F and a errors in %, runs whose larger max exceeds
    ``TARGET``) of the fitted model and of it with the correction: in-sample, held out by
    folds of materials, and on ``val`` (module docstring; ``extra``: see :func:`basis`;
    ``design(ds, coeffs)``: another design matrix instead, e.g. :func:`tensor_basis`)."""
    if design is None:
        design = lambda ds, co: basis(ds, co, knots, extra=extra)  # noqa: E731
    model = predict(cal, coeffs)
    r0 = _corrected(cal, model)
    X = design(cal, coeffs)
    out = {"parameters": 2 * X.shape[1], "knots": knots, "shift": SHIFT, "ridge": ridge,
           "extra": list(extra), "model": _scores(cal, *r0)}
    wH, wc = _fit(cal, r0, X, np.ones(cal.size, bool), ridge)
    out["in_sample"] = _scores(cal, *_corrected(cal, model, X @ wH, X @ wc))
    out["held_out"] = _scores(cal, *_corrected(cal, model, *_held_out(cal, r0, X, ridge)))
    if val is not None:
        mv, Xv = predict(val, coeffs), design(val, coeffs)
        out["validation_model"] = _scores(val, *_corrected(val, mv))
        out["validation"] = _scores(val, *_corrected(val, mv, Xv @ wH, Xv @ wc))
    return out


#: the tensor-product correction (:func:`tensor_basis`): cubic B-splines in ξ with 8 inner knots
#: on [0, XI_MAX], quadratic ones with one inner knot in n on [0, 0.5] and in log₁₀ E/σ_Y on
#: [1, 4.2], each times (1, ζ), (1, κ) and (1, ν)
TENSOR_RIDGE = 0.1


def tensor_basis(ds: Dataset, coeffs) -> np.ndarray:
    """Tensor-product design matrix (points × 12·4·4·2·2·2 = 1536): every product of the
    splines in ξ, n and log₁₀ E/σ_Y and of (1, ζ), (1, κ), (1, ν) (``TENSOR_RIDGE``'s comment):
    a correction table that can follow any interaction of the model's variables, the limit
    of what a table in them could give."""
    n, zeta, stiffness = _variables(ds, coeffs)
    nu = np.asarray([c.material.nu for c in ds.curves])[ds.run]
    one = np.ones(ds.size)
    factors = [_splines(ds.x_R + SHIFT * n, 0.0, XI_MAX, 8, 3), _splines(n, 0.0, 0.5, 1, 2),
               _splines(np.log10(stiffness), 1.0, 4.2, 1, 2), np.c_[one, zeta],
               np.c_[one, flow_curvature(ds, coeffs)], np.c_[one, nu]]
    X = factors[0]
    for M in factors[1:]:
        X = (X[:, :, None] * M[:, None, :]).reshape(ds.size, -1)
    return X


def learning_curve(cal: Dataset, coeffs, folds=(3, 5, 10, 20), knots: int = 8,
                   ridge: float = RIDGE, extra=()) -> list[dict]:
    """Held-out scores of the correction against the share of materials it is fitted on: for
    each k of ``folds``, the materials dealt into k folds (``crossval.material_folds``), each
    fold predicted from the other k − 1 (a share 1 − 1/k). Scores that stop falling as the
    share grows say that more runs of the same kind would not take the misfit out."""
    model = predict(cal, coeffs)
    r0 = _corrected(cal, model)
    X = basis(cal, coeffs, knots, extra=extra)
    return [{"folds": k, "share_fitted": round(1.0 - 1.0 / k, 3), "parameters": 2 * X.shape[1],
             "extra": list(extra), **_scores(cal, *_corrected(cal, model, *_held_out(cal, r0, X, ridge, k)))}
            for k in folds]


def step_positions(ds: Dataset, coeffs, lo: float = 0.25, hi: float = 0.7, reach: float = 0.62,
                   depth: float = STEP_DEPTH) -> list[dict]:
    """Flats whose FE c² steps (module docstring): key, a/R of the step, the slope there and n."""
    n = point_inputs(ds, coeffs)[0]
    rows = []
    for i, c in enumerate(ds.curves):
        m = ds.run == i
        x, s = ds.x_R[m], ds.slope_a[m]
        inside = (x > lo) & (x < hi)
        if not math.isinf(c.indenter_radius) or x.max() < reach or np.count_nonzero(inside) < 5:
            continue
        j = int(np.argmin(np.where(inside, s, np.inf)))
        if s[j] <= depth:
            rows.append({"key": c.key, "a_over_R": float(x[j]), "slope": float(s[j]), "n": float(n[m][j])})
    return rows


def step_law(rows: list[dict]) -> dict:
    """Least-squares a/R_step = x₀ + x_n n over ``rows``, its RMS residual, the spread of the
    positions and the correlation."""
    x = np.array([r["a_over_R"] for r in rows])
    n = np.array([r["n"] for r in rows])
    A = np.c_[np.ones_like(n), n]
    w = np.linalg.lstsq(A, x, rcond=None)[0]
    return {"x0": float(w[0]), "x_n": float(w[1]), "rms": float(np.sqrt(np.mean((A @ w - x) ** 2))),
            "spread": float(x.std()), "correlation": float(np.corrcoef(n, x)[0, 1]), "runs": int(x.size)}


def _chart(cal: Dataset, coeffs, rows: list[dict], law: dict, out: Path) -> Path:
    from spherecontact.validation.charts import pyplot

    plt = pyplot()
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4.5))
    n = np.array([r["n"] for r in rows])
    ax0.plot(n, [r["a_over_R"] for r in rows], "o", ms=4)
    nn = np.linspace(0.0, n.max(), 2)
    ax0.plot(nn, law["x0"] + law["x_n"] * nn, "k-", lw=1,
             label=f"a/R = {law['x0']:.3f} {law['x_n']:+.2f} n (RMS {law['rms']:.3f})")
    ax0.set(xlabel="effective hardening exponent n", ylabel="a/R of the FE's c² step",
            title="where c² steps (flats)")
    ax0.legend()
    rF = _corrected(cal, predict(cal, coeffs))[0]
    xi = cal.x_R + SHIFT * point_inputs(cal, coeffs)[0]
    for i, c in enumerate(cal.curves):
        if math.isinf(c.indenter_radius):
            m = cal.run == i
            ax1.plot(xi[m], 100 * rF[m], lw=0.6, alpha=0.7)
    for y in (-100 * TARGET, 100 * TARGET):
        ax1.axhline(y, color="k", lw=0.6)
    ax1.set(xlabel=f"ξ = a/R + {SHIFT} n", ylabel="model/FE − 1 of F, %", title="calibration flats: F error")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    import warnings

    from spherecontact.calibration.dataset import build_dataset
    from spherecontact.data import Database
    from spherecontact.model import load_coefficients

    p = argparse.ArgumentParser(prog="studies/calibration_ceiling.py",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--db", default="data/reference_v2.h5")
    p.add_argument("--coefficients", default="model/coefficients.json")
    p.add_argument("--out", default="reports/calibration")
    a = p.parse_args(argv)
    co = load_coefficients(a.coefficients)
    db = Database(a.db)
    one_body = lambda rec: rec.inputs.get("scene") != "two_body"  # noqa: E731
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the validation set reaches past the calibrated range
        sets = {s: build_dataset([(f"{r.case} [{r.key}]", run)
                                  for r, run in db.runs(set=s, status=None, where=one_body)])
                for s in ("calibration", "validation")}
        result = {k: ceiling(sets["calibration"], co, sets["validation"], k) for k in (6, 8, 12)}
        for extra in (("curvature",), ("pairs",), EXTRA):  # more modifiers at 8 knots
            result["8+" + "+".join(extra)] = ceiling(sets["calibration"], co, sets["validation"], 8,
                                                     extra=extra)
        result["tensor"] = ceiling(sets["calibration"], co, sets["validation"], ridge=TENSOR_RIDGE,
                                   design=tensor_basis)
    rows = step_positions(sets["calibration"], co) + step_positions(sets["validation"], co)
    law = step_law(rows)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    curves = [row for extra in ((), EXTRA) for row in learning_curve(sets["calibration"], co, extra=extra)]
    record = {"correction": result, "learning_curve": curves, "c2_step": {"law": law, "runs": rows}}
    (out / "ceiling.json").write_text(json.dumps(record, indent=1) + "\n")
    _chart(sets["calibration"], co, rows, law, out / "ceiling.png")
    print(json.dumps({"correction": result, "learning_curve": curves, "c2_step": law}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
