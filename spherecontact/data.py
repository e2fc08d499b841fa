"""The reference database: FE runs in one HDF5 file, keyed by a hash of their inputs.

The one reader and writer of the file (layout and units in ``data/README.md``)::

    /                       attrs: schema = "spherecontact.database", schema_version = 1,
                                   created, modified (UTC), campaign (TOML text),
                                   campaign_sha256, campaign_source
      runs/<key>            one run group (schema spherecontact.fem.run, see fem/io.py)
                            + attrs campaign.set, campaign.case, campaign.params (JSON),
                                    campaign.inputs (JSON, the inputs the key hashes)
      failed/<key>          attrs set, case, reason, traceback, inputs (JSON),
                                  params (JSON), wall_s, date_utc; no data
      meshes/<digest>/X, cells  one copy of each distinct mesh; the runs' mesh/X and
                            mesh/cells are soft links to it (fem.io.share_mesh)

``key`` = :func:`input_key` of the run's requested inputs. A run that reached
h_max has status ``converged``, one that stopped early (wall-time limit,
increment below dh_min) ``stopped``; both live under ``runs/`` and the reader
returns only converged runs unless asked. A run that raised lives under
``failed/``. Read with :class:`Database`, write with :func:`append_run`::

    db = Database("data/reference_v2.h5")
    for rec, run in db.runs(set="calibration"):
        rec.params["E_over_sigma_y"], run.h, run.F, run.a
"""

from __future__ import annotations

import datetime as _dt
import errno
import hashlib
import json
import math
import os
import re
import shutil
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from .fem.io import (
    INPUT_PREFIX,
    Run,
    _python_value,
    _replacing,
    _unflatten,
    copy_run_group,
    provenance,
    run_from_group,
    write_run_group,
)
from .fem.solver import RunResult

__all__ = ["SCHEMA", "SCHEMA_VERSION", "STATUSES", "Record", "Database", "input_key", "append_run",
           "remove_entries", "remove_stale_temporaries", "compact"]

SCHEMA = "spherecontact.database"
SCHEMA_VERSION = 1
#: statuses of a database entry; "failed" entries have no run data
STATUSES = ("converged", "stopped", "failed")
RUNS = "runs"
FAILED = "failed"
MESHES = "meshes"
KEY_LENGTH = 16
_KEY_RE = re.compile(rf"^[0-9a-f]{{{KEY_LENGTH}}}$")
#: attributes the database adds to a run group (JSON values where noted)
SET_ATTR, CASE_ATTR = "campaign.set", "campaign.case"
PARAMS_ATTR, INPUTS_ATTR = "campaign.params", "campaign.inputs"
FAILED_ATTRS = ("set", "case", "reason", "traceback", "inputs", "params", "wall_s")


# ============================================================================ keys
def _canonical(value):
    """JSON-ready canonical form: numbers as floats (non-finite as strings), sorted dicts."""
    if isinstance(value, dict):
        return {str(k): _canonical(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))}
    if isinstance(value, list | tuple | np.ndarray):
        return [_canonical(v) for v in value]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | float | np.integer | np.floating):
        x = float(value)
        return x if math.isfinite(x) else repr(x)  # "inf", "-inf", "nan"
    if isinstance(value, str) or value is None:
        return value
    raise TypeError(f"input_key: cannot hash a value of type {type(value).__name__}: {value!r}")


def _to_json(value) -> str:
    """JSON text of plain Python/numpy values; inf and nan as ``Infinity``/``NaN`` (Python's json)."""
    def plain(v):
        if isinstance(v, dict):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, list | tuple | np.ndarray):
            return [plain(x) for x in v]
        return _python_value(v) if isinstance(v, np.generic) else v
    return json.dumps(plain(value), sort_keys=True)


def input_key(inputs: dict) -> str:
    """Stable 16-hex-digit key of a run's inputs.

    SHA-256 of the sorted-key JSON of ``inputs`` with every number written as a
    float (``repr``; ``1`` and ``1.0`` are the same input) and ``inf`` as
    ``"inf"``. Independent of dict order, Python version and platform.
    """
    if not isinstance(inputs, dict):
        raise TypeError(f"input_key needs a dict of inputs, got {type(inputs).__name__}")
    text = json.dumps(_canonical(inputs), sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:KEY_LENGTH]


