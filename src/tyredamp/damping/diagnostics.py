"""Diagnostics of an identified damping matrix and plain-English findings.

What is checked (spec step 7 and the paper's discussion):

* symmetry of ``C'`` and ``C`` (reciprocity and a consistent mode set give a
  symmetric matrix without forcing it);
* definiteness (eigenvalues of the symmetric part): every mode combination
  must dissipate energy;
* whether the data contain damping coupling at all (zero imaginary parts of
  real modes give a diagonal ``C'`` by construction);
* truncation: ``m`` modes at ``N`` points give a rank-``m`` physical matrix,
  ``C = pinv(Phi)^T C' pinv(Phi)``; its negative entries come from projecting
  the damping distribution on the few identified shapes ("power leakage"),
  and the share of the receptance that the residual terms (out-of-band modes)
  carry;
* size of the second-order terms neglected by eq. [16]/[18].
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "COLLINEAR_MAC",
    "DampingDiagnostics",
    "collinear_pairs",
    "definiteness",
    "findings",
    "not_determined",
]

#: Relative asymmetry below which C' counts as symmetric (measured data).
SYMMETRY_OK = 0.05
#: Relative asymmetry above which the input is flagged as inconsistent.
SYMMETRY_BAD = 0.2
#: ||Im Psi^|| / ||Re Psi^|| below which the modes count as real.
REAL_MODES = 1e-10
#: MAC of two modes' real shapes at the points above which the points cannot tell them apart.
COLLINEAR_MAC = 0.9


@dataclass(frozen=True)
class DampingDiagnostics:
    """Numbers that say how far an identified damping matrix can be trusted.

    Attributes
    ----------
    n_modes, n_points : int
        ``m`` and ``N``.
    symmetry_modal, symmetry_physical : float
        ``||A - A^T||_F / ||A||_F`` of ``C'`` and ``C``.
    eigenvalues_modal : ndarray, shape (m,)
        Eigenvalues of ``(C' + C'^T)/2``, 1/s, ascending.
    eigenvalues_physical : ndarray, shape (N,)
        Eigenvalues of ``(C + C^T)/2``, N s/m, ascending (``N - m`` are ~0).
    definiteness_modal : str
        "positive definite", "positive semi-definite", "indefinite" or
        "negative semi-definite".
    negative_diagonal_physical : int
        Diagonal entries of ``C`` below zero (unphysical as local dampers);
        entries within ``1e-9 max|C|`` of zero count as zero.
    negative_offdiagonal_fraction : float
        Share of the off-diagonal entries of ``C`` that are negative (same
        tolerance).
    imaginary_ratio : float
        ``||Im Psi^||_F / ||Re Psi^||_F``; 0 for real modes.
    non_proportionality : float
        ``||C' - diag C'||_F / ||diag C'||_F``.
    shape_condition : float
        Condition number of the real shape matrix ``Phi`` (N x m).
    imaginary_outside_span : float
        ``||(I - Phi pinv(Phi)) Im Psi^||_F / ||Im Psi^||_F``: the share of the
        imaginary parts of the shapes that no combination of the identified
        real shapes explains. It comes from damping coupling to modes outside
        the identified set (and noise) and is discarded by the pseudo-inverse;
        0 for a complete set.
    residual_fraction : float or None
        RMS of the residual terms of the modal model over the RMS of its
        receptance in the band (out-of-band modes); None without residuals.
    normalisation_phase : float
        Largest phase (rad) removed by the ``alpha_n^(n) = 1`` normalisation.
    basis_residual : float
        ``"refined"``: imaginary share of ``Psi^ G^-1`` (0 otherwise).
    theory_change : float or None
        ``||C'_method - C'_refined||_F / ||C'_refined||_F``: how much the
        second-order terms neglected by eq. [16]/[18] matter; None for
        ``"refined"`` or when the refinement did not converge.
    lancaster_difference : float or None
        ``||C - C_Lancaster||_F / ||C_Lancaster||_F`` when ``m == N``.
    max_damping_ratio : float
        Largest identified ``zeta_n``.
    collinear_pairs : tuple of (int, int, float)
        Pairs of modes (0-based) whose real shapes at the points have a MAC
        above :data:`COLLINEAR_MAC`, with that MAC: the points barely tell them
        apart (e.g. a structural mode and an air-cavity mode of the same wave
        number seen by radial sensors only), so the ``C'`` terms coupling them
        rest on the small difference between two nearly equal shapes.
    """

    n_modes: int
    n_points: int
    symmetry_modal: float
    symmetry_physical: float
    eigenvalues_modal: NDArray[np.float64]
    eigenvalues_physical: NDArray[np.float64]
    definiteness_modal: str
    negative_diagonal_physical: int
    negative_offdiagonal_fraction: float
    imaginary_ratio: float
    non_proportionality: float
    shape_condition: float
    imaginary_outside_span: float
    residual_fraction: float | None
    normalisation_phase: float
    basis_residual: float
    theory_change: float | None
    lancaster_difference: float | None
    max_damping_ratio: float
    collinear_pairs: tuple[tuple[int, int, float], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary of the fields (arrays as lists)."""
        out: dict[str, Any] = {}
        for fl in fields(self):
            v = getattr(self, fl.name)
            if fl.name == "collinear_pairs":
                v = [list(p) for p in v]
            out[fl.name] = v.tolist() if isinstance(v, np.ndarray) else v
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> DampingDiagnostics:
        """Inverse of :meth:`to_dict`."""
        kw: dict[str, Any] = {}
        for fl in fields(cls):
            if fl.name == "collinear_pairs":  # absent from documents of older versions
                kw[fl.name] = tuple(
                    (int(i), int(j), float(mac)) for i, j, mac in d.get(fl.name, ())
                )
                continue
            v = d[fl.name]
            kw[fl.name] = np.asarray(v, dtype=float) if fl.name.startswith("eigenvalues") else v
        return cls(**kw)


