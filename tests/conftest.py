"""Shared fixtures."""

from __future__ import annotations

import pytest

from tyredamp.mechanics import MCKSystem

from .helpers import chain_system


@pytest.fixture
def chain() -> MCKSystem:
    return chain_system()
