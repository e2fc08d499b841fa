"""Calibration stage: dataset extraction, fit recovery, stability, errors, reproducibility."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from calibration_synthetic import (
    CALIBRATION_CASES,
    hertz_result,
    model_result,
    write_database,
)

from spherecontact.calibration.crossval import FOLDS, cross_validate, material_folds
from spherecontact.calibration.dataset import build_dataset, quantities, resample
from spherecontact.calibration.fit import Residuals, fit, rms
from spherecontact.calibration.forms import FORMS, predict, predict_exact
from spherecontact.calibration.pipeline import calibrate, calibrate_runs, coefficient_file, load_runs
from spherecontact.fem.io import Run
from spherecontact.model import Material
from spherecontact.model.cap import cap_gap_factor
from spherecontact.model.coefficients import Coefficients, load_coefficients

ROOT = Path(__file__).resolve().parents[1]
SHIPPED_DB = ROOT / "data" / "reference_v2.h5"

#: a known coefficient set (the structure of the smooth form) the synthetic runs come from
KNOWN = {
    "schema_version": 2, "source": "calibration", "provenance": {}, "beta": 0.25,
    "counter_cap": "exact",  # the geometry the calibration's c² is read with (``dataset``)
    "Lambda_I": 2.5, "Lambda_III": 150.0,
    "H_bar_III": {"prefactor": 2.9, "exp_poly": [0.3]},
    "c2_III": {"prefactor": 1.35, "exp_poly": [-0.8]},
    "level_II": {"H_bar_shape": [0.5], "c2_shape": [-0.5], "smooth": True},
    "hardening_exponent": {"method": "secant_loglog", "eps_lo": 0.01, "eps_hi": 0.1},
    "finite_size": {"ratio": "a_over_R", "H_bar": [0.3], "c2": [0.1], "H_bar_plastic": [0.4],
                    "c2_plastic": [0.0]},
    "collapse": {"H_bar": {"prefactor": 1.2, "exponent": 0.8, "x_poly": [0.0], "exp_poly": [0.5],
                           "z_poly": []},
                 "c2": {"prefactor": 0.9, "exponent": 0.0, "x_poly": [-0.3], "exp_poly": [],
                        "z_poly": []},
                 "sharpness": 2.0},
    "references": {},
}
KNOWN_CO = Coefficients.from_dict(KNOWN)
#: a small subset of the campaign grid (fast end-to-end tests)
SMALL = [c for c in CALIBRATION_CASES if c[0] in (
    "flat-E10", "flat-E100", "flat-E1000", "flat-E10000", "flat-K2-n0.3-E100",
    "flat-K2-n0.5-E1000", "sphere-E100", "sphere-K2-n0.3-E300")]



def calibrate_cli(argv: list[str]) -> int:
    """``spherecontact calibrate ARGV``."""
    from spherecontact.cli import main

    return main(["calibrate", *argv])

def as_run(res) -> Run:
    """A RunResult as the reader's Run (what the database returns)."""
    return Run(inputs=res.inputs, curves=dict(res.curves), status=res.status, reason=res.reason,
               provenance={"date_utc": "2026-01-01T00:00:00Z"}, residuals=res.residuals,
               profile_r=res.profile_r, profile_p=res.profile_p, profile_gap=res.profile_g,
               mesh=res.final)


def synthetic_runs(cases, noise=0.0):
    return [(case, as_run(model_result(m, KNOWN_CO, indenter_radius=Ri, noise=noise, seed=i)))
            for i, (case, m, Ri) in enumerate(cases)]


@pytest.fixture(scope="module")
def small_db(tmp_path_factory):
    p = tmp_path_factory.mktemp("db") / "synthetic.h5"
    write_database(p, [(c, model_result(m, KNOWN_CO, indenter_radius=Ri, noise=0.002, seed=i))
                       for i, (c, m, Ri) in enumerate(SMALL)])
    return p


