"""Calibration internals: fast paths equal the plain ones, workers do not change results,
the misfit breakdown and the noise floor."""

import math

import numpy as np
import pytest
from test_calibration import KNOWN_CO, SMALL, synthetic_runs

from spherecontact.calibration import fit as fitmod
from spherecontact.calibration.crossval import cross_validate, cross_validate_many, fold_tasks, material_folds
from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.diagnostics import breakdown, noise_floor
from spherecontact.calibration.fit import errors, fit
from spherecontact.calibration.forms import FORMS, predict
from spherecontact.calibration.workers import Workers


@pytest.fixture(scope="module")
def small_ds():
    return build_dataset(synthetic_runs(SMALL, noise=0.002))


@pytest.mark.parametrize("name", sorted(FORMS))
def test_unchecked_coefficients_equal_the_validated_ones(name):
    form = FORMS[name]
    lo, hi = form.bounds()
    rng = np.random.default_rng(7)
    for _ in range(10):
        p = lo + (hi - lo) * rng.random(form.n_params)
        assert form.coefficients_unchecked(p) == form.coefficients(p)


def test_residuals_with_memoised_parts_equal_a_fresh_evaluation(small_ds):
    """The residual function caches penalties and ``predict`` memoises half-space parts:
    a Jacobian-like sweep (one parameter moved at a time) gives the uncached values."""
    form = FORMS["smooth2_ld3"]
    f = fitmod.Residuals(form, small_ds)
    p0 = form.start()
    for i in range(form.n_params):
        for step in (1e-3, -2e-3):
            p = p0.copy()
            p[i] += step
            co = form.coefficients(p)
            pp, cc = predict(build_dataset_like(small_ds), co)
            rc = np.log(cc / small_ds.c2)   # F and a at the FE's approach (fit.py docstring)
            want = np.concatenate([np.log(pp / small_ds.p_m) + small_ds.slope_F * rc,
                                   small_ds.slope_a * rc,
                                   fitmod.monotonicity_penalty(co), fitmod.collapse_penalty(co),
                                   fitmod.finite_size_penalty(co)])
            np.testing.assert_array_equal(f(p), np.where(np.isfinite(want), want, 10.0))


def build_dataset_like(ds):
    """A copy of ``ds`` with an empty cache (no memoised parts)."""
    return ds.subset(range(len(ds.curves)))


def test_workers_give_the_same_fits_and_folds(small_ds):
    full = fit(small_ds, FORMS["smooth"])
    serial = cross_validate(small_ds, full)
    with Workers(small_ds, 2) as pool:
        fits = pool.map(fit, [(FORMS["smooth"],), (FORMS["seed"],)])
        parallel = cross_validate_many(small_ds, [full], workers=pool)[0]
    np.testing.assert_array_equal(fits[0].params, full.params)
    assert fits[0].coeff_dict == full.coeff_dict
    for a, b in zip(serial.folds, parallel.folds, strict=True):
        assert a.group == b.group
        np.testing.assert_array_equal(a.params, b.params)
        for q in ("H_bar", "c2"):
            np.testing.assert_array_equal(a.errors[q], b.errors[q])


def test_folds_queued_behind_their_fit_are_the_serial_ones(small_ds):
    """``Workers.run_then``: each form's folds start when its own fit is known (the calibration
    queues them so); fits and folds are those of the serial run, in submission order."""
    forms = (FORMS["smooth"], FORMS["seed"])
    with Workers(small_ds, 2) as pool:
        fits, folds = pool.run_then([(fit, (f,)) for f in forms], lambda i, r: fold_tasks(small_ds, r))
    for form, got, got_folds in zip(forms, fits, folds, strict=True):
        full = fit(small_ds, form)
        np.testing.assert_array_equal(got.params, full.params)
        serial = cross_validate(small_ds, full)
        assert [f.materials for f in got_folds] == material_folds(small_ds.groups)
        for a, b in zip(serial.folds, got_folds, strict=True):
            np.testing.assert_array_equal(a.params, b.params)
            np.testing.assert_array_equal(a.errors["F"], b.errors["F"])


def _size_times(ds, k):
    return ds.size * k


def test_submitted_tasks_run_while_more_are_queued_and_come_back_in_order(small_ds):
    """``Workers.submit``: the calibration queues the chosen form's follow-up work and goes on
    queueing its check; the results are those of ``run``, in submission order, with a pool and
    without one (then they run when asked for)."""
    tasks = [(_size_times, (k,)) for k in range(6)]
    with Workers(small_ds, 2) as pool:
        first = pool.submit(tasks)
        second = pool.run(tasks[:3])  # queued behind the first batch
        assert first() == pool.run(tasks) and second == [small_ds.size * k for k in range(3)]
    lazy = Workers(small_ds, 1).submit(tasks)
    assert lazy() == [small_ds.size * k for k in range(6)]