def _pct(x: float) -> str:
    """``x`` as a percentage with two significant digits, without exponent from 1 % up."""
    v = 100 * float(x)
    return f"{v:.2g}" if abs(v) < 100 else f"{v:.0f}"


def _n(k: int, word: str) -> str:
    return f"{k} {word}" + ("" if k == 1 else "s")


def _asym(a: NDArray[np.float64]) -> float:
    n = float(np.linalg.norm(a))
    return float(np.linalg.norm(a - a.T) / n) if n > 0 else 0.0


def _outside_span(basis: NDArray[np.float64], v: NDArray[np.float64]) -> float:
    nv = float(np.linalg.norm(v))
    if nv == 0:
        return 0.0
    q, _ = np.linalg.qr(basis)
    return float(np.linalg.norm(v - q @ (q.T @ v)) / nv)


def definiteness(eigenvalues: NDArray[np.float64], rtol: float = 1e-10) -> str:
    """Classify a symmetric matrix by its eigenvalues (relative tolerance ``rtol``)."""
    tol = rtol * max(float(np.max(np.abs(eigenvalues))), np.finfo(float).tiny)
    if np.all(eigenvalues > tol):
        return "positive definite"
    if np.all(eigenvalues > -tol):
        return "positive semi-definite"
    if np.all(eigenvalues < tol):
        return "negative semi-definite"
    return "indefinite"


