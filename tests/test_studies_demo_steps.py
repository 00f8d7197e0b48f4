"""The demo runs the registered steps: its knobs become the steps' settings in one place,
and what it reports is what the steps give with those settings."""

from __future__ import annotations

import dataclasses

import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.studies.registry import STEPS
from tyredamp.studies.settings import DemoSettings

from .test_studies_demo import quick_demo

# the session's one quick demo (test_studies_demo.quick_demo): same xdist group
pytestmark = pytest.mark.xdist_group("demo")


def test_step_settings_carry_the_demo_knobs() -> None:
    s = DemoSettings.quick_preset(seed=3)
    steps = s.step_settings()
    for name, settings in steps.items():
        assert isinstance(settings, STEPS[name].Settings), name
    assert steps["checks"].band == s.check_band_hz
    assert (steps["damping"].method, steps["damping"].samples, steps["damping"].seed) == (
        s.damping_method,
        s.damping_samples,
        3,
    )
    assert steps["fit"].models == s.lateral_models
    assert steps["rolling"].uncertainty is False
    # the recipe of the FRF and the modes is the steps' own (their defaults)
    assert steps["frf"] == STEPS["frf"].Settings()
    assert steps["modal"] == STEPS["modal"].Settings()
    # a demo knob the step refuses is refused with the step's words
    with pytest.raises(InputError, match="method"):
        dataclasses.replace(s, damping_method="fifth").step_settings()


def test_demo_results_are_the_steps_results() -> None:
    result, _ = quick_demo()
    s = result.settings
    steps = s.step_settings()
    main = result.radial.main
    quality, verdicts = STEPS["checks"].run(main.test.data, steps["checks"])
    assert verdicts == {"quality": quality}
    # the same data and settings: the same numbers (exactly)
    assert quality.figure == result.radial.quality.figure
    assert quality.summary == result.radial.quality.summary
    meta = {"source": f"demo, virtual truck tyre at {main.pressure_bar:g} bar", "model": "complex"}
    dm, _ = STEPS["damping"].run(main.models, steps["damping"], meta)
    assert_allclose(dm.modal, result.radial.damping.modal, rtol=0, atol=0)
    assert_allclose(dm.std["modal"], result.radial.damping.std["modal"], rtol=0, atol=0)
    ref = result.lateral.reference
    (ranking, _), _ = STEPS["fit"].run(ref.ground.frf, steps["fit"])
    assert [f.name for f in ranking.fits] == [f.name for f in ref.ranking.fits]
    assert [f.bic for f in ranking.fits] == [f.bic for f in ref.ranking.fits]
    # the modal step labels the wave numbers of the ring's outputs (their angles)
    assert len(main.models["complex"].meta["wave_number"]) == main.models["complex"].n_modes
