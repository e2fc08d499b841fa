"""End-to-end FE runs, short and coarse enough for CI (the full figures: studies/fem_verification.py)."""

import math

import numpy as np
import pytest

from spherecontact.fem.contact import RigidObstacle
from spherecontact.fem.solver import PHASES, IndentationSolver, SolverOptions
from spherecontact.model import Material
from spherecontact.peers import jackson_green, jackson_green_critical

E, NU = 200.0, 0.3
EP = E / (1 - NU**2)


@pytest.fixture(scope="module")
def elastic_run():
    """Newton converged to 1e-8 (the default stops at 1e-4): equilibrium and the rate to roundoff."""
    solver = IndentationSolver(Material.elastic(E, NU), 1.0,
                               options=SolverOptions(dh_first=1.5e-4, dh_max=1.5e-4, tol=1e-8))
    return solver.run(0.003)


def test_hertz_force_against_contact_radius(elastic_run):
    """F = 4E'a³/(3R) (Hertz) with the reference-configuration contact radius."""
    c = elastic_run.curves
    inner = (np.arange(c["h"].size) >= 3) & (np.arange(c["h"].size) < c["h"].size - 3)
    sel = (c["a_ref"] >= 0.02) & inner  # full smoothing window on both sides
    assert sel.sum() >= 5
    ratio = c["F"][sel] / (4 * EP * c["a_ref"][sel] ** 3 / 3)
    assert np.abs(ratio - 1).max() < 0.01


def test_finite_sphere_carries_more_than_hertz(elastic_run):
    """docs/design.md §2: a hemisphere loaded through its equator is stiffer than the half-space."""
    c = elastic_run.curves
    ratio = np.interp(0.002, c["h"], c["F"] / (4 / 3 * EP * c["h"] ** 1.5))
    assert 1.01 < ratio < 1.035


def test_deformed_radius_shrinks_by_hertz_radial_displacement(elastic_run):
    c = elastic_run.curves
    sel = c["a_ref"] >= 0.02
    expected = -2 * (1 - 2 * NU) / (3 * math.pi * (1 - NU)) * c["a_ref"][sel]
    assert np.abs(c["a"][sel] / c["a_ref"][sel] - 1 - expected).max() < 5e-4


def test_equilibrium_and_newton_rate(elastic_run):
    c = elastic_run.curves
    assert np.allclose(c["F_support"], c["F"], rtol=1e-7)
    assert elastic_run.status == "converged" and c["h"][-1] == pytest.approx(0.003)
    # quadratic convergence: the last step squares the residual (up to a constant)
    rates = [math.log(r[-1]) / math.log(r[-2]) for r in elastic_run.residuals
             if len(r) >= 3 and 1e-12 < r[-2] < 1e-3]
    assert rates and np.median(rates) > 1.6


def test_rigid_sphere_indenter_is_hertz_with_effective_radius():
    R2 = 1.0
    solver = IndentationSolver(Material.elastic(E, NU), 1.0, RigidObstacle(R2),
                               options=SolverOptions(dh_first=2.5e-4, dh_max=2.5e-4, tol=1e-8))
    c = solver.run(0.002).curves
    R_star = 1.0 * R2 / (1.0 + R2)
    sel = c["a_ref"] >= 0.015
    ratio = c["F"][sel] / (4 * EP * c["a_ref"][sel] ** 3 / (3 * R_star))
    assert np.abs(ratio - 1).max() < 0.02
    assert np.allclose(c["F_support"], c["F"], rtol=1e-7)