# ------------------------------------------------------------------------------ dataset
@pytest.mark.parametrize("indenter_radius", [math.inf, 1.0, 3.0])
def test_hertz_run_gives_hertz_levels(indenter_radius):
    m = Material(E=300.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    run = as_run(hertz_result(m, radius=1.0, indenter_radius=indenter_radius))
    ds = build_dataset([("hertz", run)])
    rho = 1.0 if math.isinf(indenter_radius) else indenter_radius / (1.0 + indenter_radius)
    np.testing.assert_allclose(ds.rho, rho)
    for beta in (0.2, 0.32):
        q = quantities(ds, beta)
        np.testing.assert_allclose(q["H_bar"], 4.0 * q["Lambda"] / (3.0 * math.pi), rtol=1e-10)
        np.testing.assert_allclose(q["sigma_rep"], m.flow_stress(beta * ds.a / rho), rtol=1e-12)
    # a² = R* h with the paraboloid: c² = G/2, G the sphere's exact cap over it (1 on a flat)
    G = cap_gap_factor(ds.a, 1.0 / rho, indenter_radius)[0]
    np.testing.assert_allclose(ds.c2, 0.5 * G, rtol=1e-10)
    assert (G == 1.0).all() if math.isinf(indenter_radius) else 1.0 < G.min() < G.max() < 1.03
    assert ds.a.min() >= 0.02 - 1e-12  # resolution filter at the default mesh density
    # grid: 16 nodes per decade of h, shared by every run, plus the final approach
    lnh = np.log(ds.h[:-1])
    np.testing.assert_allclose(np.diff(lnh), math.log(10.0) / 16, rtol=1e-9)
    np.testing.assert_allclose(lnh / (math.log(10.0) / 16), np.round(lnh / (math.log(10.0) / 16)),
                               atol=1e-9)
    assert ds.h[-1] == pytest.approx(0.3, rel=1e-12)


def test_resample_is_exact_for_power_laws_and_averages_a_staircase():
    h = np.geomspace(1e-3, 0.3, 400)
    F, a = 2.0 * h**1.5, 0.7 * h**0.5
    g = np.log(np.geomspace(2e-3, 0.2, 30))
    Fg, ag = resample(h, F, a, g)
    np.testing.assert_allclose(Fg, 2.0 * np.exp(g) ** 1.5, rtol=1e-12)
    np.testing.assert_allclose(ag, 0.7 * np.exp(g) ** 0.5, rtol=1e-12)
    # a ±0.5 % staircase (period of a few grid steps) shrinks by the local fit
    step = 1.0 + 0.005 * np.sign(np.sin(np.log(h) * 40.0))
    Fs, _ = resample(h, F * step, a, g)
    assert rms(Fs / (2.0 * np.exp(g) ** 1.5) - 1.0) < 0.5 * rms(step - 1.0)


def test_vectorised_prediction_equals_the_model():
    ds = build_dataset(synthetic_runs(SMALL))
    for co in (KNOWN_CO, FORMS["seed"].coefficients(FORMS["seed"].start()),
               FORMS["poly"].coefficients(FORMS["poly"].start() + 0.05)):
        p1, c1 = predict(ds, co)
        p2, c2 = predict_exact(ds, co)
        np.testing.assert_allclose(p1, p2, rtol=1e-13)
        np.testing.assert_allclose(c1, c2, rtol=1e-13)
    # the data generated by the model are reproduced by the model (dataset round trip; the
    # local linear resampling in ln-ln has a curvature bias of a few 1e-4 at most)
    p, c = predict(ds, KNOWN_CO)
    assert np.max(np.abs(p / ds.p_m - 1)) < 1e-3 and np.max(np.abs(c / ds.c2 - 1)) < 1e-3
    assert rms(p / ds.p_m - 1) < 2e-4 and rms(c / ds.c2 - 1) < 2e-4


# ------------------------------------------------------------------------------ fit
def test_fit_recovers_known_coefficients():
    ds = build_dataset(synthetic_runs(CALIBRATION_CASES))
    r = fit(ds, FORMS["smooth"])
    s = r.summary()
    assert s["H_bar"]["rms"] < 1e-4 and s["c2"]["rms"] < 1e-4
    co = r.coeff_dict
    assert co["beta"] == pytest.approx(0.25, rel=0.01)
    assert co["Lambda_I"] == pytest.approx(2.5, rel=0.01)
    assert co["Lambda_III"] == pytest.approx(150.0, rel=0.02)
    assert co["H_bar_III"]["prefactor"] == pytest.approx(2.9, rel=0.002)
    assert co["c2_III"]["prefactor"] == pytest.approx(1.35, rel=0.002)
    assert co["H_bar_III"]["exp_poly"][0] == pytest.approx(0.3, abs=0.02)
    assert co["c2_III"]["exp_poly"][0] == pytest.approx(-0.8, abs=0.02)
    assert co["level_II"]["H_bar_shape"][0] == pytest.approx(0.5, abs=0.03)
    assert co["level_II"]["c2_shape"][0] == pytest.approx(-0.5, abs=0.03)
    assert co["finite_size"]["H_bar"][0] == pytest.approx(0.3, abs=0.02)
    assert co["collapse"]["H_bar"]["prefactor"] == pytest.approx(1.2, rel=0.02)
    assert co["collapse"]["H_bar"]["exponent"] == pytest.approx(0.8, rel=0.02)
    assert co["collapse"]["sharpness"] == pytest.approx(2.0, rel=0.05)
    assert r.at_bounds == []


def _prediction_shift(ds, co_a, co_b) -> float:
    """Largest relative change of predicted H̄ or c² between two coefficient sets."""
    pa, ca = predict(ds, co_a)
    pb, cb = predict(ds, co_b)
    return float(max(np.max(np.abs(pb / pa - 1)), np.max(np.abs(cb / ca - 1))))


#: stability tolerances when one material is dropped: largest change of the predicted H̄, c²
#: over all points (synthetic data with 0.2 % noise), and of the Level III values
STABLE_SHIFT_SYNTH = 0.005
STABLE_III = 0.01


def test_dropping_a_material_keeps_the_fit_stable_synthetic():
    runs = synthetic_runs(CALIBRATION_CASES, noise=0.002)
    ds = build_dataset(runs)
    full = fit(ds, FORMS["smooth"])
    for g in ("E/sy=1000 nu=0.3 K/sy=2 n=0.5", "E/sy=300 nu=0.3", "E/sy=10 nu=0.3"):
        assert g in ds.groups
        part = fit(ds.without_groups(g), FORMS["smooth"], start=full.params)
        assert _prediction_shift(ds, full.coeffs, part.coeffs) < STABLE_SHIFT_SYNTH, g
        for k in ("H_bar_III", "c2_III"):
            assert part.coeff_dict[k]["prefactor"] == pytest.approx(
                full.coeff_dict[k]["prefactor"], rel=STABLE_III)


#: on the FE database: dropping one material may move the predictions by at most this much
#: (largest relative change over all calibration points)
STABLE_SHIFT_FE = 0.05
STABLE_RMS_FE = 0.01


@pytest.mark.skipif(not SHIPPED_DB.exists(), reason="data/reference_v2.h5 (the FE reference "
                    "database) is not present; the synthetic-database version of this test runs")
def test_dropping_a_material_keeps_the_fit_stable_on_the_shipped_database():
    coeffs = load_coefficients(ROOT / "model" / "coefficients.json")
    if coeffs.source != "calibration":
        pytest.skip("model/coefficients.json is not a calibration yet")
    runs, source = load_runs(SHIPPED_DB)
    if source["calibration_runs_hash"] != coeffs.provenance.get("fe_dataset", {}).get(
            "calibration_runs_hash"):
        pytest.skip("model/coefficients.json was calibrated on other calibration runs")
    ds = build_dataset(runs)
    form = FORMS[coeffs.provenance["form"]["name"]]
    full = fit(ds, form)
    # the material of the middle of the perfectly plastic range and a linear-hardening one
    for g in ("E/sy=316 nu=0.3", "E/sy=1000 nu=0.3 K/sy=5 n=1"):
        assert g in ds.groups, g
        part = fit(ds.without_groups(g), form, start=full.params)
        pa, ca = predict(ds, full.coeffs)
        pb, cb = predict(ds, part.coeffs)
        shift = np.concatenate([pb / pa - 1, cb / ca - 1])
        assert np.max(np.abs(shift)) < STABLE_SHIFT_FE, g
        assert rms(shift) < STABLE_RMS_FE, g


def test_cross_validation_on_synthetic_data_is_small():
    ds = build_dataset(synthetic_runs(SMALL, noise=0.002))
    full = fit(ds, FORMS["smooth"])
    cv = cross_validate(ds, full)
    # seven materials dealt into FOLDS = 5 folds: each material held out once, every point once
    assert len(ds.groups) == 7 and len(cv.folds) == FOLDS
    held = [m for f in cv.folds for m in f.materials]
    assert sorted(held) == ds.groups
    assert sum(f.n_points for f in cv.folds) == ds.size
    # every fold is refitted: its parameters and predictions move away from the full fit's
    for f in cv.folds:
        assert np.max(np.abs(f.params - full.params)) > 1e-6 and f.shift_max > 1e-6, f.group
    p = cv.pooled()
    assert p["H_bar"]["rms"] < 0.01 and p["c2"]["rms"] < 0.01


def test_materials_are_dealt_into_folds_in_turn():
    assert material_folds(list("abcdefg"), 5) == [("a", "f"), ("b", "g"), ("c",), ("d",), ("e",)]
    assert material_folds(["a", "b"], 5) == [("a",), ("b",)]


# ------------------------------------------------------------------------------ database errors
def test_missing_corrupt_and_empty_databases_get_clear_errors(tmp_path, small_db, capsys):
    missing = tmp_path / "absent.h5"
    with pytest.raises(FileNotFoundError):
        calibrate(missing)
    assert calibrate_cli(["--db", str(missing), "--out", str(tmp_path / "c.json"), "--report", ""]) == 2
    assert "not found" in capsys.readouterr().err
    garbage = tmp_path / "garbage.h5"
    garbage.write_bytes(b"this is not an HDF5 file\n" * 100)
    with pytest.raises(ValueError, match="garbage.h5"):
        calibrate(garbage)
    truncated = tmp_path / "truncated.h5"
    data = small_db.read_bytes()
    truncated.write_bytes(data[: len(data) // 3])
    with pytest.raises(ValueError, match="truncated.h5"):
        calibrate(truncated)
    assert calibrate_cli(["--db", str(truncated), "--out", str(tmp_path / "c.json"), "--report", ""]) == 2
    assert "truncated.h5" in capsys.readouterr().err
    # a valid database without calibration runs
    empty = tmp_path / "empty.h5"
    m = Material(E=100.0, nu=0.3, sigma_y=1.0)
    write_database(empty, [("validation-only", model_result(m, KNOWN_CO))], set_name="validation")
    with pytest.raises(ValueError, match="no converged calibration runs"):
        calibrate(empty)
    assert calibrate_cli(["--db", str(empty), "--out", str(tmp_path / "c.json"), "--report", ""]) == 2
    assert "no converged calibration runs" in capsys.readouterr().err
    assert not (tmp_path / "c.json").exists()


# ------------------------------------------------------------------------------ end to end
def test_cli_writes_a_loadable_file_byte_identical_on_rerun(tmp_path, small_db, monkeypatch):
    db = tmp_path / "db.h5"
    shutil.copy(small_db, db)
    out1, out2 = tmp_path / "c1.json", tmp_path / "c2.json"
    assert calibrate_cli(["--db", str(db), "--out", str(out1), "--report", str(tmp_path / "rep"),
                     "--forms", "seed,smooth"]) == 0
    assert calibrate_cli(["--db", str(db), "--out", str(out2), "--report", "", "--forms", "seed,smooth",
                     "--workers", "1"]) == 0
    assert out1.read_bytes() == out2.read_bytes()  # also with the fits on 1 or 2 processes
    d = json.loads(out1.read_text())
    assert d["source"] == "calibration" and d["schema_version"] == 2
    prov = d["provenance"]
    assert prov["created"] == "2026-01-01"  # from the database, not the wall clock
    assert len(prov["fe_dataset"]["content_hash"]) == 64
    assert len(prov["fe_dataset"]["calibration_runs_hash"]) == 64
    assert set(prov["fit_residuals"]) == {"H_bar", "c2", "F", "a"}
    assert set(prov["fit_residuals"]["c2"]) == {"rms", "max"}
    assert set(prov["cross_validation"]) == {"seed", "smooth"}
    assert prov["form"]["name"] == "smooth"  # the data come from the smooth form
    assert prov["fit_residuals"]["H_bar"]["rms"] < 0.005
    monkeypatch.setenv("SPHERECONTACT_COEFFICIENTS", str(out1))
    co = load_coefficients()
    assert co.source == "calibration" and co.has_collapse
    rep = (tmp_path / "rep" / "index.md").read_text()
    for png in ("hbar_c2_lambda.png", "hbar_c2_aR.png", "residuals.png", "model_error.png",
                "cv_parameters.png"):
        assert (tmp_path / "rep" / png).stat().st_size > 10_000
        assert png in rep
    assert "cross-validation" in rep and "| **smooth** |" in rep


def test_pipeline_checks_monotonicity_and_reports_model_error():
    cal = calibrate_runs(synthetic_runs(SMALL), candidates=("smooth",), cross_validation=False,
                         large_deformation_options=False)
    assert cal.chosen == "smooth"
    assert len(cal.checks) > 100 and all(c.ok for c in cal.checks)
    for e in cal.run_errors:  # the model reproduces its own curves
        assert e.F_max < 2e-3 and e.a_max < 2e-3, e.key
    d = coefficient_file(cal)
    assert Coefficients.from_dict(d).source == "calibration"


def test_errors_at_the_fe_approach_match_the_model_curves_to_first_order():
    """``fit.errors`` F and a: the error of the model's F(h), a(h) at the FE's approaches,
    from the errors of p_m and c² at its contact radii (first order): against the curves of
    a perturbed coefficient set evaluated at the same h."""
    from spherecontact.calibration.fit import errors
    from spherecontact.model import Sphere, contact

    cases = SMALL[:4] + SMALL[-2:]
    ds = build_dataset(synthetic_runs(cases))
    other = KNOWN_CO.replace(beta=0.27, Lambda_I=2.4, Lambda_III=180.0,
                             H_bar_III={"prefactor": 2.97, "exp_poly": [0.3]},
                             c2_III={"prefactor": 1.39, "exp_poly": [-0.8]})
    e = errors(ds, other)
    for i, (case, m, Ri) in enumerate(cases):
        sel = ds.run == i
        st = contact(Sphere(1.0, m), Sphere(Ri, Material.rigid()), ds.h[sel], other)
        exact_F, exact_a = st.F / ds.F[sel] - 1.0, st.a / ds.a[sel] - 1.0
        assert np.max(np.abs(exact_F)) > 0.003, case   # the perturbation is felt
        np.testing.assert_allclose(e["F"][sel], exact_F, atol=2e-3, err_msg=case)
        np.testing.assert_allclose(e["a"][sel], exact_a, atol=1e-3, err_msg=case)


def test_regime_folds_hold_out_whole_regimes_and_predict_them():
    from spherecontact.calibration.crossval import REGIMES, cross_validate_regimes, regime_of

    ds = build_dataset(synthetic_runs(SMALL, noise=0.002))
    labels = {f: {regime_of(c, f) for c in ds.curves} for f in REGIMES}
    assert labels["E/σY decade"] == {"1e1–1e2", "1e2–1e3", "1e3–1e4", "1e4–1e5"}
    assert labels["K/σY"] == {"0", "0–2"} and labels["partner"] == {"flat", "R_i/R 0.5–1.5"}
    full = fit(ds, FORMS["smooth"])
    folds = cross_validate_regimes(ds, full)
    assert len(folds) == sum(len(v) for v in labels.values())
    for f in folds:
        held = [c for c in ds.curves if regime_of(c, f.family) == f.label]
        assert f.runs == len(held) and f.errors["F"].size == sum(c.h.size for c in held)
        assert np.all(np.isfinite(f.errors["F"])), (f.family, f.label)
    # the runs are made by the form itself, so a fold that keeps both scenes and both hardening
    # bands finds it again from the rest and predicts the held-out E/σY decade to the noise (the
    # fold starts from the full fit in the shift from it, fit._solve: started at the full fit in
    # the parameters themselves, trf's first trust radius was ‖x‖ and the fold wandered off, to
    # 5.5 % RMS in F for the decade 1e2–1e3, 4 of the 8 runs, and 38 % for the rigid spheres)
    by = {(f.family, f.label): rms(f.errors["F"]) for f in folds}
    for decade in labels["E/σY decade"]:
        assert by[("E/σY decade", decade)] < 0.005, decade
    # without the hardening runs the data do not determine the hardening terms or β (n = 0 and
    # σ_rep = σ_Y at every training point): their Jacobian columns are exactly zero, so what the
    # fold reports for that regime is the start's hardening terms, not an extrapolation
    keep = [i for i, c in enumerate(ds.curves) if regime_of(c, "K/σY") != "0–2"]
    res = Residuals(FORMS["smooth"], ds.subset(keep))
    J = res.jacobian(full.params)
    names = FORMS["smooth"].names
    free = [names.index(n) for n in ("beta", "H_III_n0", "c2_III_n0", "Hc_n0", "c2c_n0")]
    assert not J[:, free].any()
    assert np.all(np.abs(np.delete(J, free, axis=1)).max(axis=0) > 0.01)
    with pytest.raises(ValueError, match="regime family"):
        regime_of(ds.curves[0], "colour")


def test_monotonicity_checks_on_worker_processes_match_the_serial_ones(monkeypatch):
    """``check_all`` with a pool: the same checks, in the same order, as in this process."""
    from spherecontact.calibration import check
    from spherecontact.calibration.workers import Workers

    co = load_coefficients()
    mats = [Material(E=200.0, nu=0.3, sigma_y=1.0), Material(E=1000.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)]
    pairs = check.grid_pairs(mats)[:7]
    monkeypatch.setattr(check, "grid_pairs", lambda calibration: pairs)
    monkeypatch.setattr(check, "CHUNK", 3)  # three tasks, the last one short
    serial = check.check_all(co, mats)
    with Workers(None, 2) as pool:
        parallel = check.check_all(co, mats, pool)
    assert [c.label for c in serial] == [p[0] for p in pairs]
    assert parallel == serial


def test_chart_labels_are_the_shortest_distinct_tails_of_the_form_names():
    from spherecontact.calibration.report import _short_names

    names = ["seed", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh",
             "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz"]
    assert list(_short_names(names).values()) == ["seed", "…_zn_nl", "…_nl_czh", "…_nl_cz"]
    assert _short_names(["a_b_c", "x_b_c"]) == {"a_b_c": "a_b_c", "x_b_c": "x_b_c"}  # only whole names differ


def test_a_converged_first_loading_replaces_the_run_s_own(small_db, tmp_path):
    """``--converged-fe``: the first loading of a run (h ≤ h_end of the smaller radius) is taken
    from a re-run with finer increments; the rest of the curve is the run's, and the coefficient
    file says how many runs were replaced."""
    from spherecontact.calibration.pipeline import coefficient_file, replace_first_loading
    from spherecontact.fem.increments import smaller_radius

    runs, source = load_runs(small_db, content_hash=False)
    keys = [r["key"] for r in source["runs"]]
    run, key = runs[0][1], keys[0]
    L = smaller_radius(run.inputs)
    hc = np.geomspace(1e-5, 0.01, 40) * L
    curve = {"h": hc.tolist(), "F": (2.0 * hc).tolist(), "a": np.sqrt(hc).tolist()}
    path = tmp_path / "increments_calibration.json"
    path.write_text(json.dumps({"h_end": 0.01, "cases": [{"key": key, "curve": curve}]}))
    new, replaced = replace_first_loading(runs, keys, path)
    assert replaced == [key] and [n for n, _ in new] == [n for n, _ in runs]
    r = new[0][1]
    head = r.h <= 0.01 * L * (1 + 1e-9)
    np.testing.assert_array_equal(r.h[head], hc)
    np.testing.assert_array_equal(r.F[head], 2.0 * hc)
    tail = np.asarray(run.h) > 0.01 * L * (1 + 1e-9)
    np.testing.assert_array_equal(r.F[~head], np.asarray(run.F)[tail])
    assert r.inputs is run.inputs and new[1][1] is runs[1][1]
    cal = calibrate(small_db, candidates=("smooth",), converged_fe=path, workers=1)
    assert coefficient_file(cal)["provenance"]["fe_dataset"]["first_loading_replaced"]["runs"] == 1
