"""Validation stage: error metrics, peer laws on cases, thresholds and exit status, report files."""

import math

import numpy as np
import pytest

from spherecontact import peers
from spherecontact.metrics import (
    interp_loglog,
    pool,
    relative_error,
    summarise,
    trapezoid_weights,
)
from spherecontact.model import Material, Sphere, contact
from spherecontact.validation import cases as vcases
from spherecontact.validation.cases import Case, classes, reference_radius, spheres
from spherecontact.validation.compare import W_ACCEPT, compare_case
from spherecontact.validation.config import Thresholds, load_thresholds
from spherecontact.validation.peer_scenes import NotApplicable, predict_peers
from spherecontact.validation.tables import failures

PP200 = {"E": 200.0, "nu": 0.3, "sigma_y": 1.0, "K": 0.0, "n": 1.0}
TH = Thresholds()



def _validate(argv: list[str]) -> int:
    """``spherecontact validate ARGV``."""
    from spherecontact.cli import main

    return main(["validate", *argv])

def make_case(name="run", scene="flat", material=PP200, h=None, scale_F=1.0, scale_a=1.0,
              set="validation", radius2=None, material2=None, indenter_radius=math.inf,
              params=None, wall_s=100.0, extra_inputs=None):
    """A case whose 'FE' curves are the model's own, optionally scaled (a deliberately off FE)."""
    h = np.geomspace(2e-4, 0.3, 60) if h is None else np.asarray(h, float)
    inputs = {"material": dict(material), "radius": 1.0, "indenter_radius": indenter_radius,
              "h_max": float(h[-1]), "mesh_density": 1.0, "element": "q8r",
              "options": {"strain_increment": 0.005}}
    if scene == "two_body":
        inputs["radius2"] = radius2
        inputs["material2"] = dict(material2 or material)
    for k, v in (params or {}).items():  # study variants are real inputs of the run
        if k in ("mesh_density", "element"):
            inputs[k] = v
        elif k in ("strain_increment", "penalty"):
            inputs["options"][k] = v
    inputs.update(extra_inputs or {})
    c0 = Case("k-" + name, set, name, {"scene": scene, **(params or {})}, inputs, {"h": h})
    s1, s2 = spheres(c0)
    st = contact(s1, s2, h)
    curves = {"h": h, "F": st.F * scale_F, "a": st.a * scale_a,
              "iterations": np.full(h.size, 5.0), "work_external": np.cumsum(st.F) * 1e-3,
              "energy_elastic": np.cumsum(st.F) * 5e-4, "dissipation": np.cumsum(st.F) * 5e-4}
    if scene == "two_body":
        curves["h1"], curves["h2"] = st.h1, st.h2
    return Case(c0.key, set, name, c0.params, inputs, curves, wall_s=wall_s,
                provenance={"wall_s": wall_s})


# ============================================================================ metrics
def test_relative_error_and_summary_on_known_errors():
    ref = np.array([1.0, 2.0, 4.0, 0.0])
    e = relative_error(ref * 1.03, ref)
    assert np.allclose(e[:3], 0.03) and np.isnan(e[3])
    s = summarise(e)
    assert s.max == pytest.approx(0.03) and s.rms == pytest.approx(0.03) and s.n == 3
    assert summarise(e, np.zeros(4, bool)).empty


def test_rms_is_uniform_in_h_and_grid_independent():
    # e(h) = 0.1 h on [0, 1]: RMS = 0.1/√3 whatever the spacing of the points
    for h in (np.linspace(0, 1, 2001), np.sqrt(np.linspace(0, 1, 2001))):
        s = summarise(0.1 * h, weights=trapezoid_weights(h))
        assert s.rms == pytest.approx(0.1 / math.sqrt(3), rel=1e-4)
        assert s.max == pytest.approx(0.1)


def test_pool_and_interpolation():
    a, b = summarise(np.array([0.02, -0.04])), summarise(np.array([0.01]))
    p = pool([a, b, summarise(np.array([np.nan]))])
    assert p.max == pytest.approx(0.04) and p.rms == pytest.approx(math.sqrt((a.rms**2 + b.rms**2) / 2))
    x = np.geomspace(1e-3, 1, 7)
    y = 3 * x**1.5
    xn = np.array([5e-4, 2e-3, 0.5, 2.0])
    out = interp_loglog(xn, x, y)
    assert np.isnan(out[0]) and np.isnan(out[3])
    assert np.allclose(out[1:3], 3 * xn[1:3] ** 1.5, rtol=1e-12)  # power laws are exact