def test_plastic_run_against_jackson_green_and_energy():
    mat = Material(E=E, nu=NU, sigma_y=1.0)
    omega_c = jackson_green_critical(1.0, EP, 1.0, NU)[0]
    solver = IndentationSolver(mat, 1.0, density=0.5, options=SolverOptions(dh_first=2e-5, dh_max=2e-4))
    res = solver.run(30 * omega_c)
    c = res.curves
    jg = jackson_green(c["h"], 1.0, EP, 1.0, NU)
    late = c["h"] > 5 * omega_c
    assert np.abs(c["F"][late] / jg.F[late] - 1).max() < 0.06  # the fit's own scatter is a few %
    assert c["eps_p_max"][-1] > 0.01 and c["dissipation"][-1] > 0
    balance = (c["energy_elastic"] + c["dissipation"]) / c["work_external"] - 1
    assert abs(balance[-1]) < 0.015
    # at the default tolerance (largest free residual 1e-4 of the largest reaction) the contact
    # force and the support reaction still agree far below any figure the runs are read for
    assert np.abs(c["F_support"] / c["F"] - 1).max() < 1e-5


def test_run_that_cannot_converge_stops_and_keeps_its_converged_part():
    """Two Newton iterations are too few once plasticity starts: the run must stop
    with its reason, the converged increments kept, and no exception."""
    opts = SolverOptions(dh_first=1e-4, dh_max=1e-4, dh_min=5e-5, max_iterations=2)
    solver = IndentationSolver(Material(E=E, nu=NU, sigma_y=1.0), 1.0, density=0.5, options=opts)
    res = solver.run(0.01)
    assert res.status == "stopped"
    assert "dh_min" in res.reason and "h/R" in res.reason
    assert res.h.size < 100 and (res.h.size == 0 or res.h[-1] < 0.01)
    assert len(res.residuals) == res.h.size


@pytest.mark.parametrize("kwargs, match", [
    (dict(h_max=0.0), "h_max"), (dict(h_max=-1.0), "h_max"), (dict(h_max=2.0), "h_max"),
])
def test_bad_h_max(kwargs, match):
    solver = IndentationSolver(Material.elastic(E, NU), 1.0, density=0.5)
    with pytest.raises(ValueError, match=match):
        solver.run(**kwargs)


def test_rigid_body_is_rejected():
    with pytest.raises(ValueError, match="rigid"):
        IndentationSolver(Material.rigid(), 1.0)


def test_default_options_are_valid_and_bad_ones_are_named():
    from spherecontact.fem.solver import SolverOptions

    SolverOptions().validate()
    with pytest.raises(ValueError, match="max_wall_s"):
        SolverOptions(max_wall_s=0.0).validate()
    with pytest.raises(ValueError, match="strain_increment"):
        SolverOptions(strain_increment=-1.0).validate()
    with pytest.raises(ValueError, match="predictor must be 'tangent' or 'secant'"):
        SolverOptions(predictor="quadratic").validate()


def test_wall_time_limit_stops_with_reason_and_keeps_increments():
    from spherecontact.fem.solver import SolverOptions

    solver = IndentationSolver(Material.elastic(E, NU), 1.0, density=0.5,
                               options=SolverOptions(dh_first=1e-4, dh_max=1e-4, max_wall_s=1.0))
    res = solver.run(0.5)
    assert res.status == "stopped" and "wall-time" in res.reason
    assert 0 < res.h[-1] < 0.5 and res.h.size == len(res.residuals)


def test_prescribed_schedule_is_followed_and_bad_ones_are_named():
    """``run(schedule=...)`` steps to exactly the given approaches (h_max appended)."""
    solver = IndentationSolver(Material(E=E, nu=NU, sigma_y=1.0), 1.0, density=0.5)
    sched = np.array([0.0005, 0.001, 0.002, 0.0035])
    res = solver.run(0.005, schedule=sched)
    assert res.status == "converged"
    np.testing.assert_allclose(res.h, np.append(sched, 0.005), rtol=1e-12)
    with pytest.raises(ValueError, match="schedule"):
        solver.run(0.005, schedule=[0.002, 0.001])


