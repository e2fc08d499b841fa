"""Fast per-pair table (ContactLaw) against the exact solve, and the ``model curve`` CLI."""

import argparse
import json
import math
import time

import numpy as np
import pytest

from spherecontact.model import Material, Sphere, contact, fast
from spherecontact.model.cli import curve, register
from spherecontact.model.coefficients import LITERATURE, Coefficients, default_coefficients
from spherecontact.model.fast import ContactLaw, contact_table
from spherecontact.model.single import BodyLaw

CO = Coefficients.from_dict(LITERATURE)
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
TAB = Material.from_table(E=110e9, nu=0.34, eps_p=[0.0, 0.02, 0.1, 0.5],
                          sigma=[150e6, 200e6, 260e6, 300e6])
R = 1e-3
PAIRS = {
    "equal": (Sphere(R, STEEL), Sphere(R, STEEL)),
    "dissimilar": (Sphere(R, STEEL), Sphere(2 * R, ALU)),
    "table": (Sphere(R, TAB), Sphere(3 * R, ALU)),
    "wall": (Sphere(R, ALU), Sphere(math.inf, Material.rigid())),
}


@pytest.mark.parametrize("name", PAIRS)
def test_table_error_is_bounded_against_exact_solve(name):
    s1, s2 = PAIRS[name]
    law = ContactLaw(s1, s2, coeffs=CO)
    assert law.monotone
    assert max(law.error["F"], law.error["a"], law.error["stiffness"]) <= 1e-6
    rng = np.random.default_rng(0)
    h = R * np.exp(rng.uniform(math.log(1e-9), math.log(0.5), 3000))
    h = np.concatenate([h, law.kinks, law.kinks * (1 + 1e-7), law.kinks * (1 - 1e-7)])
    ex, fa = contact(s1, s2, h, CO), law(h)
    rel = lambda f: np.max(np.abs(getattr(fa, f) / getattr(ex, f) - 1))  # noqa: E731
    assert rel("F") <= law.error["F"]
    assert rel("a") <= law.error["a"]
    assert rel("stiffness") <= law.error["stiffness"]
    assert np.max(np.abs(fa.h1 - ex.h1) / h) <= max(law.error["h1"], 1e-12)
    F, k = law.force(h)
    assert np.array_equal(F, fa.F) and np.array_equal(k, fa.stiffness)
    hs = np.sort(h)
    assert np.all(np.diff(law.force(hs)[0]) >= 0)


def test_setup_time_and_fallback_outside_table():
    s1, s2 = PAIRS["dissimilar"]
    ContactLaw(s1, s2, coeffs=CO)
    t0 = time.perf_counter()
    law = contact_table(s1, s2, h_max=0.2 * R, coeffs=CO)
    assert time.perf_counter() - t0 < 0.25  # target 50 ms; generous on a loaded machine
    h = np.array([-1.0, 0.0, 1e-16, 0.1 * R, 0.4 * R])
    F, k = law.force(h)
    ex = contact(s1, s2, h, CO)
    assert F[0] == 0.0 and F[1] == 0.0 and k[0] == 0.0
    assert np.allclose(F[2:], ex.F[2:], rtol=1e-6)
    assert np.allclose(law(h).a, ex.a, rtol=1e-6)
    assert np.ndim(law.force(1e-5)[0]) == 0


def test_bad_table_arguments():
    s1, s2 = PAIRS["equal"]
    with pytest.raises(ValueError, match="h_max"):
        ContactLaw(s1, s2, h_max=-1.0)
    with pytest.raises(ValueError, match="h_min < h_max"):
        ContactLaw(s1, s2, h_max=1e-6, h_min=1e-5)


def _parser():
    p = argparse.ArgumentParser()
    register(p.add_subparsers(dest="stage"))
    return p


