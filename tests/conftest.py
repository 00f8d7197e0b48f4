"""Shared fixtures."""

from __future__ import annotations

import gc

import pytest
from threadpoolctl import threadpool_limits

from tyredamp.mechanics import MCKSystem

from .helpers import chain_system

# The tests do many small dense solves; with several BLAS threads on a busy
# 2-core machine these run 10-15x slower (measured), so use one thread.
_BLAS_LIMIT = threadpool_limits(limits=1)


def pytest_collection_finish(session: pytest.Session) -> None:
    """Move what collection built (modules, test items) out of the garbage collector's view.

    The commands collect garbage when they end (``quiet_run``, the UFF readers),
    and a full collection walks every tracked object: in a process that holds the
    whole collected suite that took most of the time of an in-process command
    test (measured: the 41 bad-input cases of ``tyredamp modal``, 3.2 s of CPU
    before, 0.1 s after). Objects made later are collected as usual.
    """
    gc.collect()
    gc.freeze()


@pytest.fixture
def chain() -> MCKSystem:
    return chain_system()
