"""Calibrated range: the model warns (CalibrationRangeWarning) outside it, once per cause and call."""

import copy
import math
import warnings

import numpy as np
import pytest

from spherecontact.model import (
    CalibratedRange,
    CalibrationRangeWarning,
    ContactLaw,
    Material,
    Sphere,
    contact,
    contact_from_radius,
)
from spherecontact.model.calibrated_range import DEFAULT_RANGE
from spherecontact.model.coefficients import LITERATURE, Coefficients, default_path, load_coefficients

CO = Coefficients.from_dict(LITERATURE)
PP = Material(E=200.0, nu=0.3, sigma_y=1.0)                      # E/σ_Y 200, perfectly plastic
LUD = Material(E=300.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
#: a tabulated Ludwik curve σ_Y + 1.5 ε^0.3 (in range: n, K/σ_Y and the local slopes); the table
#: 1.0, 1.3, 1.7, 2.0 at 0, 0.02, 0.1, 0.5 used before reads as Ludwik K/σ_Y = 3.3 through ε = 0.01, 0.1
TAB = Material.from_table(E=500.0, nu=0.35, eps_p=[0.0, 0.01, 0.1, 0.5],
                          sigma=[1.0 + 1.5 * e**0.3 for e in (0.0, 0.01, 0.1, 0.5)])
FLAT = Sphere(math.inf, Material.rigid())
H_IN = np.geomspace(1e-5, 0.25, 400)   # h/R inside the calibrated h/R ≤ 0.3 for R = 1

IN_RANGE = {
    "rigid_flat": (Sphere(1.0, PP), FLAT),
    "rigid_flat_table": (Sphere(1.0, TAB), FLAT),
    "rigid_sphere": (Sphere(1.0, LUD), Sphere(2.0, Material.rigid())),   # calibrated R_rigid/R: 1 … inf
    "equal": (Sphere(1.0, LUD), Sphere(1.0, LUD)),
    "dissimilar": (Sphere(1.0, PP), Sphere(3.0, Material(E=500.0, nu=0.25, sigma_y=2.5, K=1.0, n=0.2))),
    "deformable_flat": (Sphere(math.inf, PP), Sphere(1.0, LUD)),
    "elastic_partner": (Sphere(1.0, PP), Sphere(2.0, Material.elastic(E=400.0, nu=0.3))),
}

# name: (s1, s2, h, pattern the warning must match)
OUT_OF_RANGE = {
    "E_over_sigma_y_low": (Sphere(1.0, Material(E=6.0, nu=0.3, sigma_y=1.0)), FLAT, H_IN,
                           r"E/sigma_y = 6 of sphere 1 is outside the calibrated range \[10, 10000\]"),
    "E_over_sigma_y_high": (Sphere(1.0, Material(E=1e5, nu=0.3, sigma_y=1.0)), FLAT, H_IN,
                            r"E/sigma_y = 100000 of sphere 1 .*\[10, 10000\]"),
    "nu": (Sphere(1.0, Material(E=200.0, nu=0.49, sigma_y=1.0)), FLAT, H_IN,
           r"nu = 0\.49 of sphere 1 is outside the calibrated range \[0\.2, 0\.45\]"),
    "ludwik_n": (Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0, K=5.0, n=1.0)), FLAT, H_IN,
                 r"hardening exponent n = 1 of sphere 1 .*\[0, 0\.5\]"),
    "table_secant_n": (Sphere(1.0, Material.from_table(200.0, 0.3, [0.0, 0.01, 0.1], [1.0, 1.0, 5.0])),
                       FLAT, H_IN, r"hardening exponent n \(secant, flow table\) = 0\.69.* of sphere 1"),
    "late_hardening_table": (Sphere(1.0, Material.from_table(200.0, 0.3, [0, 0.05, 0.5], [1.0, 1.0, 3.0])),
                             FLAT, H_IN, r"ln eps_p = 0\.5[1-9]\d* of the flow table of sphere 1"),
    "second_sphere": (Sphere(1.0, PP), Sphere(1.0, Material(E=200.0, nu=0.1, sigma_y=1.0)), H_IN,
                      r"nu = 0\.1 of sphere 2"),
    "radius_ratio": (Sphere(1.0, PP), Sphere(50.0, PP), H_IN,
                     r"radius ratio R_max/R_min = 50 of the pair .*\[1, 4\]"),
    "yield_ratio": (Sphere(1.0, PP), Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=20.0)), H_IN,
                    r"yield-stress ratio sigma_y,max/sigma_y,min = 20 of the pair .*\[1, 3\]"),
    "E_ratio": (Sphere(1.0, PP), Sphere(1.0, Material(E=2000.0, nu=0.3, sigma_y=1.0)), H_IN,
                r"Young's modulus ratio E_max/E_min = 10 of the pair .*\[1, 3\]"),
    "h_over_R": (Sphere(1.0, PP), FLAT, np.geomspace(1e-4, 0.5, 50),
                 r"h/R = 0\.5 \(largest approach of a sphere over its own radius\) is outside the "
                 r"calibrated range h/R <= 0\.3"),
    "a_over_R": (Sphere(2.0, PP), Sphere(2.0, PP), np.array([0.1, 2.0]),
                 r"a/R = 1\.\d+ \(largest contact radius over R = 2\) .*a/R <= 1"),
}