def test_subset_is_the_dataset_built_from_its_curves(small_ds):
    """A fold's dataset is sliced from the full one (``Dataset.subset``): the same arrays as
    building it from the fold's curves, in the order of the runs asked for."""
    import dataclasses

    from spherecontact.calibration.dataset import build_dataset_from_curves
    for keep in ([0, 2, 3], [3, 1], list(range(len(small_ds.curves)))[::-1]):
        sub = small_ds.subset(keep)
        ref = build_dataset_from_curves([small_ds.curves[i] for i in keep])
        assert sub.curves == ref.curves
        for f in dataclasses.fields(ref):
            if f.name not in ("curves", "cache", "elastic_sphere"):
                np.testing.assert_array_equal(getattr(sub, f.name), getattr(ref, f.name), err_msg=f.name)
    with pytest.raises(ValueError, match="no calibration points"):
        small_ds.subset([])


def test_breakdown_shares_add_up_and_bands_cover_every_point(small_ds):
    full = fit(small_ds, FORMS["smooth"])
    b = breakdown(small_ds, full.coeffs, full.errors)
    assert {"level", "a/R", "h/R", "hardening", "E/σY", "scene", "end of run"} <= set(b)
    for rows in b.values():
        assert sum(r["points"] for r in rows) == small_ds.size
        assert sum(r["H_share"] for r in rows) == pytest.approx(1.0, abs=1e-12)
        assert sum(r["c2_share"] for r in rows) == pytest.approx(1.0, abs=1e-12)
        for r in rows:
            assert r["H_max"] >= r["H_rms"] >= 0.0 and r["c2_max"] >= r["c2_rms"] >= 0.0


def test_noise_floor_measures_the_scatter_of_the_points():
    clean = build_dataset(synthetic_runs(SMALL))
    nz0 = noise_floor(clean)
    assert nz0["H_bar"] < 3e-4 and nz0["c2"] < 3e-4  # smooth curves: only the curvature
    assert nz0["points"] > 0.8 * clean.size
    noisy = build_dataset(synthetic_runs(SMALL, noise=0.002))
    nz = noise_floor(noisy)
    # 0.2 % on each increment of F and a, found again on the increments (a leave-one-out
    # error is a little above the scatter itself)
    assert 0.0018 < nz["F_increment"] < 0.0026 and 0.0018 < nz["a_increment"] < 0.0026
    # the floor is what the generating coefficients (the exact law) score on the noisy points
    e = errors(noisy, KNOWN_CO)
    for q in ("H_bar", "c2"):
        assert nz[q] == pytest.approx(fitmod.rms(e[q]), rel=0.25), q


@pytest.mark.parametrize("name", sorted(FORMS))
def test_jacobian_equals_central_differences(name):
    """The fit's Jacobian (data rows analytic, penalty rows forward differences) against
    central differences of the residual, at the start values and at a random interior point,
    with an elastic run and the Level I anchor rows; every parameter of every form is written
    out, so the whole residual is evaluated once per Jacobian."""
    import dataclasses
    import math

    from spherecontact.model import Material

    elastic = [("flat-elastic", Material.elastic(200.0, 0.3), math.inf)]  # Hertz rows (p_m)
    ds = dataclasses.replace(build_dataset(synthetic_runs(SMALL + elastic, noise=0.002)),
                             elastic_sphere=fitmod.ELASTIC_SPHERE)
    form = FORMS[name]

    class Counted(fitmod.Residuals):
        calls = 0

        def __call__(self, params):
            Counted.calls += 1
            return super().__call__(params)

    res = Counted(form, ds)
    lo, hi = form.bounds()
    for x in (form.start(), lo + (hi - lo) * np.random.default_rng(3).uniform(0.3, 0.7, lo.size)):
        Counted.calls = 0
        J = res.jacobian(x)
        assert Counted.calls == 1
        for j in range(form.n_params):
            h = 1e-6 * max(1.0, abs(x[j]))
            xp, xm = x.copy(), x.copy()
            xp[j] += h
            xm[j] -= h
            cd = (res(xp) - res(xm)) / (2.0 * h)
            scale = max(1e-3, float(np.abs(cd).max()))
            assert np.abs(J[:, j] - cd).max() < 2e-5 * scale, (name, form.names[j])


