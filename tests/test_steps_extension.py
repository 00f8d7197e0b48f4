"""A new pole estimator and a new campaign step, each added from this file in few places.

* The estimator: the function (1) and one registry line (2); the CLI's
  ``--estimator`` and a campaign's ``estimator`` then select it.
* The campaign step: the step class with its settings (1), one line of
  ``STEPS`` (2) and one entry in a study's chain (3); the campaign file then
  validates its table (unknown keys refused), the schema holds it, the
  campaign runs it on each test, and its options can be put on a command.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import click
import numpy as np
import pytest
from click.testing import CliRunner

from tyredamp.campaign import load_campaign
from tyredamp.campaign.runner import run_tests
from tyredamp.campaign.steps import process_radial_test, settings_schema, validate_settings
from tyredamp.cli import cli, main
from tyredamp.cli._settings import settings_from_options, settings_options
from tyredamp.exceptions import InputError
from tyredamp.frf import FRF
from tyredamp.io import read_frf, write_frf
from tyredamp.modal.poles.estimators import ESTIMATORS
from tyredamp.modal.poles.lscf import PoleSet, plscf
from tyredamp.studies.registry import STEPS, STUDIES, Study
from tyredamp.studies.steps import Integer, StepSettings, knob

from .helpers import chain_system

CALLS: list[int] = []


# ---------------------------------------------------------------- place 1: the estimator
def counting_plscf(
    frequency: Any, H: Any, max_order: int, *, min_order: int, band: Any, order_step: int
) -> PoleSet:
    """pLSCF that counts its calls (an estimator a user could write)."""
    CALLS.append(max_order)
    return plscf(frequency, H, max_order, min_order=min_order, band=band, order_step=order_step)


@pytest.fixture
def estimator(monkeypatch: pytest.MonkeyPatch) -> str:
    CALLS.clear()
    # ------------------------------------------------------------ place 2: its registry line
    monkeypatch.setitem(ESTIMATORS, "counting", counting_plscf)
    return "counting"


@pytest.fixture(scope="module")
def frf_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Six-mode chain, accelerance at every mass per force at the first, a little noise."""
    f = np.linspace(0.5, 40.0, 300)
    frf = chain_system().frf(f, kind="accelerance", inputs=[0])
    rng = np.random.default_rng(1)
    rms = np.sqrt(np.mean(np.abs(frf.H) ** 2, axis=2, keepdims=True))
    frf = frf.with_H(frf.H + 1e-3 * rms * rng.normal(size=frf.H.shape))
    return write_frf(frf, tmp_path_factory.mktemp("frf") / "chain.npz")


