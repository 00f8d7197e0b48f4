"""Standard errors of the damping matrices by Monte Carlo over perturbed modes.

The modal fit reports standard errors of the natural frequency (Hz), the
damping ratio and the magnitude of the complex error of each mode-shape entry
(``ModalModel.std``: ``"frequency_hz"``, ``"damping_ratio"``, ``"psi_out"``).
Each Monte Carlo sample draws independent Gaussian perturbations

* ``f_n + e_f``, ``e_f ~ N(0, std_f^2)``; ``zeta_n + e_z``, ``e_z ~ N(0, std_z^2)``
  (clipped to ``0 < zeta < 1``), and rebuilds the pole by eq. [3];
* ``psi_jn + e``, ``e`` circular complex Gaussian with ``E|e|^2 = std_psi^2``
  (real and imaginary parts each with standard deviation ``std_psi / sqrt(2)``),

forms ``Psi^`` (signs aligned with the nominal shapes), and repeats the damping
identification. The reported standard errors are the sample standard
deviations (``ddof = 1``) of ``C'`` and ``C``. Monte Carlo rather than linear
propagation is used because the estimator involves a pseudo-inverse, a
normalisation iteration and (for ``"refined"``) a fixed-point iteration, and
Monte Carlo also catches the non-linearity for close modes. Correlations
between the modal parameters are not available from the fit and are ignored.
The random generator is seeded (default 0), so results are reproducible.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import TyredampError
from ..mechanics.modal_sum import pole_quantities
from .identify import Method, align_signs, modal_damping_from_modes, physical_matrices

__all__ = ["MonteCarloResult", "missing_std", "monte_carlo_std"]


@dataclass(frozen=True)
class MonteCarloResult:
    """Standard errors of ``C'`` and ``C`` from perturbed modes.

    Attributes
    ----------
    modal : ndarray, shape (m, m)
        Standard error of ``C'``, 1/s.
    physical : ndarray, shape (N, N)
        Standard error of ``C``, N s/m.
    n_samples : int
        Samples requested.
    n_failed : int
        Samples whose identification raised (excluded from the statistics).
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    """

    modal: NDArray[np.float64]
    physical: NDArray[np.float64]
    n_samples: int
    n_failed: int
    seed: int


def missing_std(
    std: dict[str, NDArray[np.float64]],
    frequency_hz: NDArray[np.float64],
    points: Sequence[str] = (),
) -> str:
    """Which standard errors in ``std`` are not finite numbers >= 0 (NaN, inf, negative).

    The Monte Carlo propagation (:func:`monte_carlo_std`) needs every standard
    error it is given: one unknown one makes the spread of ``C'`` and ``C``
    unknown, and treating it as 0 would understate it.

    Parameters
    ----------
    std : dict
        ``ModalModel.std`` (``"frequency_hz"``, ``"damping_ratio"``: shape (m,);
        ``"psi_out"``: shape (N, m)).
    frequency_hz : ndarray, shape (m,)
        Natural frequencies of the modes, Hz (to name them).
    points : sequence of str, optional
        Labels of the ``N`` points (default their numbers from 1).

    Returns
    -------
    str
        Empty when every given standard error is usable; else ``"every mode"``
        when no mode has one usable value, or one clause per mode, e.g.
        ``"mode 2 (19.85 Hz): frequency; mode 3 (28.68 Hz): shape at points 2+Z, 3+Z"``.
    """
    m = frequency_hz.size
    names = {"frequency_hz": "frequency", "damping_ratio": "damping ratio"}
    per_mode: list[list[str]] = [[] for _ in range(m)]
    usable = np.zeros(m, dtype=bool)
    for key, name in names.items():
        if key in std:
            ok = _usable(std[key])
            usable |= ok
            for i in np.flatnonzero(~ok).tolist():
                per_mode[i].append(name)
    if "psi_out" in std and np.ndim(std["psi_out"]) == 2 and np.shape(std["psi_out"])[1] == m:
        ok2 = _usable(std["psi_out"])
        usable |= ok2.any(axis=0)
        for n in range(m):
            bad = np.flatnonzero(~ok2[:, n])
            if bad.size:
                lab = [points[j] if j < len(points) else str(j + 1) for j in bad.tolist()]
                every = bad.size == ok2.shape[0]
                where = "every point" if every else f"point{'s' * (bad.size > 1)} {', '.join(lab)}"
                per_mode[n].append(f"shape at {where}")
    if not any(per_mode):
        return ""
    if not usable.any():
        return "every mode"
    return "; ".join(
        f"mode {n + 1} ({frequency_hz[n]:.4g} Hz): {', '.join(q)}"
        for n, q in enumerate(per_mode)
        if q
    )


def _usable(a: NDArray[np.float64]) -> NDArray[np.bool_]:
    v = np.asarray(a, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.isfinite(v) & (v >= 0)


def monte_carlo_std(
    poles: NDArray[np.complex128],
    psi: NDArray[np.complex128],
    reference: NDArray[np.complex128],
    std: dict[str, NDArray[np.float64]],
    method: Method,
    normalise: bool = True,
    n_samples: int = 200,
    seed: int = 0,
) -> MonteCarloResult | None:
    """Monte Carlo standard errors of ``C'`` and ``C`` (module docstring).

    Parameters
    ----------
    poles : ndarray, complex, shape (m,)
        Nominal poles, rad/s.
    psi : ndarray, complex, shape (N, m)
        Nominal shapes in the eq. [10] scaling.
    reference : ndarray, complex, shape (N, m)
        Nominal second-order shapes; fixes the sign of each perturbed column.
    std : dict
        ``ModalModel.std``; missing keys are treated as exact.
    method : {"first", "improved", "refined"}
    normalise : bool
        As in :func:`modal_damping_from_modes`.
    n_samples : int
        Number of samples (>= 2).
    seed : int
        Random seed.

    Returns
    -------
    MonteCarloResult or None
        None when ``std`` holds none of the three keys, or fewer than two
        samples succeeded.
    """
    keys = ("frequency_hz", "damping_ratio", "psi_out")
    if not any(k in std for k in keys) or n_samples < 2:
        return None
    m = poles.size
    sf = np.asarray(std.get("frequency_hz", np.zeros(m)), dtype=float)
    sz = np.asarray(std.get("damping_ratio", np.zeros(m)), dtype=float)
    sp = np.asarray(std.get("psi_out", np.zeros(psi.shape)), dtype=float)
    if sp.shape != psi.shape:
        sp = np.zeros(psi.shape)
    f0, z0 = pole_quantities(poles)
    rng = np.random.default_rng(seed)
    modal, phys = [], []
    failed = 0
    for _ in range(n_samples):
        f = np.maximum(f0 + sf * rng.standard_normal(m), 1e-6 * f0)
        z = np.clip(z0 + sz * rng.standard_normal(m), 1e-9, 0.999)
        w = 2 * np.pi * f
        p = -z * w + 1j * w * np.sqrt(1 - z**2)  # eq. [3]
        e = (rng.standard_normal(psi.shape) + 1j * rng.standard_normal(psi.shape)) / np.sqrt(2)
        shp = align_signs((psi + sp * e) * np.sqrt(2j * p.imag), reference)
        try:
            est = modal_damping_from_modes(p, shp, method, normalise)
        except TyredampError:
            failed += 1
            continue
        modal.append(est.c_modal)
        phys.append(physical_matrices(est.basis, est.c_modal, est.omega)[1])
    if len(modal) < 2:
        return None
    return MonteCarloResult(
        modal=np.std(np.array(modal), axis=0, ddof=1),
        physical=np.std(np.array(phys), axis=0, ddof=1),
        n_samples=n_samples,
        n_failed=failed,
        seed=seed,
    )
