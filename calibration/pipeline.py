"""The calibration stage end to end: database → fits → choice → checks → coefficient file.

:func:`calibrate_runs` works on ``(key, run)`` pairs (tests use synthetic runs);
:func:`calibrate` opens the reference database through its reader API
(``spherecontact.data.Database``) and writes ``model/coefficients.json``.

Choice of the form, by the numbers: every candidate of ``forms.CANDIDATES`` is fitted
and cross-validated (``crossval``: five folds of held-out materials); the chosen form has the smallest
pooled CV error E_cv = sqrt((RMS_F² + RMS_a²)/2) (F and a at the FE's approaches, ``fit``)
among the forms whose coefficient
set passes the monotonicity/continuity check (``check``); a form with fewer parameters
is preferred when its E_cv is within ``PARSIMONY`` (relative) of the smallest. The large-deformation
options (ratio a/R or a/ρ, collapse blend or not) are compared on the full set with
the chosen Level II form. They, the chosen form's regime folds and its diagnostics are queued
as soon as the parsimony rule has picked a form and run while its check decides (``Workers.submit``).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import multiprocessing
import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..cycles import run_cycles
from ..fem.increments import read_reruns, smaller_radius
from ..model.coefficients import Coefficients
from ..model.single import hardening_magnitude
from .check import MonotoneCheck, RunError, check_all, run_errors
from .crossval import DEFAULT_FOLDS, CVResult, FoldSolve, fold_tasks, regime_tasks
from .dataset import Dataset, build_dataset, quantities
from .diagnostics import breakdown, noise_floor
from .fit import ELASTIC_SPHERE, FitResult, fit, rms, round_sig
from .forms import CANDIDATES, FORMS, Form
from .interface import InterfaceFit, fit_interface, load_pairs, two_body_runs, with_interface
from .result import Calibration, cv_score
from .threads import single_threaded_blas
from .unloading import H_RES_WEIGHT, TAIL, fit_unloading
from .workers import DEFAULT_WORKERS, Workers

__all__ = ["Calibration", "calibrate_runs", "calibrate", "load_runs", "coefficient_file",
           "write_json", "cv_score", "calibrated_range", "source_path", "STAT_SIGNIFICANT"]

#: relative E_cv margin within which the form with fewer parameters is preferred
PARSIMONY = 0.02

#: significant digits of the statistics the file records (fit residuals, noise floor,
#: cross-validation, model error per run; ``calibration/README.md``, "Reproducibility").
#: They vary by up to 3e-5 relative between machines (1.3e-3 for the E_cv of ``poly``,
#: whose folds stop at their iteration cap): 4 digits changed 1–5 of them, 3 digits none.
STAT_SIGNIFICANT = 3

METHOD = ("scipy.optimize.least_squares (trf, bounds) of ln(p_m) and ln(c2), model/FE, on FE "
          "curves resampled uniformly in ln h; form chosen by cross-validation "
          "over five folds of held-out materials")

REFERENCES = {
    "beta": "Fitted to the FE calibration set (Ludwik hardening runs); Tabor (1951) 0.2, "
            "Biwa & Storakers (1995) 0.32 for comparison.",
    "Lambda_I": "Fitted; Level I is exact Hertz (Hertz 1882; Johnson 1985 sec. 4.2).",
    "Lambda_III": "Fitted; fully plastic regime (Johnson 1985 sec. 6.5; Mesarovic & Fleck 1999).",
    "H_bar_III": "Fitted; cf. Biwa & Storakers (1995) 3.07 with beta = 0.32.",
    "c2_III": "Fitted; form of Storakers, Biwa & Larsson (1997) Int. J. Solids Struct. 34:3061.",
    "level_II": "Fitted shape; seed sec. 2 (straight in ln Lambda) compared by cross-validation.",
    "finite_size": "Fitted: finite sphere (far field cut off at ~R) and large deformation, "
                   "vanishing as a/R -> 0 (DESIGN sec. 2).",
    "interface": "Fitted on the two-body calibration runs (calibration/interface.py): a weak pull "
                 "of the split of two plastic bodies of near-equal hardness towards the Hertz "
                 "partition, which keeps the nearly neutral equal-pressure equation well posed.",
    "collapse": "Fitted: at large a/R the plastic zone reaches the free surface and the sphere "
                "flattens as a whole; smooth minimum of the half-space and whole-body hardness "
                "(model/README.md).",
    "unloading": "Fitted on the unloading branches of the calibration runs (calibration/unloading.py): "
                 "Thornton (1997) Hertz-from-the-peak unloading (stiffness 2E*a_max, exponent 3/2) "
                 "with finite-size stiffening and a peak-dependent exponent (model/unloading.py).",
}


def _variant(form: Form, **changes) -> Form:
    return dataclasses.replace(form, **changes)


def _fit_and_check(ds: Dataset, form: Form, materials, start=None) -> tuple[FitResult, bool]:
    r = fit(ds, form, start=start)
    return r, all(c.ok for c in check_all(r.coeffs, materials))


#: the model's error per calibration run (``check.run_errors``) in this many worker tasks
RUN_ERROR_TASKS = 2


def _run_errors(ds: Dataset, coeffs, part: int) -> list[RunError]:
    """``check.run_errors`` of the runs of ``ds`` in part ``part`` of ``RUN_ERROR_TASKS`` consecutive
    parts (a task of ``workers``)."""
    n = len(ds.curves)
    lo, hi = part * n // RUN_ERROR_TASKS, (part + 1) * n // RUN_ERROR_TASKS
    return [run_errors(c, coeffs) for c in ds.curves[lo:hi]]


def _warm_start(form: Form, base: FitResult) -> np.ndarray:
    """Start values of ``form``: those of ``base`` where the parameter names agree."""
    x = form.start()
    known = dict(zip(base.form.names, base.params, strict=True))
    for i, name in enumerate(form.names):
        if name in known:
            x[i] = known[name]
    return x


def calibrate_runs(runs, candidates=CANDIDATES, cross_validation: bool = True,
                   large_deformation_options: bool = True, source: dict | None = None,
                   workers: int = DEFAULT_WORKERS, pairs=(), elastic_sphere=(),
                   cycle_runs=(), folds: FoldSolve = DEFAULT_FOLDS) -> Calibration:
    """Fit, cross-validate, choose, check. ``runs``: iterable of ``(key, run)``; the
    independent fits run on ``workers`` processes, with one BLAS thread each whatever the
    environment says (the result depends on neither). ``pairs``: two-body runs
    (``interface.PairCurve``) for the interface terms of the chosen form (none: left out);
    ``elastic_sphere``: the FE elastic hemisphere's (h/R, F/Hertz), the Level I anchor of the fits
    (``fit.level_I_anchor``; none: no anchor); ``cycle_runs``: ``(name, run)`` whose unloading
    cycles give the unloading law (``unloading.py``; none: left out); ``folds``: how far the
    cross-validation's fold fits are solved (``crossval.FoldSolve``)."""
    t0 = time.perf_counter()
    with single_threaded_blas():  # the result must not depend on the BLAS thread count (threads.py)
        ds = build_dataset(runs, elastic_sphere=elastic_sphere)
        timings = {"dataset_s": time.perf_counter() - t0}
        with Workers(ds, workers) as pool:
            cal = _calibrate(ds, pool, candidates, cross_validation, large_deformation_options, timings,
                             list(pairs), folds)
    cal.source = dict(source or {})
    if cycle_runs:
        t = time.perf_counter()
        co = with_interface(cal.best.coeffs, cal.interface)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # calibrated-range warnings: these are the calibration runs
            curves = [c for name, run in cycle_runs for c in run_cycles(name, run, co)]
        cal.unloading = fit_unloading(curves)
        timings["unloading_s"] = time.perf_counter() - t
    timings["total_s"] = time.perf_counter() - t0
    return cal