# ============================================================================ scenes and peers
def test_flat_scene_is_the_equal_pair_at_twice_the_approach():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    h = np.geomspace(1e-4, 0.3, 30)
    flat = contact(Sphere(1.0, m), Sphere(math.inf, Material.rigid()), h)
    pair = contact(Sphere(1.0, m), Sphere(1.0, m), 2 * h)
    assert np.allclose(flat.F, pair.F, rtol=1e-10) and np.allclose(flat.a, pair.a, rtol=1e-10)
    assert np.allclose(pair.h1, h, rtol=1e-10)


def test_classes_and_reference_radius():
    assert classes(make_case()) == ("equal spheres",)
    lud = {**PP200, "K": 2.0, "n": 0.2}
    assert classes(make_case(material=lud)) == ("equal spheres", "hardening levels")
    rig = make_case(scene="rigid_sphere", indenter_radius=2.0)
    assert classes(rig) == ("rigid indenter",) and reference_radius(rig) == 1.0
    two = make_case(scene="two_body", radius2=0.5, material2={**PP200, "sigma_y": 3.0},
                    h=np.geomspace(2e-4, 0.1, 20))
    assert classes(two) == ("dissimilar radii", "dissimilar materials")
    assert reference_radius(two) == 0.5


@pytest.mark.parametrize("scene,kw", [
    ("flat", {}),
    ("rigid_sphere", {"indenter_radius": 2.0}),
    ("two_body", {"radius2": 2.0, "material2": {**PP200, "E": 600.0, "nu": 0.25}}),
])
def test_peers_give_hertz_in_the_elastic_limit(scene, kw):
    """Far below first yield every applicable law is Hertz with the scene's E*, R*."""
    h = np.geomspace(1e-8, 1e-6, 5)
    case = make_case(scene=scene, h=h, **kw)
    s1, s2 = spheres(case)
    E_star = 1 / (1 / s1.material.E_prime + (0 if s2.is_rigid else 1 / s2.material.E_prime))
    R_star = 1 / (1 / s1.radius + 1 / s2.radius)
    hz = peers.hertz(h, E_star, R_star)
    pred = predict_peers(case)
    for name in ("Hertz", "Jackson–Green 2005", "Kogut–Etsion 2002", "Thornton 1997"):
        assert np.allclose(pred[name].F, hz.F, rtol=1e-12), name
        assert np.allclose(pred[name].a, hz.a, rtol=1e-12), name
    # and the model tends to Hertz there too: its finite-size terms are linear in a/R
    # (docs/design.md §2), so the relative difference is at most of order a/R and vanishes with it
    st = contact(s1, s2, h)
    x = hz.a / min(s1.radius, s2.radius)
    for q in ("F", "a"):
        rel = np.abs(getattr(st, q) / getattr(hz, q) - 1)
        assert np.all(rel <= 2.0 * x), q
        assert rel[0] < 0.2 * rel[-1] + 1e-12, q  # a/R grows tenfold over h: so must the deviation


def test_peer_applicability_reasons():
    lud = make_case(material={**PP200, "K": 2.0, "n": 0.2})
    p = predict_peers(lud)
    for name in ("Jackson–Green 2005", "Kogut–Etsion 2002", "Thornton 1997", "Johnson cavity"):
        assert isinstance(p[name], NotApplicable) and "hardens" in p[name].reason
    assert not isinstance(p["Biwa–Storåkers 1995"], NotApplicable)  # secant power law
    two = make_case(scene="two_body", radius2=1.0, material2={**PP200, "sigma_y": 3.0},
                    h=np.geomspace(2e-4, 0.1, 20))
    p = predict_peers(two)
    assert isinstance(p["Biwa–Storåkers 1995"], NotApplicable)
    assert isinstance(p["Johnson cavity"], NotApplicable)
    assert "σ_Y = 1" in p["Jackson–Green 2005"].note  # the softer body yields first


def test_equal_pair_biwa_storakers_matches_the_flat_scene():
    """Equal materials, unequal radii: each body at h/2 and ρ = 2R* — for R_1 = R_2 the flat scene."""
    lud = {**PP200, "K": 2.0, "n": 0.3}
    h = np.geomspace(1e-3, 0.1, 10)
    flat = predict_peers(make_case(material=lud, h=h))["Biwa–Storåkers 1995"]
    pair = predict_peers(make_case(scene="two_body", radius2=1.0, material=lud, h=2 * h))
    assert np.allclose(pair["Biwa–Storåkers 1995"].F, flat.F, rtol=1e-12)


