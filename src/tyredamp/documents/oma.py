"""The modes JSON of an output-only identification (``tyredamp oma``).

The document is a ``"kind": "modes"`` document (:mod:`.modes`), readable by
every reader of modes files, with one ``"complex"`` model whose shapes are at
the outputs and are not scaled (``"scaled": false``; no force was measured,
so no modal mass), no inputs, and the standard errors of frequency and
damping. The output-only facts are added at the top level::

    "output_only": true,
    "oma": {
      "method": "ssi" | "plscf",
      "sample_rate_hz": float,            # after decimation
      "references": [channel, ...],       # 1-based channel numbers
      "uncertainty": "delete-one-segment jackknife over G segments",
      "selection_cut": float,             # data-driven distance cut
      "wheel_speed_hz": float | null,     # given or detected
      "harmonics": [{"frequency_hz", "damping_ratio", "kurtosis", "z", "wheel_order"}],
      "waves": [{"wave_number", "direction", "forward_share", "explained", "aliases"}] | null,
      "notes": [str, ...]
    }
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

import numpy as np

from ..frf import Channel
from ..modal.model import ModalModel
from ..oma.identify import OMAResult
from ..oma.waves import WaveContent
from .modes import modes_document

__all__ = ["oma_document", "oma_model"]

_NOTE = "output-only data: no force was measured, so the shapes cannot be mass-normalised"


def oma_model(
    res: OMAResult, outputs: Sequence[Channel], waves: Sequence[WaveContent] | None = None
) -> ModalModel:
    """The identified modes as a :class:`ModalModel` (no inputs, shapes unscaled)."""
    meta: dict[str, Any] = {
        "scaled": False,
        "scaling_note": _NOTE,
        "shapes_at": "outputs",
        "output_only": True,
        "band_hz": list(res.band_hz),
        "model_order": [int(o) for o in res.order],
        "orders_held": [int(n) for n in res.n_orders],
    }
    if waves is not None:
        meta["wave_number_label"] = [f"n={w.wave_number} {w.direction}" for w in waves]
    return ModalModel(
        res.poles,
        res.shapes,
        np.zeros((0, res.n_modes), complex),
        mode_kind="complex",
        outputs=list(outputs),
        inputs=[],
        std={"frequency_hz": res.std_frequency_hz, "damping_ratio": res.std_damping_ratio},
        meta=meta,
    )


def oma_document(
    res: OMAResult,
    outputs: Sequence[Channel],
    *,
    source: str = "",
    waves: Sequence[WaveContent] | None = None,
    n_groups: int = 16,
) -> dict[str, Any]:
    """The JSON-ready modes document of an OMA result (schema in the module docstring)."""
    doc = modes_document(
        {"complex": oma_model(res, outputs, waves)}, source=source, band_hz=res.band_hz
    )
    doc["output_only"] = True
    doc["oma"] = {
        "method": res.method,
        "sample_rate_hz": float(res.sample_rate),
        "references": [int(r) + 1 for r in res.references],
        "uncertainty": (
            f"delete-one-segment jackknife over {n_groups} segments"
            if res.method == "ssi"
            else "none (pLSCF)"
        ),
        "selection_cut": float(res.cut),
        "wheel_speed_hz": None if res.wheel_speed_hz is None else float(res.wheel_speed_hz),
        "harmonics": res.harmonics,
        "waves": None if waves is None else [asdict(w) for w in waves],
        "notes": list(res.notes),
    }
    return doc
