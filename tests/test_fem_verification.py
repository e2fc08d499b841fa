"""The FE verification's plan and helpers (the runs themselves: ``make verify-fem``)."""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from fem_verification import CAMPAIGN_BAND, LOCK_WINDOW, _run, _window_mean, plan

ROOT = Path(__file__).resolve().parents[1]


def test_window_mean_is_the_trapezoidal_mean_over_the_window():
    h = np.linspace(0.0, 0.002, 21)
    y = 3.0 + 1000.0 * h  # linear: the mean over the increments 0.0006 … 0.0012 is its middle value
    assert _window_mean(h, y, 0.00055, 0.00125) == pytest.approx(3.0 + 1000.0 * 0.0009, rel=1e-12)
    steps = np.where(np.arange(h.size) % 2 == 0, 2.9, 3.1)  # ±0.1 about 3: averaged out
    assert abs(_window_mean(h, steps, 0.0002, 0.0018) - 3.0) < 0.01
    assert np.isnan(_window_mean(h, y, 0.00051, 0.00059))  # no increment inside: no figure


def test_verification_checks_the_mesh_the_campaign_runs_on():
    """The locking check on the surface band follows the campaign's band: a campaign that
    changes it must change the verification too."""
    campaign = tomllib.loads((ROOT / "data" / "campaign_v2.toml").read_text())
    assert CAMPAIGN_BAND == campaign["defaults"]["edge_band"]
    full, quick = plan(quick=False), plan(quick=True)
    for runs in (full, quick):
        assert runs["lock_band"]["edge_band"] == runs["lock_band_fine"]["edge_band"] == CAMPAIGN_BAND
        assert runs["lock_band_fine"]["density"] > runs["lock_band"].get("density", 1.0)
        assert runs["lock_band"]["h_max"] >= LOCK_WINDOW[1]  # the window lies inside the run


def test_run_builds_the_band_mesh_it_is_given():
    plain = _run("elastic", 200.0, 2e-4, options=dict(dh_first=1e-4, dh_max=1e-4))
    band = _run("elastic", 200.0, 2e-4, edge_band=CAMPAIGN_BAND, options=dict(dh_first=1e-4, dh_max=1e-4))
    assert band["n_dofs"] > plain["n_dofs"]
    assert band["status"] == plain["status"] == "converged"


def test_a_run_on_another_runs_approaches_steps_to_them():
    """The mesh check without the increments' share: the refined run is stepped to the default
    run's converged approaches (``loading_approaches``), so both curves share their h."""
    from fem_verification import loading_approaches

    opts = dict(dh_first=1e-4, dh_max=2e-4)
    coarse = _run("epp", 200.0, 1e-3, density=0.5, options=opts)
    fine = _run("epp", 200.0, 1e-3, density=0.75, options=opts, schedule=loading_approaches(coarse))
    assert coarse["status"] == fine["status"] == "converged"
    assert np.array_equal(loading_approaches(fine), loading_approaches(coarse))
    assert fine["n_dofs"] > coarse["n_dofs"]


def test_the_edge_fit_is_checked_on_the_standard_run_and_its_2x_mesh_alike():
    """The mesh check of the fitted contact edge compares like with like: the standard run with
    ``edge_fit`` "fitted", and the 2× mesh stepped to that run's approaches with the same option."""
    from fem_verification import AFTER_POOL, EDGE_FITTED, SAME_STEPS, SAME_STEPS_FITTED

    cases = plan(quick=False)
    assert cases[EDGE_FITTED] == cases["standard"] | {"options": {"edge_fit": "fitted"}}
    assert AFTER_POOL[SAME_STEPS] == ("standard_fine", {}, "standard")
    case, options, steps_of = AFTER_POOL[SAME_STEPS_FITTED]
    assert cases[case]["density"] == 2.0 and options == {"edge_fit": "fitted"} and steps_of == EDGE_FITTED
