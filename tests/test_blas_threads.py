"""The BLAS thread limit of the identification (tyredamp._blas)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from tyredamp._blas import blas_threads
from tyredamp.exceptions import InputError
from tyredamp.modal import identify_modes
from tyredamp.modal.poles.lscf import plscf

from .test_modal_statistics import weak_beside_strong


def _threads() -> set[int]:
    return {int(d["num_threads"]) for d in threadpool_info() if d["user_api"] == "blas"}


def _recording(seen: list[set[int]]) -> Any:
    def estimator(*args: Any, **kwargs: Any) -> Any:
        seen.append(_threads())
        return plscf(*args, **kwargs)

    return estimator


@pytest.mark.parametrize("asked", [1, None])
def test_identification_limits_blas_and_restores_it(asked: int | None) -> None:
    frf = weak_beside_strong().frf(np.arange(60.0, 140.0, 0.25), "receptance")
    seen: list[set[int]] = []
    with threadpool_limits(limits=2, user_api="blas"):
        caller = _threads()  # 2, or fewer where the library allows fewer
        res = identify_modes(frf, model="complex", estimator=_recording(seen), blas_threads=asked)
        after = _threads()
    inside = {1} if asked == 1 else caller
    assert res.models["complex"].n_modes == 2
    assert seen
    assert all(s == inside for s in seen)
    assert after == caller  # the caller's setting is back


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_bad_thread_count_is_refused(bad: Any) -> None:
    with pytest.raises(InputError, match="blas_threads"):
        blas_threads(bad)


def test_the_controller_is_kept_until_a_module_is_imported() -> None:
    import sys

    from tyredamp import _blas

    first = _blas._controller()
    assert _blas._controller() is first  # kept: no library listing per call
    sys.modules["_tyredamp_test_marker"] = sys  # an import since: made again
    try:
        again = _blas._controller()
        assert again is not first
        with blas_threads(1):
            assert _threads() == {1}
    finally:
        del sys.modules["_tyredamp_test_marker"]
