"""Compact run files: profiles at selected increments in float32, old layout still readable."""

from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from spherecontact.fem import io as fio
from spherecontact.fem.io import PROFILE_ROWS, profile_increments, read_run, run_indentation, write_run
from spherecontact.model.material import Material

EPP = Material(E=200, nu=0.3, sigma_y=1.0)
F32_EPS = 2.0**-24  # largest relative rounding error of float64 → float32 (round to nearest)


@pytest.fixture(scope="module")
def cyclic():
    """A small plastic run with two unloading cycles (~100 increments, more than PROFILE_ROWS)."""
    res = run_indentation(EPP, 1.0, 0.02, unload_at=[0.005, 0.02])
    assert res.h.size > PROFILE_ROWS  # else nothing is selected and the tests below are vacuous
    return res


@pytest.fixture(scope="module")
def stored(cyclic, tmp_path_factory):
    path = write_run(tmp_path_factory.mktemp("compact") / "run.h5", cyclic)
    return path, read_run(path)


def _branch_sides(branch):
    after = np.flatnonzero(np.diff(branch) != 0) + 1
    return set((after - 1).tolist()) | set(after.tolist())


# ---------------------------------------------------------------------------- selection
def test_rows_kept_include_every_branch_change_first_and_last(cyclic, stored):
    _, run = stored
    idx = run.profile_increment
    n = cyclic.h.size
    assert idx.size <= PROFILE_ROWS and idx.size == run.profile_r.shape[0]
    assert idx[0] == 0 and idx[-1] == n - 1
    assert np.all(np.diff(idx) > 0)
    sides = _branch_sides(cyclic.curves["branch"])
    assert len(sides) == 8  # two cycles: load|unload|reload|load|unload, ends and starts
    assert sides <= set(idx.tolist())
    for k in ("increment_start", "increment_peak", "increment_end"):  # peaks and residual states
        assert set(cyclic.cycles[k].astype(int).tolist()) <= set(idx.tolist()), k


def test_loading_rows_spread_in_log_h(cyclic, stored):
    """The free rows are loading increments; no gap in log h is much wider than an even share."""
    _, run = stored
    h, branch = cyclic.h, cyclic.curves["branch"]
    free = np.setdiff1d(run.profile_increment, sorted(_branch_sides(branch) | {0, h.size - 1}))
    assert PROFILE_ROWS - 12 <= free.size <= PROFILE_ROWS - 10 and np.all(branch[free] == 0)
    kept = np.log(h[run.profile_increment[branch[run.profile_increment] == 0]])
    every = np.log(h[branch == 0])
    even = (kept.max() - kept.min()) / (kept.size - 1)
    assert np.diff(kept).max() <= max(2.0 * even, np.diff(every).max())


def test_short_runs_keep_every_increment():
    np.testing.assert_array_equal(profile_increments(np.linspace(0.1, 1, 7)), np.arange(7))
    assert profile_increments(np.zeros(0)).dtype == np.int32


def test_branch_changes_win_over_the_row_limit():
    """Eight cycles have 46 branch ends: all kept although rows = 40, nothing else added."""
    branch = np.tile(np.repeat([0, 1, 2], 10), 8)
    h = np.linspace(0.01, 1.0, branch.size)
    idx = profile_increments(h, branch, rows=40)
    assert _branch_sides(branch) | {0, h.size - 1} == set(idx.tolist()) and idx.size == 48


def test_selection_fills_the_row_budget():
    h = np.geomspace(1e-4, 0.3, 500)
    idx = profile_increments(h, None, rows=25)
    assert idx.size == 25 and idx[0] == 0 and idx[-1] == 499
    assert np.ptp(np.diff(idx)) <= 1  # log-spaced h: evenly spread in log h is evenly spread in k


@pytest.mark.parametrize("kwargs, name", [
    ({"rows": 1}, "rows"), ({"rows": 3.5}, "rows"), ({"rows": True}, "rows"),
    ({"branch": np.zeros(3)}, "branch"), ({"h": np.ones((2, 50))}, "h"),
])
def test_bad_selection_arguments_are_named(kwargs, name):
    args = {"h": np.linspace(0.01, 1, 50)} | kwargs
    with pytest.raises(ValueError, match=name):
        profile_increments(**args)


# ---------------------------------------------------------------------------- precision
def test_profiles_are_float32_close_to_the_run(cyclic, stored):
    path, run = stored
    with h5py.File(path, "r") as f:
        prof = f["run/profiles"]
        assert prof["increment"].dtype == np.int32
        assert {prof[k].dtype for k in ("r", "p", "gap")} == {np.dtype(np.float32)}
        assert f["run/newton/residuals"].dtype == np.float32
        assert f["run/mesh/eps_p"].dtype == f["run/mesh/X"].dtype == f["run/mesh/u"].dtype == np.float32
        assert f["run/mesh/cells"].dtype == np.int32
        assert f["run/curves/h"].dtype == f["run/cycles/h_res"].dtype == np.float64
    idx = run.profile_increment
    for got, want in ((run.profile_r, cyclic.profile_r), (run.profile_p, cyclic.profile_p),
                      (run.profile_gap, cyclic.profile_g)):
        assert got.dtype == np.float64
        np.testing.assert_allclose(got, want[idx], rtol=1e-6, atol=0.0)
        np.testing.assert_array_equal(got, want[idx].astype(np.float32))
    assert np.any(run.profile_p > 0) and np.any(run.profile_gap > 0)
    want = cyclic.profile_r[idx]
    nonzero = want != 0.0
    rel = np.abs(run.profile_r[nonzero] - want[nonzero]) / np.abs(want[nonzero])
    assert 0.0 < rel.max() <= F32_EPS  # rounded (not exact), to the nearest float32


