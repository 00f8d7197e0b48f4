"""The exact modal "truth" of a virtual tyre at its measured points.

Everything an identification result can be compared with: the exact complex
modes in the band (spec eq. [4]-[10]), their wave numbers and visibility from
the drive points, their complexity (modal phase collinearity), the undamped
mass-normalised modes and the damping in modal coordinates (eq. [14]), the
damping matrix reduced to the measured points, and the exact FRFs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from .._validate import as_band, as_finite
from ..exceptions import InputError, PhysicsError, ShapeError
from ..frf import FRF, Channel, FRFKind
from ..mechanics import MCKSystem, pole_quantities
from ..modal.model import ModalModel

__all__ = ["MeasuredRing", "TyreTruth", "modal_phase_collinearity", "wave_numbers"]

ModeSet = Literal["visible", "measurable", "all"]

#: Share of a mode's squared displacement that must be radial for it to be measurable.
RADIAL_THRESHOLD = 0.01
#: Drive-point amplitude, relative to the largest point amplitude, for a mode to be visible.
VISIBLE_THRESHOLD = 0.01


def wave_numbers(
    radial: ArrayLike, tangential: ArrayLike | None = None
) -> tuple[NDArray[np.int_], NDArray[np.float64]]:
    """Dominant circumferential wave number of each mode shape (Fourier analysis).

    Parameters
    ----------
    radial : array_like, shape (n_nodes, m)
        Radial shapes (real or complex) at ``n_nodes`` equally spaced angles
        starting at 0.
    tangential : array_like, shape (n_nodes, m), optional
        Tangential shapes on the same (or the half-step shifted) grid; their
        harmonic power is added (a shift does not change it). Needed to see
        the rotation mode (``n = 0``), which has no radial motion.

    Returns
    -------
    n : ndarray of int, shape (m,)
        Wave number with the largest harmonic power, ``0 .. n_nodes // 2``.
    purity : ndarray, shape (m,)
        Share of the total power in that harmonic (1 for a pure harmonic);
        low values flag shapes that mix harmonics (imperfect ring) or alias.
    """
    w = np.asarray(radial)
    if w.ndim == 1:
        w = w[:, None]
    if w.ndim != 2:
        raise ShapeError(f"radial: expected shape (n_nodes, m), got {w.shape}")
    power = _harmonic_power(w)
    if tangential is not None:
        v = np.asarray(tangential)
        if v.ndim == 1:
            v = v[:, None]
        if v.shape != w.shape:
            raise ShapeError(f"tangential: expected shape {w.shape}, got {v.shape}")
        power = power + _harmonic_power(v)
    total = power.sum(axis=0)
    n = np.argmax(power, axis=0)
    purity = power[n, np.arange(power.shape[1])] / np.where(total > 0, total, 1.0)
    return n.astype(int), purity


def _harmonic_power(x: NDArray[np.generic]) -> NDArray[np.float64]:
    """Power per wave number 0..N//2 of columns of ``x`` (real and imaginary parts)."""
    n_nodes = x.shape[0]
    xr = np.real(x).astype(float)
    xi = np.imag(x).astype(float) if np.iscomplexobj(x) else np.zeros_like(xr)
    p = np.abs(np.fft.rfft(xr, axis=0)) ** 2 + np.abs(np.fft.rfft(xi, axis=0)) ** 2
    weight = np.full(p.shape[0], 2.0)
    weight[0] = 1.0
    if n_nodes % 2 == 0:
        weight[-1] = 1.0
    return p * weight[:, None]


class MeasuredRing(Protocol):
    """What :meth:`TyreTruth.from_tyre` needs of a ring tyre (:class:`~tyredamp.virtual.RingTyre`).

    The ring's DOFs are ordered ``n_ring`` radial then ``n_ring`` tangential.
    """

    @property
    def system(self) -> MCKSystem:
        """The ``M``, ``C``, ``K`` system of the whole ring."""

    @property
    def n_ring(self) -> int:
        """Number of ring nodes."""

    @property
    def point_dofs(self) -> NDArray[np.intp]:
        """DOF index of each measured point (radial)."""

    @property
    def drive_dofs(self) -> NDArray[np.intp]:
        """DOF index of each drive point (radial)."""

    @property
    def output_channels(self) -> tuple[Channel, ...]:
        """Acceleration channels of the measured points."""

    @property
    def input_channels(self) -> tuple[Channel, ...]:
        """Force channels of the drive points."""


