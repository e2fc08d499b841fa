"""Export of a run's final state (meshio VTU) and the plastic-strain picture (pyvista, optional)."""

import meshio
import numpy as np
import pytest

from spherecontact.cli import main
from spherecontact.fem.io import read_run, run_indentation, write_run
from spherecontact.fem.render import export_vtu
from spherecontact.fem.solver import SolverOptions
from spherecontact.model import Material


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    res = run_indentation(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, 0.004, density=0.5,
                          options=SolverOptions(dh_first=2e-4, dh_max=5e-4))
    path = tmp_path_factory.mktemp("render") / "run.h5"
    write_run(path, res)
    return path


def test_vtu_holds_deformed_section_and_fields(run_file, tmp_path):
    run = read_run(run_file)
    out = export_vtu(run, tmp_path / "run.vtu")
    mesh = meshio.read(out)
    cells = mesh.cells_dict["quad8"]
    assert cells.shape == np.asarray(run.mesh["cells"]).shape
    assert np.allclose(mesh.points[:, :2].T, run.deformed())
    eps = mesh.cell_data["eps_p"][0]
    assert eps.max() > 0 and eps.max() <= run.curves["eps_p_max"][-1] + 1e-12
    ref = meshio.read(export_vtu(run, tmp_path / "ref.vtu", deformed=False))
    assert np.allclose(ref.points[:, :2].T, run.mesh["X"])


def test_render_command_needs_an_output(run_file, capsys):
    assert main(["fem", "render", str(run_file)]) == 2
    assert "--png" in capsys.readouterr().err


def test_render_png(run_file, tmp_path):
    pytest.importorskip("pyvista")
    png = tmp_path / "eps.png"
    assert main(["fem", "render", str(run_file), "--png", str(png)]) == 0
    assert png.stat().st_size > 10_000