def compute_diagnostics(
    *,
    c_modal: NDArray[np.float64],
    c_phys: NDArray[np.float64],
    shapes: NDArray[np.complex128],
    basis: NDArray[np.float64],
    damping_ratio: NDArray[np.float64],
    residual_fraction: float | None,
    normalisation_phase: NDArray[np.float64],
    basis_residual: float,
    theory_change: float | None,
    lancaster_difference: float | None,
) -> DampingDiagnostics:
    """Collect :class:`DampingDiagnostics` (see its attributes for the definitions)."""
    m, n = c_modal.shape[0], c_phys.shape[0]
    ev_m = np.asarray(np.linalg.eigvalsh(0.5 * (c_modal + c_modal.T)), dtype=float)
    ev_p = np.asarray(np.linalg.eigvalsh(0.5 * (c_phys + c_phys.T)), dtype=float)
    off = ~np.eye(n, dtype=bool)
    tiny = 1e-9 * max(float(np.max(np.abs(c_phys))), np.finfo(float).tiny)  # rounding level
    dg = np.diag(c_modal)
    sv = np.linalg.svd(basis, compute_uv=False)
    nre = float(np.linalg.norm(shapes.real))
    return DampingDiagnostics(
        n_modes=m,
        n_points=n,
        symmetry_modal=_asym(c_modal),
        symmetry_physical=_asym(c_phys),
        eigenvalues_modal=ev_m,
        eigenvalues_physical=ev_p,
        definiteness_modal=definiteness(ev_m),
        negative_diagonal_physical=int(np.count_nonzero(np.diag(c_phys) < -tiny)),
        negative_offdiagonal_fraction=float(np.mean(c_phys[off] < -tiny)) if n > 1 else 0.0,
        imaginary_ratio=float(np.linalg.norm(shapes.imag) / nre) if nre > 0 else 0.0,
        non_proportionality=float(
            np.linalg.norm(c_modal - np.diag(dg)) / max(float(np.linalg.norm(dg)), 1e-300)
        ),
        shape_condition=float(sv[0] / sv[-1]),
        imaginary_outside_span=_outside_span(basis, shapes.imag),
        residual_fraction=residual_fraction,
        normalisation_phase=float(np.max(np.abs(normalisation_phase))),
        basis_residual=basis_residual,
        theory_change=theory_change,
        lancaster_difference=lancaster_difference,
        max_damping_ratio=float(np.max(damping_ratio)),
        collinear_pairs=collinear_pairs(basis),
    )


def collinear_pairs(basis: NDArray[np.float64]) -> tuple[tuple[int, int, float], ...]:
    """Pairs of columns of ``basis`` (N x m real shapes) with a MAC above :data:`COLLINEAR_MAC`.

    ``MAC_ij = (phi_i^T phi_j)^2 / (phi_i^T phi_i phi_j^T phi_j)`` (Allemang &
    Brown 1982); 1 for shapes that are multiples of each other at the points.
    """
    b = np.asarray(basis, dtype=float)
    gram = b.T @ b
    d = np.diag(gram)
    with np.errstate(divide="ignore", invalid="ignore"):
        mac = np.where(np.outer(d, d) > 0, gram**2 / np.outer(d, d), 0.0)
    out = []
    for i in range(b.shape[1]):
        for j in range(i + 1, b.shape[1]):
            if mac[i, j] > COLLINEAR_MAC:
                out.append((i, j, float(mac[i, j])))
    return tuple(out)


def findings(
    d: DampingDiagnostics,
    method: str,
    proportional: Any = None,
    std_modal: NDArray[np.float64] | None = None,
    c_modal: NDArray[np.float64] | None = None,
) -> list[str]:
    """Plain-English conclusions from the diagnostics, most important first.

    Parameters
    ----------
    d : DampingDiagnostics
    method : str
        The estimator used.
    proportional : ProportionalComparison, optional
    std_modal : ndarray, shape (m, m), optional
        Standard errors of ``C'``.
    c_modal : ndarray, shape (m, m), optional
        ``C'`` (needed with ``std_modal``).
    """
    out: list[str] = []
    real = d.imaginary_ratio < REAL_MODES and d.n_modes > 1
    if real:
        out.append(
            "The mode shapes have no imaginary part (real modes), so C' is diagonal by "
            "construction: non-proportional damping cannot be identified from real modes. "
            "Use the complex-mode fit to identify damping coupling between modes."
        )
    why = not_determined(d, proportional)
    if why:
        out.append(
            f"C' is not determined by these modes: {why}. Use the modes' damping ratios "
            "(modal damping) rather than this matrix."
        )
    out += _collinear_findings(d)
    out += _symmetry_findings(d, real)
    out += _definiteness_findings(d)
    out += _proportionality_findings(d, real, proportional, determined=not why)
    out += _truncation_findings(d, real)
    out += _theory_findings(d, real, method)
    if std_modal is not None and c_modal is not None and d.n_modes > 1:
        out += _uncertainty_findings(d, std_modal, c_modal)
    return out


