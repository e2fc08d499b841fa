"""Reference database: round trip, keys, content hash, crash-safe append, schema validation on read."""

import math
import os
import signal
import subprocess
import sys
import textwrap

import h5py
import numpy as np
import pytest

from spherecontact import data
from spherecontact.data import Database, Record, append_run, input_key
from spherecontact.fem import run_indentation
from spherecontact.fem.solver import SolverOptions
from spherecontact.model.material import Material

EPP = Material(E=100.0, nu=0.3, sigma_y=1.0)
TINY = {"dh_first": 1e-3, "dh_max": 0.005}


def inputs(h_max=0.01, E=100.0):
    return {"material": Material(E=E, nu=0.3, sigma_y=1.0).describe(), "radius": 1.0,
            "indenter_radius": math.inf, "h_max": h_max, "mesh_density": 0.25, "element": "q8r",
            "options": dict(TINY)}


def record(inp, result=None, set="calibration", case="flat-pp-E100-nu0.3", reason="boom"):
    status = "failed" if result is None else result.status
    return Record(key=input_key(inp), set=set, case=case, status=status,
                  reason=reason if result is None else result.reason,
                  wall_s=0.5 if result is None else result.timings["wall_s"], inputs=inp,
                  params={"scene": "flat", "E_over_sigma_y": inp["material"]["E"]})


@pytest.fixture(scope="module")
def results():
    """Two tiny real runs (converged) and one stopped by the wall-time limit."""
    a = run_indentation(EPP, 1.0, 0.01, density=0.25, options=SolverOptions(**TINY))
    b = run_indentation(Material(E=200.0, nu=0.3, sigma_y=1.0), 1.0, 0.01, density=0.25,
                        options=SolverOptions(**TINY))
    c = run_indentation(EPP, 1.0, 0.02, density=0.25, options=SolverOptions(**TINY, max_wall_s=1e-3))
    assert (a.status, b.status, c.status) == ("converged", "converged", "stopped")
    return a, b, c


@pytest.fixture
def db_path(tmp_path, results):
    """A database with two converged runs, one stopped run and one failure."""
    a, b, c = results
    path = tmp_path / "ref.h5"
    append_run(path, record(inputs(), a), a, campaign_text="[defaults]\nh_max = 0.01\n",
               campaign_source="c.toml")
    append_run(path, record(inputs(E=200.0), b, set="validation", case="flat-pp-E200-nu0.3"), b)
    append_run(path, record(inputs(h_max=0.02), c, case="flat-pp-E100-nu0.3-h0.02"), c)
    append_run(path, record(inputs(h_max=0.03), None, case="flat-pp-E100-nu0.3-h0.03"), None,
               traceback="Traceback: boom")
    return path


# ---------------------------------------------------------------------------- keys
def test_input_key_is_stable_and_discriminating():
    inp = inputs()
    shuffled = {k: inp[k] for k in reversed(list(inp))}
    shuffled["material"] = dict(reversed(list(inp["material"].items())))
    assert input_key(shuffled) == input_key(inp)
    assert len(input_key(inp)) == 16 and int(input_key(inp), 16) >= 0
    assert input_key({**inp, "radius": 1}) == input_key(inp)  # 1 and 1.0 are the same input
    assert input_key({**inp, "h_max": 0.0100001}) != input_key(inp)
    assert input_key({**inp, "indenter_radius": 2.0}) != input_key(inp)
    assert input_key({**inp, "element": "q4"}) != input_key(inp)
    assert input_key({**inp, "radius2": 1.0}) != input_key(inp)
    assert input_key({**inp, "indenter_radius": np.float64(np.inf)}) == input_key(inp)
    # a fixed value: the key must not change across versions of Python or numpy
    assert input_key({"a": 1, "b": [0.5, math.inf], "c": "x"}) == input_key({"c": "x", "b": [0.5, "inf"],
                                                                              "a": 1.0})
    with pytest.raises(TypeError, match="cannot hash"):
        input_key({"a": object()})