def _calibrate(ds: Dataset, pool: Workers, candidates, cross_validation: bool,
               large_deformation_options: bool, timings: dict, pairs=(),
               folds: FoldSolve = DEFAULT_FOLDS) -> Calibration:
    """Fits, cross-validation and the choice (:func:`calibrate_runs`). With two-body ``pairs`` a
    form's monotonicity check judges the model it would ship: its body law with the interface
    terms fitted to it (``interface.py``). Without them two plastic spheres of near-equal
    hardness leave the κ equation ill-conditioned (``model/unified.py``), and whether the
    check's grid pair of equal yield stress and E ratio 200 then kept F(h) rising decided
    between forms that ship the same for it."""
    t = time.perf_counter()
    # the full fits, each form's folds queued as soon as its fit is known (a quick form's folds
    # fill the workers while a slow form still fits)
    do_cv = cross_validation and len(ds.groups) >= 2
    done, fold_results = pool.run_then([(fit, (FORMS[name],)) for name in candidates],
                                lambda i, r: fold_tasks(ds, r, folds.nfev, folds.tol) if do_cv else [])
    fits = dict(zip(candidates, done, strict=True))
    cv = {name: CVResult(form=name, folds=f) for name, f in zip(candidates, fold_results, strict=True)} \
        if do_cv else {}
    timings["fits_and_cross_validation_s"] = time.perf_counter() - t
    t = time.perf_counter()
    mats = []
    for c in ds.curves:
        if c.material not in mats:
            mats.append(c.material)
    checks_ok: dict[str, bool] = {}
    checks: dict[str, list[MonotoneCheck]] = {}
    interfaces: dict[str, InterfaceFit | None] = {}
    interface_s = 0.0

    def passes(name: str) -> bool:
        nonlocal interface_s
        if name not in checks:
            co = as_shipped(ds, fits[name].coeffs)
            t_i = time.perf_counter()
            interfaces[name] = fit_interface(pairs, co, pool) if pairs else None
            interface_s += time.perf_counter() - t_i
            checks[name] = check_all(with_interface(co, interfaces[name]), mats, pool)
            checks_ok[name] = all(c.ok for c in checks[name])
        return checks_ok[name]

    def score(name: str) -> float:
        if name in cv:
            return cv_score(cv[name])
        e = fits[name].errors
        return math.sqrt(0.5 * (rms(e["F"]) ** 2 + rms(e["a"]) ** 2))

    def follow_up(name: str):
        """Queue the large-deformation alternatives (the slowest task first), the regime folds and
        the diagnostics of ``name``: they run while its check decides whether it is chosen."""
        base = fits[name]
        variants = ({"ratio a/rho": _variant(base.form, name=base.form.name + "_a_over_rho",
                                             ratio="a_over_rho"),
                     "no collapse": _variant(base.form, name=base.form.name + "_no_collapse",
                                             collapse=False)} if large_deformation_options else {})
        regimes = (regime_tasks(ds, base, folds.nfev, folds.tol)
                   if cross_validation and len(ds.curves) >= 2 else [])
        tasks = ([(_fit_and_check, (form, mats, _warm_start(form, base))) for form in variants.values()]
                 + regimes + [(noise_floor, ()), (breakdown, (base.coeffs, base.errors))]
                 + [(_run_errors, (base.coeffs, i)) for i in range(RUN_ERROR_TASKS)])
        return variants, len(regimes), pool.submit(tasks)

    remaining = sorted(candidates, key=lambda n: (score(n), FORMS[n].n_params, n))
    chosen = None
    while remaining and chosen is None:
        limit = score(remaining[0]) * (1.0 + PARSIMONY)
        pick = min((n for n in remaining if score(n) <= limit),
                   key=lambda n: (FORMS[n].n_params, score(n), n))
        queued = follow_up(pick)  # dropped if the check refuses the pick
        if passes(pick):
            chosen = pick
        else:
            remaining.remove(pick)
    if chosen is None:
        raise ValueError("no candidate form gives a monotone and continuous F(h): "
                         + "; ".join(f"{n}: {[c.label for c in checks[n] if not c.ok][:3]}"
                                     for n in checks))
    timings["choice_s"] = time.perf_counter() - t
    if pairs:
        timings["interface_s"] = interface_s
    t = time.perf_counter()
    variants, n_regimes, results = queued
    done = results()
    fitted, regimes, (noise, bands, *per_task) = (done[:len(variants)], done[len(variants):][:n_regimes],
                                                   done[len(variants) + n_regimes:])
    alternatives = {label: r for label, (r, _) in zip(variants, fitted, strict=True)}
    alt_ok = {label: ok for label, (_, ok) in zip(variants, fitted, strict=True)}
    errs = [e for part in per_task for e in part]
    timings["follow_up_wait_s"] = time.perf_counter() - t
    return Calibration(dataset=ds, fits=fits, cv=cv, chosen=chosen, checks=checks[chosen],
                       run_errors=errs, alternatives=alternatives, alternative_checks=alt_ok,
                       form_checks=dict(checks_ok), timings=timings, noise=noise, breakdown=bands,
                       regimes=regimes, interface=interfaces.get(chosen), folds=folds)


