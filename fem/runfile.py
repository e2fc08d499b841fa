"""``read_run``: a run file of either kind, the axisymmetric pair run (:func:`.io.read_run`)
or a 3D cell run (:mod:`.cell_io`), told apart by its top group."""

from __future__ import annotations

from pathlib import Path

import h5py

from . import io
from .cell_io import GROUP as CELL_GROUP
from .cell_io import CellRun, cell_run_from_group


def read_run(path, group: str | None = None) -> io.Run | CellRun:
    """Read the run file ``path``: a :class:`.io.Run` for ``fem run`` files, a
    :class:`.cell_io.CellRun` for ``fem cell`` files (both validated).

    FileNotFoundError if ``path`` does not exist; ValueError naming the problem otherwise.
    """
    path = Path(path)
    cell = False
    if path.is_file() and h5py.is_hdf5(str(path)) and group in (None, CELL_GROUP):
        try:
            with h5py.File(path, "r") as f:
                cell = CELL_GROUP in f
                if cell:
                    return cell_run_from_group(f[CELL_GROUP], source=str(path))
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from err
        except (OSError, KeyError, RuntimeError) as err:
            raise ValueError(f"{path}: unreadable HDF5 file (truncated or corrupt): {err}") from err
    return io.read_run(path) if group is None else io.read_run(path, group)
