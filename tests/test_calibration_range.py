"""The calibrated range written by calibration (``provenance["calibrated_range"]``) matches
the calibration records it was computed from."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from calibration_synthetic import CALIBRATION_CASES, model_result
from test_calibration import KNOWN_CO, SMALL, as_run

from spherecontact.calibration.dataset import build_dataset, quantities
from spherecontact.calibration.pipeline import (
    calibrate_runs,
    calibrated_range,
    coefficient_file,
    load_runs,
)
from spherecontact.model.coefficients import Coefficients
from spherecontact.model.single import effective_exponent, hardening_magnitude

ROOT = Path(__file__).resolve().parents[1]
SHIPPED_DB = ROOT / "data" / "reference_v2.h5"
SHIPPED = ROOT / "model" / "coefficients.json"
#: the keys ``model/`` reads, in this shape (written by calibration)
KEYS = {"E_over_sigma_y", "nu", "hardening_n", "h_over_R_max", "a_over_R_max", "Lambda",
        "K_over_sigma_y", "R_over_R_rigid"}
#: the keys files written before the hardening magnitude and the scene axis were recorded have
OLD_KEYS = KEYS - {"K_over_sigma_y", "R_over_R_rigid"}


def _expected(ds, beta, growth: float = 0.0, spread: float = 0.0, co: Coefficients | None = None) -> dict:
    """The range straight from the records: materials of the runs, extremes over the points
    (Λ with the representative strain ε_rep = β x (1 + γ x), γ = ``growth``, and the
    representative stress of log-width ``spread``); a flow table's exponent and magnitude are
    those of the model (``single.effective_exponent``, ``single.hardening_magnitude`` with the
    coefficient set ``co``; without one, the records must hold Ludwik curves only)."""
    mats = [c.material for c in ds.curves]
    lam = quantities(ds, beta, growth, spread)["Lambda"]

    def n_of(m):
        return effective_exponent(m, co) if m.is_tabulated else (m.n if m.K > 0 else 0.0)

    def k_of(m):
        return hardening_magnitude(m, co) if m.is_tabulated else m.K / m.sigma_y

    return {"E_over_sigma_y": [min(m.E / m.sigma_y for m in mats), max(m.E / m.sigma_y for m in mats)],
            "nu": [min(m.nu for m in mats), max(m.nu for m in mats)],
            "hardening_n": [min(n_of(m) for m in mats), max(n_of(m) for m in mats)],
            "h_over_R_max": float(ds.h_R.max()), "a_over_R_max": float(ds.x_R.max()),
            "Lambda": [float(lam.min()), float(lam.max())],
            "K_over_sigma_y": [min(k_of(m) for m in mats), max(k_of(m) for m in mats)],
            "R_over_R_rigid": [min(c.radius / c.indenter_radius for c in ds.curves),
                               max(c.radius / c.indenter_radius for c in ds.curves)]}


def _assert_matches(block: dict, expected: dict, older_file_ok: bool = False) -> None:
    assert set(block) in ((KEYS, OLD_KEYS) if older_file_ok else (KEYS,))
    for key, want in expected.items():
        if key not in block:
            continue
        got = block[key]
        if isinstance(want, list):
            assert isinstance(got, list) and len(got) == 2, key
            assert got[0] <= got[1], key
            # ends rounded outwards to 6 significant digits: contain the data, within 1e-5
            assert got[0] <= want[0] + 1e-12 * abs(want[0]) and got[1] >= want[1] * (1 - 1e-12), key
            np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-12, err_msg=key)
        else:
            assert got >= want * (1 - 1e-12), key
            assert got == pytest.approx(want, rel=1e-5), key


def test_calibrated_range_is_written_and_matches_the_runs():
    cases = [c for c in SMALL if not math.isinf(c[1].sigma_y)]
    runs = [(case, as_run(model_result(m, KNOWN_CO, indenter_radius=Ri, seed=i)))
            for i, (case, m, Ri) in enumerate(cases)]
    cal = calibrate_runs(runs, candidates=("smooth",), cross_validation=False,
                         large_deformation_options=False)
    d = json.loads(json.dumps(coefficient_file(cal)))
    block = d["provenance"]["calibrated_range"]
    ds = cal.dataset
    co = cal.best.coeffs
    want = _expected(ds, co.beta, co.beta_growth, co.strain_spread)
    _assert_matches(block, want)
    # the cases of the synthetic grid: E/σY 10…10000, ν 0.3, Ludwik n 0 (perfectly plastic) … 0.5
    assert block["E_over_sigma_y"] == [10.0, 10000.0]
    assert block["nu"] == [0.3, 0.3]
    assert block["hardening_n"] == [0.0, 0.5]
    assert block["K_over_sigma_y"] == [0.0, 2.0]        # perfectly plastic and K/σY = 2
    assert block["R_over_R_rigid"] == [0.0, 1.0]        # rigid flat and rigid sphere of radius R
    assert block["h_over_R_max"] == pytest.approx(max(float(r.h[-1]) / r.inputs["radius"]
                                                      for _, r in runs), rel=1e-6)
    Coefficients.from_dict(d)  # the file with its range still loads


def test_calibrated_range_covers_a_dataset_of_other_runs():
    cases = [c for c in CALIBRATION_CASES if c[0] in ("flat-E100-nu0.2", "flat-E1000-nu0.45",
                                                      "flat-K2-n0.15-E100")]
    runs = [(case, as_run(model_result(m, KNOWN_CO, indenter_radius=Ri, seed=i)))
            for i, (case, m, Ri) in enumerate(cases)]
    ds = build_dataset(runs)
    block = calibrated_range(ds, KNOWN_CO)
    _assert_matches(block, _expected(ds, KNOWN_CO.beta))
    assert block["nu"] == [0.2, 0.45] and block["hardening_n"] == [0.0, 0.15]
    assert block["E_over_sigma_y"] == [100.0, 1000.0]
    assert block["K_over_sigma_y"] == [0.0, 2.0] and block["R_over_R_rigid"] == [0.0, 0.0]


@pytest.mark.skipif(not SHIPPED_DB.exists(), reason="data/reference_v2.h5 (the FE reference "
                    "database) is not present; the synthetic version of this test runs")
def test_shipped_file_records_the_range_of_its_calibration_runs():
    d = json.loads(SHIPPED.read_text())
    if d.get("source") != "calibration":
        pytest.skip("model/coefficients.json is not a calibration yet")
    runs, source = load_runs(SHIPPED_DB)
    if source["calibration_runs_hash"] != d["provenance"]["fe_dataset"]["calibration_runs_hash"]:
        pytest.skip("model/coefficients.json was calibrated on other calibration runs")
    ds = build_dataset(runs)
    _assert_matches(d["provenance"]["calibrated_range"], _expected(ds, d["beta"], d.get("beta_growth", 0.0),
                                                                     d.get("strain_spread", 0.0),
                                                                     Coefficients.from_dict(d)),
                    older_file_ok=True)