def test_fold_solve_is_checked_and_reaches_the_folds(small_ds):
    """``FoldSolve`` (``--fold-nfev``, ``--fold-tol``): bad values are refused naming the parameter;
    a fold capped at one evaluation stays at the full fit, a solved one moves away from it."""
    from spherecontact.cli import main as _main

    def calibrate_cli(argv):
        return _main(["calibrate", *argv])

    from spherecontact.calibration.crossval import FoldSolve, fold_fit

    for bad in ({"nfev": 0}, {"nfev": 2.5}, {"tol": 0.5}, {"tol": 0.0}):
        with pytest.raises(ValueError, match="fold (nfev|tol)"):
            FoldSolve(**bad)
    assert calibrate_cli(["--fold-nfev", "0", "--db", "nowhere.h5"]) == 2
    assert calibrate_cli(["--fold-tol", "1", "--db", "nowhere.h5"]) == 2
    full = fit(small_ds, FORMS["smooth"])
    group = (small_ds.groups[0],)
    capped = fold_fit(small_ds, full.form, full.params, full.coeff_dict, group, 1)
    solved = fold_fit(small_ds, full.form, full.params, full.coeff_dict, group, 200, 1e-10)
    assert np.max(np.abs(capped.params - full.params)) < np.max(np.abs(solved.params - full.params))


# ------------------------------------------------------------------ the ceiling of smooth terms
def _exact_ds():
    from test_calibration import synthetic_runs as runs

    return build_dataset(runs(SMALL, noise=0.0))


def test_ceiling_removes_a_misfit_that_is_smooth_in_xi():
    """A misfit of H̄ that is a smooth function of ξ = a/R + s n is taken out in-sample and held
    out (folds of materials); an exact dataset scores ~0 (its resampling) before any correction."""
    import dataclasses

    import calibration_ceiling as ce

    from spherecontact.calibration.forms import point_inputs

    ds = _exact_ds()
    assert ce.ceiling(ds, KNOWN_CO)["model"]["F_max_pct"] < 0.2  # the resampling on the ln h grid
    xi = ds.x_R + ce.SHIFT * point_inputs(ds, KNOWN_CO)[0]
    bent = dataclasses.replace(ds, p_m=ds.p_m * np.exp(0.04 * np.sin(6.0 * xi)), cache={})
    r = ce.ceiling(bent, KNOWN_CO)
    assert r["model"]["F_rms_pct"] > 1.0
    assert r["in_sample"]["F_rms_pct"] < 0.1 * r["model"]["F_rms_pct"]
    assert r["held_out"]["F_rms_pct"] < 0.3 * r["model"]["F_rms_pct"]
    assert r["parameters"] == 2 * 4 * (8 + 4)


def test_ceiling_cannot_remove_a_misfit_of_each_run_alone():
    """Offsets drawn per run (not a function of the variables) stay: what the ceiling reports
    when the misfit is not smooth in them."""
    import dataclasses

    import calibration_ceiling as ce

    ds = _exact_ds()
    offset = np.random.default_rng(3).choice([-0.03, 0.03], len(ds.curves))
    bent = dataclasses.replace(ds, p_m=ds.p_m * np.exp(offset[ds.run]), cache={})
    r = ce.ceiling(bent, KNOWN_CO)
    assert r["held_out"]["F_rms_pct"] > 0.5 * r["model"]["F_rms_pct"]


def test_step_positions_and_law_recover_a_planted_step():
    """Dips of d ln a/d ln h planted at a/R = 0.55 − 0.7 n are found and their law recovered."""
    import dataclasses

    import calibration_ceiling as ce

    from spherecontact.calibration.forms import point_inputs

    ds = _exact_ds()
    n = point_inputs(ds, KNOWN_CO)[0]
    x = np.linspace(0.0, 0.7, ds.size)  # every run's points spread over 0–0.7 in a/R
    for i in range(len(ds.curves)):
        m = ds.run == i
        x[m] = np.linspace(0.01, 0.7, m.sum())
    slope = 0.5 - 0.18 * np.exp(-(((x - (0.55 - 0.7 * n)) / 0.04) ** 2))
    planted = dataclasses.replace(ds, x_R=x, slope_a=slope, cache={})
    rows = ce.step_positions(planted, KNOWN_CO, lo=0.2, reach=0.6)
    flats = [c for c in ds.curves if math.isinf(c.indenter_radius)]
    assert len(rows) == len(flats) >= 4
    law = ce.step_law(rows)
    assert law["x0"] == pytest.approx(0.55, abs=0.01) and law["x_n"] == pytest.approx(-0.7, abs=0.05)


