"""identify_modes builds one options object from its keywords (IdentifyOptions)."""

from __future__ import annotations

import dataclasses
import inspect

from tyredamp.modal.identify import IdentifyOptions, identify_modes

#: parameters of identify_modes that are data or execution, not settings of the method
NOT_OPTIONS = {"frf", "band", "variance", "blas_threads"}


def test_options_mirror_the_keywords_in_order_with_their_defaults() -> None:
    # identify_modes fills IdentifyOptions by position: the fields must be its
    # parameters in the same order, with the same defaults
    params = [
        p
        for p in inspect.signature(identify_modes).parameters.values()
        if p.name not in NOT_OPTIONS
    ]
    fields = dataclasses.fields(IdentifyOptions)
    assert [f.name for f in fields] == [p.name for p in params]
    for f, p in zip(fields, params, strict=True):
        assert f.default == p.default, f.name
