"""The fit problem: the band-limited, normalised data and its noise model.

:mod:`.problem` builds it once from the FRF (band cut, unit RMS, per-line
variance or weights); :mod:`.compress` combines many outputs into their
principal combinations; :mod:`.model_error` raises the noise level by the
fit's lack of fit (a new problem from a fitted model).
"""
