"""Mesh check of stored runs (``fem/case_convergence.py``): the differences it reads, a
re-run from stored inputs, and its errors."""

import math
from pathlib import Path

import numpy as np
import pytest
from fem_case_convergence import check_case, differences, rerun

#: a campaign v2 flat's recorded inputs (options as the campaign writes them)
INPUTS = {"edge_band": 0.03, "element": "q8r", "h_max": 0.3, "indenter_radius": math.inf,
          "material": {"E": 200.0, "nu": 0.3, "sigma_y": 1.0, "K": 0.0, "n": 1.0}, "radius": 1.0,
          "mesh_density": 1.0, "scene": "rigid_flat", "unload_at": [0.01, 0.03, 0.1, 0.3],
          "options": {"dh_first": 0.0002, "dh_max": 0.01, "dh_min": 1e-07, "easy_iterations": 7,
                      "growth": 1.5, "line_search": True, "linear_solver": "ldl", "max_iterations": 25,
                      "max_wall_s": 5400.0, "segment_points": 0, "strain_increment": 0.005,
                      "tol": 1e-08, "unload_increments": 24}}


def _curve(scale_F=1.0, scale_a=1.0):
    h = np.geomspace(1e-4, 0.3, 60)
    return {"h": h, "F": scale_F * 8.0 * h ** 1.2, "a": scale_a * np.sqrt(2.0 * h)}


def test_differences_read_a_planted_offset_at_the_reference_radii():
    ref = _curve()
    d = differences(ref, {"finer": _curve(1.01, 0.995)}, radius=1.0)["finer"]
    inside = [x for x in (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7) if x <= math.sqrt(0.6)]
    assert sorted(k for k in d if k.startswith("F")) == sorted(f"F@{x:g}" for x in inside)
    assert all(v == pytest.approx(0.01, abs=1e-12) for k, v in d.items() if k.startswith("F"))
    assert all(v == pytest.approx(-0.005, abs=1e-12) for k, v in d.items() if k.startswith("a"))


def test_differences_leave_out_radii_the_other_curve_does_not_reach():
    short = {q: v[:30] for q, v in _curve().items()}  # stops at h ≈ 0.005, a ≈ 0.1
    d = differences(_curve(), {"short": short}, radius=1.0)["short"]
    assert "F@0.05" in d and "F@0.3" not in d


def test_rerun_repeats_a_stored_scene_from_its_inputs():
    """The recorded scene without its cycles (the first unloading would come at 0.01)."""
    r = rerun(INPUTS, 1.0, h_max=0.02)
    assert r["status"] == "converged" and r["h"][-1] == pytest.approx(0.02)
    assert np.all(np.diff(r["h"]) > 0)
    assert r["n_dofs"] > 0 and r["F"][-1] > 0


def test_rerun_refuses_two_bodies_and_check_case_names_a_missing_case():
    with pytest.raises(ValueError, match="one-body"):
        rerun({**INPUTS, "scene": "two_body"}, 1.0)
    with pytest.raises(ValueError, match="no-such-case"):
        check_case(Path(__file__).parents[1] / "data" / "reference_v2.h5", "no-such-case")
