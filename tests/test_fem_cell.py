"""3D octant solver: two-flat scene against the axisymmetric flat scene, lattice scenes, the
cell run file and `spherecontact fem cell` (fem/cell*.py). Meshes at density 0.5 (fast)."""

import numpy as np
import pytest

from spherecontact.fem import read_run
from spherecontact.fem.cell import run_cell, run_two_flats
from spherecontact.fem.cell_mesh import Discretisation3, build_octant_mesh
from spherecontact.fem.cell_scene import SCENES
from spherecontact.model import Material

EPP = Material(E=200.0, nu=0.3, sigma_y=1.0)
#: F_ax(h/2) of `spherecontact fem run --E 200 --sigma-y 1 --h-max 0.05 --dh-max 0.002`
#: (default mesh), interpolated at h_ax = h/2
AX_EPP200 = {0.01: 0.062081, 0.02: 0.144050}


def cli(argv):
    from spherecontact.cli import main

    return main(["fem", "cell", *argv])


def test_octant_mesh_volume():
    disc = Discretisation3(build_octant_mesh(1.0, 1.0, pole_size=0.03, pole_grade=0.0, pole_region=0.0))
    assert abs(8 * disc.weights.sum() / (4 / 3 * np.pi) - 1) < 1e-4  # curved surface: 4.8e-5


def test_two_flats_epp_against_axisymmetric():
    r = run_two_flats(EPP, np.arange(1, 11) * 0.002, density=0.5)
    d = r.arrays()
    F = dict(zip(np.round(d["h"], 6), d["F"][:, 0], strict=True))
    for h, Fa in AX_EPP200.items():  # measured −0.13 %, +0.35 % (1070 nodes)
        assert abs(F[h] / Fa - 1) < 0.02
    balance = (d["stored"][-1] + d["dissipation"][-1]) / d["work"][-1] - 1
    assert abs(balance) < 0.01  # measured 0.68 % (10 increments)


def test_approach_at_density_inverts_density():
    for name in ("sc-isostatic", "sc-die", "fcc-isostatic"):
        sc = SCENES[name]
        h = sc.approach_at_density(0.85, 1.0)
        assert sc.density(4 / 3 * np.pi, h, 1.0) == pytest.approx(0.85, rel=1e-12)


def test_density_at_contact():
    V = 4 / 3 * np.pi
    assert SCENES["sc-isostatic"].density(V, 0.0, 1.0) == pytest.approx(np.pi / 6, rel=1e-14)
    assert SCENES["sc-die"].density(V, 0.0, 1.0) == pytest.approx(np.pi / 6, rel=1e-14)
    assert SCENES["fcc-isostatic"].density(V, 0.0, 1.0) == pytest.approx(np.pi / (3 * np.sqrt(2)), rel=1e-14)
    # die: only the z period shortens
    assert SCENES["sc-die"].density(V, 0.2, 1.0) == pytest.approx(V / (4 * 1.8))


def test_fcc_contacts_equal_and_near_two_flats():
    """Oblique flats (nodal frames): the three FCC contacts agree, and at h/R 0.002 are the
    two-flat value plus the elastic interaction (measured +4 % on this mesh)."""
    r = run_cell("fcc-isostatic", EPP, [0.001, 0.002], density=0.5).arrays()
    two = run_two_flats(EPP, [0.001, 0.002], density=0.5).arrays()
    F = r["F"][-1]
    assert np.ptp(F) / F.mean() < 0.02  # measured 1.0 %
    assert 1.0 < F.mean() / two["F"][-1, 0] < 1.08
    assert r["density"][0] > np.pi / (3 * np.sqrt(2))  # compressed: denser than at contact


def test_sc_die_lateral_walls():
    r = run_cell("sc-die", EPP, [0.001, 0.002], density=0.5).arrays()
    assert np.all(r["hk"][:, :2] == 0) and np.all(r["hk"][:, 2] == r["h"])
    assert np.all(r["F"][-1, :2] >= 0) and np.all(r["F"][-1, :2] < 0.01 * r["F"][-1, 2])


