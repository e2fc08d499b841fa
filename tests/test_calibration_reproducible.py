"""Calibration output independent of the machine's settings: BLAS threads pinned to one
inside the calibration, the written numbers rounded to their documented digits (and the
model reading exactly those), the database path independent of how it was spelled."""

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
from test_calibration import SHIPPED_DB, SMALL, synthetic_runs

from spherecontact.calibration.dataset import build_dataset
from spherecontact.calibration.fit import SIGNIFICANT, errors, round_sig
from spherecontact.calibration.forms import predict
from spherecontact.calibration.pipeline import (
    STAT_SIGNIFICANT,
    calibrate_runs,
    coefficient_file,
    load_runs,
    source_path,
)
from spherecontact.calibration.threads import blas_threads, set_blas_threads, single_threaded_blas
from spherecontact.calibration.workers import Workers
from spherecontact.model.coefficients import Coefficients

needs_blas_control = pytest.mark.skipif(not blas_threads(), reason="no OpenBLAS/MKL library "
                                        "whose thread count this process can set")


def _threads_in_worker(ds):
    return blas_threads()


@needs_blas_control
def test_blas_threads_are_one_inside_the_calibration_and_restored_after():
    old = set_blas_threads(2)
    try:
        # 2 in every library that takes it (cvxopt's OpenBLAS, which the FE loads, is a
        # single-threaded build and stays at 1)
        before = blas_threads()
        assert 2 in before
        ds = build_dataset(synthetic_runs(SMALL[:2]))
        with single_threaded_blas():
            assert set(blas_threads()) == {1}
            with Workers(ds, 2) as pool:  # forked workers inherit the setting
                assert all(set(t) == {1} for t in pool.map(_threads_in_worker, [(), ()]))
        assert blas_threads() == before
    finally:
        for n in set(old):
            set_blas_threads(n)


@needs_blas_control
@pytest.mark.skipif(not SHIPPED_DB.exists(), reason="data/reference_v2.h5 (the FE reference database) "
                    "is not present")
def test_coefficients_do_not_depend_on_the_blas_threads_set_before_calibrating():
    """With two OpenBLAS threads the fits' products and factorisations sum in another
    order; on the reference database that moved the 6th digit of most coefficients of
    every form (before the calibration pinned its threads)."""
    runs, _ = load_runs(SHIPPED_DB)
    texts = []
    for n in (2, 1):
        old = set_blas_threads(n)
        try:
            cal = calibrate_runs(runs, candidates=("seed",), cross_validation=False,
                                 large_deformation_options=False, workers=1)
        finally:
            for m in set(old):
                set_blas_threads(m)
        texts.append(json.dumps(coefficient_file(cal), indent=2))
    assert texts[0] == texts[1]


def _floats(v, path=""):
    if isinstance(v, float):
        yield path, v
    elif isinstance(v, dict):
        for k, x in v.items():
            yield from _floats(x, f"{path}.{k}")
    elif isinstance(v, list):
        for i, x in enumerate(v):
            yield from _floats(x, f"{path}[{i}]")


def test_written_numbers_have_their_documented_digits_and_the_model_reads_them():
    cal = calibrate_runs(synthetic_runs(SMALL, noise=0.002), candidates=("smooth",),
                         large_deformation_options=False, workers=1)
    d = json.loads(json.dumps(coefficient_file(cal), indent=2))  # what the file holds
    coeffs = {k: v for k, v in d.items() if k not in ("provenance", "references")}
    values = list(_floats(coeffs))
    assert len(values) > 20
    for path, x in values:  # fitted coefficients: SIGNIFICANT digits
        assert round_sig(x, SIGNIFICANT) == x, path
    prov = d["provenance"]
    stats = [(p, x) for key in ("fit_residuals", "noise_floor", "cross_validation", "model_error_per_run")
             for p, x in _floats(prov[key], key)]
    assert len(stats) > 30
    for path, x in stats:  # statistics: STAT_SIGNIFICANT digits
        assert round_sig(x, STAT_SIGNIFICANT) == x, path
    for path, x in _floats(prov["calibrated_range"], "calibrated_range"):
        assert round_sig(x, SIGNIFICANT) == x, path
    # the model uses exactly what is written, and the residuals reported are of that set
    co = Coefficients.from_dict(d)
    ds = cal.dataset
    for a, b in zip(predict(ds, co), predict(ds, cal.best.coeffs), strict=True):
        np.testing.assert_array_equal(a, b)
    e = errors(ds, co)
    for q in ("H_bar", "c2"):
        np.testing.assert_array_equal(e[q], cal.best.errors[q])
        assert prov["fit_residuals"][q]["rms"] == round_sig(math.sqrt(np.mean(e[q] ** 2)), STAT_SIGNIFICANT)


def test_database_path_is_written_relative_to_the_working_directory(tmp_path, monkeypatch):
    (tmp_path / "data").mkdir()
    monkeypatch.chdir(tmp_path)
    for spelled in ("data/reference.h5", "./data/reference.h5", tmp_path / "data" / "reference.h5",
                    os.path.join(str(tmp_path), "data", "..", "data", "reference.h5")):
        assert source_path(spelled) == "data/reference.h5", spelled
    outside = Path(os.path.abspath(os.sep)) / "elsewhere" / "reference.h5"
    assert source_path(outside) == outside.as_posix()


def test_shipped_coefficients_name_the_shipped_database():
    """The shipped file's provenance names the database it was calibrated on: a database
    committed without recalibrating (on 2026-11-25 a validation pair was re-made after the
    calibration) leaves a file whose hash no longer matches; ``make calibrate`` rewrites it."""
    from spherecontact.data import Database

    root = Path(__file__).resolve().parents[1]
    prov = json.loads((root / "model" / "coefficients.json").read_text())["provenance"]["fe_dataset"]
    assert prov["content_hash"] == Database(SHIPPED_DB).content_hash
