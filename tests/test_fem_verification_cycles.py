"""The elastic-retrace measure of `make verify-cycles` on synthetic Hertz cycles."""

import numpy as np
from fem_verification_cycles import retrace, retrace_at_same_approach, unloading_approaches


def hertz_cycle(bump: float = 0.0) -> dict:
    """Load F = h^1.5 to h = 0.01 in 20 steps, unload to 0 in 40 (F scaled by 1 + bump)."""
    load = np.geomspace(1e-4, 0.01, 20)
    unload = np.linspace(0.01, 0.0, 41)[1:]
    h = np.concatenate([[0.0], load, unload])
    F = np.concatenate([[0.0], load**1.5, (1 + bump) * unload**1.5])
    branch = np.concatenate([[0], np.zeros(20), np.ones(40)]).astype(int)
    return {"curves": {"h": h.tolist(), "F": F.tolist(), "branch": branch.tolist()},
            "cycles": {"h_max": [0.01], "F_max": [0.001], "h_res": [0.0], "increment_start": [0],
                       "increment_peak": [20], "increment_end": [60]}}


def test_retrace_is_zero_for_an_exact_elastic_cycle_and_sees_an_offset():
    (exact,) = retrace(hertz_cycle())
    assert exact["F_max_dev"] < 1e-12  # log-log interpolation is exact for a power law
    (off,) = retrace(hertz_cycle(bump=0.01))
    assert abs(off["F_max_dev"] - 0.01) < 1e-12 and exact["h_res_over_h_max"] == 0.0


def kinked_cycle(bump: float = 0.0) -> dict:
    """A cycle whose F(h) has a slope jump at h = 0.005 (a surface node closing), sampled on
    loading and unloading at different approaches (unloading F scaled by 1 + bump)."""
    def F(h):
        return h**1.5 * np.where(h > 0.005, 1.0 + 40.0 * (h - 0.005), 1.0)
    load = np.geomspace(1e-4, 0.01, 40)  # fine loading, coarse unloading (as in the FE runs)
    unload = np.linspace(0.01, 0.0, 8)[1:]
    h = np.concatenate([[0.0], load, unload])
    Fh = np.concatenate([[0.0], F(load), (1 + bump) * F(unload)])
    branch = np.concatenate([[0], np.zeros(40), np.ones(7)]).astype(int)
    run = {"curves": {"h": h.tolist(), "F": Fh.tolist(), "branch": branch.tolist()},
           "cycles": {"h_max": [0.01], "F_max": [float(F(0.01))], "h_res": [0.0], "increment_start": [0],
                      "increment_peak": [40], "increment_end": [47]}}
    sched = unloading_approaches(run)
    loading = {"curves": {"h": sched.tolist(), "F": F(sched).tolist(), "branch": [0] * sched.size}}
    return run, loading


def test_retrace_at_the_same_approach_needs_no_interpolation():
    run, loading = kinked_cycle()
    (interp,) = retrace(run)
    assert interp["F_max_dev"] > 0.01  # interpolating across the kink misreads an exact retrace
    (exact,) = retrace_at_same_approach(run, loading)
    assert exact["F_max_dev"] < 1e-12 and exact["points"] >= 5
    run, loading = kinked_cycle(bump=0.002)
    (off,) = retrace_at_same_approach(run, loading)
    assert abs(off["F_max_dev"] - 0.002) < 1e-12


def test_small_contact_stiffness_is_judged_per_mesh():
    """Sneddon's limit is checked on the branches with a/R ≤ 0.05 only, separately per mesh."""
    from fem_verification_cycles import LIMITS, stiffness_small
    stiff = [{"mesh": "coarse", "a_over_R": 0.03, "S_over_2Ea": 1.036, "elastic_sphere_dFdh_over_2Ea": 1.013},
             {"mesh": "coarse", "a_over_R": 0.3, "S_over_2Ea": 1.4, "elastic_sphere_dFdh_over_2Ea": 1.3},
             {"mesh": "fine", "a_over_R": 0.04, "S_over_2Ea": 0.99, "elastic_sphere_dFdh_over_2Ea": 1.0},
             {"mesh": "fine", "a_over_R": 0.2, "S_over_2Ea": 1.2, "elastic_sphere_dFdh_over_2Ea": 1.1}]
    out = stiffness_small(stiff)
    assert LIMITS["sneddon_small"] == 0.02
    assert out["coarse"]["branches"] == 1 and not out["coarse"]["within_limit"]
    assert abs(out["coarse"]["max_dev"] - 0.036) < 1e-12
    assert out["fine"]["within_limit"] and abs(out["fine"]["max_dev"] - 0.01) < 1e-12
    assert abs(out["coarse"]["max_dev_from_elastic_sphere"] - (1.036 / 1.013 - 1)) < 1e-12