def _database_hash(db_path) -> str:
    from spherecontact.data import Database

    return Database(db_path).content_hash


@contextmanager
def _content_hash_aside(db_path):
    """The database's content hash (``Database.content_hash``: every dataset read again, ~3 s)
    computed by a forked process while this one reads the runs and calibrates; yields a function
    that waits for it. In this process where the platform cannot fork."""
    try:
        ctx = multiprocessing.get_context("fork")
    except ValueError:
        yield lambda: _database_hash(db_path)
        return
    with ProcessPoolExecutor(1, mp_context=ctx) as pool:  # forked before this process opens the file
        pending = pool.submit(_database_hash, db_path)
        yield pending.result


def load_runs(db_path, include_stopped: bool = True, db=None, content_hash: bool = True):
    """Calibration runs of the database: ``(runs, source)``.

    ``runs`` are ``(key, run)`` pairs of set "calibration" with one deformable body (scenes
    flat and rigid sphere; two-body runs, whose h = h₁ + h₂ includes the deformable
    partner's share, are left out and listed): converged runs and, with
    ``include_stopped`` (default), the converged increments of runs that stopped early
    (wall-time limit or increment floor: every stored increment is a converged state,
    the run just ends before h_max); ``source`` describes the database: path
    (:func:`source_path`), content hash, the date of the newest run used (the coefficient
    file's date, so the same database gives the same file), the keys used and those left
    out with their status.
    ``db``: the database at ``db_path`` already opened (``spherecontact.data.Database``);
    ``content_hash`` False: ``source["content_hash"]`` left None (the caller fills it).
    Raises FileNotFoundError/ValueError (from the reader) for a missing or unreadable
    file and ValueError if it holds no usable calibration run.
    """
    from spherecontact.data import Database

    db = Database(db_path) if db is None else db
    # single-body relations only: a two-body run's h = h1 + h2 includes the partner's share
    one_body = lambda rec: rec.inputs.get("scene") != "two_body"  # noqa: E731
    # status None: converged and stopped runs, sorted by (case, key) like every listing
    pairs = db.runs(set="calibration", status=None if include_stopped else "converged", where=one_body)
    if not pairs:
        n_all = len(db.records(set="calibration"))
        raise ValueError(f"{db_path}: no converged calibration runs ({n_all} calibration entries, "
                         f"{len(db)} entries in all)")
    used = {r.key for r, _ in pairs}
    left_out = [{"key": r.key, "case": r.case, "status": r.status,
                 "reason": ("two bodies: interface terms only (calibration/interface.py)"
                            if r.inputs.get("scene") == "two_body" else r.reason)}
                for r in db.records(set="calibration") if r.key not in used]
    dates = sorted(str(run.provenance.get("date_utc", "")) for _, run in pairs)
    partial = [{"key": r.key, "case": r.case, "h_last": float(run.h.max()), "reason": r.reason}
               for r, run in pairs if r.status == "stopped"]
    h = hashlib.sha256()  # the data the fit sees: keys, statuses and the curves h, F, a
    for r, run in sorted(pairs, key=lambda p: p[0].key):
        h.update(f"{r.key}\0{r.status}\0".encode())
        for arr in (run.h, run.F, run.a):
            h.update(np.ascontiguousarray(arr, dtype="<f8").tobytes())
    source = {"path": source_path(db_path), "content_hash": db.content_hash if content_hash else None,
              "calibration_runs_hash": h.hexdigest(), "date": dates[-1][:10] or None,
              "runs": [{"key": r.key, "case": r.case} for r, _ in pairs], "left_out": left_out,
              "partial": partial}
    return [(f"{r.case} [{r.key}]", run) for r, run in pairs], source