def not_determined(d: DampingDiagnostics, proportional: Any) -> str:
    """Why the damping matrix is not determined by the modes it came from, or "".

    Two facts together: ``C'`` is indefinite (a passive structure has no
    combination of modes that gains energy), and the modal system ``(I, C',
    diag omega^2)`` reproduces the complex-mode FRFs at the points *worse*
    than the same system with ``C'``'s diagonal alone
    (:class:`~tyredamp.damping.proportional.ProportionalComparison`). The
    off-diagonal terms exist to explain the modes' complexity; when adding
    them both breaks passivity and moves the model away from the modes they
    were computed from, they are what the errors of the shapes' small phases
    made of them, not damping coupling (typical of lightly damped modes
    whose phases the fit barely resolves).
    """
    if proportional is None or d.definiteness_modal != "indefinite":
        return ""
    full, modal = float(proportional.frf_error_full), float(proportional.frf_error_modal)
    if not full > modal:
        return ""
    lo, hi = float(d.eigenvalues_modal[0]), float(d.eigenvalues_modal[-1])
    return (
        f"C' is indefinite (eigenvalues {lo:.3g} to {hi:.3g} 1/s; a passive structure has "
        f"none below 0) and reproduces the FRFs of the modes it came from worse ({_pct(full)} "
        f"%) than their modal damping alone ({_pct(modal)} %): its off-diagonal terms come "
        f"from errors in the small phases of the shapes (largest damping ratio "
        f"{100 * d.max_damping_ratio:.3g} %), not from damping coupling"
    )


def _collinear_findings(d: DampingDiagnostics) -> list[str]:
    """Modes the points cannot tell apart: their coupling terms are not determined."""
    if not d.collinear_pairs:
        return []
    pairs = ", ".join(f"{i + 1} and {j + 1} (MAC {mac:.3f})" for i, j, mac in d.collinear_pairs)
    return [
        f"Modes {pairs} have nearly the same shape at the {d.n_points} measured points: "
        "the points cannot tell them apart, so the terms of C' that couple them (and with "
        "them the definiteness of C' and the physical matrix) rest on the small difference "
        "between two nearly equal shapes and are not determined by these data; their "
        "standard errors say how far. Measure where the modes differ (for an air-cavity "
        "mode beside a structural mode of the same wave number: a microphone in the "
        "cavity, or tangential responses) or leave one of them out of the damping "
        "identification."
    ]


def _symmetry_findings(d: DampingDiagnostics, real: bool) -> list[str]:
    """Symmetry of ``C'`` (reciprocity)."""
    out: list[str] = []
    # --- symmetry
    if d.n_modes > 1 and not real:
        pct = _pct(d.symmetry_modal)
        if d.symmetry_modal <= SYMMETRY_OK:
            out.append(
                f"C' is symmetric to {pct} % without any symmetrisation, as reciprocal "
                "linear viscous damping requires; the mode set looks consistent."
            )
        elif d.symmetry_modal <= SYMMETRY_BAD:
            out.append(
                f"C' is {pct} % asymmetric: noticeable, from noise on the imaginary "
                "parts of the shapes or from damping coupling to modes outside the "
                "identified set (leakage). The antisymmetric part is error (damping is "
                "reciprocal), so use the symmetric part (modal_symmetric), which is never "
                "further from the truth."
            )
        else:
            cause = (
                "strong leakage from damping coupling to modes outside the identified set "
                "(truncation), shapes and poles that do not belong together (modes out of "
                "order, a spurious or missing mode, wrong scaling), or damping too large "
                "for the small-damping theory"
            )
            out.append(
                f"C' is strongly asymmetric ({pct} %). Possible causes: {cause}. Check "
                "the modal fit before using this matrix; if the modes are right, use the "
                "symmetric part (modal_symmetric), which is never further from the truth."
            )
    return out


