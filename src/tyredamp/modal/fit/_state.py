"""What the helpers of :class:`~tyredamp.modal.fit.fit.ModalFitter` read of it.

The basis (:mod:`._basis`), the scaling (:mod:`._scaling`), the projection
of an added mode (:mod:`._added`) and the result at the optimum
(:mod:`._results`) are functions of a fitter that
:mod:`.fit` itself imports, so they cannot import the class; they take a
:class:`FitterState`, the protocol that names exactly the attributes and
methods they use. :class:`~tyredamp.modal.fit.fit.ModalFitter` satisfies it
structurally (mypy checks every call that passes one).
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray


class FitterState(Protocol):
    """The data, settings and basis methods of a modal fitter (read only).

    Shapes: ``n_out`` outputs, ``n_in`` inputs, ``n_f`` lines; the attributes are
    those of :class:`~tyredamp.modal.fit.fit.ModalFitter` (its docstring states
    their meaning and units).
    """

    @property
    def f(self) -> NDArray[np.float64]:
        """Lines (n_f,), Hz."""

    @property
    def H(self) -> NDArray[np.complex128]:
        """FRFs (n_out, n_in, n_f) of the data kind."""

    @property
    def n_out(self) -> int:
        """Number of outputs."""

    @property
    def n_in(self) -> int:
        """Number of inputs."""

    @property
    def n_f(self) -> int:
        """Number of lines."""

    @property
    def n_rows(self) -> int:
        """Real data rows ``2 n_in n_f``."""

    @property
    def kind(self) -> str:
        """Model of the residues, ``"complex"`` or ``"real"``."""

    @property
    def power(self) -> int:
        """Power of ``i w`` that turns receptance into the data kind."""

    @property
    def drive(self) -> list[tuple[int, int]]:
        """Drive points ``(output index, input index)`` of the scaling."""

    @property
    def use_upper(self) -> bool:
        """Whether the upper residual terms are columns of the basis."""

    @property
    def use_lower(self) -> bool:
        """Whether the lower residual terms are columns of the basis."""

    @property
    def line_weights(self) -> NDArray[np.float64] | None:
        """Weight of each line (n_f,), or None for 1."""

    @property
    def w_ref(self) -> float:
        """Reference angular frequency of the pole parameters, rad/s."""

    @property
    def data_ss(self) -> float:
        """Sum of squares of all unweighted data rows."""

    @property
    def noise_floor(self) -> NDArray[np.float64]:
        """Noise floor (n_out,) of the mode statistics, units of the data."""

    @property
    def _w1(self) -> NDArray[np.float64]:
        """Weights (n_out,) of a first pass: 1 / RMS per output."""

    @property
    def _yss(self) -> NDArray[np.float64]:
        """Sum of squares (n_out,) of each output's data rows."""

    def n_cols(self, m: int) -> int:
        """Basis columns of ``m`` modes and the residual terms."""

    def unpack(
        self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp]
    ) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Poles (m,) and participation (m, n_in) from the parameter vector."""

    def _pseudo_lines(self) -> Any:
        """The pseudo-lines of the data (:mod:`._pseudo`) or None."""

    def _basis_ek(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        derivatives: bool = True,
        lines: slice | None = None,
        given: tuple[Any, Any] | None = None,
    ) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
        """Basis and derivative columns of the lines (:func:`._basis.basis_ek`)."""

    def _normal(
        self, sol: dict[str, Any], n_par: int
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kaufman ``J^T J`` and ``J^T r`` of the projected residual."""

    def _ydata(self, lines: slice | None = None) -> NDArray[np.float64]:
        """Weighted data rows of the lines (:func:`._basis.ydata`)."""