class FirstLoadingReplaced:
    """A run whose loading curve up to ``h_end`` (units of the smaller radius) is its re-run with
    increments bounded by the approach (``fem/increments.py``: the campaign's increments leave a
    stiff sphere's curve up to 10 % low there); the rest of the loading curve, the cycles and
    every other attribute are the run's own."""

    def __init__(self, run, converged: dict, h_end: float):
        self._run = run
        L = smaller_radius(run.inputs)
        h, F, a = (np.asarray(v, dtype=float) for v in (run.h, run.F, run.a))
        ref = np.asarray(getattr(run, "reference", np.ones(h.size, bool)), dtype=bool)
        keep = ref & (h > h_end * L * (1.0 + 1e-9))
        new = [np.asarray(converged["curve"][q], dtype=float) for q in ("h", "F", "a")]
        self.h, self.F, self.a = (np.concatenate([n, o[keep]]) for n, o in zip(new, (h, F, a), strict=True))
        self.reference = np.ones(self.h.size, dtype=bool)

    def __getattr__(self, name):
        return getattr(self._run, name)


def replace_first_loading(runs, keys, path) -> tuple[list, list[str]]:
    """``runs`` (``(name, run)``, database keys ``keys`` in the same order, as :func:`load_runs`
    gives them) with the first loading of those the file at ``path`` re-ran replaced
    (:class:`FirstLoadingReplaced`), and the keys replaced."""
    converged, head = read_reruns(path)
    h_end = float(head["h_end"])
    out, done = [], []
    for (name, run), key in zip(runs, keys, strict=True):
        if key in converged:
            run = FirstLoadingReplaced(run, converged[key], h_end)
            done.append(key)
        out.append((name, run))
    return out, done