def test_flow_curvature_sign_and_the_extra_modifiers():
    """κ is 0 for perfect plasticity, < 0 where a curve saturates (a Voce curve past its
    linear start), > 0 where linear hardening turns from flat to slope 1; ``extra`` adds its
    columns and rejects an unknown name."""
    import dataclasses

    import calibration_ceiling as ce

    from spherecontact.model import Material

    ds = _exact_ds()
    eps = np.linspace(0.0, 2.0, 400)
    voce = Material.from_table(200.0, 0.3, eps, 1.0 + 2.0 * (1.0 - np.exp(-8.0 * eps)))
    cases = {"pp": Material(200.0, 0.3, 1.0), "voce": voce, "linear": Material(200.0, 0.3, 1.0, 5.0, 1.0)}
    for name, mat in cases.items():
        one = dataclasses.replace(ds, curves=[dataclasses.replace(c, material=mat) for c in ds.curves],
                                  cache={})
        k = ce.flow_curvature(one, KNOWN_CO)
        big = one.x_rho > 0.5  # ε_rep ≳ 0.04: Voce saturating, linear hardening past its knee
        assert big.sum() >= 10
        if name == "pp":
            assert np.all(k == 0.0)
        elif name == "voce":
            assert np.all(k[big] < -0.05)
        else:
            assert np.all(k[big] > 0.02)
    cols = ce.basis(ds, KNOWN_CO).shape[1]
    assert ce.basis(ds, KNOWN_CO, extra=("curvature",)).shape[1] == cols * 5 // 4
    assert ce.basis(ds, KNOWN_CO, extra=ce.EXTRA).shape[1] == cols * 10 // 4
    with pytest.raises(ValueError, match="extra must name"):
        ce.basis(ds, KNOWN_CO, extra=("wiggle",))


def test_learning_curve_rows_and_a_smooth_misfit_learnt_from_part_of_the_materials():
    import dataclasses

    import calibration_ceiling as ce

    from spherecontact.calibration.forms import point_inputs

    ds = _exact_ds()
    xi = ds.x_R + ce.SHIFT * point_inputs(ds, KNOWN_CO)[0]
    bent = dataclasses.replace(ds, p_m=ds.p_m * np.exp(0.04 * np.sin(6.0 * xi)), cache={})
    model_rms = ce.ceiling(bent, KNOWN_CO)["model"]["F_rms_pct"]
    rows = ce.learning_curve(bent, KNOWN_CO, folds=(2, 4))
    assert [r["folds"] for r in rows] == [2, 4] and [r["share_fitted"] for r in rows] == [0.5, 0.75]
    assert all(r["F_rms_pct"] < 0.3 * model_rms for r in rows)
    offsets = np.random.default_rng(3).choice([-0.03, 0.03], len(ds.curves))
    noisy = dataclasses.replace(ds, p_m=ds.p_m * np.exp(offsets[ds.run]), cache={})
    assert all(r["F_rms_pct"] > 0.5 * ce.ceiling(noisy, KNOWN_CO)["model"]["F_rms_pct"]
               for r in ce.learning_curve(noisy, KNOWN_CO, folds=(2, 4)))


def test_tensor_basis_shape_and_a_misfit_that_couples_xi_and_stiffness():
    """The tensor table follows a misfit whose shape in ξ changes with E/σY (a product the
    modifiers of ``basis`` hold only linearly)."""
    import dataclasses

    import calibration_ceiling as ce

    from spherecontact.calibration.forms import point_inputs

    ds = _exact_ds()
    X = ce.tensor_basis(ds, KNOWN_CO)
    assert X.shape == (ds.size, 12 * 4 * 4 * 2 * 2 * 2)
    n = point_inputs(ds, KNOWN_CO)[0]
    xi = ds.x_R + ce.SHIFT * n
    sy = np.asarray([c.material.sigma_y for c in ds.curves])[ds.run]
    e = np.log10(ds.E_prime / sy)
    bent = dataclasses.replace(ds, p_m=ds.p_m * np.exp(0.04 * np.sin(6.0 * xi) * (e - 2.5) ** 2 / 2),
                               cache={})
    r = ce.ceiling(bent, KNOWN_CO, ridge=ce.TENSOR_RIDGE, design=ce.tensor_basis)
    assert r["parameters"] == 2 * X.shape[1] and r["model"]["F_rms_pct"] > 0.5
    assert r["in_sample"]["F_rms_pct"] < 0.2 * r["model"]["F_rms_pct"]
    assert ce.ceiling(bent, KNOWN_CO)["in_sample"]["F_rms_pct"] > 0.3 * r["model"]["F_rms_pct"]
