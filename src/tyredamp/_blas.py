"""The BLAS thread limit of the project's numerical work (threadpoolctl).

The modal identification, the virtual tyre and the damping chain work on
many small dense matrices (normal equations of a few hundred columns,
companion matrices of order 60, batched 130 x 130 solves). On them, several
BLAS threads gain nothing and cost much: waking the threads for each small
product costs more than the product. Measured on two shared cores
(``python benchmarks/perf_compare.py --quick --blas-threads 2`` against
``--blas-threads 1``): the tyre's identification took 0.38-0.40 s with two
OpenBLAS threads and 0.13 s with one, the 128-output case 2.8 s against
1.35 s; the full demo 111 s against 7.9 s (``benchmarks/demo_timing.py
--compare-threads``).
"""

from __future__ import annotations

import contextlib
from typing import Any

from .exceptions import InputError

__all__ = ["blas_threads", "single_threaded_blas"]


def blas_threads(n: int | None) -> contextlib.AbstractContextManager[Any]:
    """Context limiting the BLAS pools of the process to ``n`` threads while it is open.

    ``None`` leaves them as they are (the caller's own setting, e.g.
    ``OPENBLAS_NUM_THREADS`` or an enclosing ``threadpool_limits``). The
    limit is process-wide, as BLAS's own setting is: Python threads that
    run BLAS at the same time share it.
    """
    if n is None:
        return contextlib.nullcontext()
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError(f"blas_threads: expected a positive integer or None, got {n!r}")
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        return contextlib.nullcontext()
    return threadpool_limits(limits=n, user_api="blas")


def single_threaded_blas() -> contextlib.AbstractContextManager[Any]:
    """Context limiting BLAS/LAPACK to one thread (:func:`blas_threads` ``(1)``)."""
    return blas_threads(1)
