"""3D octant solver, two-flat scene, against the axisymmetric flat scene (fem/cell.py)."""

import numpy as np

from spherecontact.fem.cell import Discretisation3, build_octant_mesh, run_two_flats
from spherecontact.model import Material

#: F_ax(h_ax) of `spherecontact fem run --E 200 --sigma-y 1 --h-max 0.03 --dh-max 0.002`
#: (default mesh), interpolated at h_ax = h/2
AX_EPP200 = {0.01: 0.062081, 0.02: 0.144050}


def test_octant_mesh_volume():
    disc = Discretisation3(build_octant_mesh(1.0, 1.0))
    assert abs(8 * disc.weights.sum() / (4 / 3 * np.pi) - 1) < 1e-4  # curved surface: 4.8e-5


def test_two_flats_epp_against_axisymmetric():
    m = Material(E=200.0, nu=0.3, sigma_y=1.0)
    r = run_two_flats(m, np.linspace(0.001, 0.02, 20), density=1.0)
    F = dict(zip(np.round(r.h, 6), r.F, strict=True))
    for h, Fa in AX_EPP200.items():  # coarse mesh (709 nodes): measured +7.0 %, +5.3 %
        assert abs(F[h] / Fa - 1) < 0.10
    W, S = np.asarray(r.work), np.asarray(r.stored) + np.asarray(r.dissipation)
    assert abs(S[-1] / W[-1] - 1) < 0.01  # energy balance: measured 0.13 %
