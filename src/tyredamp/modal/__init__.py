"""Modal identification: poles, residues, real and complex mode fits, indicators."""

from __future__ import annotations

from .model import ModalModel, ModeKind

__all__ = ["ModalModel", "ModeKind"]
