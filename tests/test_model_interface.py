"""Two-body interface terms (model/unified.py, calibration/interface.py): the split of two
plastic bodies of near-equal hardness, exactness where they must not act, derivatives, fit."""

import dataclasses
import math

import numpy as np
import pytest

from spherecontact.calibration.interface import COUPLINGS, PairCurve, fit_interface
from spherecontact.model import ContactLaw, Material, Sphere, contact, load_coefficients
from spherecontact.model.coefficients import Coefficients

BASE = load_coefficients()
CO = dataclasses.replace(BASE, interface_coupling=10.0, interface_similarity=0.1,
                         interface_radius=0.8, interface_exponent=6.0)
SOFT, STIFF = Material(E=300.0, nu=0.3, sigma_y=1.0), Material(E=900.0, nu=0.3, sigma_y=1.0)
H = np.geomspace(1e-4, 0.3, 60)


def _split(s1, s2, co, h=H):
    st = contact(s1, s2, h, co)
    return st.h1 / h, st


def test_equal_yield_split_follows_the_smooth_contact_fe_and_stays_unique():
    # EPP E/σY 300 against 900 (FE with smooth frictionless contact: 0.75 elastic, 0.91 at
    # h/R = 0.1, 0.96 at 0.3): equal pressures alone overshoot early (0.95 at h/R 0.09); the
    # calibrated weak pull to the Hertz partition keeps the split rising, below that
    s1, s2 = Sphere(1.0, SOFT), Sphere(1.0, STIFF)
    assert 0.0 < BASE.interface_coupling < 1.0 and math.isinf(BASE.interface_radius)
    assert "radius" not in BASE.to_dict()["interface"]
    without, _ = _split(s1, s2, dataclasses.replace(BASE, interface_coupling=0.0))
    with_, _ = _split(s1, s2, BASE)
    assert without[-1] > 0.95
    assert 0.85 < with_[-1] < without[-1]
    assert np.all(np.diff(with_[H > 3e-3]) > 0)  # moves one way, towards the softer sphere
    assert np.all(np.abs(with_[H < 0.003] - 0.75) < 0.02)  # the elastic partition while contained


def test_the_check_along_h_catches_the_ill_posed_pair_and_the_coupling_mends_it():
    """E/σY 3·10⁴ against 150 at equal yield stress, R₂ = 2R₁ (a pair of the check's grid): with
    equal pressures alone F(h) falls steeply where the κ root jumps (the sweep in a alone saw a
    rise there); the calibrated coupling passes both sweeps."""
    from spherecontact.calibration.check import check_pair, two_body_pairs

    (label, s1, s2), = [p for p in two_body_pairs() if p[0].startswith("E/sy=30000 vs E/sy=150 ")]
    bad = check_pair(label, s1, s2, dataclasses.replace(BASE, interface_coupling=0.0))
    assert not bad.ok and bad.min_dlnF_h < 0.0
    good = check_pair(label, s1, s2, BASE)
    assert good.ok and good.min_dlnF_h > 0.2


@pytest.mark.parametrize("pair", ["elastic", "equal_material_radii_2", "yield_ratio_1.5",
                                  "equal_E_yield_ratio_1.02"])
def test_interface_terms_leave_other_pairs_alone(pair):
    s1, s2 = {
        "elastic": (Sphere(1.0, Material.elastic(E=1.0, nu=0.3)),
                    Sphere(2.0, Material.elastic(E=3.0, nu=0.25))),
        "equal_material_radii_2": (Sphere(1.0, SOFT), Sphere(2.0, SOFT)),
        "yield_ratio_1.5": (Sphere(1.0, SOFT), Sphere(1.0, Material(E=900.0, nu=0.3, sigma_y=1.5))),
        # equal moduli: no modulus-driven run-away to correct (radius ratio 2 and 4 of the FE
        # follow the equal-pressure split within 9 and 6 percentage points)
        "equal_E_yield_ratio_1.02": (Sphere(1.0, SOFT), Sphere(0.5, Material(E=300.0, nu=0.3, sigma_y=1.02))),
    }[pair]
    a, _ = _split(s1, s2, dataclasses.replace(CO, interface_coupling=0.0))
    b, _ = _split(s1, s2, CO)
    np.testing.assert_allclose(b, a, atol=1e-9)
    if pair == "elastic":  # Hertz: h1/h = E2'/(E1' + E2') (finite-size terms: 0.2 % at h/R 1e-4)
        e1, e2 = s1.material.E_prime, s2.material.E_prime
        np.testing.assert_allclose(b[H < 1e-3], e2 / (e1 + e2), rtol=5e-3)


def test_stiffness_and_slopes_are_exact_with_the_coupling():
    s1, s2 = Sphere(1.0, SOFT), Sphere(1.5, STIFF)
    h = np.geomspace(1e-3, 0.2, 25)
    eps = 1e-6
    mid = contact(s1, s2, h, CO)
    plus, minus = contact(s1, s2, h * (1 + eps), CO), contact(s1, s2, h * (1 - eps), CO)
    fd = (plus.F - minus.F) / (2 * eps * h)
    np.testing.assert_allclose(mid.stiffness, fd, rtol=2e-4)


