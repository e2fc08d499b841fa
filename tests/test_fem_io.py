"""FE run file: round trip, atomic write, schema validation, input checks of run_indentation."""

import math
import os
import re

import h5py
import numpy as np
import pytest

import spherecontact
from spherecontact.fem import io as fio
from spherecontact.fem import read_run, run_indentation, write_run
from spherecontact.fem.solver import RunResult, SolverOptions
from spherecontact.model.material import Material

EPP = Material(E=200.0, nu=0.3, sigma_y=1.0, K=0.0, n=1.0)
TINY = SolverOptions(dh_first=1e-3, dh_max=0.005)


PROGRESS: list = []


@pytest.fixture(scope="module")
def result():
    """A tiny real run: E/σY = 200 on the coarsest mesh up to h = 0.01 R."""
    PROGRESS.clear()
    return run_indentation(EPP, 1.0, 0.01, density=0.25, options=TINY, progress=PROGRESS.append)


def test_progress_reports_every_increment(result):
    np.testing.assert_array_equal(PROGRESS, result.h)
    assert PROGRESS[-1] == pytest.approx(0.01)


def fake_result(material: Material, n: int = 3, status: str = "converged",
                reason: str = "reached h_max") -> RunResult:
    """A synthetic RunResult (no FE work) with ``n`` increments."""
    rng = np.random.default_rng(n)
    curves = {name: rng.random(n) for name in fio.CURVES}
    curves["h"] = np.linspace(0.001, 0.003, n)
    curves["iterations"] = rng.integers(2, 9, n)
    curves["active_changes"] = rng.integers(0, 3, n)
    residuals = [list(10.0 ** -np.arange(k + 2)) for k in range(n)]
    nodes, n_el, n_surf = 21, 4, 5
    inputs = {"material": material.describe(), "radius": 2.0, "indenter_radius": math.inf,
              "h_max": 0.003, "mesh_density": 0.5, "element": "q8r", "n_elements": n_el,
              "n_dofs": np.int32(2 * nodes), "options": dict(vars(SolverOptions()))}
    final = {"X": rng.random((2, nodes)), "u": rng.random(2 * nodes),
             "cells": rng.integers(0, nodes, (n_el, 8)).astype(np.int32),
             "eps_p": rng.random((n_el, 4))}
    return RunResult(inputs=inputs, curves=curves, residuals=residuals,
                     profile_r=rng.random((n, n_surf)), profile_p=rng.random((n, n_surf)),
                     profile_g=rng.random((n, n_surf)), status=status, reason=reason,
                     timings={"wall_s": 1.5, "increments": n,
                              "newton_iterations": int(curves["iterations"].sum())},
                     final=final)


# ---------------------------------------------------------------------------- round trip
def test_round_trip_of_a_real_run(result, tmp_path):
    path = write_run(tmp_path / "run.h5", result)
    run = read_run(path)
    assert run.status == result.status == "converged"
    assert run.reason == result.reason
    assert run.inputs == result.inputs
    assert set(run.curves) == set(result.curves)
    for name, values in result.curves.items():
        np.testing.assert_array_equal(run.curves[name], values, err_msg=name)
        assert run.curves[name].dtype.kind == values.dtype.kind, name
    np.testing.assert_array_equal(run.h, result.h)
    np.testing.assert_array_equal(run.F, result.F)
    np.testing.assert_array_equal(run.a, result.a)
    np.testing.assert_array_equal(run.p_m, result.curves["p_m"])
    assert run.h[-1] == pytest.approx(0.01)
    assert len(run.residuals) == run.n_increments == len(result.residuals)
    for got, want in zip(run.residuals, result.residuals, strict=True):  # stored as float32
        np.testing.assert_array_equal(got, np.asarray(want, dtype=np.float32))
    assert result.h.size <= fio.PROFILE_ROWS  # a short run keeps every profile
    np.testing.assert_array_equal(run.profile_increment, np.arange(result.h.size))
    np.testing.assert_array_equal(run.profile_r, result.profile_r.astype(np.float32))
    np.testing.assert_array_equal(run.profile_p, result.profile_p.astype(np.float32))
    np.testing.assert_array_equal(run.profile_gap, result.profile_g.astype(np.float32))
    for key in ("X", "u"):  # stored float32
        np.testing.assert_array_equal(run.mesh[key], result.final[key].astype(np.float32), err_msg=key)
    np.testing.assert_array_equal(run.mesh["cells"], result.final["cells"])
    np.testing.assert_array_equal(run.mesh["eps_p"], result.final["eps_p"].astype(np.float32))
    assert run.material() == EPP
    assert run.solver_options() == TINY