def test_residuals_and_plastic_strain_within_float32_rounding(cyclic, stored):
    _, run = stored
    assert len(run.residuals) == cyclic.h.size
    for got, want in zip(run.residuals, cyclic.residuals, strict=True):
        np.testing.assert_allclose(got, want, rtol=F32_EPS, atol=0.0)
    np.testing.assert_allclose(run.mesh["eps_p"], cyclic.final["eps_p"], rtol=F32_EPS, atol=0.0)
    np.testing.assert_array_equal(run.mesh["u"], cyclic.final["u"].astype(np.float32))
    for name, values in cyclic.curves.items():
        np.testing.assert_array_equal(run.curves[name], values, err_msg=name)


def test_profile_by_increment(cyclic, stored):
    _, run = stored
    peak = int(cyclic.cycles["increment_peak"][0])
    got = run.profile(peak)
    np.testing.assert_allclose(got["p"], cyclic.profile_p[peak], rtol=1e-6)
    np.testing.assert_allclose(run.profile(-1)["r"], cyclic.profile_r[-1], rtol=1e-6)
    np.testing.assert_array_equal(run.profile_h, cyclic.h[run.profile_increment])
    missing = int(np.setdiff1d(np.arange(cyclic.h.size), run.profile_increment)[0])
    with pytest.raises(ValueError, match=f"increment {missing}: no stored profile"):
        run.profile(missing)


# ---------------------------------------------------------------------------- old layout
def _to_old_layout(path, result):
    """Rewrite the profiles as before profiles/increment: float64, one row per increment."""
    with h5py.File(path, "r+") as f:
        prof = f["run/profiles"]
        for name in ("increment", "r", "p", "gap"):
            del prof[name]
        prof["r"], prof["p"], prof["gap"] = result.profile_r, result.profile_p, result.profile_g


def test_old_layout_reads_as_every_increment(cyclic, tmp_path):
    path = write_run(tmp_path / "old.h5", cyclic)
    _to_old_layout(path, cyclic)
    run = read_run(path)
    np.testing.assert_array_equal(run.profile_increment, np.arange(cyclic.h.size))
    np.testing.assert_array_equal(run.profile_r, cyclic.profile_r)
    np.testing.assert_array_equal(run.profile_gap, cyclic.profile_g)
    np.testing.assert_array_equal(run.profile(57)["p"], cyclic.profile_p[57])


def test_old_layout_with_missing_rows_is_rejected(cyclic, tmp_path):
    path = write_run(tmp_path / "old.h5", cyclic)
    with h5py.File(path, "r+") as f:
        del f["run/profiles/increment"]
    with pytest.raises(ValueError, match=r"profiles/r must have \d+ rows \(curves/h"):
        read_run(path)


@pytest.mark.parametrize("increment, message", [
    (lambda idx, n: idx[::-1], "increasing"),
    (lambda idx, n: np.r_[idx[:-1], n], r"\[0, \d+\)"),
    (lambda idx, n: idx[:-1], "must have"),
    (lambda idx, n: idx.astype(float), "increment indices"),
])
def test_inconsistent_increment_is_rejected(cyclic, tmp_path, increment, message):
    path = write_run(tmp_path / "run.h5", cyclic)
    with h5py.File(path, "r+") as f:
        idx = f["run/profiles/increment"][()]
        del f["run/profiles/increment"]
        f["run/profiles/increment"] = increment(idx, cyclic.h.size)
    with pytest.raises(ValueError, match=message):
        read_run(path)


def test_monkeypatched_row_limit_is_honoured(cyclic, tmp_path, monkeypatch):
    monkeypatch.setattr(fio, "PROFILE_ROWS", 16)
    run = read_run(write_run(tmp_path / "run.h5", cyclic))
    assert 14 <= run.profile_increment.size <= 16  # 10 fixed rows + up to 6 spread
    assert _branch_sides(cyclic.curves["branch"]) <= set(run.profile_increment.tolist())


# ---------------------------------------------------------------------------- loading curve
def test_calibration_and_validation_read_the_loading_curve_of_a_cyclic_run(cyclic, stored):
    """Unloading and reloading increments must not enter the fitted or validated F(h)."""
    from spherecontact.calibration.dataset import run_curve
    from spherecontact.validation.cases import Case

    _, run = stored
    load = run.loading
    assert load.sum() < run.h.size and np.all(np.diff(run.h[load]) > 0)  # monotone, cycles left out
    curve = run_curve("k", run)
    monotone = SimpleNamespace(h=run.h[load], F=run.F[load], a=run.a[load], inputs=run.inputs,
                               material=run.material)  # the same run without its cycles
    np.testing.assert_array_equal(curve.F, run_curve("k", monotone).F)
    with_cycles = SimpleNamespace(**{**vars(monotone), "h": run.h, "F": run.F, "a": run.a})
    assert not np.array_equal(run_curve("k", with_cycles).F, curve.F)  # cycles would change it
    case = Case(key="k", set="validation", name="n", params={}, inputs=run.inputs, curves=dict(run.curves))
    np.testing.assert_array_equal(case.F, run.F[load])
    assert case.raw_curve("F").size == run.h.size