# ============================================================================ records
@dataclass(frozen=True)
class Record:
    """One database entry, read from attributes only (cheap to list).

    ``inputs`` are the run's inputs as stored (material dict, radius,
    indenter_radius, h_max, mesh_density, element, options; ``radius2`` and
    ``material2`` for two-body runs); ``params`` the campaign's dimensionless
    parameters of the case. ``wall_s`` is the run's wall time in seconds.
    """

    key: str
    set: str
    case: str
    status: str
    reason: str
    wall_s: float
    inputs: dict
    params: dict

    @property
    def sort_key(self) -> tuple[str, str, str]:
        return (self.set, self.case, self.key)


def _utc_now() -> str:
    return _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def _json_attr(attrs, name: str, where: str):
    """Attribute ``name`` parsed as JSON (ValueError naming ``where`` if missing or bad)."""
    if name not in attrs:
        raise ValueError(f"{where} lacks the attribute {name!r}")
    try:
        return json.loads(_python_value(attrs[name]))
    except (TypeError, json.JSONDecodeError) as err:
        raise ValueError(f"{where}: attribute {name!r} is not valid JSON ({err})") from None


def _str_attr(attrs, name: str, where: str) -> str:
    if name not in attrs:
        raise ValueError(f"{where} lacks the attribute {name!r}")
    return str(_python_value(attrs[name]))


def _check_key(key: str, where: str) -> None:
    if not _KEY_RE.match(key):
        raise ValueError(f"{where}: {key!r} is not a key ({KEY_LENGTH} lowercase hex digits)")


def _run_record(g: h5py.Group) -> Record:
    """Record of a ``runs/<key>`` group, from its attributes."""
    where = f"run group {g.name!r}"
    key = g.name.rsplit("/", 1)[-1]
    _check_key(key, where)
    status = _str_attr(g.attrs, "status", where)
    if status not in ("converged", "stopped"):
        raise ValueError(f"{where}: status must be 'converged' or 'stopped', got {status!r}")
    requested = _json_attr(g.attrs, INPUTS_ATTR, where)
    stored = _unflatten(g.attrs, INPUT_PREFIX)
    wall = _python_value(g.attrs.get("provenance.wall_s", math.nan))
    return Record(key=key, set=_str_attr(g.attrs, SET_ATTR, where),
                  case=_str_attr(g.attrs, CASE_ATTR, where), status=status,
                  reason=_str_attr(g.attrs, "reason", where), wall_s=float(wall),
                  inputs={**requested, **stored}, params=_json_attr(g.attrs, PARAMS_ATTR, where))


def _failed_record(g: h5py.Group) -> Record:
    """Record of a ``failed/<key>`` group."""
    where = f"failed entry {g.name!r}"
    key = g.name.rsplit("/", 1)[-1]
    _check_key(key, where)
    return Record(key=key, set=_str_attr(g.attrs, "set", where), case=_str_attr(g.attrs, "case", where),
                  status="failed", reason=_str_attr(g.attrs, "reason", where),
                  wall_s=float(_python_value(g.attrs.get("wall_s", math.nan))),
                  inputs=_json_attr(g.attrs, "inputs", where), params=_json_attr(g.attrs, "params", where))


def _members(f: h5py.File, name: str) -> list[h5py.Group]:
    """Groups under ``/name`` (none if it does not exist)."""
    if name not in f:
        return []
    parent = f[name]
    if not isinstance(parent, h5py.Group):
        raise ValueError(f"/{name} must be a group")
    out = []
    for key in parent:
        if not isinstance(parent[key], h5py.Group):
            raise ValueError(f"/{name}/{key} must be a group")
        out.append(parent[key])
    return out


def _check_root(f: h5py.File) -> None:
    """Schema name and version of the root group."""
    if "schema" not in f.attrs:
        raise ValueError(f"not a {SCHEMA} file (the root attribute 'schema' is missing)")
    schema = _python_value(f.attrs["schema"])
    if schema != SCHEMA:
        raise ValueError(f"not a {SCHEMA} file (root attribute schema = {schema!r})")
    version = _python_value(f.attrs.get("schema_version"))
    if version != SCHEMA_VERSION:
        raise ValueError(f"unsupported schema_version {version!r} (this reader knows {SCHEMA_VERSION})")