def test_newton_histories_converge(result, tmp_path):
    """The stored residual histories end below the tolerance and have iterations + 1 entries."""
    run = read_run(write_run(tmp_path / "run.h5", result))
    for k, res in enumerate(run.residuals):
        assert res.size == run.iterations[k] + 1
        assert res[-1] <= TINY.tol


def test_provenance_and_header(result, tmp_path):
    path = write_run(tmp_path / "run.h5", result, extra_provenance={"campaign": "unit"})
    prov = read_run(path).provenance
    assert prov["package_version"] == spherecontact.__version__
    assert prov["git_commit"] == "unknown" or re.fullmatch(r"[0-9a-f]{40}", prov["git_commit"])
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", prov["date_utc"])
    assert prov["numpy"] == np.__version__
    assert prov["hostname"] and prov["python"] and prov["scikit_fem"] != "unknown"
    assert prov["wall_s"] == result.timings["wall_s"]
    assert prov["timings"] == result.timings
    assert prov["newton"]["iterations_total"] == int(result.curves["iterations"].sum())
    assert prov["newton"]["increments"] == result.h.size
    assert prov["extra"] == {"campaign": "unit"}
    with h5py.File(path, "r") as f:
        g = f["run"]
        assert g.attrs["schema"] == "spherecontact.fem.run"
        assert g.attrs["schema_version"] == 1
        assert g.attrs["units"] == "consistent units; lengths in the unit of radius"
        assert g.attrs["input.material.E"] == 200.0
        assert g["curves/F"].attrs["units"] == "force"
        datasets = {}

        def collect(name, obj):
            if isinstance(obj, h5py.Dataset):
                datasets[name] = obj

        g.visititems(collect)
        assert len(datasets) == len(result.curves) + 2 + 4 + 4
        for name, ds in datasets.items():  # gzip exactly on the arrays above a few KB
            big = ds.size * ds.dtype.itemsize > fio.COMPRESS_ABOVE
            assert (ds.compression == "gzip") == big, name
    with h5py.File("probe.h5", "w", driver="core", backing_store=False) as f:  # in memory
        assert fio._dataset(f, "big", np.zeros(fio.COMPRESS_ABOVE)).compression == "gzip"


@pytest.mark.parametrize("material", [
    EPP,
    Material(E=70.0, nu=0.33, sigma_y=0.1, K=0.2, n=0.5),
    Material.elastic(E=1.0, nu=0.25),
    Material.from_table(E=110.0, nu=0.34, eps_p=[0.0, 0.02, 0.1], sigma=[0.15, 0.2, 0.26]),
], ids=["epp", "ludwik", "elastic", "table"])
def test_material_is_rebuilt(material, tmp_path):
    run = read_run(write_run(tmp_path / "run.h5", fake_result(material)))
    rebuilt = run.material()
    assert rebuilt == material
    eps = np.linspace(0.0, 0.3, 7)
    np.testing.assert_array_equal(rebuilt.flow_stress(eps), material.flow_stress(eps))


def test_stopped_run_without_increments(tmp_path):
    res = fake_result(EPP, n=0, status="stopped", reason="increment below dh_min at h/R = 0")
    run = read_run(write_run(tmp_path / "stopped.h5", res))
    assert run.status == "stopped" and not run.converged
    assert run.reason == "increment below dh_min at h/R = 0"
    assert run.h.size == 0 and run.residuals == [] and run.profile_p.shape == (0, 5)


def test_curves_are_attributes_and_read_only(tmp_path):
    run = read_run(write_run(tmp_path / "run.h5", fake_result(EPP)))
    np.testing.assert_array_equal(run.dissipation, run.curves["dissipation"])
    with pytest.raises(AttributeError, match="no_such_curve"):
        _ = run.no_such_curve
    with pytest.raises(ValueError):
        run.F[0] = 1.0
    assert run.deformed().shape == run.mesh["X"].shape


def test_group_copies_into_a_database(tmp_path):
    """A run group copied into another file is read back unchanged by run_from_group."""
    path = write_run(tmp_path / "run.h5", fake_result(EPP))
    db = tmp_path / "db.h5"
    with h5py.File(path, "r") as src, h5py.File(db, "w") as dst:
        src.copy(src["run"], dst, name="runs/abc123")
    with h5py.File(db, "r") as f:
        copied = fio.run_from_group(f["runs/abc123"])
    original = read_run(path)
    assert copied.inputs == original.inputs
    np.testing.assert_array_equal(copied.F, original.F)


