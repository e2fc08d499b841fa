"""Run an FE campaign into the reference database, in parallel, resumable.

``spherecontact campaign run --campaign data/campaign_v2.toml --db data/reference_v2.h5``

The campaign file (:mod:`.design`) expands to cases; cases whose key is already
in the database are skipped (``--retry-failed`` / ``--retry-stopped`` rerun
those, ``--refresh-start`` runs made with an older, larger first step). The
rest run in local worker processes (``--workers``, default: one per core) or on
a Dask cluster (``--scheduler tcp://host:port``). Workers send the
``RunResult`` back; the main process is the only writer and appends each run
as it finishes (:func:`spherecontact.data.append_run`, crash-safe), so a killed
campaign loses at most the runs in flight. A run that raises is recorded under
``failed/`` with its reason and traceback; one that stops early (wall-time
limit, increment below dh_min) is stored with status ``stopped``. At the end a
table per set (converged / stopped / failed / missing, wall time) is printed and
written to ``<db>.summary.json``.

Entries whose key no case of the campaign produces any more (a case whose inputs
or solver options changed gets a new key) are *superseded*: ``--dry-run`` lists
them and ``--prune`` removes them, so a set never holds two runs of one case.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import json
import math
import os
import shutil
import sys
import time
import traceback as _traceback
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path

from ..data import Database, Record, append_run, remove_entries, remove_stale_temporaries
from ..fem.io import old_plastic_start, provenance, run_indentation
from ..fem.solver import RunResult
from .design import Campaign, Case

__all__ = ["Outcome", "execute", "plan", "superseded", "prune", "run_campaign", "summarize",
           "format_summary", "select_sets", "dry_run"]

#: thread counts of the numerical libraries in local workers (one core per run)
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
ENTRY_POINT = "spherecontact campaign run"


# ============================================================================ one case
@dataclass
class Outcome:
    """What a worker sends back: the result (None if the run raised), reason, traceback."""

    key: str
    status: str  # "converged" | "stopped" | "failed"
    reason: str
    wall_s: float
    result: RunResult | None = None
    provenance: dict | None = None
    traceback: str = ""


#: environment variable naming the directory where local workers report each run's progress
PROGRESS_ENV = "SPHERECONTACT_CAMPAIGN_PROGRESS"


def _progress_writer(case: Case, kwargs: dict):
    """progress(h) writing h/h_max of ``case`` to ``$PROGRESS_ENV/<key>`` (at most every 2 s,
    replaced atomically), or None when the variable is not set."""
    folder = os.environ.get(PROGRESS_ENV)
    if not folder:
        return None
    path, h_max, last = Path(folder) / case.key, kwargs["h_max"], [-math.inf]

    def progress(h: float) -> None:
        now = time.monotonic()
        if now - last[0] >= 2.0:
            last[0] = now
            tmp = path.with_suffix(".tmp")
            try:
                tmp.write_text(f"{h / h_max:.6g}")
                tmp.replace(path)
            except OSError:  # a report that cannot be written must never fail the run
                pass
    return progress


def progress_folder(db_path: Path) -> Path:
    """This invocation's folder for its workers' reports, ``.<db>.progress.<pid>`` next to the
    database: two campaigns on one database (e.g. a retry of one case beside the main run)
    each keep their own, so neither clears the other's."""
    return db_path.parent / f".{db_path.name}.progress.{os.getpid()}"


def remove_stale_progress(db_path: Path) -> list[Path]:
    """Remove the progress folders of campaigns on ``db_path`` that no longer run (killed);
    those of live processes stay. Returns the folders removed."""
    removed = []
    for folder in db_path.parent.glob(f".{db_path.name}.progress*"):
        pid = folder.name.rsplit(".", 1)[-1]
        if pid.isdigit() and _alive(int(pid)):
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def read_progress(folder: Path, cases) -> dict[str, float]:
    """case name → reported fraction h/h_max of the running ``cases`` that reported one."""
    out = {}
    for case in cases:
        try:
            out[case.name] = float((Path(folder) / case.key).read_text())
        except (OSError, ValueError):
            continue
    return out