def test_cli_cell_run_file(tmp_path):
    out = tmp_path / "sc.h5"
    assert cli(["--E", "200", "--sigma-y", "1", "--lattice", "sc", "--h-max", "0.002", "--dh", "0.001",
                "--mesh-density", "0.5", "--out", str(out), "--quiet"]) == 0
    run = read_run(out)
    assert run.h.shape == run.F.shape == run.A.shape == (2, 3)
    np.testing.assert_allclose(run.h[-1], 0.002)
    assert np.all(np.diff(run.density) > 0) and run.density[0] > np.pi / 6
    # the three contacts of the isostatic cell: equal up to the mesh's asymmetry (gmsh's
    # tetrahedra are not symmetric under axis permutation; measured 5.3 %)
    assert np.ptp(run.F[-1]) / run.F[-1].mean() < 0.08
    assert run.material.E == 200.0 and run.converged


def test_cli_cell_refuses_bad_input(tmp_path):
    out = tmp_path / "x.h5"
    base = ["--E", "200", "--sigma-y", "1", "--out", str(out), "--quiet"]
    assert cli([*base, "--lattice", "fcc", "--load", "die", "--h-max", "0.01"]) == 2
    assert cli([*base, "--lattice", "sc", "--density-max", "0.5"]) == 2
    assert cli([*base, "--lattice", "sc", "--load", "die", "--density-max", "0.9"]) == 2  # h ≈ 0.84 R
    assert cli([*base, "--lattice", "sc", "--h-max", "0.01", "--mesh-density", "3"]) == 2
    assert cli([*base, "--lattice", "sc", "--h-max", "0.01", "--E", "-1"]) == 2
    assert not out.exists()


def test_cli_cell_interrupted_keeps_converged_increments(tmp_path, monkeypatch):
    """Ctrl-C (or SIGTERM) after the second increment: the file holds those two increments,
    status 'stopped', and the command exits with the stopped code."""
    from spherecontact.fem import cell_cli

    real = cell_cli.run_cell

    def interrupted(*args, progress=None, **kw):
        def report(res):
            progress(res)
            if len(res.h) == 2:
                res.h.append(99.0)  # an increment half written when the interrupt comes
                raise KeyboardInterrupt
        return real(*args, progress=report, **kw)

    monkeypatch.setattr(cell_cli, "run_cell", interrupted)
    out = tmp_path / "cut.h5"
    rc = cli(["--E", "200", "--sigma-y", "1", "--lattice", "sc", "--h-max", "0.004", "--dh", "0.001",
              "--mesh-density", "0.5", "--out", str(out), "--quiet"])
    assert rc == cell_cli.EXIT_STOPPED
    run = read_run(out)
    assert run.status == "stopped" and "interrupted" in run.reason
    assert run.F.shape[0] == 2 and list(run.h_load) == [0.001, 0.002]


def test_cli_cell_sigterm_keeps_converged_increments(tmp_path):
    """SIGTERM to a running `spherecontact fem cell` (gmsh must not take the handler away):
    the file is written with the converged increments, status 'stopped', exit code 3."""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "killed.h5"
    exe = os.path.join(os.path.dirname(sys.executable), "spherecontact")
    p = subprocess.Popen([exe, "fem", "cell", "--E", "200", "--sigma-y", "1", "--lattice", "sc",
                          "--h-max", "0.1", "--dh", "0.001", "--mesh-density", "0.5", "--out", str(out),
                          "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(25)
    assert p.poll() is None, "the run ended before it could be stopped"
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 3, err
    run = read_run(out)
    assert run.status == "stopped" and "interrupted" in run.reason
    n = run.F.shape[0]
    assert 1 <= n < 100 and np.allclose(run.h_load, 0.001 * np.arange(1, n + 1))