def _records(fun):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fun()
    return [w for w in caught if issubclass(w.category, CalibrationRangeWarning)]


@pytest.mark.parametrize("name", OUT_OF_RANGE)
def test_out_of_range_parameter_warns_naming_it(name):
    s1, s2, h, pattern = OUT_OF_RANGE[name]
    with pytest.warns(CalibrationRangeWarning, match=pattern):
        st = contact(s1, s2, h, CO)
    assert np.all(np.isfinite(st.F))  # a warning, not a clip or an error
    with pytest.warns(CalibrationRangeWarning, match=pattern):
        law = ContactLaw(s1, s2, coeffs=CO)
        law.loading_force(h)
    with pytest.warns(CalibrationRangeWarning, match=pattern):
        contact_from_radius(s1, s2, st.a[st.a > 0], CO)


@pytest.mark.parametrize("name", IN_RANGE)
def test_in_range_call_raises_no_warning(name):
    s1, s2 = IN_RANGE[name]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        st = contact(s1, s2, H_IN, CO)
        contact_from_radius(s1, s2, st.a, CO)
        law = ContactLaw(s1, s2, coeffs=CO)
        law.loading_force(H_IN)
        law(H_IN)
        law.loading_force(np.concatenate([H_IN, [1e-14, 0.0, -1.0]]))  # exact fallback below the table
    assert law.range_issues == {}
    # at h_calibrated no sphere is beyond its own h_i/R_i = 0.3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        end = contact(s1, s2, np.array([law.h_calibrated]), CO)
    own = [h_i[0] / s.radius for h_i, s in ((end.h1, s1), (end.h2, s2)) if not s.is_rigid]
    assert max(own) <= 0.3 * (1 + 1e-6)


def test_filter_error_escalates_and_ignore_silences():
    s1 = Sphere(1.0, Material(E=200.0, nu=0.49, sigma_y=1.0))
    with warnings.catch_warnings():
        warnings.filterwarnings("error", category=CalibrationRangeWarning)
        with pytest.raises(CalibrationRangeWarning, match="nu = 0.49"):
            contact(s1, FLAT, 1e-3, CO)
        with pytest.raises(CalibrationRangeWarning, match="nu = 0.49"):
            ContactLaw(s1, FLAT, coeffs=CO)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", category=CalibrationRangeWarning)
        contact(s1, FLAT, 1e-3, CO)


def test_warning_is_a_user_warning_attributed_to_the_caller():
    assert issubclass(CalibrationRangeWarning, UserWarning)
    s1 = Sphere(1.0, Material(E=6.0, nu=0.3, sigma_y=1.0))
    for fun in (lambda: contact(s1, FLAT, 1e-3, CO), lambda: ContactLaw(s1, FLAT, coeffs=CO),
                lambda: ContactLaw(Sphere(1.0, PP), FLAT, coeffs=CO).loading_force(0.5)):
        rec = _records(fun)
        assert rec and all(w.filename == __file__ for w in rec)


