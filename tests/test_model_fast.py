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
    F, k = law.loading_force(h)
    assert np.array_equal(F, fa.F) and np.array_equal(k, fa.stiffness)
    hs = np.sort(h)
    assert np.all(np.diff(law.loading_force(hs)[0]) >= 0)


def test_setup_time_and_fallback_outside_table():
    s1, s2 = PAIRS["dissimilar"]
    ContactLaw(s1, s2, coeffs=CO)
    t0 = time.perf_counter()
    law = contact_table(s1, s2, h_max=0.2 * R, coeffs=CO)
    assert time.perf_counter() - t0 < 0.25  # target 50 ms; generous on a loaded machine
    h = np.array([-1.0, 0.0, 1e-16, 0.1 * R, 0.4 * R])
    F, k = law.loading_force(h)
    ex = contact(s1, s2, h, CO)
    assert F[0] == 0.0 and F[1] == 0.0 and k[0] == 0.0
    assert np.allclose(F[2:], ex.F[2:], rtol=1e-6)
    assert np.allclose(law(h).a, ex.a, rtol=1e-6)
    assert np.ndim(law.loading_force(1e-5)[0]) == 0


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
    # the source of the default set: "literature" until calibration writes model/coefficients.json
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


def test_two_kinks_in_one_grid_step_are_both_found():
    """A flow table with two nodes 1e-4 apart in strain: each of the representative stress's
    three strains crosses both within one grid step of the table. The search goes on above the
    first change it finds while the piece there differs from the piece at the step's upper node
    (``_find_kinks``); with one search per step the second kink was missed and the table's
    stiffness was 42 % off next to it (F 8e-4)."""
    m = Material.from_table(E=200.0, nu=0.3, eps_p=[0.0, 0.02, 0.0201, 0.1, 0.5],
                            sigma=[1.0, 1.3, 1.32, 1.6, 2.0])
    wall = Sphere(math.inf, Material.rigid())
    law = contact_table(Sphere(1.0, m), wall, h_max=0.3, coeffs=CO)
    h = np.geomspace(1e-4, 0.3, 3000)
    F, k = law.loading_force(h)
    exact = contact(Sphere(1.0, m), wall, h, coeffs=CO)
    assert law.error["stiffness"] <= 1e-6
    np.testing.assert_allclose(k, exact.stiffness, rtol=2e-6)
    np.testing.assert_allclose(F, exact.F, rtol=1e-6)


@pytest.mark.parametrize("shipped", [False, True])
@pytest.mark.parametrize("name", ["equal", "rigid_flat", "dissimilar", "table", "strong"])
def test_pieces_without_the_response_are_the_states_pieces(name, shipped):
    """The kink search reads the pieces from the bodies' ratios alone (``piece_at``): the same
    ids as the full states, across levels, flow-table segments and the continuation."""
    co = default_coefficients() if shipped else CO
    p = ContactLaw(*BATCH_PAIRS[name], coeffs=co).pair
    a = p.R_star * np.geomspace(1e-6, 2.0, 4001)
    u = p.solve_u(a) if p.mode == "general" else None
    st = p.state_at_a(a, u)
    assert np.unique(st.piece).size >= 3
    assert np.array_equal(p.piece_at(a, u), st.piece)


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


@pytest.mark.parametrize(("name", "most"), [("dissimilar", 66), ("table", 80), ("equal", 10)])
def test_setup_cost_in_body_responses(monkeypatch, name, most):
    """The setup cost is the number of body-response evaluations (each one vectorised over all
    active points; its fixed cost dominates): 64, 78 and 6 with this coefficient set since the
    kink search's first pass splits a grid interval at every piece change it sees (80, 96 and 6
    when a second change in one interval took a second search; the five survey pairs of
    ``make bench``: 294 against 310 evaluations); 80, 96 and 6 since the
    unloading onset ramp, read at Λ_u, has a kink at each end that the kink search finds (64,
    80 and 6 with one kink at the ramp's end on Λ, where the refinement then had to take the
    ramp's start; the five survey pairs of ``make bench``: 310 against 314 evaluations, the
    unloading table's error 2–3e-4 of F_max against 6–8e-4); 56, 78 and 6 with an earlier
    coefficient set; 90, 124 and 16 when the table's ends were inverted on their own, the kink search
    solved full states and every refinement solved the whole table again; 178, 376 and 114
    before the κ solves were batched and warm-started."""
    calls = [0]
    response = BodyLaw.response

    def counted(self, *args, **kw):
        calls[0] += 1
        return response(self, *args, **kw)
    ContactLaw(*BATCH_PAIRS[name], coeffs=CO)  # the pair's domain is cached: not counted
    monkeypatch.setattr(BodyLaw, "response", counted)
    ContactLaw(*BATCH_PAIRS[name], coeffs=CO)
    assert 0 < calls[0] <= most


@pytest.mark.parametrize(("name", "shipped"), [("equal", False), ("rigid_flat", False), ("dissimilar", False),
                                             ("table", False), ("dissimilar", True), ("strong", True)])
def test_table_ends_are_the_radii_of_h_min_and_h_max(name, shipped):
    """The first and last nodes are the exact states at h_min and h_max (grid interpolation,
    ~1e-9 off with the shipped coefficients, and one Newton step of h(a) = h), to 1e-12."""
    law = ContactLaw(*BATCH_PAIRS[name], coeffs=default_coefficients() if shipped else CO)
    assert math.exp(law._s[0]) == pytest.approx(law.h_min, rel=1e-12, abs=0.0)
    assert math.exp(law._s[-1]) == pytest.approx(law.h_max, rel=1e-12, abs=0.0)