def test_cli_curve_json_and_csv(tmp_path, capsys):
    p = _parser()
    args = p.parse_args(["model", "curve", "--E", "210e9", "--nu", "0.3", "--sigma-y", "400e6",
                         "--K", "600e6", "--n", "0.3", "--radius", "1e-3", "--E2", "70e9",
                         "--nu2", "0.33", "--sigma-y2", "100e6", "--radius2", "2e-3",
                         "--h-max", "1e-4", "--points", "5", "--json"])
    assert args.func(args) == 0
    out = json.loads(capsys.readouterr().out)
    # the source of the default set: "literature" until calibration writes data/coefficients.json
    assert len(out["F"]) == 5
    assert out["meta"]["coefficients_source"] == default_coefficients().source
    ref = contact(Sphere(1e-3, STEEL), Sphere(2e-3, Material(E=70e9, nu=0.33, sigma_y=100e6,
                                                            K=600e6, n=0.3)), 1e-4)
    assert out["F"][-1] == pytest.approx(float(ref.F), rel=1e-12)
    csv = tmp_path / "c.csv"
    # literature set (no finite-size terms): an elastic sphere on a rigid flat is exact Hertz;
    # the calibrated default adds the finite-sphere term, +0.4 a/R at this a/R = 0.1
    lit = tmp_path / "literature.json"
    lit.write_text(json.dumps(LITERATURE))
    args = p.parse_args(["model", "curve", "--E", "210e9", "--radius", "1e-3", "--E2", "inf",
                         "--radius2", "inf", "--h-max", "1e-5", "--out", str(csv),
                         "--coefficients", str(lit)])
    args.func(args)
    rows = [r for r in csv.read_text().splitlines() if not r.startswith("#")]
    assert rows[0] == "h,F,a,h1,h2,stiffness" and len(rows) == 51
    h, F = map(float, rows[-1].split(",")[:2])
    assert F == pytest.approx(4 / 3 * 210e9 / 0.91 * math.sqrt(1e-3) * h**1.5, rel=1e-9)


def test_cli_bad_input_is_value_error():
    p = _parser()
    args = p.parse_args(["model", "curve", "--E", "210e9", "--nu", "0.7", "--radius", "1e-3",
                         "--h-max", "1e-5"])
    with pytest.raises(ValueError, match="nu"):
        args.func(args)
    with pytest.raises(ValueError, match="h-max"):
        curve(Sphere(R, STEEL), Sphere(R, STEEL), -1.0)


STRONG = (Sphere(R, Material(E=200e9, nu=0.3, sigma_y=1500e6, K=500e6, n=0.2)),
          Sphere(3 * R, Material(E=70e9, nu=0.33, sigma_y=60e6, K=150e6, n=0.4)))
BATCH_PAIRS = {**PAIRS, "rigid_flat": (Sphere(R, STEEL), Sphere(math.inf, Material.rigid())),
               "strong": STRONG}


@pytest.mark.parametrize("name", ["equal", "rigid_flat", "dissimilar", "table", "strong"])
def test_batched_table_states_equal_scalar_solves(name):
    """The build solves nodes, the one-sided points at kinks and the error probes in one
    vectorised κ solve (warm-started from the regular grid): each state equals the exact
    state of that contact radius solved alone from the Hertz start, to 1e-12."""
    law = ContactLaw(*BATCH_PAIRS[name], coeffs=CO)
    p = law.pair
    st = law._node_state
    k = np.nonzero(np.isin(law._lnX_nodes, np.log(law.pair.state_from_h(law.kinks).a / p.R_star)))[0]
    nodes = np.unique(np.concatenate([np.arange(0, st.a.size, 37), [st.a.size - 1], k]))
    probes = np.arange(0, law._probe_state.a.size, 101)
    for batch, sel in ((st, nodes), (law._probe_state, probes)):
        for i in sel:
            one = p.state_at_a(batch.a[i:i + 1])
            for f in ("F", "h", "h1", "stiffness", "dlnh1_dlna"):
                x, y = getattr(batch, f)[i], getattr(one, f)[0]
                assert abs(x - y) <= 1e-12 * max(abs(y), 1e-300), (f, i, x, y)
            assert batch.piece[i] == one.piece[0]