def execute(case: Case) -> Outcome:
    """Run one case (in a worker); every exception becomes a failed Outcome. Local workers
    report the run's progress when :data:`PROGRESS_ENV` is set."""
    t0 = time.perf_counter()
    try:
        kwargs = case.run_kwargs()
        result = run_indentation(**kwargs, progress=_progress_writer(case, kwargs))
        prov = provenance(result, extra={"entry_point": ENTRY_POINT, "set": case.set,
                                         "case": case.name})
        return Outcome(case.key, result.status, result.reason,
                       float(result.timings.get("wall_s", time.perf_counter() - t0)), result, prov)
    except Exception as err:  # recorded, never raised: one bad case must not stop the campaign
        return Outcome(case.key, "failed", f"{type(err).__name__}: {err}", time.perf_counter() - t0,
                       traceback=_traceback.format_exc())


def _lost(case: Case, err: BaseException) -> Outcome:
    """Outcome of a case whose worker died or could not run it."""
    return Outcome(case.key, "failed", f"worker error: {type(err).__name__}: {err}", 0.0,
                   traceback="".join(_traceback.format_exception(err)))


# ============================================================================ executors
Runner = Callable[[Case], Outcome]


def _inline(cases: list[Case], runner: Runner) -> Iterator[tuple[Case, Outcome]]:
    """Run in this process, one after the other (``--workers 0``)."""
    for case in cases:
        yield case, runner(case)


def _local(cases: list[Case], runner: Runner, workers: int, progress_dir: Path | None = None,
           on_wait: Callable[[list[Case]], None] | None = None) -> Iterator[tuple[Case, Outcome]]:
    """Local worker processes (spawned, one numerical thread each); results as they finish.
    With ``progress_dir`` the workers report their runs' progress there, and ``on_wait(running)``
    is called every few seconds while no run finishes."""
    env = {v: "1" for v in THREAD_VARS}
    if progress_dir is not None:
        env[PROGRESS_ENV] = str(progress_dir)
    saved = {v: os.environ.get(v) for v in env}
    os.environ.update(env)  # inherited by the spawned workers
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"))
    try:
        pending = {pool.submit(runner, case): case for case in cases}
        while pending:
            done, _ = wait(pending, timeout=5.0 if on_wait else None, return_when=FIRST_COMPLETED)
            if not done and on_wait is not None:
                on_wait([c for f, c in pending.items() if f.running()])
            for fut in done:
                case = pending.pop(fut)
                err = fut.exception()
                yield case, (_lost(case, err) if err is not None else fut.result())
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        if progress_dir is not None:
            shutil.rmtree(progress_dir, ignore_errors=True)
        for var, value in saved.items():
            if value is None:
                os.environ.pop(var, None)
            else:
                os.environ[var] = value


def _dask(cases: list[Case], runner: Runner, scheduler: str) -> Iterator[tuple[Case, Outcome]]:
    """A Dask cluster at ``scheduler``; results as they finish."""
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise ValueError("--scheduler needs dask.distributed: pip install 'spherecontact[campaign]'") \
            from None
    try:
        client = Client(scheduler, timeout="30s")
    except (OSError, TimeoutError) as err:
        raise ValueError(f"--scheduler {scheduler}: cannot connect: {err}") from None
    try:
        futures = {client.submit(runner, case, pure=False): case for case in cases}
        for fut in as_completed(list(futures)):
            case = futures.pop(fut)
            try:
                outcome = fut.result()
            except Exception as err:  # the task died with its worker
                outcome = _lost(case, err)
            fut.release()
            yield case, outcome
    finally:
        client.close()


# ============================================================================ planning
def _state(db: Database | None, key: str) -> str:
    """Database status of ``key``, or ``"missing"``."""
    return db.record(key).status if db is not None and key in db else "missing"


