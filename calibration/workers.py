"""Independent fits (candidate forms, cross-validation folds) on worker processes.

The fits of a calibration do not depend on each other once the full fits are known: the
folds of every form, and the large-deformation variants, are separate least-squares
problems on the same dataset. :class:`Workers` maps a module-level function over
argument tuples, on ``workers`` forked processes that inherit the dataset (it is not
sent with every task), or in this process with ``workers=1``. Every task is
deterministic and single-threaded (BLAS threads are pinned to 1), and results come back
in submission order, so the output does not depend on the number of workers. What the
tasks share need not be a dataset: the report's charts share their drawing context the same way.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed

from .dataset import Dataset

__all__ = ["DEFAULT_WORKERS", "Workers"]

#: worker processes by default: the two cores of the reference machine (at most os.cpu_count())
DEFAULT_WORKERS = 2

_DATASET: Dataset | object | None = None  # what the tasks share, of the pool being forked (inherited)


def _run(task):
    fn, args = task
    return fn(_DATASET, *args)


class Workers:
    """``map(fn, arglist)`` → ``[fn(ds, *args) for args in arglist]``, on forked processes.

    Use as a context manager. Falls back to this process when ``workers`` ≤ 1, when the
    platform cannot fork, or when only one task is given.
    """

    def __init__(self, ds: Dataset | object, workers: int = DEFAULT_WORKERS) -> None:
        self.ds = ds
        self.workers = max(1, min(int(workers), os.cpu_count() or 1))
        self._pool: ProcessPoolExecutor | None = None

    def __enter__(self) -> Workers:
        global _DATASET
        if self.workers > 1 and "fork" in multiprocessing.get_all_start_methods():
            _DATASET = self.ds
            self._pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("fork"))
        return self

    def __exit__(self, *exc) -> None:
        global _DATASET
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None
        _DATASET = None

    def map(self, fn, arglist) -> list:
        return self.run([(fn, args) for args in arglist])

    def run(self, tasks) -> list:
        """``[fn(ds, *args) for fn, args in tasks]``: tasks of several functions in one batch."""
        tasks = list(tasks)
        if self._pool is None or len(tasks) < 2:
            return [fn(self.ds, *args) for fn, args in tasks]
        return list(self._pool.map(_run, tasks))

    def submit(self, tasks):
        """Queue ``tasks`` (as :meth:`run`) and return a function that waits for their results:
        they run while this process goes on and queues more (without a pool they run when the
        results are asked for)."""
        tasks = list(tasks)
        if self._pool is None:
            return lambda: [fn(self.ds, *args) for fn, args in tasks]
        futures = [self._pool.submit(_run, t) for t in tasks]
        return lambda: [f.result() for f in futures]

    def run_then(self, tasks, then) -> tuple[list, list[list]]:
        """The results of ``tasks`` (as :meth:`run`) and, for each, the results of the tasks
        ``then(i, result)`` (a list of ``(fn, args)``), which start as soon as that result is
        known: the follow-up tasks of a quick first task fill the workers while a slow one
        runs. Results in submission order whatever the schedule."""
        tasks = list(tasks)
        if self._pool is None:
            first = [fn(self.ds, *args) for fn, args in tasks]
            return first, [self.run(then(i, r)) for i, r in enumerate(first)]
        futures = [self._pool.submit(_run, t) for t in tasks]
        index = {f: i for i, f in enumerate(futures)}
        follow: list[list] = [[] for _ in tasks]
        for f in as_completed(futures):
            i = index[f]
            follow[i] = [self._pool.submit(_run, t) for t in then(i, f.result())]
        return [f.result() for f in futures], [[f.result() for f in fs] for fs in follow]