# ---------------------------------------------------------------------------- round trip
def test_round_trip(db_path, results):
    a, b, c = results
    db = Database(db_path)
    assert len(db) == 4 and db.schema_version == data.SCHEMA_VERSION
    keys = [input_key(inputs()), input_key(inputs(E=200.0)), input_key(inputs(h_max=0.02)),
            input_key(inputs(h_max=0.03))]
    assert all(k in db for k in keys) and set(db) == set(keys)
    recs = db.records()
    assert [r.sort_key for r in recs] == sorted(r.sort_key for r in recs)
    assert [r.status for r in db.records(set="calibration")] == ["converged", "stopped", "failed"]
    assert [r.case for r in db.records(set="validation")] == ["flat-pp-E200-nu0.3"]
    rec = db.record(keys[0])
    assert rec.params == {"scene": "flat", "E_over_sigma_y": 100.0}
    assert rec.inputs["material"]["E"] == 100.0 and rec.inputs["mesh_density"] == 0.25
    assert rec.inputs["n_dofs"] > 0  # the solver's stored inputs complete the requested ones
    assert rec.wall_s == pytest.approx(a.timings["wall_s"])
    run = db.run(keys[0])
    np.testing.assert_array_equal(run.h, a.h)
    np.testing.assert_array_equal(run.F, a.F)
    np.testing.assert_array_equal(run.mesh["eps_p"], a.final["eps_p"].astype(np.float32))  # stored float32
    assert run.material() == EPP and run.source.endswith(f"runs/{keys[0]}")
    assert db.campaign == {"text": "[defaults]\nh_max = 0.01\n", "source": "c.toml",
                           "sha256": db.campaign["sha256"]} and len(db.campaign["sha256"]) == 64


def test_status_filters_keep_stopped_and_failed_apart(db_path):
    db = Database(db_path)
    assert {r.status for r, _ in db.runs()} == {"converged"}
    assert len(db.runs()) == 2 and len(db.runs(set="calibration")) == 1
    stopped = db.runs(status="stopped")
    assert len(stopped) == 1 and stopped[0][1].status == "stopped"
    assert "wall-time" in stopped[0][0].reason
    assert len(db.runs(status=None)) == 3  # converged and stopped; failed runs have no data
    (fail,) = db.failed()
    assert fail.reason == "boom" and fail.case == "flat-pp-E100-nu0.3-h0.03"
    assert fail.inputs["indenter_radius"] == math.inf and fail.inputs["h_max"] == 0.03
    with pytest.raises(ValueError, match="failed and has no data: boom"):
        db.run(fail.key)
    with h5py.File(db_path, "r") as f:
        assert f["failed"][fail.key].attrs["traceback"] == "Traceback: boom"
    with pytest.raises(KeyError, match="0123456789abcdef"):
        db.run("0123456789abcdef")
    with pytest.raises(ValueError, match="status must be one of"):
        db.records(status="done")
    with pytest.raises(ValueError, match="failed"):
        db.runs(status="failed")


def test_runs_where_reads_only_the_entries_that_pass(db_path, monkeypatch):
    db = Database(db_path)
    read = []
    original = Database._read
    monkeypatch.setattr(Database, "_read",
                        lambda self, f, rec: read.append(rec.key) or original(self, f, rec))
    e200 = db.runs(status=None, where=lambda r: r.inputs["material"]["E"] == 200.0)
    assert [r.case for r, _ in e200] == ["flat-pp-E200-nu0.3"] and read == [e200[0][0].key]
    assert db.runs(where=lambda r: False) == [] and len(read) == 1
    everything = db.runs(status=None)
    assert [r.key for r, _ in db.runs(status=None, where=lambda r: True)] == [r.key for r, _ in everything]


def test_content_hash_is_deterministic_and_tracks_content(tmp_path, db_path, results):
    a, b, _ = results
    h = Database(db_path).content_hash
    assert Database(db_path).content_hash == h and len(h) == 64
    other = tmp_path / "other.h5"  # the same two runs appended in the other order
    append_run(other, record(inputs(E=200.0), b, set="validation"), b)
    append_run(other, record(inputs(), a), a)
    first = tmp_path / "first.h5"
    append_run(first, record(inputs(), a), a)
    append_run(first, record(inputs(E=200.0), b, set="validation"), b)
    assert Database(other).content_hash == Database(first).content_hash
    append_run(first, record(inputs(h_max=0.05), None), None)
    assert Database(first).content_hash != Database(other).content_hash
    assert Database(first).content_hash != h


