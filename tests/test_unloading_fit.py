"""FE cycles (spherecontact.cycles), the unloading fit (calibration/unloading.py) and the
unloading validation (validation/unloading.py) on the shipped database."""

import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from spherecontact.calibration.unloading import fit_unloading
from spherecontact.cycles import branch_errors, run_cycles
from spherecontact.data import Database
from spherecontact.model import load_coefficients
from spherecontact.model.coefficients import UnloadingCoefficients
from spherecontact.model.unloading import unloading_law
from spherecontact.validation.cases import load_cases
from spherecontact.validation.unloading import EKK, ekk_branch, unloading_failures, unloading_rows

ROOT = Path(__file__).resolve().parents[1]
DB = ROOT / "data" / "reference_v2.h5"
pytestmark = pytest.mark.skipif(not DB.exists(), reason="data/reference_v2.h5 is not present")

#: a flat, a rigid sphere and a two-body pair of the calibration set
CASES = ("flat-K5-n1-E100-nu0.3", "rsphere0.88-K1.16-n0.2-E1360-nu0.3", "two-pp-E300-nu0.3-vs-sy4")


@pytest.fixture(scope="module")
def curves():
    co = load_coefficients()
    db = Database(DB)
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for rec, run in db.runs(set="calibration", where=lambda r: r.case in CASES):
            out += run_cycles(rec.case, run, co)
    assert len(out) >= 3 * 4
    return out


def test_cycles_read_the_fe_peak_and_branch(curves):
    for c in curves:
        assert c.f[0] == pytest.approx(1.0)       # the branch starts at the peak
        assert c.f[-1] < 0.05                     # and ends where the force vanishes
        assert np.all(np.diff(c.h) < 0.0)
        assert 0.0 <= c.h[-1] - c.h_res < 0.01 * c.h_max  # h_res: where F reaches 0 (interpolated)
        assert c.peak.F[0] > 0 and 0 < c.peak.lam[0] <= 1.0
        assert c.peak.h_i[0].sum() == pytest.approx(c.h_max, rel=2e-3)


def test_fit_recovers_a_known_law(curves):
    known = UnloadingCoefficients(stiffness=1.2, size_a=0.5, size_h=1.5, m_plastic=1.25, m_c2=0.2,
                                  m_counter=1.4, m_elastic_size=0.5, elastic_weight=2.0,
                                  size_counter=0.6, stiffness_c2=0.1, m_lambda=0.3,
                                  stiffness_c2_counter=-0.3, stiffness_c2_depth=-0.1, stiffness_c2_c2=-0.15,
                                  m_counter_depth=-0.7)
    synthetic = []
    for c in curves:
        m, delta_e, h_res, _ = unloading_law(c.peak, known)
        f = np.clip((c.h - h_res[0]) / delta_e[0], 0.0, 1.0) ** m[0]
        synthetic.append(replace(c, f=f, h_res=float(h_res[0])))
    fit = fit_unloading(synthetic)
    assert np.max(fit.errors) < 1e-4
    assert np.max(fit.h_res_errors) < 1e-4


def test_fit_beats_thornton_on_the_fe_branches(curves):
    fit = fit_unloading(curves)
    assert np.median(fit.errors) < 0.3 * np.median(fit.thornton)
    assert np.max(fit.errors) < np.max(fit.thornton)
    err, _ = branch_errors(fit.law, curves)
    np.testing.assert_array_equal(err, fit.errors)
    assert fit_unloading([]) is None


def test_ekk_limits():
    h = np.linspace(0.0, 1.0, 11)
    F, h_res = ekk_branch(h, 1.0, 2.0, omega_c=2.0)  # ω* = 0.5: elastic, Hertz exponent
    assert h_res == 0.0
    np.testing.assert_allclose(F, 2.0 * h**1.5)
    _, h_res = ekk_branch(h, 1.0, 1.0, omega_c=1e-6)  # far beyond the fit: held at ω* = 110
    assert h_res == pytest.approx(1.02 * (1 - (115.9 / 6.9) ** -0.54), rel=1e-12)  # 0.80


def test_validation_rows_and_failures():
    cases = [c for c in load_cases(DB, "validation")
             if c.label in ("flat-pp-E250-nu0.3", "two-pp-E200-nu0.3-vs-sy5")]
    assert len(cases) == 2
    rows = unloading_rows(cases)
    assert len(rows) == 8
    for r in rows:
        assert set(r.F_err) == {"law", "model", "Thornton 1997", EKK}
        assert r.F_err["law"] < r.F_err["Thornton 1997"]
        assert 0.0 <= r.h_res_fe < 1.0
    first = [r for r in rows if r.cycle == 1]
    assert all(abs(r.e_model - r.e_fe) < 0.03 for r in first)
    assert all(math.isnan(r.e_fe) for r in rows if r.cycle > 1)
    worst = max(r.F_err["law"] for r in rows)
    assert unloading_failures(rows, worst * 1.01, 1.0) == []
    fails = unloading_failures(rows, worst * 0.99, 1.0)
    assert len(fails) >= 1 and "F max error" in fails[0]


def test_validation_compares_mdr_unloading_where_it_applies():
    from spherecontact.validation.mdr import load_store

    path = ROOT / "data" / "peers" / "mdr.json"
    if not path.exists():
        pytest.skip("data/peers/mdr.json is not present")
    cases = [c for c in load_cases(DB, "validation")
             if c.label in ("flat-pp-E250-nu0.3", "flat-K5-n0.3-E300-nu0.3")]
    rows = unloading_rows(cases, mdr=load_store(path))
    with_mdr = [r for r in rows if "LAMMPS mdr" in r.F_err]
    # mdr applies to the perfectly plastic equal pair only, on its last cycle (its stored h_max)
    assert [(r.run, r.cycle) for r in with_mdr] == [("flat-pp-E250-nu0.3", 4)]
    r = with_mdr[0]
    assert r.branches["LAMMPS mdr"].shape == r.curve.h.shape
    assert 0.0 < r.F_err["LAMMPS mdr"] < 1.0