def test_points_toggling_at_yield_in_a_two_cycle_are_kept_elastic():
    """A Gauss point toggling at yield makes Newton repeat two residuals (residuals of the
    stopped campaign v2 run); at the 2-cycle the toggling points are frozen elastic."""
    from spherecontact.fem.plasticity import PlasticState, stress_update
    from spherecontact.fem.solver import freeze_toggling, new_active_log, stalled, two_cycle

    stopped = [2.63e-8, 2.33e-8, 3.05e-8, 2.33e-8, 3.05e-8]  # rsphere2.91-K8.12, h/R = 0.2876
    assert two_cycle(stopped)
    assert not two_cycle([1e-2, 1e-4, 1e-8]) and not two_cycle([3e-3, 6e-4, 1e-5, 2e-8])
    # stalled near convergence without a clean cycle (points at ε_p ~ 1e-16 toggling in turn)
    assert stalled([9.7e-8, 2.6e-8, 4.1e-8, 4.7e-8]) and not stalled([9.7e-8, 2.6e-8, 8.7e-9, 4e-10])
    assert not stalled([0.4, 0.3, 0.35, 0.3])  # far from convergence: no freezing
    log = new_active_log()
    a, b = np.array([True, True, False]), np.array([True, False, False])
    elastic = None
    for k, res in enumerate(stopped):
        log["res"].append(res)
        elastic = freeze_toggling(log, a if k % 2 == 0 else b, elastic)
        assert (elastic is None) == (k < 3)  # frozen once stalled (the 4th residual)
    np.testing.assert_array_equal(elastic, [False, True, False])
    assert log["plastic_frozen"]
    # a frozen point stays elastic above yield: Δγ = 0 where the return mapping gives Δγ > 0
    mat = Material(E=41.3, nu=0.3, sigma_y=1.0, K=8.12, n=0.178)
    F = np.array([[1.0], [0.0], [0.0], [0.9], [1.0]])  # 10 % axial compression
    state = PlasticState.virgin(1)
    free = stress_update(F, state.cp_inv, state.eps_p, mat)
    kept = stress_update(F, state.cp_inv, state.eps_p, mat, elastic=np.array([True]))
    assert free.dgamma[0] > 0 and kept.dgamma[0] == 0.0
    assert abs(kept.P[3, 0]) > abs(free.P[3, 0])  # the frozen point's stress stays above yield


def _trap_until_a_back_up(monkeypatch, solver_class, after: int) -> None:
    """Every step from increment ``after`` of ``solver_class`` fails until one increment has
    been undone (a dead end, as in campaign v2)."""
    from spherecontact.fem.solver import IncrementFailed

    solve = solver_class._solve

    def trapped(self, run, h_new):
        if len(self._hist.h) == after and self.backed_up_increments == 0:
            err = IncrementFailed("trapped (test)")
            self.rejected.append((h_new, h_new - run.h, str(err)))
            return err
        return solve(self, run, h_new)

    monkeypatch.setattr(solver_class, "_solve", trapped)


def test_a_dead_end_increment_is_undone_and_the_run_goes_on(monkeypatch):
    """A converged increment can end in a state no step leaves (campaign v2, rigid sphere
    R2/R1 = 2.07, Ludwik K/σY = 6.2, n = 0.149 on the band mesh: the increment to h/R = 6.3e-4
    converged with its contact edge frozen, and every step from there failed down to dh_min).
    Here every step from the fifth increment fails until one increment has been undone: the
    run undoes it and steps on from the one before; without back-ups it stops."""
    import spherecontact.fem.solver as solver_module

    _trap_until_a_back_up(monkeypatch, IndentationSolver, after=5)
    mat = Material(E=200.0, nu=0.3, sigma_y=1.0)
    res = IndentationSolver(mat, 1.0, RigidObstacle()).run(1e-3)
    assert res.status == "converged" and res.timings["backed_up_increments"] == 1
    assert np.all(np.diff(res.h) > 0)  # the undone increment left no trace in the curves
    assert len(res.residuals) == res.h.size
    monkeypatch.setattr(solver_module, "MAX_BACK_UPS", 0)
    stuck = IndentationSolver(mat, 1.0, RigidObstacle()).run(1e-3)
    assert stuck.status == "stopped" and "dh_min" in stuck.reason and stuck.h.size == 5