def test_runs_share_one_copy_of_each_mesh(db_path, results):
    """Three runs on one mesh: one copy under meshes/, read back through the links."""
    a, b, c = results
    with h5py.File(db_path, "r") as f:
        assert list(f[data.MESHES]) == [a_digest := f[data.RUNS][input_key(inputs())]["mesh"].attrs["shared"]]
        for g in f[data.RUNS].values():
            assert isinstance(g["mesh"].get("X", getlink=True), h5py.SoftLink)
            assert g["mesh"].attrs["shared"] == a_digest
    db = Database(db_path)
    for inp, res in ((inputs(), a), (inputs(E=200.0), b)):
        run = db.run(input_key(inp))
        assert np.array_equal(run.mesh["X"], res.final["X"].astype(np.float32))
        assert np.array_equal(run.mesh["cells"], res.final["cells"])


def _unshared_copy(src, dst):
    """The database ``src`` written the way it was before meshes were shared."""
    with h5py.File(src, "r") as fs, h5py.File(dst, "w") as fd:
        fd.attrs.update(dict(fs.attrs))
        fs.copy(fs[data.FAILED], fd, name=data.FAILED)
        runs = fd.create_group(data.RUNS)
        for key in fs[data.RUNS]:  # one copy each: separate X and cells per run
            fs.copy(fs[data.RUNS][key], runs, name=key, expand_soft=True)


def _stored_meshes(path) -> int:
    """How many coordinate arrays the file stores (each object once, links not followed)."""
    names = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: names.append(name) if name.endswith("/X") else None)
    return len(names)


def test_compact_shares_meshes_and_keeps_content(tmp_path, db_path):
    old = tmp_path / "old.h5"
    _unshared_copy(db_path, old)
    with h5py.File(old, "r") as f:
        assert data.MESHES not in f and isinstance(f[data.RUNS][input_key(inputs())]["mesh/X"], h5py.Dataset)
    h = Database(old).content_hash
    assert h == Database(db_path).content_hash  # a shared mesh hashes like one held by the run
    assert _stored_meshes(old) == 3
    data.compact(old)
    assert _stored_meshes(old) == 1
    with h5py.File(old, "r") as f:
        assert len(f[data.MESHES]) == 1
    assert Database(old).content_hash == h and len(Database(old)) == 4


def test_removing_runs_drops_meshes_no_run_uses(tmp_path, results):
    a = results[0]
    path = tmp_path / "one.h5"
    append_run(path, record(inputs(), a), a)
    other = run_indentation(EPP, 1.0, 0.005, density=0.3, options=SolverOptions(**TINY))
    inp = {**inputs(h_max=0.005), "mesh_density": 0.3}
    append_run(path, record(inp, other), other)
    with h5py.File(path, "r") as f:
        assert len(f[data.MESHES]) == 2
    data.remove_entries(path, [input_key(inp)])
    with h5py.File(path, "r") as f:
        assert len(f[data.MESHES]) == 1
    assert np.array_equal(Database(path).run(input_key(inputs())).mesh["cells"], a.final["cells"])


# ---------------------------------------------------------------------------- appending
def test_append_refuses_duplicates_and_inconsistent_records(db_path, results):
    a, _, c = results
    with pytest.raises(ValueError, match="already present with status 'converged'"):
        append_run(db_path, record(inputs(), a), a)
    bad = Record(**{**record(inputs(E=300.0), a).__dict__, "key": "0" * 16})
    with pytest.raises(ValueError, match="is not input_key"):
        append_run(db_path, bad, a)
    with pytest.raises(ValueError, match="only failed runs come without a result"):
        append_run(db_path, record(inputs(E=300.0), a), None)
    with pytest.raises(ValueError, match="differs from the result"):
        append_run(db_path, record(inputs(E=300.0), a), c)


def test_failed_entry_is_replaced_by_a_run(db_path, results):
    a = results[0]
    key = input_key(inputs(h_max=0.03))
    rec = Record(**{**record(inputs(h_max=0.03), a).__dict__, "case": "flat-pp-E100-nu0.3-h0.03"})
    append_run(db_path, rec, a)
    db = Database(db_path)
    assert db.record(key).status == "converged" and db.failed() == [] and len(db) == 4


def test_stopped_run_is_replaced_only_on_request(db_path, results):
    a = results[0]
    key = input_key(inputs(h_max=0.02))
    rec = Record(**{**record(inputs(h_max=0.02), a).__dict__, "case": "flat-pp-E100-nu0.3-h0.02"})
    with pytest.raises(ValueError, match="already present with status 'stopped'"):
        append_run(db_path, rec, a)
    append_run(db_path, rec, a, replace=True)
    db = Database(db_path)
    assert db.record(key).status == "converged" and len(db) == 4
    assert db.run(key).n_increments == a.h.size


