"""The ``>>>`` examples in the docstrings of the key public functions run.

These are the examples the API reference shows (``identify_modes``, ``FRF``,
``read_frf``, the virtual tyre); each module's examples run
under :mod:`doctest` as written.
"""

from __future__ import annotations

import doctest
import importlib

import pytest

#: Modules whose docstring examples must run (each has at least one).
MODULES = [
    "tyredamp.frf",
    "tyredamp.io",
    "tyredamp.modal.identify",
    "tyredamp.virtual",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(
        module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False
    )
    assert result.attempted > 0, f"{name}: no docstring example found"
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed"