def source_path(db_path) -> str:
    """The database path as the file records it: relative to the working directory when the
    database lies under it (``data/reference_v2.h5`` whether given as that, ``./data/…`` or
    absolute), with ``/`` separators; otherwise as given."""
    p = os.path.abspath(os.fspath(db_path))
    try:
        return Path(p).relative_to(os.path.abspath(os.getcwd())).as_posix()
    except ValueError:
        return Path(os.fspath(db_path)).as_posix()


def _stat(x: float) -> float:
    return round_sig(x, STAT_SIGNIFICANT)


def _stats(e) -> dict:
    e = np.asarray(e, dtype=float)
    return {"rms": _stat(rms(e)), "max": _stat(float(np.max(np.abs(e))))}


def _round_out(x: float, up: bool) -> float:
    """``x`` to ``SIGNIFICANT`` digits, rounded outwards (a range end stays outside the data)."""
    r = round_sig(x)
    if (r < x if up else r > x) and abs(r - x) > 1e-12 * abs(x):
        step = 10.0 ** (math.floor(math.log10(abs(x))) - 5)
        r = round_sig(r + step if up else r - step)
    return r


def _interval(values) -> list[float]:
    v = np.asarray(values, dtype=float)
    return [_round_out(float(v.min()), False), _round_out(float(v.max()), True)]


def as_shipped(ds: Dataset, coeffs: Coefficients) -> Coefficients:
    """``coeffs`` with the calibrated range of ``ds`` in their provenance, as the written file has
    it: the range sets where the model continues its fitted terms (``levels.py``), and the
    checks must judge the model that ships (without it, a/R < 1 instead of the fitted 0.72:
    a pair of the check at the edge of its jump criterion passed in the fit and failed as
    written, largest secant slope 6.07 against 6)."""
    return dataclasses.replace(coeffs, provenance={**coeffs.provenance,
                                                    "calibrated_range": calibrated_range(ds, coeffs)})