def expected_cost(case: Case) -> float:
    """A rough relative wall time: increments grow with E/σY (plastic onset at smaller h),
    two bodies cost about 3x and penalty pairs 10x a one-body run."""
    p = case.params
    factor = 1.0 if case.scene != "two_body" else (10.0 if case.inputs["options"].get("penalty") else 3.0)
    return factor * p["E_over_sigma_y"] ** 0.5 * p.get("mesh_density", 1.0) ** 2


def old_start(db: Database, key: str) -> bool:
    """True when the run stored under ``key`` began with a larger first step than today's
    solver takes, across first yield (``fem.io.old_plastic_start``): its first increments carry
    the transient ``fem.io.reference_mask`` leaves out, and a re-run would not."""
    run = db.run(key)
    h = run.h[run.loading]
    h = h[h > 0]
    return h.size > 0 and old_plastic_start(db.record(key).inputs, float(h[0]))


def plan(cases: list[Case], db: Database | None, retry_failed: bool = False,
         retry_stopped: bool = False, refresh_start: bool = False) -> list[Case]:
    """The cases to run: missing ones, plus failed / stopped ones when asked to retry, and
    stored runs with an old first step (:func:`old_start`) when asked to refresh them; the
    cheapest first (:func:`expected_cost`), so an interrupted campaign has done the most runs."""
    rerun = {"missing"} | ({"failed"} if retry_failed else set()) | ({"stopped"} if retry_stopped else set())

    def wanted(c: Case) -> bool:
        state = _state(db, c.key)
        return state in rerun or (refresh_start and state in ("converged", "stopped")
                                  and old_start(db, c.key))
    return sorted(filter(wanted, cases), key=expected_cost)


def superseded(campaign: Campaign, db: Database | None) -> list[Record]:
    """Database entries whose key no case of ``campaign`` (any set) produces."""
    if db is None:
        return []
    keys = {c.key for c in campaign.cases}
    return sorted((db.record(k) for k in db if k not in keys), key=lambda r: (r.set, r.case))


def prune(campaign: Campaign, db_path) -> list[Record]:
    """Remove the superseded entries of the database ``db_path``; return them."""
    db = _open_db(Path(db_path))
    return remove_entries(db_path, [r.key for r in superseded(campaign, db)]) if db else []


def _open_db(path: Path) -> Database | None:
    return Database(path) if path.exists() else None


# ============================================================================ summary
def summarize(campaign: Campaign, cases: list[Case], db_path, elapsed_s: float, ran: int,
              backend: str) -> dict:
    """Per-set counts (converged / stopped / failed / missing) and wall times of ``cases``."""
    db = _open_db(Path(db_path))
    sets: dict = {}
    for case in cases:
        s = sets.setdefault(case.set, {"cases": 0, "converged": 0, "stopped": 0, "failed": 0,
                                       "missing": 0, "wall_s_total": 0.0})
        s["cases"] += 1
        state = _state(db, case.key)
        s[state] += 1
        if state != "missing":
            s["wall_s_total"] += db.record(case.key).wall_s
    total = {k: sum(s[k] for s in sets.values()) for k in
             ("cases", "converged", "stopped", "failed", "missing", "wall_s_total")}
    for s in [*sets.values(), total]:
        done = s["cases"] - s["missing"]
        s["wall_s_mean"] = s["wall_s_total"] / done if done else None
    known = {c.key for c in campaign.cases}
    return {"database": str(db_path), "campaign": campaign.source,
            "date_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "backend": backend, "ran": ran, "elapsed_s": elapsed_s, "sets": sets, "total": total,
            "entries_not_in_campaign": 0 if db is None else sum(k not in known for k in db),
            "content_hash": None if db is None else db.content_hash}


def format_summary(summary: dict) -> str:
    """The summary as a text table (one row per set and a total)."""
    head = (f"{'set':<14}{'cases':>6}{'converged':>10}{'stopped':>8}{'failed':>7}{'missing':>8}"
            f"{'wall total [s]':>16}{'wall/run [s]':>14}")
    rows = [head, "-" * len(head)]
    for name, s in [*summary["sets"].items(), ("total", summary["total"])]:
        mean = "-" if s["wall_s_mean"] is None else f"{s['wall_s_mean']:.1f}"
        rows.append(f"{name:<14}{s['cases']:>6}{s['converged']:>10}{s['stopped']:>8}{s['failed']:>7}"
                    f"{s['missing']:>8}{s['wall_s_total']:>16.1f}{mean:>14}")
    rows.append(f"this invocation: {summary['ran']} runs in {summary['elapsed_s']:.1f} s "
                f"({summary['backend']})")
    return "\n".join(rows)


