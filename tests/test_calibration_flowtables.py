"""The stacked flow tables of the calibration (``calibration/flowtables.py``) give the
per-material flow stress, slope and representative stress bit for bit."""

import numpy as np
import pytest

from spherecontact.calibration.flowtables import FlowTables
from spherecontact.model import Material
from spherecontact.model.single import representative_stress, spread_average

VOCE = Material.from_table(E=300.0, nu=0.3, eps_p=np.linspace(0.0, 2.0, 91),
                           sigma=1.0 + 1.5 * (1.0 - np.exp(-8.0 * np.linspace(0.0, 2.0, 91))))
PLATEAU = Material.from_table(E=200.0, nu=0.3, eps_p=[0.0, 0.01, 0.02, 0.5], sigma=[1.0, 1.0, 1.4, 2.0])
LINEAR = Material.from_table(E=1000.0, nu=0.3, eps_p=[0.0, 1.0], sigma=[1.0, 6.0])


def _strains(m: Material) -> np.ndarray:
    """Strains inside, at and between the nodes, below zero and beyond the table's end."""
    et = np.asarray(m.eps_table)
    rng = np.random.default_rng(3)
    return np.concatenate([et, et * (1 + 1e-12), 0.5 * (et[1:] + et[:-1]), [-1.0, 3.0 * et[-1]],
                           rng.uniform(0.0, 1.2 * et[-1], 200)])


def test_the_stacked_tables_give_each_material_s_flow_curve_bit_for_bit():
    mats = [VOCE, PLATEAU, LINEAR]
    tables = FlowTables(mats)
    for row, m in enumerate(mats):
        e = _strains(m)
        s, slope = tables.flow(np.full(e.size, row), e)
        assert np.array_equal(s, m.flow_stress(e)), row
        assert np.array_equal(slope, m.flow_slope(e)), row
    # points of different tables in one call, interleaved
    e = np.concatenate([_strains(m) for m in mats])
    rows = np.concatenate([np.full(_strains(m).size, i) for i, m in enumerate(mats)])
    order = np.random.default_rng(5).permutation(e.size)
    s, slope = tables.flow(rows[order], e[order])
    assert np.array_equal(s, np.concatenate([m.flow_stress(_strains(m)) for m in mats])[order])
    assert np.array_equal(slope, np.concatenate([m.flow_slope(_strains(m)) for m in mats])[order])


@pytest.mark.parametrize("spread", [0.6, 1.0, 1.5])
def test_the_representative_stress_of_stacked_tables_is_the_material_s(spread):
    tables = FlowTables([VOCE, PLATEAU])
    for row, m in enumerate((VOCE, PLATEAU)):
        e = np.abs(_strains(m))
        got = spread_average(lambda x: tables.flow(np.full(x.size, row), x), e, spread)  # noqa: B023
        want = representative_stress(m, e, spread)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1]), (row, spread)