def modal_phase_collinearity(shapes: ArrayLike) -> NDArray[np.float64]:
    """Modal phase collinearity (MPC) of complex mode shapes.

    ``MPC = ((l1 - l2) / (l1 + l2))^2`` with ``l1 >= l2`` the eigenvalues of
    ``[[Re.Re, Re.Im], [Re.Im, Im.Im]]`` of each shape (Pappa, Elliott &
    Schenk, J. Guidance 16(5), 1993, without mean removal). 1 for a real
    (mono-phase) mode, whatever its complex scaling; lower for a complex mode;
    0 for a travelling wave with equal real and imaginary parts.

    Parameters
    ----------
    shapes : array_like, complex, shape (n_points, m)
        Mode shapes in columns (any complex scaling).

    Returns
    -------
    ndarray, shape (m,)
        MPC in [0, 1] of each mode.
    """
    psi = as_finite(shapes, "shapes", dtype=complex)
    if psi.ndim == 1:
        psi = psi[:, None]
    if psi.ndim != 2:
        raise ShapeError(f"shapes: expected shape (n_points, m), got {psi.shape}")
    x, y = psi.real, psi.imag
    sxx = np.sum(x * x, axis=0)
    syy = np.sum(y * y, axis=0)
    sxy = np.sum(x * y, axis=0)
    tr = sxx + syy
    disc = np.sqrt((sxx - syy) ** 2 + 4 * sxy**2)  # l1 - l2
    with np.errstate(invalid="ignore", divide="ignore"):
        mpc = np.where(tr > 0, (disc / np.where(tr > 0, tr, 1.0)) ** 2, 1.0)
    return np.clip(mpc, 0.0, 1.0)