# ============================================================================ comparison and thresholds
def test_model_on_its_own_curves_has_zero_error_and_two_body_split():
    c = compare_case(make_case(scene="two_body", radius2=2.0, material2={**PP200, "sigma_y": 2.0},
                               h=np.geomspace(2e-4, 0.3, 40)), None, TH)
    for q in ("F", "a", "h1", "h2", "split"):
        assert c.model.summary(W_ACCEPT, q).max < 1e-9, q
    assert failures([c], TH) == []


def test_scaled_fe_curve_fails_with_the_known_error():
    good = compare_case(make_case("good"), None, TH)
    off = compare_case(make_case("off", scale_F=1 / 1.08), None, TH)  # model 8 % above "FE"
    assert off.model.summary(W_ACCEPT, "F").max == pytest.approx(0.08, rel=1e-9)
    assert off.model.summary(W_ACCEPT, "a").max < 1e-9
    f = failures([good, off], TH)
    assert [x.label for x in f] == ["off"] and "F max error 8.0 %" in str(f[0])


def test_thresholds_file(tmp_path):
    th = load_thresholds("validation/thresholds.toml")
    assert th.F_max == 0.05 and th.a_max == 0.05 and th.h_over_R_max == 0.3
    bad = tmp_path / "t.toml"
    bad.write_text("[model]\nF_maks = 0.1\n")
    with pytest.raises(ValueError, match="F_maks"):
        load_thresholds(bad)
    bad.write_text("[model]\nF_max = -1\n")
    with pytest.raises(ValueError, match="F_max"):
        load_thresholds(bad)


def _studies():
    kw = dict(set="studies", h=np.geomspace(2e-4, 0.3, 50))
    return [make_case("base", wall_s=100, **kw),
            make_case("fine", scale_F=1.002, wall_s=800, params={"mesh_density": 2.0}, **kw),
            make_case("dt", scale_F=0.999, wall_s=150, params={"strain_increment": 0.0025}, **kw),
            make_case("dt4", scale_F=1.01, wall_s=60, params={"strain_increment": 0.02}, **kw),
            make_case("q4", scale_F=1.2, wall_s=90, params={"element": "q4"}, **kw),
            make_case("pen", scale_F=0.97, wall_s=90, params={"penalty": 100.0}, **kw),
            make_case("extreme", wall_s=300, set="studies", h=np.geomspace(2e-4, 0.6, 60))]


def test_cli_exit_status_names_failing_runs(tmp_path, monkeypatch, capsys):
    main = _validate

    runs = {"validation": [make_case("fine_run", h=np.geomspace(2e-4, 0.3, 30)),
                           make_case("scaled_run", scale_F=1.1, h=np.geomspace(2e-4, 0.3, 30))],
            "studies": _studies()}
    monkeypatch.setattr(vcases, "load_cases", lambda db, s: runs.get(s, []))
    monkeypatch.setattr(vcases, "load_records", lambda db, s: [])
    db = tmp_path / "db.h5"
    db.write_bytes(b"")
    out = tmp_path / "report"
    rc = main(["--db", str(db), "--out", str(out), "--thresholds", "validation/thresholds.toml"])
    err = capsys.readouterr().err
    assert rc == 1 and "scaled_run" in err and "fine_run" not in err
    text = (out / "index.md").read_text()
    assert "**FAIL**" in text and "scaled_run" in text
    for png in ("speed_accuracy.png", "stability_locking.png", "stability_penalty.png",
                "stability_increments.png", "stability_extreme.png", "model_outside_range.png",
                "error_vs_lambda.png", "curves_fine_run.png"):
        assert (out / png).stat().st_size > 1000, png
    assert "does not warn" in text or "warned" in text
    # all runs within the thresholds: exit 0
    runs["validation"], runs["studies"] = runs["validation"][:1], []
    assert main(["--db", str(db), "--out", str(out)]) == 0
    # no database: exit 2
    assert main(["--db", str(tmp_path / "missing.h5"), "--out", str(out)]) == 2


