"""studies/fem_pair_speed.py: the split comparison and the runs it builds from a stored pair."""

from pathlib import Path

import numpy as np
import pytest
from fem_pair_speed import CASES, PENALTY, flat_kwargs, pair_kwargs, split_difference

from spherecontact.campaign.design import load_campaign

#: campaign v1's design, whose equal-hardness pairs the study re-runs
V1 = Path(__file__).resolve().parents[1] / "studies" / "campaign_v1.toml"


def _curves(h, split):
    h = np.asarray(h, dtype=float)
    return {"h": h, "h1": split * h}


def test_split_difference_reads_a_planted_offset_within_the_window():
    h = np.geomspace(1e-3, 0.3, 60)
    stored = _curves(h, 0.6 + 0.1 * h)
    new = _curves(np.geomspace(1e-3, 0.25, 90), 0.6 + 0.1 * np.geomspace(1e-3, 0.25, 90))
    assert split_difference(stored, new, 0.01) == pytest.approx(0.0, abs=1e-12)
    new["h1"] = new["h1"] + 0.03 * new["h"] * (new["h"] > 0.1)  # 3 points above from h = 0.1 on
    assert split_difference(stored, new, 0.01) == pytest.approx(0.03, abs=1e-3)
    # beyond the new run's end (0.25) and below h_min the stored curve is not read
    stored["h1"][h > 0.26] = 0.0
    stored["h1"][h < 0.009] = 0.0
    assert split_difference(stored, new, 0.01) == pytest.approx(0.03, abs=1e-3)


def test_unloading_increments_of_the_stored_run_are_left_out():
    h = np.array([0.01, 0.02, 0.03, 0.025, 0.02, 0.03, 0.04])
    stored = {"h": h, "h1": 0.5 * h, "branch": np.array([0, 0, 0, 1, 1, 2, 0])}
    stored["h1"][3:6] = 0.9 * h[3:6]  # unloading and reloading far off: ignored
    new = _curves(np.linspace(0.005, 0.05, 20), 0.5)
    assert split_difference(stored, new, 0.01) == pytest.approx(0.0, abs=1e-12)


def test_the_pairs_are_rerun_with_the_approach_scaled_penalty_and_body_1_alone():
    cases = {c.name: c for c in load_campaign(V1).cases}
    for name in CASES:
        case = cases[name]
        assert case.inputs["material"] == case.inputs["material2"] or case.inputs["radius2"] == 1.0
        kw = pair_kwargs(case)
        assert kw["options"].penalty == PENALTY and kw["options"].penalty_scale == "approach"
        assert kw["unload_at"] is None and kw["radius2"] == case.inputs["radius2"]
        flat = flat_kwargs(case)
        assert "radius2" not in flat and "options" not in flat
        assert flat["material"].sigma_y == kw["material2"].sigma_y  # equal hardness


def test_iteration_split_reads_the_phases_a_run_timed():
    """Milliseconds per Newton iteration of the whole run and of each phase it timed; a phase the
    run did not time (timings stored before the phase was split off) is left out, not reported as 0."""
    from spherecontact.fem.solver import iteration_split

    t = {"wall_s": 2.0, "newton_iterations": 100, "factorisation_s": 0.5, "line_search_s": 0.25}
    assert iteration_split(t) == {"total": 20.0, "factorisation": 5.0, "line_search": 2.5}


def test_a_surface_band_given_applies_to_the_pair_and_its_flat_run_alike():
    cases = {c.name: c for c in load_campaign(V1).cases}
    case = cases[CASES[2]]
    assert case.run_kwargs()["edge_band"] == 0.0  # campaign v1's pairs: the default mesh
    mesh = {"edge_band": 0.03, "band_floor": 0.003}
    pair, flat = pair_kwargs(case, mesh=mesh), flat_kwargs(case, mesh)
    for kw in (pair, flat):
        assert (kw["edge_band"], kw["band_floor"]) == (0.03, 0.003)
    assert pair_kwargs(case)["edge_band"] == 0.0 and flat_kwargs(case)["edge_band"] == 0.0


@pytest.mark.parametrize("args, word", [(["--edge-band", "0.5"], "--edge-band"),
                                        (["--edge-band", "0"], "--edge-band"),
                                        (["--edge-band", "0.03", "--band-floor", "0"], "--band-floor"),
                                        (["--edge-band", "0.03", "--band-floor", "0.05"], "--band-floor"),
                                        (["--interleave", "11"], "--interleave")])
def test_a_bad_band_is_named_before_any_run(args, word, capsys):
    from fem_pair_speed import main

    with pytest.raises(SystemExit):
        main(["--db", "no-such.h5", *args])
    assert f"error: {word}" in capsys.readouterr().err


def test_the_stored_pairs_database_is_asked_for_with_the_way_to_restore_it(tmp_path, capsys):
    """Campaign v1's database left the tree: --db has no default, and a missing file says where
    it is."""
    from fem_pair_speed import main

    with pytest.raises(SystemExit):
        main([])
    assert "--db" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--db", str(tmp_path / "reference.h5")])
    err = capsys.readouterr().err
    assert "no such file" in err and "git show 3667b84:data/reference.h5 > data/reference.h5" in err


def test_interleaved_rounds_alternate_the_flat_and_the_pair(monkeypatch):
    """Each round runs body 1's flat and then the pair; the ratio is that of the summed walls."""
    import fem_pair_speed as pair_speed

    calls, walls = [], iter([10.0, 30.0, 12.0, 30.0])
    monkeypatch.setattr(pair_speed, "_timed", lambda kw: (calls.append("options" in kw), next(walls)))
    case = {c.name: c for c in load_campaign(V1).cases}[CASES[0]]
    out = pair_speed.interleaved(case, 2)
    assert calls == [False, True, False, True]  # flat (no solver options), pair, flat, pair
    assert [r["ratio"] for r in out["rounds"]] == [3.0, 2.5]
    assert out["ratio"] == pytest.approx(60.0 / 22.0)
