"""Coefficient set (schema, loading, validation) and the level functions H̄(Λ), c²(Λ)."""

import json
import math

import numpy as np
import pytest

from spherecontact.model import levels
from spherecontact.model.coefficients import (
    LITERATURE,
    Coefficients,
    default_path,
    load_coefficients,
)

CO = Coefficients.from_dict(LITERATURE)


def test_shipped_file_is_valid_and_the_literature_set_still_reads():
    # the shipped file is the literature set until calibration (make calibrate) replaces it
    shipped = json.loads(default_path().read_text())
    co = load_coefficients()
    assert Coefficients.from_dict(co.to_dict()) == co
    if shipped["source"] == "literature":
        assert shipped == json.loads(json.dumps(LITERATURE)) and co == CO
    else:
        assert co.source == "calibration" and co.schema_version >= 2
        assert len(co.provenance["fe_dataset"]["content_hash"]) == 64
    assert CO.source == "literature" and CO.schema_version == 1


def test_missing_default_file_is_an_error_not_the_literature_set(tmp_path, monkeypatch):
    monkeypatch.setattr(
        "spherecontact.model.coefficients.default_path", lambda: tmp_path / "absent.json"
    )
    with pytest.raises(ValueError, match=r"absent\.json.*Reinstall.*make calibrate"):
        load_coefficients()
    assert load_coefficients("literature") == CO


def test_env_override(tmp_path, monkeypatch):
    d = CO.to_dict()
    d["beta"] = 0.2
    d["source"] = "calibration"
    p = tmp_path / "c.json"
    p.write_text(json.dumps(d))
    monkeypatch.setenv("SPHERECONTACT_COEFFICIENTS", str(p))
    co = load_coefficients()
    assert co.beta == 0.2 and co.source == "calibration"
    monkeypatch.setenv("SPHERECONTACT_COEFFICIENTS", str(tmp_path / "nope.json"))
    with pytest.raises(ValueError, match=r"cannot read .*nope\.json named by \$SPHERECONTACT_COEFFICIENTS"):
        load_coefficients()


@pytest.mark.parametrize(
    "mutate, key",
    [
        (lambda d: d.update(schema_version=2), "schema_version"),
        (lambda d: d.pop("schema_version"), "schema_version"),
        (lambda d: d.pop("Lambda_III"), "Lambda_III"),
        (lambda d: d.update(beta="0.3"), "beta"),
        (lambda d: d.update(beta=-1.0), "beta"),
        (lambda d: d.update(Lambda_I=50.0), "Lambda_I"),
        (lambda d: d.update(source="guess"), "source"),
        (lambda d: d["c2_III"].update(exp_poly=[[1.0]]), "c2_III.exp_poly"),
        (lambda d: d["c2_III"].update(exp_poly=5), "c2_III.exp_poly"),
        (lambda d: d["finite_size"].update(ratio="h_over_R"), "finite_size.ratio"),
        (lambda d: d["finite_size"].update(H_bar=[float("nan")]), "finite_size.H_bar"),
        (lambda d: d["H_bar_III"].pop("prefactor"), "H_bar_III.prefactor"),
        (lambda d: d["hardening_exponent"].update(eps_lo=1.0), "eps_lo"),
    ],
)
def test_bad_coefficient_sets_name_the_key(mutate, key):
    d = CO.to_dict()
    mutate(d)
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        Coefficients.from_dict(d)


def test_bad_json_file(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        load_coefficients(p)


def test_level_I_is_hertz():
    Lam = np.linspace(0.0, CO.Lambda_I, 7)
    assert np.array_equal(levels.H_bar(Lam, CO), 4.0 * Lam / (3.0 * math.pi))
    assert np.all(levels.c2(Lam, CO) == 0.5)


def test_levels_continuous_at_boundaries():
    for n in (0.0, 0.3, 1.0):
        for L in (CO.Lambda_I, CO.Lambda_III):
            lo, hi = L * (1 - 1e-12), L * (1 + 1e-12)
            for f in (levels.H_bar, levels.c2):
                assert f(lo, CO, n) == pytest.approx(f(hi, CO, n), rel=1e-10)
    assert levels.H_bar(1e6, CO, 0.0) == pytest.approx(3.07)
    assert levels.c2(1e6, CO, 0.0) == pytest.approx(1.43)
    assert levels.c2(1e6, CO, 1.0) == pytest.approx(1.43 * math.exp(-0.97))


def test_level_II_linear_in_ln_Lambda_and_shape_terms_keep_ends():
    Lam = np.geomspace(CO.Lambda_I, CO.Lambda_III, 9)[1:-1]
    H = levels.H_bar(Lam, CO)
    assert np.allclose(np.diff(H, 2), 0.0, atol=1e-12)
    shaped = CO.replace(level_II={"H_bar_shape": [0.5, -0.2], "c2_shape": [0.3]})
    for L in (CO.Lambda_I, CO.Lambda_III):
        assert levels.H_bar(L, shaped) == pytest.approx(levels.H_bar(L, CO), rel=1e-12)
        assert levels.c2(L, shaped) == pytest.approx(levels.c2(L, CO), rel=1e-12)
    assert not np.allclose(levels.H_bar(Lam, shaped), H)


def test_log_slopes_match_finite_differences():
    shaped = CO.replace(level_II={"H_bar_shape": [0.5, -0.2], "c2_shape": [0.3]})
    Lam = np.array([1.0, 5.0, 12.0, 30.0, 100.0])
    d = 1e-6
    for fun in (levels.H_bar_and_slope, levels.c2_and_slope):
        q, s = fun(Lam, shaped, 0.2)
        qp, _ = fun(Lam * math.exp(d), shaped, 0.2)
        qm, _ = fun(Lam * math.exp(-d), shaped, 0.2)
        assert np.allclose(s, (np.log(qp) - np.log(qm)) / (2 * d), rtol=1e-6, atol=1e-9)


def test_finite_size_factor_vanishes_at_zero():
    f, s = levels.finite_size_factor(np.array([0.0, 1e-12, 0.1]), (0.7, -0.3, 2.0))
    assert f[0] == 1.0 and s[0] == 0.0
    assert abs(f[1] - 1.0) < 1e-11
    assert f[2] == pytest.approx(1 + 0.07 - 0.003 + 0.002)