def test_one_warning_per_cause_per_call_not_per_point():
    s1 = Sphere(1.0, Material(E=6.0, nu=0.49, sigma_y=1.0))   # E/σ_Y and ν out
    h = np.geomspace(1e-5, 1.0, 20000)                           # h/R and a/R out at many points
    rec = _records(lambda: contact(s1, FLAT, h, CO))
    msgs = sorted(str(w.message).split(" = ")[0] for w in rec)
    assert msgs == ["E/sigma_y", "a/R", "h/R", "nu"]
    assert "h/R = 1 " in " ".join(str(w.message) for w in rec)   # the largest value is named
    assert len(_records(lambda: contact(s1, FLAT, h, CO))) == 4  # again on the next call


def test_table_warns_once_per_cause_not_per_evaluation():
    s1 = Sphere(1.0, Material(E=6.0, nu=0.3, sigma_y=1.0))
    rec = _records(lambda: ContactLaw(s1, FLAT, coeffs=CO))
    assert [str(w.message).split(" = ")[0] for w in rec] == ["E/sigma_y"]
    law = ContactLaw(Sphere(1.0, PP), FLAT, coeffs=CO)
    rng = np.random.default_rng(1)
    h = np.exp(rng.uniform(math.log(1e-5), math.log(0.8), 10000))   # table and exact fallback
    rec = _records(lambda: [law.loading_force(h) for _ in range(50)] + [law(h)])
    assert sorted(str(w.message).split(" = ")[0] for w in rec) == ["a/R", "h/R"]
    assert set(law.range_issues) == {"h_over_R", "a_over_R"}
    assert law.describe()["calibrated_range_warnings"] == list(law.range_issues.values())


def test_table_approach_threshold_matches_the_exact_check():
    s1, s2 = Sphere(1.0, PP), Sphere(1.0, PP)    # equal spheres: a reaches R inside the table
    law = ContactLaw(s1, s2, h_max=2.0, coeffs=CO)   # the end of the domain: h_i = R_i
    assert law.h_calibrated == pytest.approx(0.6, rel=1e-8)  # each sphere at h/R = 0.3
    h_a = law._pending["a_over_R"][1]          # approach where a/R first reaches 1
    a_exact = contact(s1, s2, np.array([0.99 * h_a, 1.01 * h_a]), CO).a
    assert a_exact[0] < 1.0 < a_exact[1]
    rec = _records(lambda: law.loading_force(np.array([0.1, 0.99 * h_a])))
    assert [str(w.message).split(" = ")[0] for w in rec] == ["h/R"]
    rec = _records(lambda: law.loading_force(np.array([0.1, 1.01 * h_a])))
    assert [str(w.message).split(" = ")[0] for w in rec] == ["a/R"]


def _with_range(block) -> Coefficients:
    d = copy.deepcopy(LITERATURE)
    d["provenance"]["calibrated_range"] = block
    return Coefficients.from_dict(d)


NARROW = {"E_over_sigma_y": [100, 1000], "nu": [0.25, 0.35], "hardening_n": [0.0, 0.3],
          "h_over_R_max": 0.1, "a_over_R_max": 0.5, "Lambda": [0.5, 50.0]}


def test_range_from_provenance_when_present_default_otherwise():
    assert CO.calibrated_range == DEFAULT_RANGE and CO.calibrated_range.source == "default"
    assert DEFAULT_RANGE.E_over_sigma_y == (10.0, 1e4) and DEFAULT_RANGE.nu == (0.2, 0.45)
    assert DEFAULT_RANGE.hardening_n == (0.0, 0.5) and DEFAULT_RANGE.h_over_R_max == 0.3
    co = _with_range(NARROW)
    rng = co.calibrated_range
    assert rng.source == "provenance"
    assert rng.E_over_sigma_y == (100.0, 1000.0) and rng.Lambda == (0.5, 50.0)
    assert (rng.radius_ratio_max, rng.yield_ratio_max, rng.E_ratio_max) == (4.0, 3.0, 3.0)
    # round trip keeps the block; the set compares equal (provenance is not compared)
    again = Coefficients.from_dict(co.to_dict())
    assert again.calibrated_range == rng and again == CO
    assert CalibratedRange.from_provenance({"calibrated_range": rng.to_dict()}) == rng
    # the same pair: in range by default, outside the narrow range (checks not shared by the cache)
    s1 = Sphere(1.0, PP)
    h = np.geomspace(1e-5, 0.05, 100)
    assert _records(lambda: contact(s1, FLAT, h, CO)) == []
    msgs = " | ".join(str(w.message) for w in _records(lambda: contact(s1, FLAT, h, co)))
    assert "hardening" not in msgs and "nu" not in msgs
    assert "Lambda = " in msgs and "[0.5, 50]" in msgs
    s2 = Sphere(1.0, Material(E=50.0, nu=0.3, sigma_y=1.0))
    with pytest.warns(CalibrationRangeWarning, match=r"E/sigma_y = 50 of sphere 1 .*\[100, 1000\]"):
        contact(s2, FLAT, h, co)
    with pytest.warns(CalibrationRangeWarning, match=r"h/R = 0\.2 .*h/R <= 0\.1"):
        ContactLaw(s2, FLAT, coeffs=co).loading_force(np.array([0.01, 0.2]))