def _agrees_with_exact(law, s1, s2, co):
    """The table's ends are h_min and h_max, its bound ≤ rtol and a dense sweep of the exact
    solve stays within the bound."""
    assert math.exp(law._s[0]) == pytest.approx(law.h_min, rel=1e-12, abs=0.0)
    assert math.exp(law._s[-1]) == pytest.approx(law.h_max, rel=1e-12, abs=0.0)
    assert max(law.error["F"], law.error["a"], law.error["stiffness"]) <= law.rtol
    h = np.geomspace(law.h_min, law.h_max, 5001)
    ex, fa = contact(s1, s2, h, co), law(h)
    for f in ("F", "a", "stiffness"):
        assert np.max(np.abs(getattr(fa, f) / getattr(ex, f) - 1.0)) <= law.error[f]


def test_grid_short_of_the_ends_is_extended(monkeypatch):
    """A regular grid whose estimated range falls short of both ends (it starts from the Hertz
    radii) is extended step by step until it covers them; the table is then the same."""
    s1, s2 = BATCH_PAIRS["strong"]
    ref = ContactLaw(s1, s2, coeffs=CO)
    monkeypatch.setattr(fast, "_BELOW", -3.0)   # three steps above the Hertz radius of h_min
    monkeypatch.setattr(fast, "_WIDER", -0.2)   # below the radius of h_max (plastic: wider)
    monkeypatch.setattr(fast, "_EXTEND", 2)
    law = ContactLaw(s1, s2, coeffs=CO)
    _agrees_with_exact(law, s1, s2, CO)
    assert law.nodes == ref.nodes
    assert np.allclose(law._lnX, ref._lnX, rtol=0.0, atol=1e-12)


def test_ends_fall_back_to_the_exact_inversion(monkeypatch):
    """Where the Newton step of an end is larger than _END_STEP, the end is the exact
    inversion h → a (here forced for both ends)."""
    s1, s2 = BATCH_PAIRS["dissimilar"]
    ref = ContactLaw(s1, s2, coeffs=CO)
    inverted = []
    a_from_h = type(ref.pair).a_from_h

    def counted(self, h):
        inverted.append(np.size(h))
        return a_from_h(self, h)
    monkeypatch.setattr(type(ref.pair), "a_from_h", counted)
    monkeypatch.setattr(fast, "_END_STEP", -1.0)  # every step is larger
    law = ContactLaw(s1, s2, coeffs=CO)
    assert inverted == [2]
    _agrees_with_exact(law, s1, s2, CO)
    assert np.allclose(law._lnX, ref._lnX, rtol=0.0, atol=1e-12)


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
    F, _ = law.loading_force(h)
    assert np.max(np.abs(F / contact(s1, s2, h, co).F - 1.0)) <= law.error["F"]


def test_refinement_keeps_nodes_and_probes_in_order():
    """A tighter rtol refines (midpoints of the intervals whose probes miss it, merged with the
    kept nodes and probes): every node's state is that node's, every interval's probes lie at
    _PROBES of it, and the bound and the exact solve agree with the table."""
    s1, s2 = BATCH_PAIRS["table"]
    coarse = ContactLaw(s1, s2, coeffs=CO)
    law = ContactLaw(s1, s2, coeffs=CO, rtol=3e-8)
    assert law.nodes > coarse.nodes + 20
    X = law._lnX_nodes
    Rs = law.pair.R_star
    assert np.allclose(np.log(law._node_state.a / Rs), X, rtol=0.0, atol=1e-14)
    probes = np.log(law._probe_state.a / Rs).reshape(X.size - 1, len(fast._PROBES))
    want = X[:-1, None] + np.diff(X)[:, None] * np.array(fast._PROBES)[None, :]
    assert np.allclose(probes, want, rtol=0.0, atol=1e-14)
    _agrees_with_exact(law, s1, s2, CO)


def test_h_over_R_limit_is_read_from_the_table():
    """h_calibrated of a dissimilar pair, whose shares h_i/h change with h, is where the exact
    max_i h_i/R_i reaches the calibrated h/R = 0.3, to the table's bound (interpolating the
    nodes' h_i/R_i/h linearly in ln h was off by up to ~2e-6, depending on where the nodes
    fall)."""
    pp = Material(E=200.0, nu=0.3, sigma_y=1.0)
    for s2 in (Sphere(3.0, Material(E=500.0, nu=0.25, sigma_y=2.5, K=1.0, n=0.2)),
               Sphere(2.0, Material.elastic(E=400.0, nu=0.3))):
        s1 = Sphere(1.0, pp)
        law = ContactLaw(s1, s2, coeffs=CO)
        assert law.h_min < law.h_calibrated < law.h_max
        end = contact(s1, s2, np.array([law.h_calibrated]), CO)
        own = max(float(end.h1[0]) / s1.radius, float(end.h2[0]) / s2.radius)
        assert own == pytest.approx(0.3, rel=1e-8, abs=0.0)


def test_midpoints_only_where_asked():
    nodes = np.linspace(0.0, 1.0, 11)
    bad = np.zeros(10, dtype=bool)
    bad[[3, 7]] = True
    assert np.allclose(fast._midpoints(nodes, bad), [0.35, 0.75])
