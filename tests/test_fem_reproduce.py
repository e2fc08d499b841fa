"""reproduce: stored and new curves compared on their loading increments."""

import numpy as np
import pytest
from fem_reproduce import compare_loading


def _curves(h, branch=None):
    c = {"h": h, "F": h**1.5, "a": np.sqrt(h)}
    if branch is not None:
        c["branch"] = branch
    return c


def test_cycles_are_left_out_of_the_comparison():
    h = np.geomspace(1e-3, 0.3, 60)
    stored = _curves(h)
    # the same loading with an unloading branch (lower F at lower h) inserted in the middle
    h_cyc = np.concatenate([h[:30], np.linspace(h[29], 0.5 * h[29], 8), h[30:]])
    new = _curves(h_cyc, np.concatenate([np.zeros(30), np.ones(8), np.zeros(30)]).astype(int))
    new["F"][30:38] = 0.1 * new["F"][30:38]
    d = compare_loading(stored, new, 0.01)
    assert abs(d["F"]["systematic"]) < 1e-12 and d["F"]["max"] < 1e-12
    assert d["a"]["max"] < 1e-12
    # without the mask the branch would enter: a 10 % change of the loading curve is seen
    off = _curves(h)
    off["F"] = 1.1 * off["F"]
    assert abs(compare_loading(stored, off, 0.01)["F"]["systematic"] - np.log(1.1)) < 1e-12


def test_an_unknown_edge_fit_is_named_before_any_run(capsys):
    from fem_reproduce import main

    with pytest.raises(SystemExit):
        main(["--edge-fit", "free", "--cases"])
    assert "--edge-fit" in capsys.readouterr().err
