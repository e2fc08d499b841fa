"""Collapse limits with x·n terms (``xn_poly``) and a c² weight of its own (``sharpness_c2``,
``offset_c2``): schema keys, numbers of older files, exact slopes, calibration forms and penalty."""

import copy
import json
import math
import re
import warnings

import numpy as np
import pytest
from _slopes import assert_body_log_slopes
from test_calibration_schema import COLLAPSE, v2

from spherecontact.calibration import fit as fitmod
from spherecontact.calibration.forms import CANDIDATES, FORMS, X_C2
from spherecontact.model import ContactLaw, Material, Sphere, contact, levels
from spherecontact.model.calibrated_range import DEFAULT_RANGE
from spherecontact.model.coefficients import Coefficients, CollapseLimit, load_coefficients
from spherecontact.model.single import BodyLaw
from spherecontact.model.unified import UnifiedPair

XN = copy.deepcopy(COLLAPSE)
XN["H_bar"]["xn_poly"] = [1.5]
XN["c2"]["xn_poly"] = [2.0, -0.8]
XN["sharpness_c2"] = 4.0
XN["offset_c2"] = -0.3

HARD = Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
#: BodyLaw(HARD, v2()).response(x, 0.7 x, 0.4) at x = 0.02, 0.1, 0.3, 0.6, computed before the
#: xn_poly and sharpness_c2 keys existed: a file without them must give these numbers
BEFORE = {
    "p_m": [2.7603721484699797, 4.6636482537901776, 4.801386850650434, 4.339614714401383],
    "c2": [0.7787013011113887, 1.185012719918224, 1.1806799163765573, 1.1175716520360273],
    "dlnp_dlnx": [0.41416126773453116, 0.3101786403516602, 0.14925938509130862, 0.1648068145715863],
    "dlnp_dlny": [-0.0028792540378283975, -0.07876968291774847, -0.23782478366668783,
                  -0.36686563278565026],
    "dlnc2_dlnx": [0.3446692831152856, 0.1916925330181558, 0.0, 0.0],
    "dlnc2_dlny": [0.0031153959530151208, -0.018189357810737557, -0.06977635749428647,
                   -0.07909476493751305],
}
#: contact() of Sphere(1, HARD) with Sphere(2, E/σY = 100) at h = 1e-3, 0.03, 0.2, same set.
#: The yield stresses are equal and HARD has five times the modulus, so since 2026-11-28 body 2
#: sees it as a rigid sphere of its radius (``unified.harder_partner_weight``, w = 0.997):
#: curvature ratio z_2 = 2.0 (it was z_2 = R_2 E*/(E'_2 R*) − 1 = 1.5 at the Hertz partition, F
#: 0.428 / 2.469 at h = 0.03 / 0.2 then), beyond the default calibrated z ≤ 1, where the z-terms
#: of the collapse limits are continued to constants (levels.py): these numbers hold for a set
#: whose range covers z = 2 (``_z_covered``), the default set gives ``CONTINUED_F``,
#: ``CONTINUED_K``.
BEFORE_F = [0.0035406208135961878, 0.43227073150778006, 2.531441568399702]
BEFORE_K = [6.182958386268945, 16.682775575721227, 10.754554212361166]
CONTINUED_F = [0.0035420639657804684, 0.43206427256760727, 2.516628200343591]
CONTINUED_K = [6.186364056083501, 16.65145196474727, 10.668244819759849]


def _z_covered(co: Coefficients) -> Coefficients:
    """``co`` with the default calibrated range but R/R_rigid up to 2 (z ≤ 2)."""
    d = co.to_dict()
    d["provenance"]["calibrated_range"] = dict(DEFAULT_RANGE.to_dict(), R_over_R_rigid=[0.0, 2.0])
    return Coefficients.from_dict(d)


def test_new_keys_round_trip(tmp_path):
    co = v2(XN)
    assert co.collapse_H_bar.xn_poly == (1.5,) and co.collapse_c2.xn_poly == (2.0, -0.8)
    assert co.collapse_sharpness_c2 == 4.0 and co.c2_sharpness == 4.0 and co.collapse_sharpness == 1.6
    assert co.collapse_offset_c2 == -0.3
    d = co.to_dict()
    assert d["collapse"]["H_bar"]["xn_poly"] == [1.5] and d["collapse"]["sharpness_c2"] == 4.0
    assert d["collapse"]["offset_c2"] == -0.3
    assert Coefficients.from_dict(d) == co
    p = tmp_path / "c.json"
    p.write_text(json.dumps(d))
    assert load_coefficients(p) == co