# ---------------------------------------------------------------------------- atomic write
def _failing_group_writer(parent, name, result, prov=None):
    parent.create_group(name).create_dataset("half", data=np.arange(10))
    raise RuntimeError("simulated failure in the middle of a write")


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    monkeypatch.setattr(fio, "write_run_group", _failing_group_writer)
    with pytest.raises(RuntimeError, match="simulated"):
        write_run(tmp_path / "run.h5", fake_result(EPP))
    assert os.listdir(tmp_path) == []  # neither the final name nor a temporary file


def test_failed_write_keeps_previous_file(tmp_path, monkeypatch):
    path = tmp_path / "run.h5"
    write_run(path, fake_result(EPP, n=4))
    before = path.read_bytes()
    monkeypatch.setattr(fio, "write_run_group", _failing_group_writer)
    with pytest.raises(RuntimeError):
        write_run(path, fake_result(EPP, n=2))
    assert path.read_bytes() == before
    assert read_run(path).n_increments == 4
    assert os.listdir(tmp_path) == ["run.h5"]


def test_write_goes_through_a_temporary_name(tmp_path, monkeypatch):
    """The final name appears only by the rename, never while the data are written."""
    path = tmp_path / "run.h5"
    seen = []
    real_replace = os.replace

    def spy(src, dst):
        seen.append((os.path.dirname(src), path.exists(), h5py.is_hdf5(src)))
        real_replace(src, dst)

    monkeypatch.setattr(fio.os, "replace", spy)
    write_run(path, fake_result(EPP))
    assert seen == [(str(tmp_path), False, True)]
    assert read_run(path).n_increments == 3


# ---------------------------------------------------------------------------- validation on read
@pytest.fixture
def good_file(tmp_path):
    return write_run(tmp_path / "run.h5", fake_result(EPP))


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.h5"
    with pytest.raises(FileNotFoundError, match="nope.h5"):
        read_run(missing)


def test_not_hdf5(tmp_path):
    path = tmp_path / "run.h5"
    path.write_text("h,F\n0,0\n")
    with pytest.raises(ValueError, match="not an HDF5 file"):
        read_run(path)


def test_truncated_file(good_file):
    data = good_file.read_bytes()
    good_file.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="run.h5"):
        read_run(good_file)


def test_foreign_hdf5(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as f:
        f["x"] = np.arange(3)
    with pytest.raises(ValueError, match="no group 'run'"):
        read_run(path)


@pytest.mark.parametrize("attr, value, message", [
    ("schema", "someone.else", "schema"),
    ("schema_version", 2, "schema_version 2"),
    ("status", "exploded", "status"),
])
def test_bad_header(good_file, attr, value, message):
    with h5py.File(good_file, "r+") as f:
        f["run"].attrs[attr] = value
    with pytest.raises(ValueError, match=message):
        read_run(good_file)


@pytest.mark.parametrize("member", ["curves/F", "newton/offsets", "profiles/gap", "mesh/cells",
                                    "mesh"])
def test_missing_dataset(good_file, member):
    with h5py.File(good_file, "r+") as f:
        del f["run"][member]
    with pytest.raises(ValueError, match=member.split("/")[-1]):
        read_run(good_file)


def test_inconsistent_lengths(good_file):
    with h5py.File(good_file, "r+") as f:
        del f["run/curves/a"]
        f["run/curves/a"] = np.zeros(7)
    with pytest.raises(ValueError, match="length"):
        read_run(good_file)


# ---------------------------------------------------------------------------- input checks
class _NoSolver:
    def __init__(self, *args, **kwargs):
        raise AssertionError("the solver must not be built for invalid inputs")


@pytest.mark.parametrize("kwargs, name", [
    ({"radius": -1.0}, "radius"),
    ({"radius": math.inf}, "radius"),
    ({"h_max": 0.0}, "h_max"),
    ({"h_max": 0.9}, "h_max"),
    ({"h_max": math.nan}, "h_max"),
    ({"indenter_radius": 0.0}, "indenter_radius"),
    ({"density": 0.1}, "mesh density"),
    ({"density": 5.0}, "mesh density"),
    ({"element": "q9"}, "element"),
    ({"options": SolverOptions(dh_first=0.1, dh_max=0.01)}, "dh_first"),
    ({"material": Material.rigid()}, "rigid"),
    ({"progress": 3}, "progress"),
])
def test_run_indentation_rejects_bad_input_before_work(kwargs, name, monkeypatch):
    monkeypatch.setattr(fio, "IndentationSolver", _NoSolver)
    args = {"material": EPP, "radius": 1.0, "h_max": 0.1} | kwargs
    with pytest.raises(ValueError, match=name):
        run_indentation(**args)