def calibrated_range(ds: Dataset, coeffs: Coefficients) -> dict:
    """The inputs the fit saw, as ``provenance["calibrated_range"]`` (read by ``model/``).

    Materials of the calibration runs used (E/σ_Y, the hardening exponent and the hardening
    magnitude K/σ_Y of the bodies that yield, ν of all; n: the Ludwik exponent, 0 for
    perfect plasticity, the secant exponent of the model for a flow table; K/σ_Y:
    ``single.hardening_magnitude``), the scenes (curvature ratio R/R_i of the body over its
    rigid partner, 0 for a flat), and over the calibration points of the fit: the largest
    approach h/R and contact radius a/R of the body, and the Λ range with the fitted β.
    Ends rounded outwards to ``SIGNIFICANT`` digits.
    """
    mats = [c.material for c in ds.curves]
    plastic = [m for m in mats if math.isfinite(m.sigma_y)]
    ns = [m.flow.range_exponent(coeffs.eps_lo, coeffs.eps_hi, coeffs.strain_spread) for m in plastic]
    lam = quantities(ds, coeffs.beta, coeffs.beta_growth, coeffs.strain_spread)["Lambda"]
    lam = lam[np.isfinite(lam) & (lam > 0.0)]
    return {
        "E_over_sigma_y": _interval([m.E / m.sigma_y for m in plastic]) if plastic else None,
        "nu": _interval([m.nu for m in mats]),
        "hardening_n": _interval(ns) if ns else None,
        "h_over_R_max": _round_out(float(ds.h_R.max()), True),
        "a_over_R_max": _round_out(float(ds.x_R.max()), True),
        "Lambda": _interval(lam) if lam.size else None,
        "K_over_sigma_y": _interval([hardening_magnitude(m, coeffs) for m in plastic]) if plastic
        else None,
        "R_over_R_rigid": _interval([c.radius / c.indenter_radius for c in ds.curves]),
    }


def coefficient_file(cal: Calibration) -> dict:
    """The schema-2 dictionary written to ``model/coefficients.json``."""
    best = cal.best
    d = json.loads(json.dumps(best.coeff_dict))
    ds = cal.dataset
    d["provenance"] = {
        "created": cal.source.get("date"),
        "created_from": "date of the newest FE run used (not the wall clock): the same database "
                        "gives the same file",
        "method": METHOD,
        "form": {"name": best.form.name, "description": best.form.description,
                 "n_params": best.form.n_params},
        "fe_dataset": {
            "path": cal.source.get("path"),
            "content_hash": cal.source.get("content_hash"),
            "calibration_runs_hash": cal.source.get("calibration_runs_hash"),
            "hashes": "content_hash: the whole database when calibrated (spherecontact.data); "
                      "calibration_runs_hash: SHA-256 of the keys, statuses and curves h, F, a of "
                      "the runs used (unchanged when other sets are added)",
            "set": "calibration",
            **({"first_loading_replaced": cal.source["first_loading_replaced"]}
               if "first_loading_replaced" in cal.source else {}),
            "runs": len(ds.curves),
            "materials": len(ds.groups),
            "points": ds.size,
            "filter": f"a >= {ds.curves[0].a_min / ds.curves[0].radius:g} R at mesh density 1 "
                      "(20/3 pole elements of the default mesh, 10/3 on the surface-band mesh)",
        },
        "fit_residuals": {q: _stats(e) for q, e in best.errors.items()},
        "noise_floor": {"H_bar": _stat(cal.noise["H_bar"]), "c2": _stat(cal.noise["c2"]),
                        "note": "RMS scatter of the calibration points about a local cubic in ln h "
                                "of their own run (leave-one-out, +-0.25 decade): the floor of "
                                "fit_residuals; systematic FE errors not included"}
        if cal.noise else None,
        "cross_validation": {n: {q: {k: _stat(v) for k, v in s.items()}
                                 for q, s in cv.pooled().items()} | {"score": _stat(cv_score(cv))}
                             for n, cv in cal.cv.items()},
        "cross_validation_folds": {"max_nfev": cal.folds.nfev, "tol": cal.folds.tol,
                                   "note": "each fold fit warm-started from the full fit and stopped "
                                           "after max_nfev evaluations or at tol (crossval.FoldSolve)"},
        "cross_validation_regimes": {
            f"{r.family}: {r.label}": {"runs": r.runs} | {
                q: {"rms": _stat(rms(r.errors[q])), "max": _stat(float(np.max(np.abs(r.errors[q]))))}
                for q in ("F", "a")} for r in cal.regimes},
        "model_error_per_run": {e.key: {"F": {"rms": _stat(e.F_rms), "max": _stat(e.F_max)},
                                        "a": {"rms": _stat(e.a_rms), "max": _stat(e.a_max)}}
                                for e in cal.run_errors},
        "model_error_note": "F(h), a(h) of the model in the FE scene against the resampled FE curves "
                            "(relative), a >= a_min",
        "monotone_check": {"pairs": len(cal.checks), "passed": sum(c.ok for c in cal.checks)},
        "calibrated_range": calibrated_range(ds, best.coeffs),
        "notes": "Residuals are relative (model/FE - 1) over the calibration points; "
                 "see reports/calibration/index.md.",
    }
    if cal.interface is not None:
        f = cal.interface
        if f.coupling > 0.0:
            d["interface"] = {k: round_sig(v) for k, v in f.section().items()}
        d["provenance"]["interface_fit"] = {
            "method": "grid search of the coupling on the two-body calibration runs, the largest "
                      "error over its target (|h1/h model - FE| / 0.05, |F|, |a| relative / 0.03) "
                      "among the couplings whose model passes the two-body monotonicity check "
                      "(calibration/interface.py)",
            "pairs": {name: {"split_max": _stat(e), "split_max_without": _stat(f.errors_none[name]),
                             "F_max": _stat(f.F_errors[name]), "a_max": _stat(f.a_errors[name])}
                      for name, e in f.errors.items()}}
    if cal.unloading is not None:
        u = cal.unloading
        d["unloading"] = u.section()
        d["provenance"]["unloading_fit"] = {
            "method": "least squares of F/F_max along every unloading branch of the calibration runs "
                      f"and {H_RES_WEIGHT:g} (h_res - h_res,FE)/h_max per branch, residuals r as "
                      f"r*sqrt(1 + (r/{TAIL:g})^2) (the worst branches weigh more), peak state from the "
                      "FE (calibration/unloading.py)",
            **{k: ({q: (_stat(x) if isinstance(x, float) else x) for q, x in v.items()}
                  if isinstance(v, dict) else v)
               for k, v in u.summary().items()}}
    d["references"] = dict(REFERENCES)
    Coefficients.from_dict(d)  # validate before writing
    return d