def test_file_without_the_new_keys_gives_the_numbers_of_before():
    co = v2()
    assert co.collapse_H_bar.xn_poly == () and co.collapse_sharpness_c2 is None
    assert co.collapse_offset_c2 is None and co.c2_sharpness == co.collapse_sharpness
    assert not {"sharpness_c2", "offset_c2"} & set(co.to_dict()["collapse"])
    x = np.array([0.02, 0.1, 0.3, 0.6])
    r = BodyLaw(HARD, co).response(x, 0.7 * x, 0.4)
    for f, v in BEFORE.items():
        np.testing.assert_allclose(getattr(r, f), v, rtol=1e-13, atol=1e-15, err_msg=f)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pair = Sphere(1.0, HARD), Sphere(2.0, Material(E=100.0, nu=0.3, sigma_y=1.0))
        st = contact(*pair, np.array([1e-3, 0.03, 0.2]), coeffs=_z_covered(co))
        default = contact(*pair, np.array([1e-3, 0.03, 0.2]), coeffs=co)
    np.testing.assert_allclose(st.F, BEFORE_F, rtol=1e-12)
    np.testing.assert_allclose(st.stiffness, BEFORE_K, rtol=1e-12)
    np.testing.assert_allclose(default.F, CONTINUED_F, rtol=1e-12)
    np.testing.assert_allclose(default.stiffness, CONTINUED_K, rtol=1e-12)
    # writing the keys with their neutral values changes no bit
    explicit = copy.deepcopy(COLLAPSE)
    explicit["H_bar"]["xn_poly"] = []
    explicit["c2"]["xn_poly"] = []
    explicit["sharpness_c2"] = explicit["sharpness"]
    explicit["offset_c2"] = 0.0
    r2 = BodyLaw(HARD, v2(explicit)).response(x, 0.7 * x, 0.4)
    for f in r._fields:
        np.testing.assert_array_equal(getattr(r2, f), getattr(r, f))


@pytest.mark.parametrize("mutate, key", [
    (lambda c: c.update(sharpness_c2=0.0), "collapse.sharpness_c2"),
    (lambda c: c.update(sharpness_c2=-2.0), "collapse.sharpness_c2"),
    (lambda c: c.update(sharpness_c2="2"), "collapse.sharpness_c2"),
    (lambda c: c.update(sharpness_c2=None), "collapse.sharpness_c2"),
    (lambda c: c.update(offset_c2="0"), "collapse.offset_c2"),
    (lambda c: c.update(offset_c2=math.inf), "collapse.offset_c2"),
    (lambda c: c["H_bar"].update(xn_poly="a"), "collapse.H_bar.xn_poly"),
    (lambda c: c["c2"].update(xn_poly=1.0), "collapse.c2.xn_poly"),
    (lambda c: c["c2"].update(xn_poly=[1.0, "b"]), "collapse.c2.xn_poly[1]"),
    (lambda c: c["H_bar"].update(xn_poly=[math.nan]), "collapse.H_bar.xn_poly[0]"),
])
def test_bad_new_keys_name_the_key(mutate, key):
    d = v2(XN).to_dict()
    mutate(d["collapse"])
    with pytest.raises(ValueError, match=re.escape(f"'{key}'")):
        Coefficients.from_dict(d)