def test_an_undone_increment_of_two_bodies_leaves_no_profile_row(monkeypatch):
    """The two-body solver keeps its residual histories and surface profiles apart from the
    curves; an undone increment must take its rows with it (campaign v2, E ratio 3 pair: ten
    back-ups left 316 profile rows for 306 increments and the run could not be written)."""
    from spherecontact.fem.io import run_indentation
    from spherecontact.fem.twobody import TwoBodySolver

    _trap_until_a_back_up(monkeypatch, TwoBodySolver, after=4)
    m1 = Material(E=200.0, nu=0.3, sigma_y=1.0)
    m2 = Material(E=200.0, nu=0.3, sigma_y=2.0)
    res = run_indentation(m1, 1.0, 0.002, radius2=2.0, material2=m2, density=0.5)
    assert res.timings["backed_up_increments"] == 1 and res.status == "converged"
    assert np.all(np.diff(res.h) > 0)
    assert len(res.residuals) == res.h.size == res.profile_r.shape[0] == res.profile_p.shape[0]


def test_restoring_step_threshold():
    """Roundoff-sized gap corrections of a curved obstacle do not count as restoring contact."""
    from spherecontact.fem.solver import restores_contact
    du = np.array([1e-5, -2e-5, 0.0])
    assert not restores_contact(np.array([0.0, 1e-14, 0.0]), du)
    assert restores_contact(np.array([0.0, -1e-6, 0.0]), du)
    assert not restores_contact(np.zeros(3), np.zeros(3))


def test_plastic_sphere_on_rigid_sphere_converges_like_the_flat():
    """The line search stays on for curved obstacles: a Ludwik sphere (E/σY 1360, K/σY 1.16,
    n 0.2) pressed by a rigid sphere of 0.88 R to h/R = 0.002 needs no rejected increment and
    about as many as on the flat (31 against 24 measured); with every step taken whole it
    needed 72 increments, 29 of them rejected."""
    mat = Material(E=1360.0, nu=0.3, sigma_y=1.0, K=1.16, n=0.2)
    flat = IndentationSolver(mat, 1.0).run(0.002).timings
    sphere = IndentationSolver(mat, 1.0, obstacle=RigidObstacle(0.88)).run(0.002).timings
    assert flat["rejected_increments"] == 0 and sphere["rejected_increments"] == 0
    assert sphere["increments"] <= 1.5 * flat["increments"]


def test_smoothness_rerun_of_some_cases_keeps_the_others(tmp_path, monkeypatch):
    """``--only`` re-measures the chosen cases and keeps every earlier one in the file."""
    import json

    import fem_smoothness as smoothness

    earlier = [{"label": c[0], "wall_s": 1.0, "scatter_F": 0.01, "edge_band": c[3],
                "indenter_radius": "inf", "E_over_sigma_y": c[1]} for c in smoothness.CASES]
    (tmp_path / "smoothness.json").write_text(json.dumps(earlier))
    monkeypatch.setattr(smoothness, "measure", lambda *a, **k: {"wall_s": 2.0, "scatter_F": 0.02, "n_dofs": 1,
                                                                "scatter_a": 0.0})
    monkeypatch.setattr(smoothness, "chart", lambda results, path: None)
    smoothness.main(["--out", str(tmp_path), "--only", "1"])
    out = json.loads((tmp_path / "smoothness.json").read_text())
    assert [r["label"] for r in out] == [c[0] for c in smoothness.CASES]
    assert [r["wall_s"] for r in out] == [2.0 if i == 1 else 1.0 for i in range(len(out))]