def _definiteness_findings(d: DampingDiagnostics) -> list[str]:
    """Definiteness of ``C'`` (passivity)."""
    out: list[str] = []
    # --- definiteness
    lo, hi = float(d.eigenvalues_modal[0]), float(d.eigenvalues_modal[-1])
    if d.definiteness_modal == "positive definite":
        out.append(
            "C' is positive definite: every identified mode and combination of modes "
            "dissipates energy."
        )
    elif d.definiteness_modal == "positive semi-definite":
        tol = 1e-10 * max(abs(lo), abs(hi))
        n_zero = int(np.count_nonzero(np.abs(d.eigenvalues_modal) <= tol))
        out.append(
            f"C' is positive semi-definite with {n_zero} zero eigenvalue(s): some "
            "combinations of modes are undamped (for example when a few local dampers "
            "carry all the damping); none gains energy."
        )
    else:
        out.append(
            f"C' is {d.definiteness_modal} (eigenvalues {lo:.3g} to {hi:.3g} 1/s): some "
            "combination of modes would gain energy, which no passive tyre does. This "
            "points to errors in the modal data (noise, mismatched or spurious modes)."
        )
    return out


def _proportionality_findings(
    d: DampingDiagnostics, real: bool, proportional: Any, determined: bool = True
) -> list[str]:
    """Proportional damping and the best Rayleigh model (the share of C' off its
    diagonal only for a C' that the modes determine, :func:`not_determined`)."""
    out: list[str] = []
    # --- proportionality
    if not real and determined and d.n_modes > 1:
        pct = _pct(d.non_proportionality)
        kind = (
            "close to proportional" if d.non_proportionality < 0.1 else "clearly non-proportional"
        )
        out.append(
            f"The off-diagonal part of C' is {pct} % of its diagonal: the damping is {kind}."
        )
    if proportional is not None:
        pr = proportional
        out.append(
            f"Best Rayleigh model alpha = {pr.rayleigh_alpha:.4g} 1/s, beta = "
            f"{pr.rayleigh_beta:.4g} s fits the modal damping ratios to "
            f"{_pct(pr.zeta_fit_error)} % RMS. Relative FRF error at the points against "
            f"the complex-mode data: full C' {_pct(pr.frf_error_full)} %, modal (diagonal) "
            f"damping {_pct(pr.frf_error_modal)} %, Rayleigh "
            f"{_pct(pr.frf_error_rayleigh)} %."
        )
        if not real and pr.frf_error_modal > 2 * max(pr.frf_error_full, 1e-12):
            out.append(
                "The full damping matrix describes the data clearly better than any "
                "proportional model: keep the off-diagonal terms in simulations."
            )
    return out