def test_limit_log_and_slope_with_xn_terms():
    lim = CollapseLimit(prefactor=1.3, exponent=0.7, x_poly=(0.2,), exp_poly=(0.5,), z_poly=(0.3,),
                        xn_poly=(1.5, -0.6))
    x = np.geomspace(0.02, 1.0, 7)
    n = np.linspace(0.0, 0.6, 7)
    lnL, s, sz = lim.log_and_slope(x, n, 0.2)
    expect = (math.log(1.3) - 0.7 * np.log(x) + 0.2 * x + 0.5 * n + 0.3 * 0.2
              + n * (1.5 * x - 0.6 * x**2))
    np.testing.assert_allclose(lnL, expect, rtol=1e-14)
    e = 1e-7
    fd = (lim.log_and_slope(x * (1 + e), n, 0.2)[0] - lim.log_and_slope(x * (1 - e), n, 0.2)[0]) / (2 * e)
    np.testing.assert_allclose(s, fd, atol=1e-7)
    np.testing.assert_allclose(s, -0.7 + 0.2 * x + n * (1.5 * x - 1.2 * x**2), rtol=1e-13)
    assert np.all(np.abs(s - lim.log_and_slope(x, 0.0, 0.2)[1])[n > 0] > 1e-3)  # n enters the slope
    np.testing.assert_allclose(sz, 0.3)


@pytest.mark.parametrize("kc, s", [(4.0, 0.0), (None, -0.3), (4.0, -0.3)])
def test_c2_weight_of_its_own_leaves_H_bar(kc, s):
    own = {"sharpness_c2": kc, "offset_c2": s}
    co = v2({k: v for k, v in (XN | own).items() if v is not None})
    co0 = v2({k: v for k, v in XN.items() if k not in own})
    x = np.full(5, 0.4)
    H_hs = co.collapse_H_bar(x, 0.2) * np.array([0.3, 0.8, 1.0, 1.5, 4.0])
    c_hs = np.full(5, 1.3)
    b, b0 = levels.collapse_blend(H_hs, c_hs, x, co, 0.2), levels.collapse_blend(H_hs, c_hs, x, co0, 0.2)
    np.testing.assert_array_equal(b.H_bar, b0.H_bar)
    np.testing.assert_array_equal(b.w, b0.w)
    np.testing.assert_array_equal(b0.w_c2, b0.w)
    q = (H_hs / co.collapse_H_bar(x, 0.2) * math.exp(s)) ** (kc or XN["sharpness"])
    wc = q / (1.0 + q)
    np.testing.assert_allclose(b.w_c2, wc, rtol=1e-12)
    np.testing.assert_allclose(b.c2, c_hs ** (1 - wc) * co.collapse_c2(x, 0.2) ** wc, rtol=1e-12)
    assert np.all(np.abs(b.c2 / b0.c2 - 1.0)[[0, 1, 3, 4]] > 1e-3)


@pytest.mark.parametrize("mat", [HARD, Material(E=50.0, nu=0.3, sigma_y=1.0),
                                 Material.from_table(200.0, 0.3, [0, 0.05, 0.5], [1.0, 1.5, 2.2])])
@pytest.mark.parametrize("z", [0.0, 0.6])
def test_body_log_slopes_are_exact_with_the_new_terms(mat, z):
    law = BodyLaw(mat, v2(XN))
    assert law.n_eff > 0.0 or mat.K == 0.0
    x = np.geomspace(0.01, 0.8, 9)
    y = 0.7 * x
    r = assert_body_log_slopes(law, x, y, z)
    assert np.max(np.abs(np.log(r.c2 / BodyLaw(mat, v2()).response(x, y, z).c2))) > 1e-3


SOFT = Material(E=100.0, nu=0.3, sigma_y=1.0)
WALL = Sphere(math.inf, Material.rigid())


@pytest.mark.parametrize("ratio", ["a_over_R", "a_over_rho"])
@pytest.mark.parametrize("s2", [WALL, Sphere(0.5, Material.rigid()), Sphere(1.0, HARD),
                                Sphere(2.0, SOFT)], ids=["flat", "rigid-sphere", "equal", "general"])
def test_two_body_stiffness_and_table_with_the_new_terms(ratio, s2):
    co = v2(XN, ratio=ratio)
    s1 = Sphere(1.0, HARD)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = UnifiedPair(s1, s2, co)
        h = np.geomspace(1e-4, 0.3, 30)
        d = 1e-6
        mid, plus, minus = p.state_from_h(h), p.state_from_h(h * (1 + d)), p.state_from_h(h * (1 - d))
        smooth = (plus.piece == minus.piece) & (plus.piece == mid.piece)
        assert smooth.sum() > 20
        fd = (plus.F - minus.F) / (2 * d * h)
        np.testing.assert_allclose(mid.stiffness[smooth], fd[smooth], rtol=2e-5)
        fda = (np.log(plus.a) - np.log(minus.a)) / (np.log(plus.h) - np.log(minus.h))
        np.testing.assert_allclose((mid.dlnh_dlna * fda)[smooth], 1.0, rtol=2e-5)
        law = ContactLaw(s1, s2, coeffs=co, h_max=0.4)
        assert law.error["F"] < 1e-6
        F, k = law.loading_force(h)
        np.testing.assert_allclose(F, mid.F, rtol=1e-6)
        np.testing.assert_allclose(k[smooth], mid.stiffness[smooth], rtol=1e-5)