def test_smoothness_records_the_solver_settings_each_figure_was_measured_with():
    """A scatter figure depends on the Newton tolerance and the predictor (fem/README.md: E/σY 10⁴ on
    the band 0.02, 1.61 % at 1e-4 with the tangent predictor, 0.53 % at 1e-8 with the secant
    one), so every measurement carries them and its date."""
    import re

    from fem_smoothness import measure
    r = measure(50.0, np.inf, 0.0, {"tol": 1e-6, "predictor": "secant"}, h_max=0.002)
    assert r["status"] == "converged" and r["newton_tol"] == 1e-6 and r["predictor"] == "secant"
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", r["date_utc"])


@pytest.mark.parametrize("indenter", [np.inf, 1.5])
def test_tangent_predictor_is_the_last_converged_tangents_step(indenter, monkeypatch):
    """The predictor solves K Δu = 0 on the free dofs with the equator moved by −dh and the
    active contact dofs held (in their nodal frames on a curved obstacle), on the factors of
    the last converged increment; without those factors the secant predictor takes over and
    the run ends at the same state within the path dependence of plasticity."""
    mat = Material(E=E, nu=NU, sigma_y=1.0)
    solver = IndentationSolver(mat, 1.0, RigidObstacle(indenter), density=0.5)
    calls = []
    predictor = solver._tangent_predictor

    def recorded(u, dh):
        K, fixed, scale, frames = solver._tangent
        pred = predictor(u, dh)
        calls.append((u, dh, pred, K, fixed, frames))
        return pred

    monkeypatch.setattr(solver, "_tangent_predictor", recorded)
    res = solver.run(0.01)
    assert res.status == "converged"
    assert len(calls) >= res.timings["increments"] - 3  # all but the first increments
    u, dh, pred, K, fixed, frames = calls[len(calls) // 2]
    du = solver._rotate(pred - u, frames)  # into the nodal frames of the factored K
    free = np.ones(du.size, dtype=bool)
    free[fixed] = False
    assert np.abs((K @ du)[free]).max() <= 1e-9 * np.abs(K @ du).max()
    equator_z = 2 * solver.hmesh.equator + 1
    assert np.allclose(du[equator_z], -dh)
    assert np.abs(du[np.setdiff1d(fixed, equator_z)]).max() <= 1e-12 * dh  # held on the obstacle

    secant = IndentationSolver(mat, 1.0, RigidObstacle(indenter), density=0.5,
                               options=SolverOptions(predictor="secant")).run(0.01)
    fallback = IndentationSolver(mat, 1.0, RigidObstacle(indenter), density=0.5)
    monkeypatch.setattr(fallback, "_tangent_predictor", lambda u, dh: None)  # factors never at hand
    fallback = fallback.run(0.01)
    assert secant.status == fallback.status == "converged"
    assert np.array_equal(fallback.F, secant.F)
    assert abs(secant.F[-1] / res.F[-1] - 1) < 5e-3


def test_timings_split_the_newton_phases_and_the_predictor():
    """Every phase of :data:`PHASES` is timed; the tangent predictor's triangular solves count
    in its own phase, not in the Newton step's solves or its set-up (``constraints``)."""
    solver = IndentationSolver(Material(E=E, nu=NU, sigma_y=1.0), 1.0, density=0.5)
    t = solver.run(0.01).timings
    assert all(t[f"{k}_s"] >= 0.0 for k in PHASES)
    assert min(t["factorisation_s"], t["solve_s"], t["predictor_s"], t["constraints_s"]) > 0.0
    assert sum(t[f"{k}_s"] for k in PHASES) <= t["wall_s"]
    predictor_solves = solver.linear.times["solve"] - t["solve_s"]
    assert 0.0 < predictor_solves <= t["predictor_s"]


def test_a_failed_loading_step_caps_the_next_ones(monkeypatch):
    """After a failed step the strain step is capped at STEP_SHRINK × the failed size and grows
    back slowly (× STEP_RECOVERY per easy increment); without the cap (a huge STEP_SHRINK)
    growth brings the step back to the failed size at once."""
    import spherecontact.fem.solver as solver_module
    from spherecontact.fem.solver import STEP_SHRINK, IncrementFailed

    def steps_after_a_failure():
        solver = IndentationSolver(Material(E=E, nu=NU, sigma_y=1.0), 1.0, density=0.5)
        solve, failed = solver._solve, []

        def failing_once(run, h_new):
            if not failed and len(solver._hist.h) == 15:
                failed.append(h_new - run.h)
                return IncrementFailed("test")
            return solve(run, h_new)

        monkeypatch.setattr(solver, "_solve", failing_once)
        res = solver.run(0.01)
        assert res.status == "converged" and failed
        return np.diff(res.h)[14:18] / failed[0]  # increments 0 … 14 came before the failure

    capped = steps_after_a_failure()
    monkeypatch.setattr(solver_module, "STEP_SHRINK", 1e9)
    uncapped = steps_after_a_failure()
    assert capped[0] == uncapped[0] == pytest.approx(0.5)  # halved
    assert uncapped[1:].max() >= 1.0  # back to the size that failed
    # the cap binds from the first growth on; once the uncapped step is back at the strain step
    # the capped one stays at about STEP_SHRINK of it
    assert np.all(capped[1:] <= uncapped[1:])
    assert np.all(capped[2:] <= (STEP_SHRINK + 0.05) * uncapped[2:])


def _kinked_slope(s0: float, entry: float, stiffness: float):
    """s(α) of a step along which a penalty node enters contact at α = ``entry``: the linear slope
    s0 (1 − α) of the Newton model, bent up by ``stiffness`` past the entry; the calls recorded."""
    calls = []

    def slope(alpha):
        calls.append(alpha)
        return s0 * (1.0 - alpha) + stiffness * max(alpha - entry, 0.0), alpha
    return slope, calls


@pytest.mark.parametrize("entry", [0.8, 0.3, 0.05])
def test_line_search_brackets_the_zero_of_a_kinked_slope(entry):
    """The zero of s past a node's entry is bracketed, not left at the first descending α: the
    accepted α has |s| ≤ ½|s0| or lies just below the entry (2⁻⁷ of the step, in 8 trials), where
    the secant alone gives 0.1 (entries 0.8, 0.3) or 0.01 (entry 0.05), which the one-body rule
    accepts as descending."""
    from spherecontact.fem.solver import bracketed_line_search
    s0 = -1.0
    slope, calls = _kinked_slope(s0, entry, 1e4)
    alpha, payload = bracketed_line_search(slope, s0, max_steps=8)
    s_a = slope(alpha)[0]
    assert payload == alpha
    assert abs(s_a) <= 0.5 * abs(s0) or (entry - 2**-7 <= alpha <= entry and s_a < 0.0)
    assert alpha >= min(0.5, entry - 2**-7) and calls[0] == 1.0 and len(calls) <= 9


def test_line_search_takes_the_full_step_or_the_best_descent_it_found():
    """s(1) < 0: the full step at once; a search that runs out of steps returns the last
    descending α tried, not the last α (whose slope is positive), and without any, the last α."""
    from spherecontact.fem.solver import bracketed_line_search
    slope, calls = _kinked_slope(-1.0, 2.0, 1e4)  # no entry within the step
    assert bracketed_line_search(slope, -1.0)[0] == 1.0 and calls == [1.0]
    slope, calls = _kinked_slope(-1.0, 0.3, 1e4)
    assert bracketed_line_search(slope, -1.0, max_steps=3)[0] == 0.25 and calls == [1.0, 0.5, 0.25]
    slope, calls = _kinked_slope(-1.0, 0.01, 1e6)
    assert bracketed_line_search(slope, -1.0, max_steps=2)[0] == 0.5 and calls == [1.0, 0.5]
