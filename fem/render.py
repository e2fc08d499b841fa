"""Final fields of a run for ParaView (meshio VTU) and a PNG of plastic strain (pyvista).

The meridian section is written as it is (r, z, 0), deformed or not, with the
displacement as point data and the equivalent plastic strain (mean of each
element's Gauss points) as cell data. The picture mirrors the section about the
axis so the whole diametral cut of the sphere is seen.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: meshio cell type by nodes per element (serendipity quads: corners, then midsides)
CELL_TYPES = {8: "quad8", 4: "quad"}


def section_mesh(run, deformed: bool = True):
    """meshio.Mesh of a run's final state: points (n, 3), quad8/quad cells, u and ε_p."""
    import meshio

    X = run.deformed() if deformed else run.mesh["X"]
    cells = np.asarray(run.mesh["cells"])
    if cells.shape[1] not in CELL_TYPES:
        raise ValueError(f"run mesh has {cells.shape[1]}-node cells; expected 4 or 8")
    points = np.column_stack([X[0], X[1], np.zeros(X.shape[1])])
    u = np.asarray(run.mesh["u"]).reshape(-1, 2)
    eps_p = np.asarray(run.mesh["eps_p"]).mean(axis=1)
    return meshio.Mesh(points, [(CELL_TYPES[cells.shape[1]], cells)],
                       point_data={"u": np.column_stack([u, np.zeros(len(u))])},
                       cell_data={"eps_p": [eps_p]})


def export_vtu(run, path, deformed: bool = True) -> Path:
    """Write the final state to a VTU file (ParaView, meshio)."""
    path = Path(path)
    section_mesh(run, deformed).write(path)
    return path


def render_png(run, path, window: tuple[int, int] = (1200, 700)) -> Path:
    """PNG of the equivalent plastic strain on the deformed section and its mirror image.

    Needs pyvista (``pip install '.[render]'``); renders off-screen.
    """
    try:
        import pyvista as pv
    except ImportError as err:
        raise ValueError("rendering needs pyvista: pip install 'spherecontact[render]'") from err
    import os

    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    pv.OFF_SCREEN = True
    mesh = section_mesh(run, deformed=True)
    cells = mesh.cells[0].data[:, :4]  # corners: linear quads are enough for a picture
    eps = mesh.cell_data["eps_p"][0]
    pts = mesh.points
    mirror = pts * np.array([-1.0, 1.0, 1.0])
    n = len(pts)
    all_pts = np.vstack([pts, mirror])
    quads = np.vstack([cells, cells[:, ::-1] + n])
    vtk_cells = np.hstack([np.full((len(quads), 1), 4), quads]).ravel()
    grid = pv.UnstructuredGrid(vtk_cells, np.full(len(quads), pv.CellType.QUAD, dtype=np.uint8), all_pts)
    grid.cell_data["equivalent plastic strain"] = np.concatenate([eps, eps])
    plotter = pv.Plotter(off_screen=True, window_size=list(window))
    plotter.add_mesh(grid, scalars="equivalent plastic strain", cmap="viridis", show_edges=False)
    h = float(run.h[-1]) if len(run.h) else 0.0
    plotter.add_text(f"h/R = {h / run.inputs['radius']:.3g}, F = {run.F[-1]:.4g}, status {run.status}",
                     font_size=10)
    plotter.view_xy()
    path = Path(path)
    plotter.screenshot(str(path))
    plotter.close()
    return path
