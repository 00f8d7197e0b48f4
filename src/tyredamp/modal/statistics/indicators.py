"""Fit-quality and mode-shape indicators (spec ``radial-damping.md`` eq. [19], step 6).

All functions are pure NumPy; complex mode shapes are columns of a matrix
``(n_points, n_modes)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..._validate import as_finite
from ...exceptions import ShapeError

__all__ = [
    "auto_mac",
    "discrepancy",
    "equivalent_real_modes",
    "mac",
    "mean_phase_deviation",
    "modal_phase_collinearity",
    "relative_error",
    "rmsd",
]


def _pair(
    h_exp: ArrayLike, h_th: ArrayLike
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    a = as_finite(h_exp, "h_exp", dtype=complex)
    b = as_finite(h_th, "h_th", dtype=complex)
    if a.shape != b.shape:
        raise ShapeError(f"h_th: expected the shape of h_exp {a.shape}, got {b.shape}")
    return a, b


def rmsd(h_exp: ArrayLike, h_th: ArrayLike, axis: int | None = None) -> NDArray[np.float64] | float:
    """Root-mean-square discrepancy exactly as printed in spec eq. [19].

    ``RMSD = (1/m) sqrt( sum_i |H_th(i) - H_exp(i)|^2 )`` with ``m`` the
    number of values summed (the ``1/m`` stands outside the root, as in the
    paper; it is therefore not a plain RMS and depends on ``m``).

    Parameters
    ----------
    h_exp, h_th : array_like, complex, same shape
        Measured and synthesised FRF values (any kind, in its SI unit).
    axis : int, optional
        Axis holding the frequency lines (for example ``-1`` for one value
        per FRF of an ``(n_out, n_in, n_freq)`` array). Default: all values
        together, ``m`` = total number of values.

    Returns
    -------
    float or ndarray
        RMSD in the unit of the FRF.
    """
    a, b = _pair(h_exp, h_th)
    sq = np.abs(b - a) ** 2
    if axis is None:
        return float(np.sqrt(sq.sum()) / sq.size)
    m = sq.shape[axis]
    return np.asarray(np.sqrt(sq.sum(axis=axis)) / m)


def relative_error(
    h_exp: ArrayLike, h_th: ArrayLike, axis: int | None = None
) -> NDArray[np.float64] | float:
    """Scale-free fit error: RMS of ``H_th - H_exp`` over RMS of ``H_exp`` (dimensionless).

    Unlike :func:`rmsd` it does not depend on the number of lines or the FRF
    unit, so it compares fits across data sets. Same ``axis`` convention as
    :func:`rmsd`.
    """
    a, b = _pair(h_exp, h_th)
    num = np.sum(np.abs(b - a) ** 2, axis=axis)
    den = np.sum(np.abs(a) ** 2, axis=axis)
    out = np.sqrt(num / np.where(den > 0, den, np.inf))
    return float(out) if axis is None else np.asarray(out)


def discrepancy(h_exp: ArrayLike, h_th: ArrayLike) -> NDArray[np.float64]:
    """Discrepancy per frequency line: RMS over FRFs of ``|H_th - H_exp|``.

    Parameters
    ----------
    h_exp, h_th : array_like, complex, shape (n_out, n_in, n_freq) or (n_freq,)

    Returns
    -------
    ndarray, shape (n_freq,)
        ``sqrt(mean_jk |H_th,jk(f) - H_exp,jk(f)|^2)`` in the FRF unit (the
        curve of the paper's figure 4).
    """
    a, b = _pair(h_exp, h_th)
    d = np.abs(b - a) ** 2
    return np.sqrt(d.reshape(-1, d.shape[-1]).mean(axis=0))


def _shapes(x: ArrayLike, name: str) -> NDArray[np.complex128]:
    a = as_finite(x, name, dtype=complex)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2:
        raise ShapeError(f"{name}: expected shape (n_points, n_modes), got {a.shape}")
    return a


def mac(phi_a: ArrayLike, phi_b: ArrayLike) -> NDArray[np.float64]:
    """Modal assurance criterion ``|a^H b|^2 / ((a^H a)(b^H b))`` for complex shapes.

    Parameters
    ----------
    phi_a : array_like, shape (n_points, m_a)
    phi_b : array_like, shape (n_points, m_b)

    Returns
    -------
    ndarray, shape (m_a, m_b)
        Values in [0, 1]; invariant to a complex scale of either shape.
    """
    a = _shapes(phi_a, "phi_a")
    b = _shapes(phi_b, "phi_b")
    if a.shape[0] != b.shape[0]:
        raise ShapeError(
            f"phi_b: expected {a.shape[0]} points (rows) to match phi_a, got {b.shape[0]}"
        )
    num = np.abs(a.conj().T @ b) ** 2
    na = np.sum(np.abs(a) ** 2, axis=0)
    nb = np.sum(np.abs(b) ** 2, axis=0)
    den = np.outer(na, nb)
    return np.asarray(np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0))


def auto_mac(phi: ArrayLike) -> NDArray[np.float64]:
    """MAC of a set of shapes with itself, shape (m, m); small off-diagonals: distinct shapes."""
    return mac(phi, phi)


def modal_phase_collinearity(psi: ArrayLike) -> NDArray[np.float64]:
    """Modal phase collinearity (MPC) of each complex shape (Pappa et al., 1993).

    ``MPC = ((l1 - l2) / (l1 + l2))^2`` with ``l1 >= l2`` the eigenvalues of
    the 2x2 covariance of ``[Re psi, Im psi]`` (the shape centred on its mean
    is not used: a real mode rotated by any phase gives MPC = 1).

    Parameters
    ----------
    psi : array_like, complex, shape (n_points, m)

    Returns
    -------
    ndarray, shape (m,)
        1 for a real (monophase) mode, down to 0 for a travelling-wave-like mode.
    """
    a = _unit_columns(_shapes(psi, "psi"))
    re, im = a.real, a.imag
    sxx = np.sum(re * re, axis=0)
    syy = np.sum(im * im, axis=0)
    sxy = np.sum(re * im, axis=0)
    tr = sxx + syy
    det_term = np.sqrt((sxx - syy) ** 2 + 4 * sxy**2)
    out = np.where(tr > 0, (det_term / np.where(tr > 0, tr, 1.0)) ** 2, 1.0)
    return np.asarray(out)


def mean_phase_deviation(psi: ArrayLike) -> NDArray[np.float64]:
    """Mean phase deviation (MPD) of each complex shape in degrees.

    The amplitude-weighted mean absolute angle between each entry and the best
    straight line through the origin in the complex plane (the principal
    direction of ``[Re psi, Im psi]``), taken modulo 180 degrees. 0 for a real
    mode; at most 90.

    Parameters
    ----------
    psi : array_like, complex, shape (n_points, m)

    Returns
    -------
    ndarray, shape (m,)
    """
    a = _unit_columns(_shapes(psi, "psi"))
    re, im = a.real, a.imag
    sxx = np.sum(re * re, axis=0)
    syy = np.sum(im * im, axis=0)
    sxy = np.sum(re * im, axis=0)
    theta = 0.5 * np.arctan2(2 * sxy, sxx - syy)  # principal direction
    ang = np.angle(a) - theta[None, :]
    dev = np.abs((ang + np.pi / 2) % np.pi - np.pi / 2)  # modulo 180 deg, in [0, pi/2]
    w = np.abs(a)
    wsum = np.sum(w, axis=0)
    out = np.where(wsum > 0, np.sum(w * dev, axis=0) / np.where(wsum > 0, wsum, 1.0), 0.0)
    return np.asarray(np.degrees(out))


def equivalent_real_modes(psi: ArrayLike) -> NDArray[np.float64]:
    """Equivalent real modes: each complex shape rotated to its best real line.

    Each column is multiplied by ``exp(-i theta)`` with ``theta`` the principal
    direction of its entries in the complex plane (the rotation that maximises
    ``||Re||``), and the real part is returned. For a monophase (real) mode
    this is exact up to sign; for a complex mode it is the least-squares
    closest real vector up to scale. The sign makes the largest entry positive.

    Parameters
    ----------
    psi : array_like, complex, shape (n_points, m)

    Returns
    -------
    ndarray, real, shape (n_points, m)
        Same units as ``psi`` (magnitude preserved along the principal line).
    """
    a = _shapes(psi, "psi")
    re, im = _unit_columns(a).real, _unit_columns(a).imag
    sxx = np.sum(re * re, axis=0)
    syy = np.sum(im * im, axis=0)
    sxy = np.sum(re * im, axis=0)
    theta = 0.5 * np.arctan2(2 * sxy, sxx - syy)
    r = np.real(a * np.exp(-1j * theta)[None, :])
    idx = np.argmax(np.abs(r), axis=0)
    sign = np.sign(r[idx, np.arange(r.shape[1])])
    sign[sign == 0] = 1.0
    return np.asarray(r * sign)


def _unit_columns(a: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """Each column divided by its largest magnitude (MPC, MPD and the principal
    direction do not depend on the scale of a shape; this keeps their squares
    finite for any magnitude)."""
    mx = np.max(np.abs(a), axis=0) if a.shape[0] else np.zeros(a.shape[1])
    return np.asarray(a / np.where(mx > 0, mx, 1.0)[None, :])