# ============================================================================ reading
class Database:
    """The reference database at ``path``, opened read-only and validated.

    FileNotFoundError if ``path`` does not exist; ValueError starting with the
    path and naming the problem if it is not HDF5, truncated or corrupt, of a
    foreign schema or an unknown schema version. The index (records) is read
    once; run data are read on demand.
    """

    def __init__(self, path):
        self.path = Path(path)
        if not self.path.exists():
            raise FileNotFoundError(errno.ENOENT, "no such reference database", str(self.path))
        with self._open() as f:
            try:
                _check_root(f)
                self.schema_version = int(_python_value(f.attrs["schema_version"]))
                self._campaign = self._read_campaign(f)
                runs = [_run_record(g) for g in _members(f, RUNS)]
                failed = [_failed_record(g) for g in _members(f, FAILED)]
            except (OSError, KeyError, RuntimeError) as err:
                raise ValueError(f"{self.path}: unreadable HDF5 file (truncated or corrupt): {err}") from err
            except ValueError as err:
                raise ValueError(f"{self.path}: {err}") from err
        both = {r.key for r in runs} & {r.key for r in failed}
        if both:
            raise ValueError(f"{self.path}: keys both under runs/ and failed/: {sorted(both)}")
        self._records = {r.key: r for r in sorted(runs + failed, key=lambda r: r.sort_key)}
        self._content_hash: str | None = None

    # ------------------------------------------------------------------ file access
    @contextmanager
    def _open(self):
        """The file opened read-only; unreadable files become a ValueError naming the path."""
        if not self.path.is_file() or not h5py.is_hdf5(str(self.path)):
            raise ValueError(f"{self.path}: not an HDF5 file")
        try:
            f = h5py.File(self.path, "r")
        except (OSError, RuntimeError) as err:
            raise ValueError(f"{self.path}: unreadable HDF5 file (truncated or corrupt): {err}") from err
        try:
            yield f
        finally:
            f.close()

    @staticmethod
    def _read_campaign(f: h5py.File) -> dict | None:
        if "campaign" not in f.attrs:
            return None
        return {"text": str(_python_value(f.attrs["campaign"])),
                "sha256": str(_python_value(f.attrs.get("campaign_sha256", ""))),
                "source": str(_python_value(f.attrs.get("campaign_source", "")))}

    # ------------------------------------------------------------------ index
    @property
    def campaign(self) -> dict | None:
        """The campaign that wrote the file: ``{"text", "sha256", "source"}`` (None if none)."""
        return None if self._campaign is None else dict(self._campaign)

    def __len__(self) -> int:
        return len(self._records)

    def __contains__(self, key) -> bool:
        return key in self._records

    def __iter__(self) -> Iterator[str]:
        return iter(self._records)

    def __repr__(self) -> str:
        return f"Database({str(self.path)!r}, {len(self)} entries)"

    def records(self, set: str | None = None, status: str | None = None) -> list[Record]:
        """Entries sorted by (set, case, key); ``None`` selects all (failed ones included)."""
        if status is not None and status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES} or None, got {status!r}")
        return [r for r in self._records.values()
                if (set is None or r.set == set) and (status is None or r.status == status)]

    def failed(self) -> list[Record]:
        """Entries of runs that raised (reason and traceback in the file)."""
        return self.records(status="failed")

    def record(self, key: str) -> Record:
        """The entry of ``key`` (KeyError naming the key if absent)."""
        try:
            return self._records[key]
        except KeyError:
            raise KeyError(f"no entry {key!r} in {self.path}") from None

    # ------------------------------------------------------------------ run data
    def _read(self, f: h5py.File, rec: Record) -> Run:
        where = f"{self.path}:{RUNS}/{rec.key}"
        try:
            return run_from_group(f[RUNS][rec.key], source=where)
        except (ValueError, OSError, KeyError, RuntimeError) as err:
            raise ValueError(f"{where}: {err}") from err

    def run(self, key: str) -> Run:
        """The run data of ``key``, validated (KeyError if absent, ValueError if it failed)."""
        rec = self.record(key)
        if rec.status == "failed":
            raise ValueError(f"{self.path}: run {key} ({rec.case}) failed and has no data: {rec.reason}")
        with self._open() as f:
            return self._read(f, rec)

    def runs(self, set: str | None = None, status: str | None = "converged",
             where: Callable[[Record], bool] | None = None) -> list[tuple[Record, Run]]:
        """(record, run) pairs sorted by (set, case, key); by default converged runs only.

        ``status=None`` returns converged and stopped runs; failed runs have no data.
        ``where``: a test on the entry (its attributes: scene, materials, …); only the runs
        that pass it are read.
        """
        if status == "failed":
            raise ValueError("failed runs have no data; use Database.failed()")
        recs = [r for r in self.records(set=set, status=status)
                if r.status != "failed" and (where is None or where(r))]
        if not recs:
            return []
        with self._open() as f:
            return [(r, self._read(f, r)) for r in recs]

    @property
    def content_hash(self) -> str:
        """SHA-256 (hex) over keys, statuses and every dataset's bytes, in sorted key order.

        Attributes (provenance, dates) do not enter: the same runs give the same hash.
        """
        if self._content_hash is None:
            h = hashlib.sha256()
            with self._open() as f:
                for key in sorted(self._records):
                    rec = self._records[key]
                    h.update(f"{key}\0{rec.status}\0".encode())
                    if rec.status != "failed":
                        _hash_group(h, f[RUNS][key])
            self._content_hash = h.hexdigest()
        return self._content_hash


