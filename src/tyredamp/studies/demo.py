"""The main job: both studies of the papers on the built-in virtual tyres.

:func:`run_demo` runs, in memory and without printing:

* the **radial study** (paper 000, spec ``radial-damping.md``;
  :func:`.radial.run_radial`) on the virtual truck tyre
  (:class:`~tyredamp.virtual.RingTyre`): the modal test with a periodic chirp
  at the main pressure (7.5 bar) and at further pressures, FRFs (H1, cyclic),
  a linearity check at two force levels, a reciprocity check with two drive
  points, a data-quality check, the real-mode (eq. [2]/[3]) and complex-mode
  (eq. [10]) fits with their RMSD (eq. [19]) and the damping identification
  (eq. [14]-[18]) and the tyre model (flexible ring across the pressures,
  rigid ring per pressure, ``.tir`` subsets; :mod:`.tyremodel`); every
  identified value is paired with the exact value of
  the tyre (:class:`~tyredamp.virtual.TyreTruth`);
* the **lateral study** (paper 001, spec ``lateral-models.md``;
  :func:`.lateral.run_lateral`) on the virtual rolling-tyre rig
  (:class:`~tyredamp.virtual.VirtualLateralRig`): ground- and axle-force FRFs
  at both speeds and the three pressures, every model fitted to the
  ground-force FRF and ranked, axle-force predictions, the corner frequency
  of the proposed model (eq. 38-40), the single-DOF vehicle (eq. 41-44), the
  2.73 Hz time response and the error of a causal approximation of the
  hysteretic tyre;
* the **rolling tyre** (:func:`.rolling.run_rolling`): the rotating virtual
  tyre at 40 and 80 km/h (80 only with ``quick``) identified output-only,
  each exact travelling wave beside the identified one;
* the **damping model** (:func:`.dampmodels.run_dampmodels`): every damping
  model fitted to the rubber tyre's FRFs and ranked, the truth beside it.

Each identification runs a registered step
(:data:`tyredamp.studies.registry.STEPS`: ``frf``, ``checks``, ``modal``,
``damping``, ``fit``, ``rolling``), the recipe of the command line and of a
campaign, with the settings :meth:`DemoSettings.step_settings` makes from
the demo's own.

:func:`tyredamp.report.demo.save_demo` writes what :func:`run_demo` returned
into a directory (report, results.json, figures, data, modes and damping
JSON).

:func:`run_demo` takes an optional progress callback ``progress(description,
done, total)``, called before each stage (``done`` stages finished out of
``total``) and once more at the end with ``done == total``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .._blas import single_threaded_blas
from ..exceptions import InputError
from .dampmodels import run_dampmodels
from .lateral import conditions, run_lateral
from .radial import run_radial
from .results import DemoResult
from .rolling import run_rolling
from .settings import DemoSettings

__all__ = ["DemoResult", "DemoSettings", "ProgressCallback", "run_demo", "single_threaded_blas"]

#: ``progress(description, done, total)``: called before each stage.
ProgressCallback = Callable[[str, int, int], None]


class _Stages:
    """Counts stages and reports them to the progress callback."""

    def __init__(self, total: int, progress: ProgressCallback | None) -> None:
        self.total = total
        self.done = 0
        self.progress = progress
        self.timings: dict[str, float] = {}
        self._name: str | None = None
        self._t0 = 0.0

    def start(self, name: str) -> None:
        self._close()
        self._name = name
        self._t0 = time.perf_counter()
        if self.progress is not None:
            self.progress(name, self.done, self.total)

    def _close(self) -> None:
        if self._name is not None:
            self.timings[self._name] = time.perf_counter() - self._t0
            self.done += 1
            self._name = None

    def finish(self) -> None:
        self._close()
        if self.progress is not None:
            self.progress("done", self.total, self.total)


# ------------------------------------------------------------------------------- running
def run_demo(
    settings: DemoSettings | None = None, progress: ProgressCallback | None = None
) -> DemoResult:
    """Run both studies on the virtual tyres (module docstring); no printing, no files.

    Parameters
    ----------
    settings : DemoSettings, optional
        Default :meth:`DemoSettings.full`.
    progress : callable, optional
        ``progress(description, done, total)`` before each stage.

    Returns
    -------
    DemoResult

    Raises
    ------
    InputError
        Invalid settings.
    ConvergenceError
        A fit that did not converge (not expected on the built-in tyres).
    """
    s = DemoSettings.full() if settings is None else settings
    if not isinstance(s, DemoSettings):
        raise InputError(f"settings: expected DemoSettings, got {type(s).__name__}")
    with single_threaded_blas():
        return _run(s, progress)


def _run(s: DemoSettings, progress: ProgressCallback | None) -> DemoResult:
    t_start = time.perf_counter()
    n_stages = len(s.radial_pressures_bar) + 4 + len(conditions(s)) + 3
    st = _Stages(n_stages, progress)
    radial = run_radial(s, st.start)
    lateral = run_lateral(s, st.start)
    st.start("rolling tyre, output-only")
    speeds = (80.0,) if s.quick else (40.0, 80.0)
    rolling = run_rolling(speeds, seed=s.seed, settings=s.step_settings()["rolling"])
    st.start("damping model of the rubber tyre")
    damping_models = run_dampmodels(seed=s.seed)
    st.finish()
    return DemoResult(
        settings=s,
        radial=radial,
        lateral=lateral,
        timings=dict(st.timings),
        elapsed_s=time.perf_counter() - t_start,
        rolling=rolling,
        damping_models=damping_models,
    )
