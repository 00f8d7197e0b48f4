"""The fitter: residues and poles of real and complex modes fitted to the FRFs.

:mod:`.fit` holds :class:`~tyredamp.modal.fit.fit.ModalFitter` (LSFD and the
variable-projection refinement); its private helpers hold the basis
(:mod:`._basis`), the linear algebra (:mod:`._linalg`), the scaling and shape
errors (:mod:`._scaling`), :class:`~tyredamp.modal.fit._results.FitResult` and its
assembly at the optimum (:mod:`._results`) and the projection of one added mode
(:mod:`._added`); :mod:`.ml` refines a fit by maximum likelihood with the full
per-line variance and :mod:`.profile` gives its likelihood intervals.
"""