def _write_json(path: Path, data: dict) -> None:
    """Write JSON atomically (temporary sibling, then rename)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=2) + "\n")
    os.replace(tmp, path)


# ============================================================================ running
def _log(bar, text: str) -> None:
    """One line per finished run, above the progress bar (or plain when the bar is off)."""
    if bar.disable:
        print(text, file=sys.stderr, flush=True)
    else:
        bar.write(text, file=sys.stderr)


def _running_reporter(bar, folder: Path, every_s: float = 300.0):
    """on_wait callback: the running cases' h/h_max in the bar's postfix (on a terminal), or a
    log line every ``every_s`` seconds (otherwise)."""
    last = [time.monotonic()]

    def report(running: list[Case]) -> None:
        frac = read_progress(folder, running)
        text = ", ".join(f"{name} {100 * f:.0f} %" for name, f in frac.items())
        if not bar.disable:
            bar.set_postfix_str(text, refresh=True)
        elif text and time.monotonic() - last[0] >= every_s:
            last[0] = time.monotonic()
            print(f"running: {text} of h_max", file=sys.stderr, flush=True)
    return report


def run_campaign(campaign: Campaign, db_path, *, sets=None, only: str | None = None,
                 workers: int | None = None, scheduler: str | None = None,
                 retry_failed: bool = False, retry_stopped: bool = False,
                 refresh_start: bool = False, runner: Runner = execute) -> dict:
    """Run the selected cases not yet in the database; return the summary (also written as JSON).

    ``workers = 0`` runs in this process; ``scheduler`` a Dask cluster instead of
    local processes. ``runner(case) -> Outcome`` executes one case (must be
    importable by the workers).
    """
    from tqdm import tqdm

    db_path = Path(db_path)
    if not db_path.parent.is_dir():
        raise ValueError(f"--db: directory {db_path.parent} does not exist")
    remove_stale_temporaries(db_path)
    selected = campaign.select(sets, only)
    db = _open_db(db_path)
    todo = plan(selected, db, retry_failed, retry_stopped, refresh_start)
    workers = (os.cpu_count() or 1) if workers is None else workers
    backend = f"dask {scheduler}" if scheduler else (
        "in-process" if workers == 0 else f"{workers} local worker process(es)")
    print(f"{len(selected)} cases selected, {len(selected) - len(todo)} already in {db_path}, "
          f"{len(todo)} to run on {backend}", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    if todo:
        bar = tqdm(total=len(todo), unit="run", desc="fem campaign", file=sys.stderr,
                   disable=not sys.stderr.isatty(), smoothing=0.1)
        if scheduler:
            stream = _dask(todo, runner, scheduler)
        elif workers == 0:
            stream = _inline(todo, runner)
        else:  # workers report their runs' h/h_max to a folder next to the database
            remove_stale_progress(db_path)  # a killed campaign's reports are stale
            folder = progress_folder(db_path)
            folder.mkdir()
            stream = _local(todo, runner, min(workers, len(todo)), folder,
                            _running_reporter(bar, folder))
        try:
            for done, (case, out) in enumerate(stream, start=1):
                present = _state(db, case.key)
                record = Record(key=case.key, set=case.set, case=case.name, status=out.status,
                                reason=out.reason, wall_s=out.wall_s, inputs=case.inputs,
                                params=case.params)
                if present == "stopped" and _not_further(db, case.key, out):
                    bar.update(1)
                    _log(bar, f"[{done}/{len(todo)}] {case.set} {case.name}: stopped again, at "
                              f"h = {_reached(out):.6g}, short of the stored run: the stored run is "
                              f"kept ({out.reason})")
                    continue
                if present == "converged" and out.status != "converged":  # a refresh that failed
                    bar.update(1)
                    _log(bar, f"[{done}/{len(todo)}] {case.set} {case.name}: the re-run {out.status} "
                              f"({out.reason}): the stored converged run is kept")
                    continue
                try:
                    append_run(db_path, record, out.result, out.provenance, traceback=out.traceback,
                               campaign_text=campaign.text, campaign_source=campaign.source,
                               replace=present in ("stopped", "converged"))
                except ValueError as err:  # a result the writer rejects fails its case, not the campaign
                    out = _unwritable(db_path, record, present, err, campaign)
                bar.update(1)
                _log(bar, f"[{done}/{len(todo)}] {case.set} {case.name}: {out.status} "
                          f"({out.wall_s:.1f} s){'' if out.status == 'converged' else ': ' + out.reason}")
        finally:
            bar.close()
            stream.close()
    summary = summarize(campaign, selected, db_path, time.perf_counter() - t0, len(todo), backend)
    if db_path.exists():
        _write_json(Path(f"{db_path}.summary.json"), summary)
    return summary


def _reached(out: Outcome) -> float:
    """The largest approach of a run's loading curve (0 without a result)."""
    if out.result is None or len(out.result.curves.get("h", ())) == 0:
        return 0.0
    return float(max(out.result.curves["h"]))


