"""Each paper end to end as named steps, and the demo that runs both.

* :mod:`.radial` -- paper 000: modal test -> FRF -> checks -> real and
  complex modes -> damping matrix.
* :mod:`.lateral` -- paper 001: lateral FRFs -> model fits and ranking ->
  corner frequency, vehicle, time response.
* :mod:`.steps` -- one module per step (frf, checks, modal, damping, lateral
  fit): its typed settings, each knob declared once, and its ``run``;
  :mod:`.registry` lists them (``STEPS``) and the chains a campaign runs
  (``STUDIES``).
* :mod:`.demo` -- both studies on the built-in virtual tyres
  (:func:`~tyredamp.studies.demo.run_demo`); the result types are in
  :mod:`.results`; saving the demo output is :func:`tyredamp.report.demo.save_demo`.

The command line, the demo and batch processing call these steps, so each
pipeline exists once.
"""