# ============================================================================ through the database
def _result(case: Case):
    """A RunResult holding a case's curves (the fixture database stores real run groups)."""
    from spherecontact.fem.solver import RunResult

    n = case.raw_curve("h").size   # every increment (case.h leaves the start transient out)
    curves = {k: np.asarray(v, float) for k, v in case.curves.items()}
    F, a = curves["F"], curves["a"]
    curves.update(F_support=F.copy(), a_nodes=a.copy(), a_ref=a.copy(), p_m=F / (np.pi * a**2),
                  eps_p_max=np.linspace(0, 0.3, n), active_changes=np.zeros(n))
    final = {"X": np.zeros((2, 4)), "u": np.zeros(8), "cells": np.array([[0, 1, 2, 3]]),
             "eps_p": np.zeros((1, 4))}
    return RunResult(inputs=case.inputs, curves=curves, residuals=[[1e-3, 1e-9]] * n,
                     profile_r=np.zeros((n, 3)), profile_p=np.zeros((n, 3)), profile_g=np.zeros((n, 3)),
                     status="converged", reason="reached h_max",
                     timings={"wall_s": case.wall_s, "increments": n}, final=final)


def _fixture_database(path, cases):
    from spherecontact.data import Record, append_run, input_key

    for c in cases:
        key = input_key(c.inputs)
        rec = Record(key, c.set, c.name, "converged", "reached h_max", c.wall_s, c.inputs, c.params)
        append_run(path, rec, _result(c))


def test_report_from_a_fixture_database(tmp_path, capsys):
    main = _validate

    db = tmp_path / "reference.h5"
    val = [make_case("flat-E300", material={**PP200, "E": 300.0}, h=np.geomspace(2e-4, 0.3, 25)),
           make_case("two-R2-Y2", scene="two_body", radius2=2.0, material2={**PP200, "sigma_y": 2.0},
                     h=np.geomspace(2e-4, 0.3, 25), scale_F=1 / 1.07)]
    _fixture_database(db, val + _studies()[:3])
    out = tmp_path / "report"
    rc = main(["--db", str(db), "--out", str(out), "--coefficients", "model/coefficients.json"])
    err = capsys.readouterr().err
    assert rc == 1 and "two-R2-Y2" in err and "flat-E300" not in err
    text = (out / "index.md").read_text()
    assert "dissimilar radii" in text and "h₁/h split" in text
    # the flat run's first step (2e-4 R) crossed first yield; the pair's stayed elastic
    assert "FE increments: 1 of the runs began with a first step larger than today's" in text
    assert (out / "curves_two_r2_y2.png").stat().st_size > 1000
    assert (out / "speed_accuracy.png").stat().st_size > 1000


@pytest.mark.slow
def test_report_from_tiny_fe_runs(tmp_path):
    """Real coarse FE runs (flat and a dissimilar pair) through the database and the CLI."""
    from spherecontact.data import Record, append_run, input_key
    from spherecontact.fem.io import run_indentation
    main = _validate

    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    db = tmp_path / "reference.h5"
    for name, kw in (("flat", {"density": 0.5}),
                     ("two-R2-Y2", {"density": 0.25, "radius2": 2.0,
                                    "material2": Material(E=200.0, nu=0.3, sigma_y=2.0)})):
        res = run_indentation(m, 1.0, 0.02, **kw)
        rec = Record(input_key(res.inputs), "validation", name, res.status, res.reason,
                     res.timings["wall_s"], res.inputs, {})
        append_run(db, rec, res)
    out = tmp_path / "report"
    rc = main(["--db", str(db), "--out", str(out)])
    assert rc in (0, 1)
    text = (out / "index.md").read_text()
    assert "flat" in text and "two-R2-Y2" in text and "dissimilar radii" in text
    assert (out / "curves_two_r2_y2.png").stat().st_size > 1000


def test_scatter_measures_noise_not_curvature():
    from spherecontact.metrics import scatter

    h = np.geomspace(1e-3, 0.3, 200)
    smooth = 2 * h**1.3 * (1 + h)
    assert scatter(h, smooth) < 1e-4
    wiggle = smooth * (1 + 0.01 * (-1) ** np.arange(h.size))
    assert 0.008 < scatter(h, wiggle) < 0.015  # ±1 % alternating noise (ends one-sided)
    from spherecontact.metrics import smooth_loglog

    assert np.allclose(smooth_loglog(h, smooth), smooth, rtol=1e-4)
    assert np.max(np.abs(smooth_loglog(h, wiggle)[10:-10] / smooth[10:-10] - 1)) < 0.002