@pytest.mark.parametrize("key, bad", [("nu", [0.3]), ("h_over_R_max", "0.3"), ("E_over_sigma_y", [10, 1]),
                                      ("a_over_R_max", -1.0), ("Lambda", {"max": 1})])
def test_malformed_range_block_raises_naming_the_key(key, bad):
    block = dict(NARROW, **{key: bad})
    with pytest.raises(ValueError, match=f"calibrated_range.{key}"):
        _with_range(block)
    block = {k: v for k, v in NARROW.items() if k != key}
    with pytest.raises(ValueError, match=f"missing key 'provenance.calibrated_range.{key}'"):
        _with_range(block)
    assert _with_range(dict(NARROW, Lambda=None)).calibrated_range.Lambda is None


def test_null_entries_take_the_default_and_the_shipped_file_is_read():
    rng = _with_range(dict(NARROW, E_over_sigma_y=None, hardening_n=None, Lambda=None)).calibrated_range
    assert rng.E_over_sigma_y == DEFAULT_RANGE.E_over_sigma_y
    assert rng.hardening_n == DEFAULT_RANGE.hardening_n and rng.nu == (0.25, 0.35)
    shipped = load_coefficients(default_path()) if default_path().exists() else CO
    block = shipped.provenance.get("calibrated_range")
    if block is None:
        assert shipped.calibrated_range == DEFAULT_RANGE
    else:
        assert shipped.calibrated_range.source == "provenance"
        assert shipped.calibrated_range.h_over_R_max == block["h_over_R_max"]
        assert list(shipped.calibrated_range.nu) == block["nu"]


def test_approach_check_is_per_sphere_like_the_calibration_scenes():
    """Calibrated on one sphere against a rigid flat (h_1 = h): an equal pair at 2h is as far
    in as its flat scene at h, and a dissimilar pair is limited by its sphere with the
    largest h_i/R_i — in the exact check and in the table alike."""
    eq, flat = ContactLaw(Sphere(1.0, PP), Sphere(1.0, PP), h_max=1.0, coeffs=CO), ContactLaw(
        Sphere(1.0, PP), FLAT, coeffs=CO)
    assert eq.h_calibrated == pytest.approx(2 * flat.h_calibrated, rel=1e-12)
    assert flat.h_calibrated == pytest.approx(0.3, rel=1e-8)
    for h, warns in ((0.6, False), (0.61, True)):
        rec = _records(lambda h=h: contact(Sphere(1.0, PP), Sphere(1.0, PP), np.array([0.01, h]), CO))
        assert any("h/R" in str(w.message) for w in rec) == warns
    s1, s2 = Sphere(1.0, PP), Sphere(4.0, PP)            # radius ratio 4, equal materials
    law = ContactLaw(s1, s2, h_max=1.0, coeffs=CO)
    t = law._pending["h_over_R"][1]                       # where the h/R check is first exceeded
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        st = contact(s1, s2, np.array([t]), CO)
    assert max(st.h1[0] / 1.0, st.h2[0] / 4.0) == pytest.approx(0.3, rel=1e-6)  # table == exact
    assert t > 0.45                                       # body 2 takes part of the approach
    for h, warns in ((0.999 * t, False), (1.001 * t, True)):
        law = ContactLaw(s1, s2, h_max=1.0, coeffs=CO)
        rec = _records(lambda law=law, h=h: law.loading_force(np.array([0.01, h])))
        assert any("h/R" in str(w.message) for w in rec) == warns