def test_interrupted_append_leaves_the_file_intact(db_path, results, monkeypatch):
    before = Database(db_path).content_hash
    size = db_path.stat().st_size

    def crash(*args, **kwargs):
        raise KeyboardInterrupt  # e.g. Ctrl-C in the middle of writing

    monkeypatch.setattr(data, "write_run_group", crash)
    with pytest.raises(KeyboardInterrupt):
        append_run(db_path, record(inputs(E=300.0), results[0]), results[0])
    assert Database(db_path).content_hash == before and db_path.stat().st_size == size
    assert [p.name for p in db_path.parent.iterdir() if p.suffix == ".tmp"] == []


def test_sigkill_during_append_leaves_the_file_intact(db_path):
    """A writer killed between writing its temporary and the rename: old file intact, temporary stale."""
    before = Database(db_path).content_hash
    script = textwrap.dedent(f"""
        import math, os, signal
        from spherecontact import data
        from spherecontact.fem import run_indentation
        from spherecontact.fem.solver import SolverOptions
        from spherecontact.model.material import Material
        m = Material(E=300.0, nu=0.3, sigma_y=1.0)
        r = run_indentation(m, 1.0, 0.005, density=0.25, options=SolverOptions(dh_first=1e-3))
        inp = {{"material": m.describe(), "radius": 1.0, "h_max": 0.005}}
        rec = data.Record(data.input_key(inp), "calibration", "killed", r.status, r.reason, 1.0, inp, {{}})
        data.os.replace = lambda *a: os.kill(os.getpid(), signal.SIGKILL)
        data.append_run({str(db_path)!r}, rec, r)
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    stale = [p for p in db_path.parent.iterdir() if p.name.endswith(".tmp")]
    assert len(stale) == 1
    assert Database(db_path).content_hash == before and len(Database(db_path)) == 4
    assert data.remove_stale_temporaries(db_path) == stale and not stale[0].exists()


def test_live_temporaries_are_kept(tmp_path):
    mine = tmp_path / f".ref.h5.{os.getpid()}.abcd1234.tmp"
    mine.write_bytes(b"")
    assert data.remove_stale_temporaries(tmp_path / "ref.h5") == [] and mine.exists()


# ---------------------------------------------------------------------------- schema on read
def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such reference database"):
        Database(tmp_path / "nope.h5")


def test_not_hdf5(tmp_path):
    path = tmp_path / "ref.h5"
    path.write_text("run,h,F\n1,2,3\n")
    with pytest.raises(ValueError, match=f"^{path}: not an HDF5 file"):
        Database(path)


def test_truncated_file(tmp_path, db_path):
    cut = tmp_path / "cut.h5"
    raw = db_path.read_bytes()
    cut.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ValueError, match=f"^{cut}: unreadable HDF5 file \\(truncated or corrupt\\)"):
        Database(cut)


def test_foreign_and_future_files(tmp_path, db_path):
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f.create_dataset("x", data=np.arange(3))
    with pytest.raises(ValueError, match=f"^{foreign}: not a spherecontact.database file "
                                         "\\(the root attribute 'schema' is missing\\)"):
        Database(foreign)
    with h5py.File(foreign, "a") as f:
        f.attrs["schema"] = "spherecontact.fem.run"
    with pytest.raises(ValueError, match="root attribute schema = 'spherecontact.fem.run'"):
        Database(foreign)
    future = tmp_path / "future.h5"
    future.write_bytes(db_path.read_bytes())
    with h5py.File(future, "a") as f:
        f.attrs["schema_version"] = 2
    with pytest.raises(ValueError, match=f"^{future}: unsupported schema_version 2"):
        Database(future)


def test_damaged_entries_are_named(tmp_path, db_path):
    key = input_key(inputs())
    path = tmp_path / "damaged.h5"
    path.write_bytes(db_path.read_bytes())
    with h5py.File(path, "a") as f:
        del f["runs"][key].attrs["campaign.case"]
    with pytest.raises(ValueError, match=f"^{path}: run group '/runs/{key}' lacks the attribute "
                                         "'campaign.case'"):
        Database(path)
    path.write_bytes(db_path.read_bytes())
    with h5py.File(path, "a") as f:
        del f["runs"][key]["curves"]["F"]
    db = Database(path)  # the index is intact; the run data are checked when read
    with pytest.raises(ValueError, match=f"runs/{key}: .*lacks F"):
        db.run(key)
