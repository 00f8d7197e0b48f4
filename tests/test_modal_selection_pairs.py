"""The pair sweep and the component labels of the pole clustering against SciPy's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from tyredamp.modal.poles.selection import _components, _pairs_within


@pytest.mark.parametrize("seed", range(6))
def test_pairs_within_equal_the_kd_tree_query(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    x = rng.normal(size=(n, 2)) * rng.uniform(0.5, 20.0, size=2)
    x[rng.integers(0, n, size=n // 4)] = x[0]  # repeated points: every pair of them
    r = float(rng.uniform(0.1, 3.0))
    i, j = _pairs_within(x, r)
    ref = cKDTree(x).query_pairs(r, p=np.inf, output_type="ndarray")
    want = {(int(a), int(b)) for a, b in ref}
    assert set(zip(i.tolist(), j.tolist(), strict=True)) == want
    assert len(i) == len(want)  # each pair once
    assert np.all(i < j)


@pytest.mark.parametrize("seed", range(6))
def test_components_equal_scipys_labels(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    a = rng.random((n, n)) < rng.uniform(0.0, 0.1)
    a = a | a.T | np.eye(n, dtype=bool)
    _, ref = connected_components(a, directed=False)
    got = _components(a)
    # the same partition, each component labelled by its smallest node
    assert np.array_equal(np.unique(got, return_inverse=True)[1], ref)
    assert all(got[k] == np.flatnonzero(got == got[k]).min() for k in range(n))
