"""BLAS/LAPACK threads of the calibration: one, whatever the environment says.

The fits are small dense least-squares problems (~2000 rows, 20–34 columns): OpenBLAS
splits the larger products and factorisations of ``scipy.optimize.least_squares`` over
its threads, which changes the order of the sums, hence the last bits of the results,
which the fits amplify to the 6th digit of some coefficients (reference database,
``OPENBLAS_NUM_THREADS=2`` against 1: 7 coefficients and 5 statistics of the file
differed). On a machine shared with other jobs the threads also spin against them (the
same run took 700 s instead of 80 s). ``calibration/__init__.py`` sets the thread
variables to 1 only if they are unset, and that only takes effect before NumPy is loaded;
:func:`single_threaded_blas` sets the thread count of the BLAS libraries already loaded
(``threadpoolctl``), for the duration of a calibration. Worker processes forked inside it
inherit the setting.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from threadpoolctl import threadpool_info, threadpool_limits

__all__ = ["single_threaded_blas", "blas_threads", "set_blas_threads"]


def blas_threads() -> list[int]:
    """Thread counts of the BLAS libraries loaded in this process."""
    return [int(i["num_threads"]) for i in threadpool_info() if i["user_api"] == "blas"]


def set_blas_threads(n: int) -> list[int]:
    """Set the thread count of every loaded BLAS library to ``n``; the previous counts."""
    old = blas_threads()
    threadpool_limits(limits=int(n), user_api="blas")
    return old


@contextlib.contextmanager
def single_threaded_blas() -> Iterator[None]:
    """One BLAS/LAPACK thread inside the block (restored afterwards)."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield
