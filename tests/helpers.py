"""Small analytic MCK systems shared by the tests."""

from __future__ import annotations

import numpy as np

from tyredamp.mechanics import MCKSystem


def chain_system(
    n: int = 6, m: float = 1.0, k: float = 1.0e4, c_local: tuple[float, ...] = (5.0, 0.0, 2.0)
) -> MCKSystem:
    """Fixed-free spring-mass chain with local (non-proportional) dampers.

    Masses ``m`` (kg), springs ``k`` (N/m); dashpots of ``c_local[i]`` N s/m
    from mass ``i`` to ground (a standard non-proportional test case).
    """
    M = m * np.eye(n)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k
        if i + 1 < n:
            K[i, i] += k
            K[i + 1, i + 1] += 0.0
            K[i, i + 1] -= k
            K[i + 1, i] -= k
    C = np.zeros((n, n))
    for i, c in enumerate(c_local):
        C[i, i] += c
    return MCKSystem(M, C, K)


def random_system(rng: np.random.Generator, n: int, damping: float = 1.0) -> MCKSystem:
    """Random SPD ``M`` and ``K`` and a random PSD non-proportional ``C``."""
    a = rng.normal(size=(n, n))
    M = a @ a.T + n * np.eye(n)
    b = rng.normal(size=(n, n))
    K = (b @ b.T + n * np.eye(n)) * 1e4
    d = rng.normal(size=(n, max(1, n // 2)))
    # a floor of 0.1*n on the diagonal keeps every mode damped (zeta >~ 1e-5), where
    # the FRF at a resonance line is well conditioned
    C = damping * (d @ d.T + 0.1 * n * np.eye(n))
    return MCKSystem(M, C, K)