def test_new_forms_are_candidates_and_write_the_new_keys():
    # the x·n terms are in every candidate that grows the representative strain
    assert {"smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl", "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_czh",
            "smooth2_fs2_xn2n_x2_g_csl_w1_sn_zn_nl_cz"} <= set(CANDIDATES)
    assert all(FORMS[n].n_collapse_xnH >= 1 for n in CANDIDATES if n.endswith("_g"))
    assert all(FORMS[n].n_collapse_xnH >= 1 for n in CANDIDATES if "_xn" in n)
    base, xn, xnw = FORMS["smooth2_fs2"], FORMS["smooth2_fs2_xn"], FORMS["smooth2_fs2_xnw"]
    assert (xn.n_params, xnw.n_params) == (base.n_params + 2, base.n_params + 4)
    d = xnw.to_dict(xnw.start())
    assert {"sharpness_c2", "offset_c2"} <= set(d["collapse"]) and len(d["collapse"]["c2"]["xn_poly"]) == 1
    assert not {"sharpness_c2", "offset_c2"} & set(xn.to_dict(xn.start())["collapse"])
    # at the start values the own weight equals the common one
    assert xnw.to_dict(xnw.start())["collapse"]["sharpness_c2"] == d["collapse"]["sharpness"]
    # the base form's coefficients are unchanged by the new (empty) terms
    assert base.coefficients(base.start()) == v2_strip(xn.coefficients(_with(xn, base.start())))


def _with(form, base_params):
    """Parameters of ``form``: the base form's values, 0 for the x·n terms."""
    names = FORMS["smooth2_fs2"].names
    v = dict(zip(names, base_params, strict=True))
    return np.array([v.get(n, 0.0) for n in form.names])


def v2_strip(co: Coefficients) -> Coefficients:
    """``co`` without its (zero) x·n terms."""
    d = co.to_dict()
    for k in ("H_bar", "c2"):
        assert not any(d["collapse"][k]["xn_poly"])
        d["collapse"][k]["xn_poly"] = []
    return Coefficients.from_dict(d)


def test_c2_xn_term_is_parametrised_at_X_C2():
    """ln c²_c(X_C2, n) does not depend on the x·n parameter (it moves the slope only)."""
    form = FORMS["smooth2_fs2_xn"]
    i = form.names.index("c2c_xn0")
    p = form.start()
    n = np.array([0.0, 0.2, 0.5])
    ref = form.coefficients(p).collapse_c2.log_and_slope(X_C2, n)[0]
    for v in (-2.0, 1.5):
        p[i] = v
        lim = form.coefficients(p).collapse_c2
        np.testing.assert_allclose(lim.log_and_slope(X_C2, n)[0], ref, rtol=1e-12, atol=1e-12)
        assert abs(lim.log_and_slope(0.2, 0.5)[0] - form.coefficients(form.start()).collapse_c2
                   .log_and_slope(0.2, 0.5)[0]) > 0.1


def test_collapse_penalty_checks_the_c2_slope_at_the_largest_exponent():
    ok = copy.deepcopy(COLLAPSE)
    ok["c2"] = {"prefactor": 0.9, "exponent": 0.0, "x_poly": [0.5], "exp_poly": [], "z_poly": []}
    assert not fitmod.collapse_penalty(v2(ok)).any()
    steep = copy.deepcopy(ok)
    steep["c2"]["xn_poly"] = [4.0]  # d ln c²_c/d ln x = 0.5x + 4 n x: > 1.7 at n = 0.6, x ≥ 0.6
    pen = fitmod.collapse_penalty(v2(steep))
    assert pen.min() < 0.0
    assert pen.size == 2 * fitmod.COLLAPSE_X.size