@dataclass(frozen=True, eq=False)
class TyreTruth:
    """Exact modal description of a virtual tyre in a frequency band.

    Built by :meth:`RingTyre.truth`. All in-band complex modes of the full
    discretisation are kept (ascending ``Im p``), with flags saying which ones
    a test with the tyre's points and drive points can see.

    Attributes
    ----------
    system : MCKSystem
        The full discretisation (``M``, ``C``, ``K``).
    band : (float, float)
        Band in Hz; modes with ``|p_n| / 2 pi`` inside are kept.
    point_dofs : ndarray of int, shape (n_points,)
        DOF index of each measured point (radial).
    drive_dofs : ndarray of int, shape (n_drive,)
        DOF index of each drive point (radial).
    outputs, inputs : tuple of Channel
        Acceleration channels of the points, force channels of the drives.
    poles : ndarray, complex, shape (m,)
        ``p_n = -sigma_n + i Omega_n`` in rad/s (eq. [5]).
    psi_points : ndarray, complex, shape (n_points, m)
        Complex modes at the points in the eq. [10] scaling
        (``psi = Psi / sqrt(a)``), in 1/sqrt(kg/s).
    psi_drive : ndarray, complex, shape (n_drive, m)
        The same at the drive points.
    wave_number, purity : ndarray, shape (m,)
        Dominant circumferential wave number of each mode (Fourier analysis of
        its full radial and tangential shape) and the share of power in it.
    radial_fraction : ndarray, shape (m,)
        ``|Psi_w|^2 / (|Psi_w|^2 + |Psi_v|^2)`` over the whole ring; about
        ``n^2/(n^2 + 1)`` for flexural modes, 0 for the rotation mode.
    participation : ndarray, shape (m,)
        ``max_drive |psi| / max_points |psi|``.
    measurable, visible : ndarray of bool, shape (m,)
        ``radial_fraction >= 0.01``; and, in addition, ``participation >= 0.01``
        (the mode appears in the FRFs from the drive points).
    mpc : ndarray, shape (m,)
        Modal phase collinearity of ``psi_points`` (1 for real modes).
    undamped_index : ndarray of int, shape (m,)
        Index of the matching undamped mode in ``system.undamped_modes()``
        (one-to-one assignment maximising ``|Phi^T M Psi|``).
    phi_points : ndarray, shape (n_points, m)
        Those mass-normalised undamped modes at the points (1/sqrt(kg)), each
        signed so that its largest-magnitude entry at the points is positive
        (the convention of :meth:`ModalModel.second_order_shapes`).
    modal_damping : ndarray, shape (m, m)
        ``C'_kn = phi_k^T C phi_n`` (eq. [14]) of those modes with the same
        signs, in 1/s.
    """

    system: MCKSystem
    band: tuple[float, float]
    point_dofs: NDArray[np.intp]
    drive_dofs: NDArray[np.intp]
    outputs: tuple[Channel, ...]
    inputs: tuple[Channel, ...]
    poles: NDArray[np.complex128]
    psi_points: NDArray[np.complex128]
    psi_drive: NDArray[np.complex128]
    wave_number: NDArray[np.int_]
    purity: NDArray[np.float64]
    radial_fraction: NDArray[np.float64]
    participation: NDArray[np.float64]
    measurable: NDArray[np.bool_]
    visible: NDArray[np.bool_]
    mpc: NDArray[np.float64]
    undamped_index: NDArray[np.intp]
    phi_points: NDArray[np.float64]
    modal_damping: NDArray[np.float64]

    @classmethod
    def from_tyre(cls, tyre: MeasuredRing, band: tuple[float, float] = (0.0, 200.0)) -> TyreTruth:
        """Compute the truth of ``tyre`` in ``band`` (Hz).

        Raises
        ------
        InputError
            A band that is not ``0 <= f_lo < f_hi``.
        PhysicsError
            An overdamped mode in the discretisation (too much band loss for
            this ``n_ring``), where complex modes in pairs do not exist.
        """
        b = as_band(band)
        system = tyre.system
        try:
            cm = system.complex_modes()
        except PhysicsError as exc:
            raise PhysicsError(
                f"RingTyre (n_ring={tyre.n_ring}): {exc}; lower params.band_loss_factor or n_ring "
                "(the bending loss grows with frequency and overdamps the shortest waves)"
            ) from None
        f = cm.frequency_hz
        sel = np.flatnonzero((f >= b[0]) & (f <= b[1]))
        n = tyre.n_ring
        big_psi = cm.Psi[:, sel]
        wn, purity = wave_numbers(big_psi[:n], big_psi[n : 2 * n])
        pw = np.sum(np.abs(big_psi[:n]) ** 2, axis=0)
        pv = np.sum(np.abs(big_psi[n : 2 * n]) ** 2, axis=0)
        radial_fraction = pw / (pw + pv)
        psi = cm.psi[:, sel]
        pts, drv = tyre.point_dofs, tyre.drive_dofs
        psi_points, psi_drive = psi[pts], psi[drv]
        amp_pts = np.max(np.abs(psi_points), axis=0)
        amp_drv = np.max(np.abs(psi_drive), axis=0)
        measurable = radial_fraction >= RADIAL_THRESHOLD
        participation = np.where(measurable, amp_drv / np.where(amp_pts > 0, amp_pts, 1.0), 0.0)
        visible = measurable & (participation >= VISIBLE_THRESHOLD)
        um = system.undamped_modes()
        gamma = um.phi.T @ system.M @ big_psi
        # one undamped mode per complex mode, largest total |Phi^T M Psi| (close
        # modes mix strongly under non-proportional damping)
        rows, cols = linear_sum_assignment(-np.abs(gamma))
        uidx = np.empty(sel.size, dtype=np.intp)
        uidx[cols] = rows
        phi = um.phi[:, uidx]
        phi_pts = phi[pts]
        sign = np.ones(sel.size)
        for j in range(sel.size):
            ref = phi_pts[:, j] if np.max(np.abs(phi_pts[:, j])) > 0 else phi[:, j]
            sign[j] = 1.0 if ref[np.argmax(np.abs(ref))] >= 0 else -1.0
        phi = phi * sign
        cprime = phi.T @ system.C @ phi
        return cls(
            system=system,
            band=(float(b[0]), float(b[1])),
            point_dofs=pts,
            drive_dofs=drv,
            outputs=tyre.output_channels,
            inputs=tyre.input_channels,
            poles=cm.poles[sel],
            psi_points=psi_points,
            psi_drive=psi_drive,
            wave_number=wn,
            purity=purity,
            radial_fraction=radial_fraction,
            participation=participation,
            measurable=measurable,
            visible=visible,
            mpc=modal_phase_collinearity(psi_points),
            undamped_index=uidx,
            phi_points=phi[pts],
            modal_damping=0.5 * (cprime + cprime.T),
        )

    # ------------------------------------------------------------ derived
    @property
    def n_modes(self) -> int:
        """Number of in-band modes kept."""
        return int(self.poles.size)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Natural frequencies ``|p_n| / 2 pi`` in Hz, shape (m,)."""
        return pole_quantities(self.poles)[0]

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """Damping ratios ``-Re p_n / |p_n|``, shape (m,)."""
        return pole_quantities(self.poles)[1]

    def select(self, modes: ModeSet = "visible") -> NDArray[np.intp]:
        """Indices of the ``"visible"``, ``"measurable"`` or ``"all"`` in-band modes."""
        if modes == "visible":
            return np.flatnonzero(self.visible)
        if modes == "measurable":
            return np.flatnonzero(self.measurable)
        if modes == "all":
            return np.arange(self.n_modes)
        raise InputError(f"modes: expected 'visible', 'measurable' or 'all', got {modes!r}")

    def modal_model(self, modes: ModeSet = "visible") -> ModalModel:
        """The exact complex modes at the points as a :class:`ModalModel` (eq. [10]).

        Without residual terms: modes outside the band are not represented,
        so its FRF differs from :meth:`frf` by their contribution.
        """
        idx = self.select(modes)
        return ModalModel(
            self.poles[idx],
            self.psi_points[:, idx],
            self.psi_drive[:, idx],
            mode_kind="complex",
            outputs=self.outputs,
            inputs=self.inputs,
            meta={
                "source": "exact complex modes of the virtual ring tyre",
                "band_hz": list(self.band),
                "wave_number": self.wave_number[idx].tolist(),
                "mpc": self.mpc[idx].tolist(),
            },
        )

    def reduced_damping(self, modes: ModeSet = "visible") -> NDArray[np.float64]:
        """The true damping matrix reduced to the measured points, shape (n_points, n_points).

        Modal projection on the chosen in-band modes, the reduction the
        identification of spec step 7 performs:
        ``C_red = pinv(U)^T C' pinv(U)`` with ``U = phi_points[:, modes]``
        (true mass-normalised undamped modes at the points) and ``C'`` the
        matching block of :attr:`modal_damping` (eq. [14]). ``U C_red U^T``
        is not the full ``C``: modes outside the band and the unmeasured DOFs
        are truncated (the "power leakage" of paper 000), so entries can be
        negative.

        Raises
        ------
        PhysicsError
            When ``U`` has more modes than points (the projection is then not
            unique).
        """
        idx = self.select(modes)
        u = self.phi_points[:, idx]
        if idx.size > u.shape[0]:
            raise PhysicsError(
                f"reduced_damping: {idx.size} modes but only {u.shape[0]} points; "
                "U must have full column rank"
            )
        pu = np.linalg.pinv(u)
        cr = pu.T @ self.modal_damping[np.ix_(idx, idx)] @ pu
        return 0.5 * (cr + cr.T)

    def frf(self, frequency: ArrayLike, kind: FRFKind = "accelerance") -> FRF:
        """Exact FRF of the full discretisation at the points, shape (n_points, n_drive, n_freq).

        Direct solution of ``(K - omega^2 M + i omega C) X = F`` (spec eq. [1]);
        ``kind`` as in :class:`FRF` (default accelerance, m/(s^2 N)).
        """
        out = self.system.frf(
            frequency,
            kind=kind,
            outputs=self.point_dofs.tolist(),
            inputs=self.drive_dofs.tolist(),
            method="direct",
            output_channels=self.outputs,
            input_channels=self.inputs,
        )
        return FRF(
            out.frequency,
            out.H,
            kind=out.kind,
            outputs=out.outputs,
            inputs=out.inputs,
            meta={"source": "exact FRF of the virtual ring tyre"},
        )

    def table(self, modes: ModeSet = "all") -> list[dict[str, Any]]:
        """One dict per mode: frequency (Hz), damping ratio, wave number, MPC, flags."""
        rows = []
        for i in self.select(modes):
            rows.append(
                {
                    "frequency_hz": float(self.frequency_hz[i]),
                    "damping_ratio": float(self.damping_ratio[i]),
                    "wave_number": int(self.wave_number[i]),
                    "purity": float(self.purity[i]),
                    "mpc": float(self.mpc[i]),
                    "participation": float(self.participation[i]),
                    "visible": bool(self.visible[i]),
                    "measurable": bool(self.measurable[i]),
                }
            )
        return rows
