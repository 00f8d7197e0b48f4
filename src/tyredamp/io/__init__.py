"""File formats: UFF 58 (pyuff), CSV, NPZ and JSON results."""
