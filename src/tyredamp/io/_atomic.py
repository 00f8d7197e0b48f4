"""Atomic file output: a file appears whole or not at all (see :mod:`._safety`)."""

from __future__ import annotations

from ._safety import atomic_dir, atomic_path, atomic_paths

__all__ = ["atomic_dir", "atomic_path", "atomic_paths"]