def _truncation_findings(d: DampingDiagnostics, real: bool) -> list[str]:
    """Truncation to the identified modes, leakage, residuals, conditioning."""
    out: list[str] = []
    # --- truncation and leakage
    if d.n_modes < d.n_points:
        out.append(
            f"Only {_n(d.n_modes, 'mode')} {'is' if d.n_modes == 1 else 'are'} known at "
            f"{d.n_points} points: the physical matrices "
            f"C, M and K have rank {d.n_modes} (M is singular, so there is no full MCK model "
            "at the points) and describe only motions made of the identified mode shapes. "
            "Projecting the damping on so few shapes smears it over the points ('power "
            f"leakage'): {d.negative_diagonal_physical} negative "
            f"diagonal and {100 * d.negative_offdiagonal_fraction:.0f} % negative off-diagonal "
            "entries, which are artefacts of truncation, not local negative dampers. C is "
            "as definite as C' (same signs of eigenvalues)."
        )
    else:
        out.append(
            f"The modal set is complete ({_n(d.n_modes, 'mode')} at {d.n_points} points): C is a "
            "full-rank physical damping matrix."
        )
    if d.n_modes < d.n_points and not real:
        out.append(
            f"{_pct(d.imaginary_outside_span)} % of the imaginary parts of the shapes lie "
            "outside the span of the identified real shapes: damping coupling to modes "
            "outside the identified set (or noise), which the pseudo-inverse discards. "
            "Coupling to outside modes whose shapes look like identified ones at the points "
            "cannot be separated and leaks into C' instead."
        )
    if d.residual_fraction is not None:
        out.append(
            f"The residual terms (modes outside the band) carry {_pct(d.residual_fraction)} "
            "% of the receptance RMS in the band; the identified modes explain the rest."
            + (
                " That share is large: out-of-band modes couple through damping too, and "
                "their effect leaks into C'."
                if d.residual_fraction > 0.2
                else ""
            )
        )
    if d.shape_condition > 1e3:
        out.append(
            f"The mode shapes are nearly dependent at the points (condition number "
            f"{d.shape_condition:.3g}); the pseudo-inverse amplifies noise: more points or "
            "fewer modes would help."
        )
    return out


def _theory_findings(d: DampingDiagnostics, real: bool, method: str) -> list[str]:
    """The small-damping theory, the normalisation and the refined basis."""
    out: list[str] = []
    # --- theory
    if d.theory_change is not None and not real:
        pct = _pct(d.theory_change)
        msg = (
            f"The second-order terms neglected by the {method} small-damping formula change "
            f"C' by {pct} % (largest damping ratio {_pct(d.max_damping_ratio)} %)."
        )
        if d.theory_change > 0.05:
            msg += " That is significant: use method 'refined'."
        out.append(msg)
    if d.normalisation_phase > 0.05:
        out.append(
            f"The mode normalisation needed a phase correction up to {d.normalisation_phase:.2g} "
            "rad: the scaling of some complex shapes is poorly determined by the fit."
        )
    if d.basis_residual > 0.05:
        out.append(
            f"The refined model leaves {_pct(d.basis_residual)} % imaginary residue in the "
            "real mode basis: the data are not fully consistent with the truncated modal system."
        )
    if d.lancaster_difference is not None:
        out.append(
            f"Complete modal set: Lancaster's exact formula gives a C within "
            f"{_pct(d.lancaster_difference)} % (Frobenius) of this estimate."
        )
    return out


def _uncertainty_findings(
    d: DampingDiagnostics, std_modal: NDArray[np.float64], c_modal: NDArray[np.float64]
) -> list[str]:
    """Monte Carlo standard errors against the asymmetry."""
    out: list[str] = []
    # --- uncertainty
    off = ~np.eye(d.n_modes, dtype=bool)
    sig = np.abs(c_modal[off]) > 2 * std_modal[off]
    dm = np.abs(np.diag(c_modal))
    rel_d = np.median(np.diag(std_modal) / np.where(dm > 0, dm, np.inf))
    out.append(
        f"Monte Carlo standard errors: diagonal of C' to {_pct(rel_d)} % (median); "
        f"{int(np.count_nonzero(sig))} of {int(np.count_nonzero(off))} off-diagonal terms "
        "exceed twice their standard error."
    )
    # the antisymmetric part is pure error: compare it with the noise it could come from
    anti = 0.5 * (c_modal - c_modal.T)[off]
    noise = 0.5 * np.sqrt(std_modal[off] ** 2 + std_modal.T[off] ** 2)
    ratio = float(np.linalg.norm(anti) / max(float(np.linalg.norm(noise)), 1e-300))
    if ratio > 3:
        out.append(
            f"The asymmetry of C' is {ratio:.2g} times what the standard errors allow: it "
            "is a systematic error (leakage from modes outside the set, or model error), "
            "which the standard errors do not include. The symmetric part removes the "
            "antisymmetric share of it."
        )
    return out
