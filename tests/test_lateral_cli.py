"""``tyredamp lateral fit`` and ``tyredamp lateral simulate``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from tyredamp.cli import cli, main
from tyredamp.io import read_frf


def test_simulate_then_fit(tmp_path: Path) -> None:
    runner = CliRunner()
    frf_path = tmp_path / "rig.npz"
    res = runner.invoke(
        cli,
        [
            "lateral",
            "simulate",
            "--out",
            str(frf_path),
            "--speed",
            "10",
            "--pressure",
            "2.4",
            "--force",
            "axle",
            "--seed",
            "3",
        ],
    )
    assert res.exit_code == 0, res.output
    frf = read_frf(frf_path)
    assert frf.meta["force"] == "axle"
    assert frf.meta["pressure_bar"] == 2.4
    out = tmp_path / "fit.json"
    res = runner.invoke(
        cli,
        [
            "lateral",
            "fit",
            str(frf_path),
            "--out",
            str(out),
            "--models",
            "proposed,maxwell",
            "--models",
            "string",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "rank  model" in res.output
    assert "amp.err %" in res.output
    doc = json.loads(out.read_text())
    assert doc["tyredamp"] == "lateral-fit"
    assert sorted(doc["order"]) == ["hysteretic", "maxwell", "string"]
    assert doc["conditions"]["force"] == "axle"
    assert doc["conditions"]["wheel_mass_kg"] == 100.0
    assert abs(doc["conditions"]["speed_kmh"] - 10.0) < 1e-12
    fit0 = doc["fits"][0]
    for key in ("params", "stderr", "units", "aic", "bic", "amplitude_error", "amplitude_bias"):
        assert key in fit0
    assert len(doc["reasons"]) == 3


def test_fit_options_override_meta(tmp_path: Path) -> None:
    runner = CliRunner()
    frf_path = tmp_path / "rig.csv"
    assert runner.invoke(cli, ["lateral", "simulate", "-o", str(frf_path)]).exit_code == 0
    out = tmp_path / "fit.json"
    res = runner.invoke(
        cli,
        [
            "lateral",
            "fit",
            str(frf_path),
            "-o",
            str(out),
            "--speed",
            "7",
            "--band",
            "0.5",
            "8",
            "--criterion",
            "aic",
            "--weights",
            "relative",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(out.read_text())
    assert doc["criterion"] == "aic"
    assert abs(doc["conditions"]["speed_kmh"] - 7.0) < 1e-12
    assert doc["input"]["band_hz"][0] >= 0.5


@pytest.mark.parametrize("cmd", [["lateral"], ["lateral", "fit"], ["lateral", "simulate"]])
def test_help_has_example(cmd: list[str]) -> None:
    res = CliRunner().invoke(cli, [*cmd, "--help"])
    assert res.exit_code == 0
    assert "Example:" in res.output


def test_errors_are_one_line_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fit.json"
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(tmp_path / "missing.npz"), "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("tyredamp: error:")
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()
    # A model that needs the speed, on a file without one: input error, no output written.
    frf_path = tmp_path / "plain.npz"
    assert CliRunner().invoke(cli, ["lateral", "simulate", "-o", str(frf_path)]).exit_code == 0
    frf = read_frf(frf_path)
    from tyredamp.io import write_frf

    bare = tmp_path / "bare.npz"
    write_frf(frf._new(meta={}), bare)
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(bare), "--out", str(out), "--models", "relaxation"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "give --speed KMH" in err  # the CLI option, not a Python keyword
    assert "meta[" not in err
    assert "speed=" not in err
    assert not out.exists()
    # --channel counts from 1 like every other option; 0 and out-of-range are errors
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(bare), "--out", str(out), "--channel", "2", "1"])
    assert exc.value.code == 2
    assert "--channel: expected an output 1..1" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(bare), "--out", str(out), "--channel", "0", "0"])
    assert exc.value.code == 2
    capsys.readouterr()
    main(["lateral", "fit", str(bare), "--out", str(out), "--channel", "1", "1"])
    assert json.loads(out.read_text())["fits"]
    # a file without its conditions: the assumption is said, not silent
    assert "note: the file does not say which force" in capsys.readouterr().err
    out.unlink()
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(bare), "--out", str(out), "--models", "nonsense"])
    assert exc.value.code == 2


def test_channel_counts_from_one_and_is_needed_for_several_frfs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One FRF needs no --channel; a file with several needs it, counted from 1."""
    import numpy as np

    from tyredamp.frf import FRF, Channel
    from tyredamp.io import write_frf

    single = tmp_path / "single.npz"
    assert CliRunner().invoke(cli, ["lateral", "simulate", "-o", str(single)]).exit_code == 0
    frf = read_frf(single)
    # output 1: the rig's FRF scaled by 10 (a different tyre), output 2: the rig's FRF
    h = np.concatenate([10 * frf.H, frf.H], axis=0)
    coh = None if frf.coherence is None else np.concatenate([frf.coherence] * 2, axis=0)
    two = FRF(
        frf.frequency,
        h,
        frf.kind,
        outputs=(frf.outputs[0], Channel(node=2, direction=frf.outputs[0].direction)),
        inputs=frf.inputs,
        coherence=coh,
        meta=frf.meta,
    )
    pair = tmp_path / "pair.npz"
    write_frf(two, pair)
    out = tmp_path / "fit.json"
    with pytest.raises(SystemExit) as exc:
        main(["lateral", "fit", str(pair), "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--channel" in err
    assert "counted from 1" in err
    assert not out.exists()
    ref = tmp_path / "ref.json"
    main(["lateral", "fit", str(single), "--out", str(ref)])
    main(["lateral", "fit", str(pair), "--out", str(out), "--channel", "2", "1"])
    a, b = json.loads(ref.read_text()), json.loads(out.read_text())
    assert a["order"] == b["order"]
    for fa, fb in zip(a["fits"], b["fits"], strict=True):
        assert fa["params"] == pytest.approx(fb["params"], rel=1e-9)
