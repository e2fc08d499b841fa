"""The elastic-retrace measure of `make verify-cycles` on synthetic Hertz cycles."""

import numpy as np

from spherecontact.fem.verification_cycles import retrace


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
