"""How the data and a fit are judged: the mode test and the goodness of fit
(:mod:`.stats`), the fit and mode-shape indicators (:mod:`.indicators`) and
the typed fit-quality record (:mod:`.quality`).

Pure functions and records on arrays: nothing here imports another part of
:mod:`tyredamp.modal` (the floor every other group stands on).
"""