def test_local_fit_reads_through_the_steps_that_the_point_value_sits_on():
    from spherecontact.metrics import local_fit_at

    h = np.geomspace(1e-3, 0.3, 200)
    smooth = 2 * h**1.3 * (1 + h)
    steps = smooth * (1 + 0.02 * (np.arange(h.size) % 4 == 0))  # +2 % on every 4th increment
    at = float(h[100])  # an increment on a step
    assert steps[100] / smooth[100] - 1 == pytest.approx(0.02)
    assert abs(local_fit_at(h, steps, at) / (2 * at**1.3 * (1 + at)) - 1.005) < 0.002  # the mean offset
    with pytest.raises(ValueError, match="window = 11"):
        local_fit_at(h[:5], smooth[:5], at)


def test_study_runs_outside_the_database(tmp_path):
    """Verification JSON (inputs from the verification plan) and study files (inputs stored)."""
    import json

    from validation_fem_reports import load_verification_runs

    from spherecontact.validation.studies import variant
    from spherecontact.validation.study_runs import load_study_files

    c = make_case("x", h=np.geomspace(2e-4, 0.3, 20))
    curves = {k: v.tolist() for k, v in c.curves.items()}
    (tmp_path / "run_standard_fine.json").write_text(json.dumps(
        {"curves": curves, "status": "converged", "reason": "", "timings": {"wall_s": 900.0}}))
    (tmp_path / "run_hertz.json").write_text("{}")  # elastic verification run: not a study
    inputs = {**c.inputs, "options": {"strain_increment": 0.02}}
    (tmp_path / "standard_de0.02.json").write_text(json.dumps(
        {"inputs": inputs, "curves": curves, "status": "converged", "reason": "",
         "timings": {"wall_s": 60.0}}, default=float))
    (fine,) = load_verification_runs(tmp_path)
    assert fine.name == "standard_fine" and fine.wall_s == 900.0
    assert variant(fine, TH).mesh_density == 2.0 and variant(fine, TH).kind == "refinement"
    (de,) = load_study_files(tmp_path)
    assert variant(de, TH).strain_increment == 0.02 and de.label == "standard_de0.02"


def test_report_reads_no_uncommitted_verification_runs_by_default():
    """The FE verification runs (reports/fem/run_*.json, git-ignored) never enter the studies of
    ``spherecontact validate`` (only ``studies/validation_fem_reports.py`` reads them), so the same
    repository gives the same report on every machine."""
    from spherecontact.cli import build_parser

    args = build_parser().parse_args(["validate"])
    assert args.study_runs == "data/validation_studies" and not hasattr(args, "studies_fallback")
    assert args.converged_fe == "data/increments_v2.json"


def test_small_contact_section_reads_the_model_against_converged_fe(tmp_path):
    """A stored 'FE' 3 % below the model whose converged re-run is the model's own curve: the
    model's 3 % error there is the FE's (``increments_report``)."""
    import json

    from spherecontact.validation.increments_report import (
        load_converged,
        small_contact_rows,
        small_contact_section,
    )

    low = make_case("low", scale_F=1 / 1.03)
    s1, s2 = spheres(low)
    hc = np.geomspace(1e-4, 0.01, 80)
    Fc = contact(s1, s2, hc).F
    path = tmp_path / "increments_validation.json"
    path.write_text(json.dumps({"date_utc": "2026-11-27", "h_end": 0.01, "cases": [
        {"key": low.key, "relative_step": 0.03, "curve": {"h": hc.tolist(), "F": Fc.tolist()}}]}))
    store = load_converged(path)
    assert load_converged(tmp_path / "absent.json") is None
    comp = compare_case(low, None, TH)
    (row,) = small_contact_rows([comp, compare_case(make_case("other"), None, TH)], store)
    assert row["run"] == "low" and row["points"] > 5
    assert row["fe"][0] == pytest.approx(1 / 1.03 - 1, abs=2e-3)
    assert row["model_stored"][0] == pytest.approx(0.03, abs=1e-9)
    assert abs(row["model_converged"][0]) < 2e-3 and row["model_converged"][1] <= 0.01
    text = "\n".join(small_contact_section([comp], store))
    assert "closer to the converged curve on 1 of 1 runs" in text
    assert "not compared" in "\n".join(small_contact_section([comp], None))