@pytest.mark.parametrize("name", ["dissimilar", "table"])
def test_kinks_are_located_to_the_tolerance(name):
    """Every kink is the first radius of its new piece: the piece changes within _KINK_TOL
    (ln a) below it."""
    law = ContactLaw(*BATCH_PAIRS[name], coeffs=CO)
    p = law.pair
    lnX = law._lnX_nodes[np.isin(np.exp(law._s), law.kinks)]
    assert lnX.size == law.kinks.size > 0
    at = p.state_at_a(p.R_star * np.exp(lnX)).piece
    below = p.state_at_a(p.R_star * np.exp(lnX - 2.0 * fast._KINK_TOL)).piece
    assert np.all(at != below)


@pytest.mark.parametrize("width", [0.02, 0.01, 0.005, 1e-6])
@pytest.mark.parametrize("kinks", [1, 3, 6, 20, 200])
def test_kink_search_sections(width, kinks):
    """Sections per pass: brackets of ``width`` shrink below _KINK_TOL in the fewest passes
    the point budget allows (16 sections per kink at least), and no more sections than that
    number of passes needs (plus the 1 % margin against rounding)."""
    n = fast._sections(width, kinks)
    ratio = width / fast._KINK_TOL
    passes = math.ceil(math.log(ratio) / math.log(n))
    assert n ** passes >= ratio
    assert (n - 1) * kinks <= max(fast._KINK_POINTS, 16 * kinks)
    most = max(fast._KINK_POINTS // kinks, 16)
    assert passes == math.ceil(math.log(ratio) / math.log(most))
    assert n <= 1.01 * ratio ** (1.0 / passes) + 1.0


@pytest.mark.parametrize(("name", "most"), [("dissimilar", 110), ("table", 150), ("equal", 30)])
def test_setup_cost_in_body_responses(monkeypatch, name, most):
    """The setup cost is the number of body-response evaluations (each one vectorised over all
    active points; its fixed cost dominates): 90, 124 and 16 with this coefficient set (178,
    376 and 114 before the κ solves were batched and warm-started)."""
    calls = [0]
    response = BodyLaw.response

    def counted(self, *args, **kw):
        calls[0] += 1
        return response(self, *args, **kw)
    ContactLaw(*BATCH_PAIRS[name], coeffs=CO)  # the pair's domain is cached: not counted
    monkeypatch.setattr(BodyLaw, "response", counted)
    ContactLaw(*BATCH_PAIRS[name], coeffs=CO)
    assert 0 < calls[0] <= most


def test_refinement_is_local_and_keeps_the_error_bound():
    """A pair whose coarse table misses rtol in a few intervals (steel 2R on aluminium R, the
    shipped coefficients) refines only those: ~600 nodes, where halving the step everywhere
    took 2322; the bound and the exact solve still agree with the table."""
    co = default_coefficients()
    s1, s2 = Sphere(2 * R, STEEL), Sphere(R, ALU)
    law = ContactLaw(s1, s2, coeffs=co)
    lo, hi = law._lnX
    coarse = math.ceil((hi - lo) / fast.DEFAULT_STEP) + 1
    assert law.nodes < 1.2 * coarse
    assert max(law.error["F"], law.error["a"], law.error["stiffness"]) <= law.rtol
    h = np.geomspace(law.h_min * 1.01, law.h_max * 0.99, 20001)
    F, _ = law.force(h)
    assert np.max(np.abs(F / contact(s1, s2, h, co).F - 1.0)) <= law.error["F"]


def test_refine_adds_midpoints_only_where_asked():
    reg = np.linspace(0.0, 1.0, 11)
    out = fast._refine(reg, np.array([0.31, 0.72]), np.array([0.34, 0.8]))
    assert set(np.round(np.setdiff1d(out, reg), 12)) == {0.35, 0.75}
