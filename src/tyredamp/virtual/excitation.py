"""Excitation helpers of the virtual modal test (pure functions).

The default shaker signal of the rig is the periodic linear sweep of
:func:`tyredamp.signal.periodic_chirp` (the chirp of paper 000). This module
adds what the rig needs beyond it:

* :func:`schroeder_multisine` (defined in :mod:`tyredamp.signal.excitation`,
  re-exported here): a band-limited "periodic chirp": equal
  amplitudes on every DFT line of one period in the band and the phases
  ``phi_j = -pi j (j + 1) / K`` (``j = 0..K-1``, ``K`` lines; Schroeder, IEEE
  Trans. Inf. Theory 16(1), 1970). Its instantaneous frequency sweeps the band
  once per period like the swept sine, but its spectrum is exactly flat on
  the band and zero elsewhere (Pintelon & Schoukens, *System Identification:
  A Frequency Domain Approach*, 2nd ed., Wiley-IEEE 2012), which makes the
  virtual test exactly checkable against the true FRF.
* :func:`hadamard_drive_matrix`: signs of simultaneous inputs over several
  runs (orthogonal multisines).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError
from ..signal.excitation import schroeder_multisine

__all__ = ["hadamard_drive_matrix", "schroeder_multisine"]


def hadamard_drive_matrix(n_inputs: int) -> NDArray[np.float64]:
    """Signs of each input in each run of an orthogonal multi-input test.

    Rows are runs, columns inputs: the first ``n_inputs`` columns of the
    Sylvester-Hadamard matrix of order ``2^ceil(log2 n_inputs)``. Every input
    plays the same periodic signal times its sign, so the input cross-spectral
    matrix summed over the runs is ``n_runs |X_k|^2 I`` at every line: the
    best-conditioned multi-input estimate ("orthogonal multisines",
    Dobrowiecki, Schoukens & Guillaume, IEEE Trans. Instrum. Meas. 55(6), 2006).

    Parameters
    ----------
    n_inputs : int
        Number of simultaneously driven inputs, >= 1.

    Returns
    -------
    ndarray, shape (n_runs, n_inputs)
        Entries +1 or -1.
    """
    if isinstance(n_inputs, bool) or not isinstance(n_inputs, int | np.integer) or n_inputs < 1:
        raise InputError(f"n_inputs: expected an integer >= 1, got {n_inputs!r}")
    h = np.ones((1, 1))
    while h.shape[0] < n_inputs:
        h = np.block([[h, h], [h, -h]])
    return h[:, :n_inputs]
