"""Shared fixtures."""

from __future__ import annotations

import pytest
from threadpoolctl import threadpool_limits

from tyredamp.mechanics import MCKSystem

from .helpers import chain_system

# The tests do many small dense solves; with several BLAS threads on a busy
# 2-core machine these run 10-15x slower (measured), so use one thread.
_BLAS_LIMIT = threadpool_limits(limits=1)


@pytest.fixture
def chain() -> MCKSystem:
    return chain_system()
