"""Which damping model does the virtual tyre have? The demo's damping-model section.

The ring tyre with the tread rubber (:data:`~tyredamp.virtual.rubber.DEFAULT_TREAD`,
a fractional Zener law on the sidewalls and the band) is reduced to the modes
of one band (:func:`~tyredamp.virtual.rubber.modal_band_system`); its exact
receptances at the measurement points, driven at one of them, get complex
noise at 40 dB (standard deviation 1 % of ``|H|`` per line). Every damping
model of :data:`~tyredamp.dampmodels.MODELS` is fitted to them and ranked
(:func:`~tyredamp.dampmodels.compare_models`), starting from the modes that
:func:`~tyredamp.modal.identify_modes` identifies in the same noisy FRFs,
turned into a viscous modal model (the part-1 estimate), as a user's chain
does it (``tyredamp modal``, then ``tyredamp damping --models``). Beside the
verdict stands the truth: in this band
the rubber is the fractional law ``C' s^alpha`` to first order in
``(s tau)^alpha`` (below 1 % here), with the rubber's ``alpha``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..dampmodels import ModalStart, ModelComparison, compare_models, start_from_modes
from ..virtual import RingTyre
from ..virtual.rubber import DEFAULT_TREAD, ModalBand, modal_band_system

__all__ = [
    "TRUE_MODEL",
    "DampModelStudy",
    "dampmodels_section",
    "identified_start",
    "run_dampmodels",
    "tyre_band_data",
]

#: The model the rubber tyre is in its band (module docstring).
TRUE_MODEL = "fractional"
#: Band of the modes kept, Hz (three modes of the ring tyre).
BAND_HZ = (40.0, 110.0)
#: Signal-to-noise ratio of the FRFs, dB.
SNR_DB = 40.0


@dataclass(frozen=True, eq=False)
class DampModelStudy:
    """The comparison on the virtual tyre's FRFs and the truth beside it.

    Attributes
    ----------
    band : ModalBand
        The tyre reduced to the band (truth: ``omega``, ``c_fractional``, ``alpha``).
    frequency : ndarray, shape (n_f,)
        Lines, Hz.
    comparison : ModelComparison
    snr_db : float
    """

    band: ModalBand
    frequency: NDArray[np.float64]
    comparison: ModelComparison
    snr_db: float


def tyre_band_data(
    rng: np.random.Generator,
    n_lines: int = 60,
    snr_db: float = SNR_DB,
    band: ModalBand | None = None,
) -> tuple[ModalBand, NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64]]:
    """The band's exact receptances at the points with complex noise at ``snr_db``.

    Returns
    -------
    band : ModalBand
    frequency : ndarray, shape (n_f,), Hz
    H : ndarray, complex, shape (16, 1, n_f), m/N
        Receptances, input at the drive point.
    sigma : ndarray, shape (16, 1, n_f)
        Standard deviation of the real and of the imaginary part of the noise, m/N.
    """
    b = modal_band_system(RingTyre(), BAND_HZ, DEFAULT_TREAD) if band is None else band
    fz = b.omega / (2 * np.pi)
    f = np.linspace(0.85 * fz.min(), 1.15 * fz.max(), n_lines)
    q = b.system.receptance(f)
    H0 = np.einsum("im,mnf,n->if", b.shapes, q, b.shapes[b.drive])[:, None, :]
    sig = 10 ** (-snr_db / 20) * np.abs(H0) / np.sqrt(2)
    noise = rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
    return b, f, np.asarray(H0 + sig * noise, dtype=complex), sig


def identified_start(
    band: ModalBand, frequency: NDArray[np.float64], H: NDArray[np.complex128], sigma: Any
) -> ModalStart:
    """The viscous start of the model fits from the modes identified in ``H``.

    The receptances (16 points, input at the drive point, complex noise of
    standard deviation ``sigma`` per part: variance ``2 sigma^2``) go through
    :func:`~tyredamp.modal.identify_modes` (complex modes, eq. [10] shapes); the
    start is :func:`~tyredamp.dampmodels.start_from_modes` of their poles and
    second-order shapes ``psi sqrt(2 i Im p)`` (as ``tyredamp damping --models``
    takes them from a modes file).
    """
    from ..frf import FRF, Channel
    from ..modal import identify_modes

    n = band.shapes.shape[0]
    points = tuple(Channel(k + 1, 3, 360.0 * k / n, f"P{k + 1}") for k in range(n))
    frf = FRF(
        frequency,
        H,
        kind="receptance",
        outputs=points,
        inputs=(points[band.drive],),
        variance=2.0 * np.broadcast_to(sigma, H.shape) ** 2,
    )
    mm = identify_modes(frf, model="complex").models["complex"]
    return start_from_modes(mm.poles, mm.psi_out * np.sqrt(2j * mm.poles.imag))


def run_dampmodels(seed: int = 0, n_lines: int = 60) -> DampModelStudy:
    """Fit and rank every damping model on the virtual tyre's noisy FRFs (module docstring)."""
    b, f, H, sig = tyre_band_data(np.random.default_rng(seed), n_lines)
    cmp = compare_models(f, H, sig, [b.drive], identified_start(b, f, H, sig))
    return DampModelStudy(b, f, cmp, SNR_DB)


def dampmodels_section(study: DampModelStudy) -> dict[str, Any]:
    """The ``damping_models`` section of results.json: ranking, tests, verdict and truth."""
    cmp = study.comparison
    fits = cmp.fits
    b = study.band
    frac = fits.get(TRUE_MODEL)
    models = []
    for name in cmp.ranking:
        fit = fits[name]
        models.append(
            {
                "model": name,
                "n_params": fit.n_params,
                "chi2": fit.chi2,
                "bic": fit.bic,
                "delta_bic": cmp.delta_bic[name],
            }
        )
    return {
        "snr_db": study.snr_db,
        "band_hz": [float(study.frequency[0]), float(study.frequency[-1])],
        "n_lines": int(study.frequency.size),
        "n_data": int(next(iter(fits.values())).n_data),
        "models": models,
        "tests": [
            {
                "simple": t.simple,
                "complex": t.complex,
                "statistic": t.statistic,
                "df": t.df,
                "p_value": t.p_value,
                "rejected": t.rejected,
            }
            for t in cmp.tests
        ],
        "best": cmp.best,
        "verdict": cmp.verdict,
        "fit_p_value": cmp.fit_p_value,
        "truth": {
            "model": TRUE_MODEL,
            "alpha": b.alpha,
            "frequency_hz": (b.omega / (2 * np.pi)).tolist(),
            "c_diagonal": np.diag(b.c_fractional).tolist(),
        },
        "fitted": None
        if frac is None
        else {
            "alpha": frac.extra["alpha"],
            "alpha_std": float(frac.std[-1]),
            "frequency_hz": (frac.omega / (2 * np.pi)).tolist(),
            "c_diagonal": np.diag(frac.c_modal).tolist(),
        },
    }