def _not_further(db: Database, key: str, out: Outcome) -> bool:
    """True when a retried run that did not converge got no further than the stopped run stored
    under ``key`` in ``db`` (opened when the campaign started): the stored run, which holds
    more of the curve, is kept."""
    if out.status == "converged":
        return False
    return _reached(out) <= float(max(db.run(key).h))


def _unwritable(db_path, record: Record, present: str, err: ValueError, campaign: Campaign) -> Outcome:
    """A finished run whose result cannot be written (``err``): recorded as failed with the
    reason, unless the database already holds a stopped run of the case, which is kept."""
    reason = f"result could not be stored: {err}"
    if present != "stopped":
        failed = dataclasses.replace(record, status="failed", reason=reason)
        append_run(db_path, failed, None, None, traceback="".join(_traceback.format_exception(err)),
                   campaign_text=campaign.text, campaign_source=campaign.source)
    return Outcome(record.key, "failed", reason + ("" if present != "stopped" else
                                                   " (the stored stopped run is kept)"), record.wall_s)


def dry_run(campaign: Campaign, db_path, sets=None, only: str | None = None) -> str:
    """Table of the selected cases: set, name, key and database status; counts per set."""
    db = _open_db(Path(db_path))
    selected = campaign.select(sets, only)
    width = max([len(c.name) for c in selected] + [4])
    lines = [f"{'set':<12} {'case':<{width}} {'key':<16} status", ""]
    counts: dict = {}
    for c in selected:
        state = _state(db, c.key)
        lines.insert(-1, f"{c.set:<12} {c.name:<{width}} {c.key} {state}")
        counts.setdefault(c.set, {}).setdefault(state, 0)
        counts[c.set][state] += 1
    for name, cnt in counts.items():
        detail = ", ".join(f"{v} {k}" for k, v in sorted(cnt.items()))
        lines.append(f"{name}: {sum(cnt.values())} cases ({detail})")
    lines.append(f"total: {len(selected)} cases")
    old = superseded(campaign, db)
    if old:
        lines += ["", f"{len(old)} superseded database entries (no case of the campaign has their key; "
                      "--prune removes them):"]
        lines += [f"{r.set:<12} {r.case:<{width}} {r.key} {r.status}" for r in old]
    return "\n".join(lines)


# ============================================================================ command line


def select_sets(campaign: Campaign, name: str):
    """The sets to run: None for ``"all"``, else ``{name}`` (ValueError for a set the campaign lacks)."""
    if name == "all":
        return None
    if name not in campaign.sets:
        raise ValueError(f"--set {name}: the campaign has the sets {', '.join(campaign.sets)} (or all)")
    return {name}