def _dataset_paths(g: h5py.Group, prefix: str = "") -> list[str]:
    """Paths of every dataset under ``g``, soft links followed (shared meshes count)."""
    out = []
    for name in g:
        obj = g[name]
        if isinstance(obj, h5py.Group):
            out += _dataset_paths(obj, f"{prefix}{name}/")
        elif isinstance(obj, h5py.Dataset):
            out.append(f"{prefix}{name}")
    return out


def _hash_group(h, g: h5py.Group) -> None:
    """Feed every dataset of ``g`` (sorted paths: name, dtype, shape, bytes) into ``h``;
    a mesh shared by soft links hashes as if the run held it."""
    for name in sorted(_dataset_paths(g)):
        arr = np.ascontiguousarray(g[name][()])
        h.update(f"{name}\0{arr.dtype.str}\0{arr.shape}\0".encode())
        h.update(arr.tobytes())


# ============================================================================ writing
@contextmanager
def _directory_lock(directory: Path):
    """Exclusive advisory lock on ``directory`` (serialises writers; released on exit or death)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def _check_record(record: Record, result: RunResult | None) -> None:
    """The record is consistent with the result and its key with its inputs."""
    if not isinstance(record, Record):
        raise ValueError(f"record must be a Record, got {type(record).__name__}")
    _check_key(record.key, "record.key")
    if record.key != input_key(record.inputs):
        raise ValueError(f"record.key {record.key} is not input_key(record.inputs) = "
                         f"{input_key(record.inputs)}")
    for name in ("set", "case"):
        if not (isinstance(getattr(record, name), str) and getattr(record, name)):
            raise ValueError(f"record.{name} must be a non-empty string")
    if result is None:
        if record.status != "failed":
            raise ValueError(f"record {record.key} has status {record.status!r} but no result; "
                             "only failed runs come without a result")
    elif record.status != result.status:
        raise ValueError(f"record.status {record.status!r} differs from the result's {result.status!r}")


def _write_entry(f: h5py.File, record: Record, result: RunResult | None, prov: dict | None,
                 traceback: str) -> None:
    """Add ``runs/<key>`` or ``failed/<key>`` to the open file."""
    if result is None:
        g = f.require_group(FAILED).create_group(record.key)
        g.attrs.update({"set": record.set, "case": record.case, "reason": record.reason,
                        "traceback": traceback, "inputs": _to_json(record.inputs),
                        "params": _to_json(record.params),
                        "wall_s": np.float64(record.wall_s), "date_utc": _utc_now()})
        return
    g = write_run_group(f.require_group(RUNS), record.key, result,
                        provenance(result) if prov is None else prov, f.require_group(MESHES))
    g.attrs[SET_ATTR] = record.set
    g.attrs[CASE_ATTR] = record.case
    g.attrs[PARAMS_ATTR] = _to_json(record.params)
    g.attrs[INPUTS_ATTR] = _to_json(record.inputs)


def _copy_without(src: Path, dst: Path, drop) -> None:
    """Copy the database ``src`` to ``dst`` leaving out the group(s) ``drop`` (space reclaimed).

    Runs are copied with their meshes shared (``fem.io.copy_run_group``): one copy of each
    mesh a kept run uses, whether ``src`` shared them or not.
    """
    drop = {drop} if isinstance(drop, str) else set(drop)
    with h5py.File(src, "r") as fs, h5py.File(dst, "w") as fd:
        fd.attrs.update(dict(fs.attrs))
        for top in fs:
            if top == MESHES:
                continue  # rebuilt from the runs kept
            if not isinstance(fs[top], h5py.Group):
                fs.copy(fs[top], fd, name=top)
                continue
            fd.create_group(top).attrs.update(dict(fs[top].attrs))
            for name in fs[top]:
                if f"{top}/{name}" in drop:
                    continue
                if top == RUNS:
                    copy_run_group(fs[top][name], fd[top], name, fd.require_group(MESHES))
                else:
                    fs.copy(fs[top][name], fd[top], name=name)


def compact(path) -> tuple[int, int]:
    """Rewrite the database ``path`` with shared meshes and the space of removed or replaced
    entries reclaimed; return its size in bytes (before, after). Crash-safe like
    :func:`append_run`; the entries and their data are unchanged."""
    path = Path(path)
    with _directory_lock(path.parent):
        Database(path)  # validated before it is rewritten
        before = path.stat().st_size
        with _replacing(path) as tmp:
            _copy_without(path, tmp, [])
    return before, path.stat().st_size


def remove_entries(path, keys) -> list[Record]:
    """Remove the runs or failures ``keys`` from the database ``path``; return their records.

    Used to drop entries the campaign no longer produces (e.g. after a case's solver
    options changed, which changes its key). An unknown key is a ValueError and nothing
    is removed. Crash-safe and serialised like :func:`append_run`.
    """
    path = Path(path)
    keys = list(dict.fromkeys(keys))
    with _directory_lock(path.parent):
        db = Database(path)
        unknown = [k for k in keys if k not in db]
        if unknown:
            raise ValueError(f"{path}: no entry with key {', '.join(unknown)}")
        if not keys:
            return []
        removed = [db.record(k) for k in keys]
        with _replacing(path) as tmp:
            _copy_without(path, tmp, [f"{FAILED if r.status == 'failed' else RUNS}/{r.key}"
                                      for r in removed])
            with h5py.File(tmp, "a") as f:
                f.attrs["modified"] = _utc_now()
    return removed


def append_run(path, record: Record, result: RunResult | None, prov: dict | None = None, *,
               traceback: str = "", campaign_text: str | None = None, campaign_source: str = "",
               replace: bool = False) -> None:
    """Add one run (``result``) or one failure (``result=None``) to the database ``path``.

    A run goes to ``runs/<key>`` (``fem.io.write_run_group`` plus the campaign
    attributes; ``prov`` defaults to ``fem.io.provenance(result)``), a failure
    to ``failed/<key>`` with ``record.reason`` and ``traceback``. A key already
    present is a ValueError, except a failed entry, which the new entry
    replaces, and a run when ``replace=True`` (e.g. a stopped run rerun with a
    longer wall-time limit). ``campaign_text`` stores the campaign file in the
    root attributes. Creates the file when missing.

    Crash-safe: the file is copied to a temporary sibling, the entry written
    there, flushed to disk and renamed over ``path``; a process killed at any
    point leaves ``path`` as it was or with the entry complete. Writers are
    serialised by a lock on the directory.
    """
    path = Path(path)
    _check_record(record, result)
    if not path.parent.is_dir():
        raise ValueError(f"{path}: directory {path.parent} does not exist")
    with _directory_lock(path.parent):
        db = Database(path) if path.exists() else None
        present = db.record(record.key) if db is not None and record.key in db else None
        if present is not None and present.status != "failed" and not replace:
            raise ValueError(f"{path}: key {record.key} ({present.case}) is already present "
                             f"with status {present.status!r}")
        with _replacing(path) as tmp:
            if present is not None and present.status != "failed":
                _copy_without(path, tmp, f"{RUNS}/{record.key}")
            elif path.exists():
                shutil.copyfile(path, tmp)
            with h5py.File(tmp, "a") as f:
                if "schema" not in f.attrs:
                    f.attrs.update({"schema": SCHEMA, "schema_version": np.int64(SCHEMA_VERSION),
                                    "created": _utc_now()})
                if present is not None and present.status == "failed":
                    del f[FAILED][record.key]
                _write_entry(f, record, result, prov, traceback)
                if campaign_text is not None:
                    f.attrs["campaign"] = campaign_text
                    f.attrs["campaign_sha256"] = hashlib.sha256(campaign_text.encode()).hexdigest()
                    f.attrs["campaign_source"] = str(campaign_source)
                f.attrs["modified"] = _utc_now()


def remove_stale_temporaries(path) -> list[Path]:
    """Delete temporaries next to ``path`` left by writers that were killed; return them.

    A temporary is ``.<name>.<pid>.<hex>.tmp``; it is stale when no process ``pid`` runs.
    """
    path = Path(path)
    pattern = re.compile(rf"^\.{re.escape(path.name)}\.(\d+)\.[0-9a-f]+\.tmp$")
    removed = []
    for tmp in path.parent.glob(f".{path.name}.*.tmp"):
        m = pattern.match(tmp.name)
        if not m:
            continue
        try:
            os.kill(int(m.group(1)), 0)
            continue  # the writer is alive
        except ProcessLookupError:
            pass
        except PermissionError:
            continue  # alive, another user's
        tmp.unlink(missing_ok=True)
        removed.append(tmp)
    return removed
