"""A local pool of worker processes for a campaign: starts in a fraction of a second.

:class:`concurrent.futures.ProcessPoolExecutor` with one task at a time per
process and one BLAS thread per task (:func:`.runner.execute` limits it).
The processes are forked where the platform allows it and no other thread
runs (no imports to repeat, no port opened); otherwise started by a fork
server. A worker process that dies (the system's out-of-memory killer, a
crash in a native library) breaks the pool: the tests still unfinished are
run again in a new pool; after :data:`RESTARTS` broken pools each test still
unfinished runs alone in a pool of its own, so that only the test whose
process dies fails (with the reason) and the others complete.
"""

from __future__ import annotations

import multiprocessing
import sys
import threading
from collections.abc import Callable, Generator, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

__all__ = ["RESTARTS", "run_in_pool"]

#: How many times a broken pool is replaced before its unfinished tests fail.
RESTARTS = 1

T = TypeVar("T")
R = TypeVar("R")


def _context() -> Any:
    methods = multiprocessing.get_all_start_methods()
    if sys.platform.startswith("linux") and "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    if "forkserver" in methods:
        return multiprocessing.get_context("forkserver")
    return multiprocessing.get_context("spawn")


def run_in_pool(
    fn: Callable[[T], R],
    items: Sequence[T],
    workers: int,
    on_broken: Callable[[T], R],
) -> Iterator[tuple[T, R]]:
    """Yield ``(item, fn(item))`` as each finishes, on ``workers`` local processes.

    Parameters
    ----------
    fn : callable
        A module-level function (it is sent to the processes by reference).
    items : sequence
        The work, submitted in order.
    workers : int
        Processes (>= 1).
    on_broken : callable
        ``on_broken(item)`` gives the result of an item whose process died
        in a pool of its own (after ``RESTARTS`` broken pools).
    """
    todo = list(items)
    for attempt in range(RESTARTS + 1):
        if not todo:
            return
        if attempt < RESTARTS:
            todo = yield from _round(fn, todo, workers)
            continue
        for it in todo:  # the last round: each alone, so only the culprit fails
            left = yield from _round(fn, [it], 1)
            if left:
                yield it, on_broken(it)


def _round(
    fn: Callable[[T], R], todo: list[T], workers: int
) -> Generator[tuple[T, R], None, list[T]]:
    """One pool over ``todo``; yields what finished and returns what a broken pool lost."""
    broken: list[T] = []
    ex = ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=_context())
    clean = False
    try:
        futures: dict[Future[R], T] = {ex.submit(fn, it): it for it in todo}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                try:
                    result = fut.result()
                except BrokenProcessPool:
                    broken.append(futures[fut])
                    continue
                yield futures[fut], result
        clean = True
    finally:
        # an interruption (or a consumer that stops) does not wait for the queued tests
        ex.shutdown(wait=clean, cancel_futures=not clean)
    return broken
