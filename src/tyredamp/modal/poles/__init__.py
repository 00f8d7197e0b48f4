"""Poles of the band and which of them are physical: the stabilisation diagram.

:mod:`.lscf` (poly-reference LSCF) and the estimator protocol and registry
(:mod:`.estimators`) give the poles of a range of model orders;
:mod:`.selection` flags and clusters them; :mod:`.order` settles the model
order of the diagram.
"""
