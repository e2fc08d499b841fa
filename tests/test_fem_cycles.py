"""Unloading and reloading cycles of the FE solver (fem/solver.py ``unload_at``)."""

import math

import numpy as np
import pytest

from spherecontact.cli import main
from spherecontact.fem import read_run, run_indentation, write_run
from spherecontact.fem.solver import (
    LOAD,
    RELOAD,
    UNLOAD,
    IndentationSolver,
    check_unload_at,
    pole_radius,
    quadratic_work,
    residual_approach,
)
from spherecontact.model import Material

ELASTIC = Material(E=200.0, nu=0.3, sigma_y=math.inf)
EPP = Material(E=200.0, nu=0.3, sigma_y=1.0)


@pytest.fixture(scope="module")
def elastic_run():
    return IndentationSolver(ELASTIC, 1.0, density=0.5).run(0.004, unload_at=[0.002, 0.004])


@pytest.fixture(scope="module")
def plastic_run():
    return IndentationSolver(EPP, 1.0, density=0.5).run(0.012, unload_at=[0.006, 0.01])


@pytest.mark.parametrize("bad, message", [
    ([0.0, 0.1], r"\(0, h_max\]"), ([0.1, 0.4], r"\(0, h_max\]"), ([0.2, 0.1], "strictly increasing"),
    ([], "non-empty"), ([float("nan")], "finite"),
])
def test_bad_schedules_are_named(bad, message):
    with pytest.raises(ValueError, match="unload_at") as err:
        check_unload_at(bad, 0.3)
    assert err.match(message)


def test_helpers_against_closed_forms():
    h = np.array([0.9, 0.8])
    assert residual_approach(h, 3.0 * (h - 0.35) ** 1.5) == pytest.approx(0.35, rel=1e-12)
    r = np.linspace(0.0, 0.2, 9)
    assert pole_radius(r, 5.0 - np.sqrt(5.0**2 - r**2) + 0.1, 0.2) == pytest.approx(5.0, rel=2e-3)
    assert quadratic_work(0.0, 1.0, 2.0, 0.0, 1.0, 4.0) == pytest.approx(7.0 / 3.0, rel=1e-12)  # ∫₁² h² dh


def test_elastic_unloading_retraces_loading(elastic_run):
    r = elastic_run
    c, cyc = r.curves, r.cycles
    assert set(np.unique(c["branch"])) == {LOAD, UNLOAD, RELOAD}
    assert cyc["h_max"].tolist() == pytest.approx([0.002, 0.004])
    # elastic: no residual dent (to within the last contact ring of this coarse pole mesh)
    assert np.all(cyc["h_res"] / cyc["h_max"] < 0.03)
    ip, ie = int(cyc["increment_peak"][1]), int(cyc["increment_end"][1])
    load = np.flatnonzero(c["branch"] == LOAD)
    up = np.arange(ip, ie + 1)
    sel = up[c["F"][up] > 0.05 * cyc["F_max"][1]]
    ref = np.exp(np.interp(np.log(c["h"][sel]), np.log(c["h"][load]), np.log(c["F"][load])))
    assert np.max(np.abs(c["F"][sel] / ref - 1)) < 0.01
    balance = (cyc["work_in"] - cyc["work_returned"]) / cyc["work_in"]
    assert np.all(np.abs(balance) < 2e-3) and np.all(cyc["dissipation"] == 0.0)


def test_plastic_cycle_leaves_a_dent_and_reloads_elastically(plastic_run):
    r = plastic_run
    c, cyc = r.curves, r.cycles
    assert r.status == "converged" and cyc["h_max"].size == 2
    ratio = cyc["h_res"] / cyc["h_max"]
    assert np.all((ratio > 0.3) & (ratio < 0.95)) and ratio[1] > ratio[0]
    assert np.all(cyc["dissipation"] > 0) and np.all(cyc["pole_radius"] > 1.0)  # flattened pole
    lhs = cyc["work_in"] - cyc["work_returned"]
    rhs = cyc["dissipation"] + cyc["elastic_energy_change"]
    assert np.all(np.abs(lhs / rhs - 1) < 0.02)
    first = np.arange(int(cyc["increment_start"][1]), int(cyc["increment_peak"][1]))
    first = first[c["branch"][first] == RELOAD]  # the reload that opens the second cycle
    assert first.size > 3  # elastic reloading up to h_max: no new dissipation
    assert c["dissipation"][first].max() - c["dissipation"][first].min() < 0.01 * cyc["dissipation"][0]
    assert c["h"][-1] == pytest.approx(0.012) and c["branch"][-1] == LOAD


def test_stiff_sphere_cycle_closes_its_energy_balance():
    """EPP E/σY = 1000, one cycle at h/R = 0.001 (coarse mesh). With the strain bound alone its
    loading took 35 increments (the stress deviator of the flowing points rotating 0.2-0.4 rad per
    step) and work in − returned fell 1.6 % short of dissipation + Δ stored; a cycle's new loading
    now takes ≥ CYCLE_LOADING × unload_increments increments: 0.07 %. Monotone runs keep their steps."""
    from spherecontact.fem.solver import CYCLE_LOADING, SolverOptions

    stiff = Material(E=1000.0, nu=0.3, sigma_y=1.0)
    res = IndentationSolver(stiff, 1.0, density=0.5).run(0.001, unload_at=[0.001])
    cyc = res.cycles
    assert res.status == "converged" and cyc["h_max"].tolist() == pytest.approx([0.001])
    error = (cyc["work_in"] - cyc["work_returned"] - cyc["dissipation"] - cyc["elastic_energy_change"])
    assert abs(error[0]) < 0.01 * cyc["work_in"][0]  # the cycle verification's target
    loading = int(cyc["increment_peak"][0]) + 1
    assert loading >= CYCLE_LOADING * SolverOptions().unload_increments
    mono = IndentationSolver(stiff, 1.0, density=0.5).run(0.001)
    assert mono.timings["increments"] < 0.75 * loading  # the bound is the cycle's alone


