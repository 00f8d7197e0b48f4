"""Which damping model does the virtual tyre have? The demo's damping-model section.

The ring tyre with the tread rubber (:data:`~tyredamp.virtual.rubber.DEFAULT_TREAD`,
a fractional Zener law on the sidewalls and the band) is reduced to the modes
of one band (:func:`~tyredamp.virtual.rubber.modal_band_system`); its exact
receptances at the measurement points, driven at one of them, get complex
noise at 40 dB (standard deviation 1 % of ``|H|`` per line). Every damping
model of :data:`~tyredamp.dampmodels.MODELS` is fitted to them and ranked
(:func:`~tyredamp.dampmodels.compare_models`), starting from the tyre's
exact modes turned into a viscous modal model (the part-1 estimate, as a
modal fit would give it). Beside the verdict stands the truth: in this band
the rubber is the fractional law ``C' s^alpha`` to first order in
``(s tau)^alpha`` (below 1 % here), with the rubber's ``alpha``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..dampmodels import ModelComparison, compare_models, start_from_modes
from ..virtual import RingTyre
from ..virtual.rubber import DEFAULT_TREAD, ModalBand, modal_band_system

__all__ = [
    "TRUE_MODEL",
    "DampModelStudy",
    "dampmodels_section",
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


def run_dampmodels(seed: int = 0, n_lines: int = 60) -> DampModelStudy:
    """Fit and rank every damping model on the virtual tyre's noisy FRFs (module docstring)."""
    b, f, H, sig = tyre_band_data(np.random.default_rng(seed), n_lines)
    md = b.system.modes()
    start = start_from_modes(md.poles, b.shapes @ md.shapes * np.sqrt(2j * md.poles.imag))
    cmp = compare_models(f, H, sig, [b.drive], start)
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