@pytest.mark.parametrize("ratio", [1.02, 1.05, 1.1, 1.2, 1.3])
def test_near_equal_hardness_stays_finite_and_monotone(ratio):
    # the similarity factor's transition band (fully plastic pressures 2-30 % apart)
    s1 = Sphere(1.0, SOFT)
    s2 = Sphere(1.0, Material(E=900.0, nu=0.3, sigma_y=ratio, K=0.5, n=0.3))
    split, st = _split(s1, s2, CO, np.geomspace(1e-5, 0.4, 300))
    assert np.all(np.isfinite(st.F)) and np.all(np.diff(st.F) > 0) and np.all(np.diff(st.a) > 0)
    assert np.all((split > 0.0) & (split < 1.0))


def test_fast_path_tabulates_the_coupled_pair():
    law = ContactLaw(Sphere(1.0, SOFT), Sphere(1.0, STIFF), coeffs=CO, h_max=0.3)
    assert law.error["F"] < 1e-6
    h = np.geomspace(1e-4, 0.3, 200)
    F, k = law.loading_force(h)
    ex = contact(Sphere(1.0, SOFT), Sphere(1.0, STIFF), h, CO)
    np.testing.assert_allclose(F, ex.F, rtol=1e-6)


def test_coefficient_file_round_trip_and_bad_values():
    d = CO.to_dict()
    assert d["interface"] == {"coupling": 10.0, "similarity": 0.1, "radius": 0.8, "exponent": 6.0}
    assert Coefficients.from_dict(d) == CO
    assert Coefficients.from_dict(BASE.to_dict()) == BASE  # the Hertz anchor: no radius written
    assert "interface" not in dataclasses.replace(CO, interface_coupling=0.0).to_dict()
    older = {k: v for k, v in d.items() if k != "interface"}
    assert Coefficients.from_dict(older).interface_coupling == 0.0  # older files read
    for key, bad in (("radius", 0.0), ("exponent", 50.0), ("coupling", -1.0), ("similarity", math.nan)):
        dd = CO.to_dict()
        dd["interface"][key] = bad
        with pytest.raises(ValueError, match=f"interface.{key}"):
            Coefficients.from_dict(dd)


def _synthetic_pairs(truth):
    pairs = []
    softer = Sphere(1.0, Material(E=99.9, nu=0.3, sigma_y=1.0))
    for name, s2 in (("stiffer", Sphere(1.0, STIFF)), ("softer", softer)):
        s1 = Sphere(1.0, SOFT)
        h = np.geomspace(3e-3, 0.3, 30)
        split, _ = _split(s1, s2, truth, h)
        pairs.append(PairCurve(name, s1, s2, h, split))
    return pairs


def test_grid_search_recovers_the_coupling_it_was_given():
    # synthetic "FE" splits made by the model with a known coupling: the fit finds it again
    truth = dataclasses.replace(BASE, interface_coupling=COUPLINGS[4], interface_similarity=0.1,
                                interface_radius=math.inf)
    pairs = _synthetic_pairs(truth)
    off = dataclasses.replace(BASE, interface_coupling=0.0)
    f = fit_interface(pairs, off, check=None)
    assert f.coupling == COUPLINGS[4] and f.section() == {"coupling": COUPLINGS[4], "similarity": 0.1}
    assert max(f.errors.values()) < 1e-9 < min(f.errors_none.values())
    assert [lam for lam, _, _ in f.tried][0] == COUPLINGS[4] and len(f.tried) == len(COUPLINGS)
    # the grid spread over two worker processes gives the same fit, error for error
    from spherecontact.calibration.workers import Workers

    with Workers(None, 2) as pool:
        g = fit_interface(pairs, off, pool, check=None)
    assert (g.coupling, g.errors, g.errors_none, g.tried) == (f.coupling, f.errors, f.errors_none, f.tried)


def test_a_coupling_whose_model_fails_the_check_is_passed_over():
    truth = dataclasses.replace(BASE, interface_coupling=COUPLINGS[4], interface_similarity=0.1,
                                interface_radius=math.inf)
    pairs = _synthetic_pairs(truth)
    seen = []

    def check(co):  # refuses the best coupling
        seen.append(co.interface_coupling)
        return co.interface_coupling != COUPLINGS[4]

    f = fit_interface(pairs, dataclasses.replace(BASE, interface_coupling=0.0), check=check)
    assert seen[:2] == [COUPLINGS[4], f.coupling] and f.coupling != COUPLINGS[4]
    assert f.tried[0] == (COUPLINGS[4], pytest.approx(0.0, abs=1e-9), False)
    assert f.tried[1][2] is True and all(ok is None for _, _, ok in f.tried[2:])
    assert max(f.errors.values()) > 0.0


def test_pairs_of_clearly_unequal_hardness_skip_the_coupling():
    # steel against aluminium (fully plastic pressures ~4x apart): the factor is < e^-36 at every
    # admissible contact radius, so the terms are not evaluated; equal yield stress: evaluated
    from spherecontact.model.unified import UnifiedPair

    steel = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
    alu = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
    assert not UnifiedPair(Sphere(1e-3, steel), Sphere(2e-3, alu), CO)._coupled
    assert UnifiedPair(Sphere(1.0, SOFT), Sphere(1.0, STIFF), CO)._coupled
    off = dataclasses.replace(CO, interface_coupling=0.0)
    assert not UnifiedPair(Sphere(1.0, SOFT), Sphere(1.0, STIFF), off)._coupled