def test_cycles_survive_the_run_file(plastic_run, tmp_path):
    path = write_run(tmp_path / "run.h5", plastic_run)
    back = read_run(path)
    assert np.array_equal(back.branch, plastic_run.curves["branch"])
    assert np.allclose(back.cycles["h_res"], plastic_run.cycles["h_res"])
    assert back.cycles["profile_z"].shape == (2, back.profile_r.shape[1])


def test_equal_pair_doubles_the_approaches():
    res = run_indentation(EPP, 1.0, 0.012, radius2=1.0, material2=EPP, density=0.5, unload_at=[0.012])
    assert res.inputs["scene"] == "equal_pair_symmetry"
    assert res.cycles["h_max"][0] == pytest.approx(0.012)
    assert 0.3 < res.cycles["h_res"][0] / 0.012 < 0.95


def test_two_deformable_bodies_unload_and_reload():
    """Elastic pair E₂/E₁ = 3: no dent, the split h₁/h stays E₂'/(E₁' + E₂') on unloading;
    a plastic pair of yield ratio 3 leaves a dent, mostly in the softer body."""
    stiff = Material(E=600.0, nu=0.3, sigma_y=math.inf)
    el = run_indentation(ELASTIC, 1.0, 0.004, radius2=1.0, material2=stiff, density=0.5, unload_at=[0.004],
                         scene="two_body")
    c, cyc = el.curves, el.cycles
    assert el.inputs["scene"] == "two_body" and el.status == "converged"
    assert cyc["h_res"][0] / cyc["h_max"][0] < 0.03
    unl = (c["branch"] == UNLOAD) & (c["F"] > 0.2 * cyc["F_max"][0])
    assert np.allclose(c["h1"][unl] / c["h"][unl], 0.75, atol=0.02)
    hard = Material(E=200.0, nu=0.3, sigma_y=3.0)
    pl = run_indentation(EPP, 1.0, 0.01, radius2=1.0, material2=hard, density=0.5, unload_at=[0.01],
                         scene="two_body")
    assert 0.3 < pl.cycles["h_res"][0] / 0.01 < 0.95
    assert pl.curves["dissipation_1"][-1] > 10 * pl.curves["dissipation_2"][-1]
    balance = pl.cycles["work_in"] - pl.cycles["work_returned"]
    assert balance[0] == pytest.approx(pl.cycles["dissipation"][0] + pl.cycles["elastic_energy_change"][0],
                                       rel=0.03)


def test_cli_rejects_a_bad_schedule_before_any_work(tmp_path, capsys):
    code = main(["fem", "run", "--E", "200", "--h-max", "0.02", "--unload-at", "0.03",
                 "--out", str(tmp_path / "x.h5")])
    assert code == 2 and "unload_at" in capsys.readouterr().err
    assert not (tmp_path / "x.h5").exists()


def test_unloading_tail_that_fails_ends_the_branch_with_an_extrapolated_residual_approach(
        plastic_run, monkeypatch):
    """Near zero force the whole contact can open at once and Newton fail; below UNLOAD_TAIL
    F_max the branch ends there (h_res extrapolated, F_end kept) instead of stopping the run.
    Simulated here: every unloading step (h decreasing) from F < 1 % F_max fails, with
    UNLOAD_TAIL at 2 %."""
    from spherecontact.fem import solver as fs

    monkeypatch.setattr(fs, "UNLOAD_TAIL", 0.02)
    solver = IndentationSolver(EPP, 1.0, density=0.5)
    solve = solver._solve

    def failing_near_zero(run, h_new, *args, **kw):
        if h_new < run.h and solver._hist.branch[-1] == UNLOAD and run.F < 1e-2 * run_peak(solver):
            return fs.IncrementFailed("roundoff floor (simulated)")
        return solve(run, h_new, *args, **kw)

    def run_peak(s):
        b = np.array(s._hist.branch)
        return np.array(s._hist.F)[np.flatnonzero(b != UNLOAD)[-1]]

    solver._solve = failing_near_zero
    res = solver.run(0.012, unload_at=[0.006, 0.01])
    assert res.status == "converged", res.reason
    got, ref = res.cycles["h_res"], plastic_run.cycles["h_res"]
    assert got.size == ref.size == 2
    np.testing.assert_allclose(got, ref, rtol=0.02)  # extrapolated from F < 1 % F_max
    ends = res.cycles["increment_end"].astype(int)
    assert np.any(res.F[ends] > 0)  # a branch ended on its tail, before a solved state at F = 0
    tail = res.cycles["F_end"] > 0
    np.testing.assert_array_equal(res.cycles["F_end"][tail], res.F[ends][tail])
    assert np.all(res.cycles["F_end"][tail] < 0.02 * res.cycles["F_max"][tail])
    assert np.all(plastic_run.cycles["F_end"] == 0.0)  # branches that reached F = 0
    assert np.all(res.cycles["h_res"] <= res.h[ends] + 1e-15)
    monkeypatch.setattr(fs, "UNLOAD_TAIL", 1e-5)  # without the tail rule the run stops
    stopped = IndentationSolver(EPP, 1.0, density=0.5)
    inner = stopped._solve
    stopped._solve = lambda run, h, *a, **k: (
        fs.IncrementFailed("simulated") if h < run.h and stopped._hist.branch[-1] == UNLOAD
        and run.F < 1e-2 * run_peak(stopped) else inner(run, h, *a, **k))
    assert stopped.run(0.012, unload_at=[0.006, 0.01]).status == "stopped"