def test_a_new_estimator_is_selected_from_the_cli(
    estimator: str, frf_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "modes.json"
    args = ["modal", str(frf_file), "-o", str(out), "--band", "0", "40", "--no-search"]
    res = CliRunner().invoke(cli, [*args, "--estimator", estimator])
    assert res.exit_code == 0, res.output
    assert CALLS, "the CLI did not call the selected estimator"
    assert "complex modes (6)" in res.output
    # an unknown name: one line naming the option and the known names, exit 2
    with pytest.raises(SystemExit) as exc:
        main([*args, "--estimator", "nope"])
    assert exc.value.code == 2
    assert capsys.readouterr().err == (
        "tyredamp: error: --estimator: expected a pole estimator of ['counting', 'plscf'], "
        "got 'nope'\n"
    )


def test_a_new_estimator_is_selected_from_a_campaign(estimator: str, frf_file: Path) -> None:
    settings = {"modal": {"estimator": estimator, "band": [0, 40], "search": False}}
    result = process_radial_test(frf_file, settings={**settings, "damping": {"enabled": False}})
    assert CALLS, "the campaign did not call the selected estimator"
    assert len(result.documents["modal"]["models"]["complex"]["modes"]) == 6
    with pytest.raises(InputError, match=r"settings\.radial\.modal\.estimator: expected a pole"):
        validate_settings("radial", {"modal": {"estimator": "nope"}}, "settings.radial")


# ---------------------------------------------------------------- place 1: the step
@dataclass(frozen=True)
class PeakSettings(StepSettings):
    """How many of the largest FRF peaks a test reports."""

    count: int = knob(
        3, "Number of peaks to report.", Integer(1, optional=False), "--count", unit="peaks"
    )


class PeakStep:
    """FRF -> the frequencies of its largest peaks (summed over every FRF)."""

    name: ClassVar[str] = "peaks"
    Settings: ClassVar[type[PeakSettings]] = PeakSettings

    @staticmethod
    def run(frf: FRF, settings: PeakSettings) -> tuple[list[float], dict[str, Any]]:
        power = np.sum(np.abs(frf.H) ** 2, axis=(0, 1))
        inner = np.flatnonzero((power[1:-1] > power[:-2]) & (power[1:-1] > power[2:])) + 1
        top = inner[np.argsort(power[inner])[::-1][: settings.count]]
        return sorted(float(frf.frequency[i]) for i in top), {}

    @staticmethod
    def run_file(
        path: Path, upstream: Mapping[str, Any], settings: Mapping[str, Any], conditions: Any
    ) -> dict[str, Any]:
        peaks, _ = PeakStep.run(read_frf(path), PeakSettings.from_mapping(settings["peaks"]))
        n_modes = len(upstream["modal"]["models"]["complex"]["modes"])
        return {"kind": "peaks", "peaks_hz": peaks, "n_modes": n_modes}


@pytest.fixture
def peak_step(monkeypatch: pytest.MonkeyPatch) -> None:
    # ------------------------------------------------------------ place 2: STEPS
    monkeypatch.setitem(STEPS, "peaks", PeakStep)
    # ------------------------------------------------------------ place 3: the study's chain
    monkeypatch.setitem(STUDIES, "radial", Study("radial", ("modal", "damping", "peaks")))


@pytest.mark.usefixtures("peak_step")
def test_a_new_campaign_step_runs_in_a_campaign(frf_file: Path, tmp_path: Path) -> None:
    camp = tmp_path / "campaign.toml"
    camp.write_text(
        f"[settings.radial.modal]\nband = [0.0, 40.0]\nsearch = false\n"
        f"[settings.radial.damping]\nenabled = false\n"
        f"[settings.radial.peaks]\ncount = 4\n"
        f'[[tests]]\nfiles = "{frf_file.as_posix()}"\n',
        encoding="utf-8",
    )
    campaign = load_campaign(camp)
    assert campaign.settings["radial"]["peaks"] == {"count": 4}
    runs = run_tests(campaign, tmp_path / "out", mode="serial")
    doc = runs[0].documents["peaks"]
    assert len(doc["peaks_hz"]) == 4
    assert doc["n_modes"] == 6  # it ran after the modal step, with its document
    # the chain system's natural frequencies are the peaks of its FRFs
    f_n = np.sort(chain_system().complex_modes().frequency_hz)
    for p in doc["peaks_hz"]:
        assert np.min(np.abs(f_n - p)) < 0.3  # within two lines of 0.13 Hz of a mode
    # its table is checked like every other: unknown keys and bad values refused
    with pytest.raises(InputError, match=r"settings\.radial\.peaks: unknown key 'cout'"):
        validate_settings("radial", {"peaks": {"cout": 4}}, "settings.radial")
    with pytest.raises(InputError, match=r"settings\.radial\.peaks\.count: expected an integer"):
        validate_settings("radial", {"peaks": {"count": 0}}, "settings.radial")
    # the campaign schema holds it, with its text and default
    peaks = settings_schema()["properties"]["radial"]["properties"]["peaks"]
    assert peaks["properties"]["count"]["default"] == 3
    assert "Number of peaks" in peaks["properties"]["count"]["description"]


@pytest.mark.usefixtures("peak_step")
def test_a_new_step_gets_its_command_line_options_from_its_settings(frf_file: Path) -> None:
    seen: list[list[float]] = []

    @click.command("peaks")
    @click.argument("frf_file")
    @settings_options(PeakSettings)
    def peaks(frf_file: str, **options: Any) -> None:
        peaks, _ = PeakStep.run(read_frf(frf_file), settings_from_options(PeakSettings, options))
        seen.append(peaks)

    res = CliRunner().invoke(peaks, [str(frf_file), "--count", "2"])
    assert res.exit_code == 0, res.output
    assert len(seen[0]) == 2
    assert "Number of peaks to report." in CliRunner().invoke(peaks, ["--help"]).output
