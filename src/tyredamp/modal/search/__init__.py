"""Which modes the data hold: the automatic mode count on one fitter.

:mod:`.search` (the mode test and the residual search) with its stages and
helpers: a trial mode refined alone against the modes held (:mod:`.trials`),
the joint refit of a trial mode and the split of a mode in two
(:mod:`.joint`), the mode set (:mod:`.modeset`), out-of-band residual modes
(:mod:`.out_of_band`), where trial modes start (:mod:`.search_starts`,
:mod:`.residual_peaks`), each mode's threshold (:mod:`.thresholds`,
:mod:`.span_noise`), poles narrower than the lines (:mod:`.narrow`,
:mod:`.resolution`) and the mode statistic with the neighbours refitted
(:mod:`.refitted`).
"""