def write_json(path, d: dict) -> Path:
    """Write ``d`` as JSON (sorted layout fixed by insertion order, 2-space indent, final newline)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(d, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
    return path


def calibrate(db_path, out=None, report_dir=None, include_stopped: bool = True,
              candidates=CANDIDATES, workers: int = DEFAULT_WORKERS,
              folds: FoldSolve = DEFAULT_FOLDS, converged_fe=None) -> Calibration:
    """Calibrate from the database at ``db_path``; write the coefficient file and the report.
    ``converged_fe``: a ``fem/increments.py`` file whose re-run first loadings replace the runs'
    own (:func:`replace_first_loading`; recorded in the file's ``fe_dataset``)."""
    t0 = time.perf_counter()
    from spherecontact.data import Database

    with _content_hash_aside(db_path) as content_hash:
        db = Database(db_path)  # opened once: listing its entries reads every run's attributes
        runs, source = load_runs(db_path, include_stopped, db=db, content_hash=False)
        if converged_fe is not None:
            runs, replaced = replace_first_loading(runs, [r["key"] for r in source["runs"]], converged_fe)
            source["first_loading_replaced"] = {"path": source_path(converged_fe), "runs": len(replaced)}
        two = two_body_runs(db)
        pairs = load_pairs(db_path, runs=two)
        source["pairs"] = [c.name for c in pairs]
        read_s = time.perf_counter() - t0
        cal = calibrate_runs(runs, candidates=candidates, source=source, workers=workers, pairs=pairs,
                             elastic_sphere=ELASTIC_SPHERE,
                             cycle_runs=runs + [(f"{r.case} [{r.key}]", run) for r, run in two],
                             folds=folds)
        cal.source["content_hash"] = content_hash()
    cal.timings["read_s"] = read_s
    if out is not None:
        write_json(out, coefficient_file(cal))
    if report_dir is not None:
        from .report import write_report

        t = time.perf_counter()
        write_report(cal, report_dir)
        cal.timings["report_s"] = time.perf_counter() - t
    return cal
