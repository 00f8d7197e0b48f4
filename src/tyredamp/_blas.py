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
import sys
import threading
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
    controller = _controller()
    if controller is None:  # pragma: no cover - threadpoolctl is a dependency
        return contextlib.nullcontext()
    return controller.limit(limits=n, user_api="blas")


_LOCK = threading.Lock()
#: the controller of the loaded BLAS libraries and the number of modules imported
#: when it was made (a later import may load another library: it is made again)
_HELD: list[Any] = [None, -1]


def _controller() -> Any:
    """threadpoolctl's controller of the BLAS libraries loaded in the process.

    Making one lists the process's shared libraries (about 1 ms, each call of
    ``threadpool_limits`` does it); a limit through a kept one costs 20 us.
    It is made again when modules were imported since (a new extension module
    may bring its own BLAS). None without threadpoolctl.
    """
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        return None
    with _LOCK:
        n_mod = len(sys.modules)
        if _HELD[0] is None or _HELD[1] != n_mod:
            _HELD[0], _HELD[1] = ThreadpoolController(), n_mod
        return _HELD[0]


def single_threaded_blas() -> contextlib.AbstractContextManager[Any]:
    """Context limiting BLAS/LAPACK to one thread (:func:`blas_threads` ``(1)``)."""
    return blas_threads(1)
