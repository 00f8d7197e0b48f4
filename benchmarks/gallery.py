"""The real-data gallery: every public measured file through the commands a user runs.

Every file of ``../shared/real-data`` (see its CATALOGUE.md) goes through the
real command line (``tyredamp check quality``, ``frf``, ``modal``,
``damping``, ``campaign``, ``report``, ``tyre-model``) in a temporary folder,
and the outcome (a result, or the one-line refusal) is compared with a
reference that tyredamp did not compute: the source's own published values,
a peer tool (sdypy-EMA) run on the same data with its results stored in
``benchmarks/results/gallery_references.json`` together with the command
that made them, an independent reading of the file (numpy, scipy, pyuff,
lvm_read, a plain ``KEY = value`` parse), or the physics.

Run::

    python benchmarks/gallery.py [--real-data DIR] [--out docs/gallery.md]
                                 [--json benchmarks/results/gallery.json]
    python benchmarks/gallery.py --make-references   # needs sdypy-EMA (extra "bench")

The rows (:data:`ROWS`) are the single definition of the table:
``tests/test_real_data.py`` runs the same rows under pytest (the ``long`` ones with
``pytest -m long``).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
#: Where CI and the developers keep the gallery: beside the repository.
REAL_DATA = REPO.parent / "shared" / "real-data"
REFERENCES = REPO / "benchmarks" / "results" / "gallery_references.json"
REFERENCES_COMMAND = "python benchmarks/gallery.py --make-references"

# Files of the catalogue, relative to the gallery folder.
LVM_LONG = "ladisk_lvm_read/data/long_single_header_multi_ch.lvm"
LVM_SHORT = "ladisk_lvm_read/data/short.lvm"
CONVERTED = "converted/impact_test_3ch"
CASE = "vibrationtoolbox_vibration_toolbox/vibration_toolbox/data/case{}.mat"
UFF = "ladisk_pyuff/data/"
BEAM = UFF + "meas_point_{}.txt"
POMA = "pyOMA-dev_pyOMA/tests/files/"
TIR_FED = "projectchrono_chrono/data/vehicle/feda/tires/335_65R22_5_G275MSA_{}psi.tir"
TIR_MF62 = "matheusft_MFeval_julia/test/fixtures/MagicFormula62_Parameters.tir"

#: The hammer channel of the LADISK impact test is labelled "g" but is the
#: (uncalibrated) force: what a user says on the command line.
IMPACT_MAP = ["--channel", "F=force:N"]
#: The re-encoded copies (CSV, TDMS without units) name the accelerometers too.
IMPACT_MAP_FULL = [
    *IMPACT_MAP,
    "--channel",
    "m_1=acceleration:m/s^2",
    "--channel",
    "m_2=acceleration:m/s^2",
]
CASE_MAP = ["--channel", "Time_chan_1=force:N", "--channel", "Time_chan_2=acceleration:m/s^2"]

#: The measured beam's published modes (sdypy-EMA, pyuff README example), Hz.
BEAM_PUBLISHED = [51.5, 142.2, 278.7, 460.4, 687.2, 958.5]
#: The vibration toolbox's SDOF example on case1.mat (its documentation), Hz.
CASE1_PUBLISHED = 212.09


# --------------------------------------------------------------------------- running


@dataclass(frozen=True)
class Run:
    """One command's exit code and output."""

    argv: tuple[str, ...]
    code: int
    out: str
    err: str

    @property
    def error_lines(self) -> list[str]:
        """The ``tyredamp: error:`` lines of stderr."""
        return [ln for ln in self.err.splitlines() if ln.startswith("tyredamp: error:")]


@dataclass
class Context:
    """What a row needs: the gallery folder, a scratch folder, the CLI, the references."""

    real: Path
    tmp: Path
    references: dict[str, Any]
    subprocess: bool = True
    commands: list[str] = field(default_factory=list)

    def path(self, rel: str) -> Path:
        """A gallery file (read only)."""
        return self.real / rel

    def cli(self, *args: str | Path) -> Run:
        """Run ``tyredamp ARGS`` (in a subprocess, or in this process) in the scratch folder."""
        argv = tuple(str(a) for a in args)
        shown = " ".join(shlex.quote(_shorten(a, self)) for a in argv)
        self.commands.append(f"tyredamp {shown}")
        if self.subprocess:
            env = dict(os.environ)
            env["PYTHONPATH"] = os.pathsep.join(
                [str(REPO / "src")] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else [])
            )
            code = "import sys; from tyredamp.cli import main; main(sys.argv[1:])"
            p = subprocess.run(
                [sys.executable, "-c", code, *argv],
                cwd=self.tmp,
                env=env,
                capture_output=True,
                text=True,
                timeout=900,
            )
            return Run(argv, p.returncode, p.stdout, p.stderr)
        from tyredamp.cli import main

        out, err = io.StringIO(), io.StringIO()
        rc = 0
        cwd = Path.cwd()
        try:
            os.chdir(self.tmp)
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                main(list(argv))
        except SystemExit as exc:
            rc = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        finally:
            os.chdir(cwd)
        return Run(argv, rc, out.getvalue(), err.getvalue())


def _shorten(arg: str, ctx: Context) -> str:
    """A command-line argument as the table shows it (gallery and scratch paths relative)."""
    arg = arg.replace(str(ctx.real) + os.sep, "")
    return arg.replace(str(ctx.tmp) + os.sep, "")


@dataclass(frozen=True)
class Check:
    """A row's outcome and how it compares with its reference."""

    outcome: str
    agreement: str
    ok: bool


@dataclass(frozen=True)
class Row:
    """One line of the gallery table.

    ``run`` performs the user's commands and returns the :class:`Check`;
    ``xfail`` is the reason why the current code is known not to meet the
    reference (the test then expects the failure, strictly); ``subprocess``
    marks the rows the test also runs through a real subprocess; ``long`` the
    rows whose identification takes half a minute or more, which the test
    suite runs on request (``pytest -m long``) and this script always.
    """

    id: str
    file: str
    what: str
    source: str
    reference: str
    run: Callable[[Context], Check]
    xfail: str = ""
    subprocess: bool = False
    needs_references: bool = False
    long: bool = False


# --------------------------------------------------------------------------- helpers


def refused(run: Run, *expected: str) -> Check:
    """A refusal: exit code 2, one ``tyredamp: error:`` line that says each of ``expected``."""
    lines = run.error_lines
    text = lines[0][len("tyredamp: error: ") :] if lines else (run.err.strip() or run.out.strip())
    missing = [e for e in expected if e.lower() not in text.lower()]
    ok = run.code == 2 and len(lines) == 1 and not missing
    if run.code == 0:
        return Check(_first(run.out), "not refused: the command gave a result", False)
    agree = "refused as expected" if ok else f"refusal does not say: {', '.join(missing)}"
    if run.code != 2 or len(lines) != 1:
        agree = f"exit code {run.code}, {len(lines)} error line(s)"
    return Check(f"refused: {_strip_paths(text)}", agree, ok)


def _first(text: str) -> str:
    """The first line of a command's output that is not a ``note:``."""
    lines = [ln for ln in text.strip().splitlines() if not ln.startswith("note:")]
    return lines[0] if lines else ""


def _strip_paths(text: str) -> str:
    """An error message without the absolute folder of its file."""
    # an absolute path (not "m/s^2/N"): a slash at the start of a word, two folders or more
    return re.sub(r"(?<![\w\[\]^])/(?:[^\s:/]+/){2,}", "", text)


def succeeded(run: Run) -> None:
    """Raise with the command's own message when it did not succeed."""
    if run.code != 0:
        raise RuntimeError(f"tyredamp {' '.join(run.argv)} exited {run.code}: {run.err.strip()}")


def modes_hz(path: Path, model: str = "complex") -> list[float]:
    """Natural frequencies (Hz) of one model of a modes JSON file, ascending."""
    doc = json.loads(path.read_text("utf-8"))
    modes = doc["models"][model]["modes"]
    return sorted(float(m["frequency_hz"]) for m in modes)


def kept_hz(path: Path) -> list[float]:
    """Natural frequencies (Hz) of the complex modes that pass their mode test, ascending
    (a model holds one mode even when none passes: "the only mode left, not significant")."""
    doc = json.loads(path.read_text("utf-8"))
    modes = doc["models"]["complex"]["modes"]
    return sorted(
        float(m["frequency_hz"])
        for m in modes
        if "test" not in m or (m["test"]["statistic"] or 0.0) > (m["test"]["threshold"] or 0.0)
    )


def match_modes(
    found: Sequence[float],
    ref: Sequence[float],
    rel_tol: float,
    confirm: Callable[[float], str] | None = None,
    of: str = "",
) -> tuple[bool, str]:
    """Does every reference mode have one found mode within ``rel_tol``, and no more modes?

    Found modes are counted in the reference's band (its lowest to its
    highest mode, widened by 5 %): a missed mode and an extra (split or
    spurious) one are both disagreements, except an extra mode that
    ``confirm`` finds in independent data (it returns where, or "" when it
    does not): a mode the reference does not list, not a split. ``of`` names
    the reference in the text.
    """
    found = sorted(found)
    lo, hi = min(ref) / 1.05, max(ref) * 1.05
    in_band = [f for f in found if lo <= f <= hi]
    devs, missed, used = [], [], set()
    for r in ref:
        i = min(range(len(in_band)), key=lambda j: abs(in_band[j] - r), default=-1)
        d = abs(in_band[i] - r) / r if i >= 0 else np.inf
        if d <= rel_tol:
            devs.append(d)
            used.add(i)
        else:
            missed.append(r)
    others = [f for j, f in enumerate(in_band) if j not in used]
    seen = {f: confirm(f) if confirm is not None else "" for f in others}
    extra = [f for f in others if not seen[f]]
    parts = [f"{len(ref) - len(missed)}/{len(ref)} modes within {100 * rel_tol:g} %{of}"]
    if devs:
        parts.append(f"largest deviation {100 * max(devs):.3f} %")
    if missed:
        parts.append("missed " + ", ".join(f"{m:g}" for m in missed) + " Hz")
    if extra:
        parts.append(f"{len(extra)} extra mode(s) in the band: {fmt_hz(extra)}")
    why: dict[str, list[float]] = {}
    for f in others:
        if seen[f]:
            why.setdefault(seen[f], []).append(f)
    parts += [f"{fmt_hz(fs)} not in the reference but {msg}" for msg, fs in why.items()]
    return (not missed and not extra), "; ".join(parts)


def beam_confirm(
    ctx: Context, source: Callable[[float], set[int]], rel_tol: float = 0.002
) -> Callable[[float], str]:
    """Look for a mode at ``f`` in the FRFs of the hammer points it did not come
    from (``source(f)``).

    Each is an independent measurement of the same beam: ``tyredamp modal``
    on its band ``f +- 5 %`` (so the strong modes' fit errors elsewhere do not
    hide a weak one) with the default mode test. A mode there within
    ``rel_tol`` (or one line) of ``f`` confirms ``f`` as a mode of the
    structure; noise or an artefact of one record does not recur in another
    at the same frequency.
    """

    def confirm(f: float) -> str:
        hits = []
        for j in sorted({1, 2, 3} - source(f)):
            src = write_beam_csv(ctx, j)
            out = ctx.tmp / f"beam{j}_near_{f:.0f}.json"
            run = ctx.cli("modal", src, "-o", out, "--band", f"{0.95 * f:g}", f"{1.05 * f:g}")
            if run.code != 0:
                continue
            near = [g for g in modes_hz(out) if abs(g - f) <= max(rel_tol * f, 1.0)]
            hits += [f"found at {g:.1f} Hz in hammer point {j}'s FRF" for g in near[:1]]
        return " and ".join(hits)

    return confirm


def fmt_hz(values: Sequence[float]) -> str:
    """Frequencies for the table."""
    return ", ".join(f"{v:.1f}" for v in values) + " Hz"


def write_beam_csv(ctx: Context, k: int) -> Path:
    """A measured beam FRF as the plain CSV a user writes from the .txt file.

    The .txt holds one complex accelerance per line at 0, 1, ..., 1000 Hz
    (pyuff README); line 0 (DC) is meaningless and left out.
    """
    h = np.genfromtxt(ctx.path(BEAM.format(k)), dtype=complex)
    f = np.arange(h.size, dtype=float)
    out = ctx.tmp / f"beam_point{k}.csv"
    with out.open("w", encoding="utf-8", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["freq_Hz", "H.re [m/s^2/N]", "H.im [m/s^2/N]"])
        for fi, hi in zip(f[1:], h[1:], strict=True):
            w.writerow([f"{fi:g}", repr(float(hi.real)), repr(float(hi.imag))])
    return out


def parse_tir_plain(path: Path) -> dict[str, float]:
    """Numeric ``KEY = value`` pairs of a .tir file, by a plain parse (a reference)."""
    values: dict[str, float] = {}
    for raw in path.read_text("latin-1").splitlines():
        m = re.match(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([-+0-9.eE]+)", raw)
        if m:
            with contextlib.suppress(ValueError):
                values.setdefault(m.group(1), float(m.group(2)))
    return values


# --------------------------------------------------------------------------- rows


def impact_modes(ctx: Context, time_file: str, label: str) -> Check:
    """``frf`` with the hammer named, then ``modal``, against sdypy-EMA on an independent H1.

    The LVM's two hits are also given to ``modal`` one by one as replicates
    (``--replicate``): a mode the reference does not list must be found again
    in each hit (:func:`impact_hit_confirm`) or be marked undecidable by ``modal``.
    """
    frf = ctx.tmp / f"{label}_frf.uff"
    cmap = IMPACT_MAP if time_file.endswith((".lvm", ".mf4")) else IMPACT_MAP_FULL
    succeeded(ctx.cli("frf", ctx.path(time_file), "-o", frf, *cmap))
    modes = ctx.tmp / f"{label}_modes.json"
    hits = _hit_frfs(ctx) if time_file == LVM_LONG else []
    succeeded(ctx.cli("modal", frf, "-o", modes, *[a for h in hits for a in ("--replicate", h)]))
    found = modes_hz(modes)
    ref = ctx.references["impact"]["sdypy_ema"]["frequency_hz"]
    confirm = impact_hit_confirm(ctx, hits, modes) if hits else None
    ok, agree = match_modes(found, ref, 0.005, confirm)
    return Check(f"{len(found)} modes: {fmt_hz(found)}", agree, ok)


def impact_hit_spectra(real: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The impact test read by lvm_read, cut into one record per hit: the frequency
    axis (Hz), the force spectra (hits, lines), the two responses' spectra (hits,
    lines, 2) and the samples per record (from 20 samples before each hit)."""
    import lvm_read

    lvm = lvm_read.read(str(real / LVM_LONG), read_from_pickle=False, dump_file=False)
    data, dt = lvm[0]["data"], float(lvm[0]["Delta_X"][0])
    force, resp = data[:, 0], data[:, 1:3]
    hits = [int(i) for i in np.flatnonzero(np.abs(force) > 0.5 * np.abs(force).max())]
    starts = sorted({h - 20 for h in hits if all(abs(h - g) > 100 for g in hits if g < h)})
    n = min(data.shape[0] - s for s in starts)
    fspec = np.array([np.fft.rfft(force[s : s + n] - np.median(force[:50])) for s in starts])
    xspec = np.array([np.fft.rfft(resp[s : s + n], axis=0) for s in starts])
    return np.fft.rfftfreq(n, dt), fspec, xspec, n


def _hit_frfs(ctx: Context) -> list[Path]:
    """The impact test's FRF of each hit alone (numpy on lvm_read's data, as the
    reference's H1 but one hit per file), written as UFF 58 for ``tyredamp modal``."""
    from tyredamp.frf import FRF, Channel
    from tyredamp.io import write_frf

    f, fspec, xspec, _ = impact_hit_spectra(ctx.real)
    band = (f > 0) & (f <= 500.0)
    out = []
    for k, (fs, xs) in enumerate(zip(fspec, xspec, strict=True), start=1):
        frf = FRF(
            f[band],
            (xs[band] / fs[band, None]).T[:, None, :],
            kind="accelerance",
            outputs=[Channel(2, 3), Channel(3, 3)],
            inputs=[Channel(1, 3)],
        )
        out.append(Path(write_frf(frf, ctx.tmp / f"impact_hit{k}.uff")))
    return out


def impact_hit_confirm(
    ctx: Context, hits: list[Path], joint: Path, rel_tol: float = 0.005
) -> Callable[[float], str]:
    """Look for a mode at ``f`` in each hit of the impact test identified alone.

    The hits are independent measurements of one structure: a mode of the
    structure is found again in each, noise or a fit artefact of one record is
    not. Found again means within ``rel_tol`` (the reference's tolerance) or
    within the mode's half-power half-width ``zeta f`` in the joint fit
    (``joint``, a modes JSON), whichever is wider: two estimates of a broad
    resonance differ by up to that. Each hit is identified over the whole band
    first, then, for a mode not found there, over the band ``f +- 5 %`` (as
    the beam rows' :func:`beam_confirm`): the records cut the ringing of the
    lightly damped modes near 20 Hz, and the misfit this leaves widens a
    whole-band fit's noise (a model error of about half the response in each
    hit) until it hides a weak mode elsewhere. Each search is ``tyredamp
    modal``'s own, with its own threshold over the lines of its band. A mode
    not found again in each hit must be one that ``modal --replicate`` marks
    undecidable (``meta.replicates`` of ``joint``): the data then do not show
    whether it is a weak mode or an artefact of the joint fit, and ``modal``
    says so.
    """
    model = json.loads(joint.read_text("utf-8"))["models"]["complex"]
    zeta = {float(m["frequency_hz"]): float(m["damping_ratio"]) for m in model["modes"]}
    marked = dict(zip(zeta, model["meta"].get("replicates", []), strict=False))
    whole: list[list[float]] = []
    within = f"within {100 * rel_tol:g} % or the mode's half-power half-width"

    def near(modes: Sequence[float], f: float) -> bool:
        tol = max(rel_tol, zeta.get(f, 0.0))
        return min((abs(g - f) / f for g in modes), default=np.inf) <= tol

    def local(k: int, src: Path, f: float) -> list[float]:
        out = ctx.tmp / f"impact_hit{k}_near_{f:.1f}.json"
        band = (f"{0.95 * f:g}", f"{1.05 * f:g}")
        run = ctx.cli("modal", src, "-o", out, "--model", "complex", "--band", *band)
        return kept_hz(out) if run.code == 0 else []

    def confirm(f: float) -> str:
        if not whole:
            for k, src in enumerate(hits, start=1):
                out = ctx.tmp / f"impact_hit{k}_modes.json"
                run = ctx.cli("modal", src, "-o", out, "--model", "complex")
                whole.append(kept_hz(out) if run.code == 0 else [])
        if all(near(hit, f) for hit in whole):
            return f"found again in each of the {len(hits)} hits alone ({within})"
        if all(near(local(k, src, f), f) for k, src in enumerate(hits, start=1)):
            return f"found again in each of the {len(hits)} hits alone in f +- 5 % ({within})"
        rep = marked.get(f)
        if rep is not None and not rep["confirmed"]:
            n = sum(g is not None for g in rep["found_hz"])
            return f"found in {n} of the {len(hits)} hits alone and marked undecidable by modal"
        return ""

    return confirm


def _uff_frfs(path: Path) -> tuple[np.ndarray, np.ndarray, list[tuple[Any, ...]]]:
    """The frequency axis, values and keys of every UFF 58 record of a file, read by pyuff."""
    import pyuff

    sets = [d for d in pyuff.UFF(str(path)).read_sets() if d["type"] == 58]
    keys = [(d["rsp_node"], d["rsp_dir"], d["ref_node"], d["ref_dir"], d["id1"]) for d in sets]
    return np.real(sets[0]["x"]), np.array([d["data"] for d in sets]), keys


def impact_same_frf(ctx: Context, rel: str, label: str) -> Check:
    """``frf`` on a re-encoded copy: the same records as from the LVM, peaks at the reference's.

    The copy holds the LVM's samples unchanged (the CSV to its six printed
    digits), so ``frf`` must write the same FRF, coherence and variance, read
    back by pyuff; its peaks must sit within a line of those of the
    independent H1 (lvm_read, numpy) in the stored references. The modes of
    that FRF are the ``impact-lvm-modes`` row's: ``modal`` reads a UFF file,
    whichever format the time data came in.
    """
    lvm = ctx.tmp / "lvm_frf.uff"
    succeeded(ctx.cli("frf", ctx.path(LVM_LONG), "-o", lvm, *IMPACT_MAP))
    copy = ctx.tmp / f"{label}_frf.uff"
    cmap = IMPACT_MAP if rel.endswith(".mf4") else IMPACT_MAP_FULL
    succeeded(ctx.cli("frf", ctx.path(rel), "-o", copy, *cmap))
    f0, h0, k0 = _uff_frfs(lvm)
    f1, h1, k1 = _uff_frfs(copy)
    same_axis = k0 == k1 and f0.shape == f1.shape and bool(np.array_equal(f0, f1))
    accel = [i for i, k in enumerate(k1) if "accelerance" in str(k[-1])]
    # the CSV prints 6 significant digits: a relative change of about 1e-6 per sample
    dev = (
        float(np.max(np.abs(h1 - h0)[accel].max(axis=1) / np.abs(h0)[accel].max(axis=1)))
        if same_axis and accel
        else 1.0
    )
    peaks = _peaks(f1, h1[accel], 5.0, 500.0, 1.0)
    ref = ctx.references["impact"]["peaks_hz"]
    # each H1 places a peak on its own grid of lines (records of 8136 and 8100 samples)
    line = float(f1[1] - f1[0])
    near = len(peaks) == len(ref) and all(
        abs(a - b) <= line for a, b in zip(peaks, ref, strict=True)
    )
    ok = same_axis and dev < 1e-4 and near
    agree = f"records as the LVM's, FRFs within {dev:.1e} of their peak; {len(peaks)} peaks, " + (
        "each within a line of the reference's" if near else f"reference {len(ref)}"
    )
    return Check(f"{len(accel)} FRFs, {f1.size} lines: {fmt_hz(peaks)}", agree, ok)


def row_lvm_refused(ctx: Context) -> Check:
    return refused(ctx.cli("frf", ctx.path(LVM_LONG), "-o", "frf.uff"), "output-only", "--channel")


def row_lvm_check(ctx: Context) -> Check:
    """``check quality`` with the hammer named: impacts read, coherence judged."""
    run = ctx.cli("check", "quality", ctx.path(LVM_LONG), *IMPACT_MAP)
    succeeded(run)
    verdict = _first(run.out)
    # physics: two clean hits and an accelerometer response: no clipping, no dead channel
    ok = "clipped_channels: 0" in run.out and "dead_channels: 0" in run.out
    return Check(verdict, "no clipping, no dead channel" if ok else "clipping or dead channel", ok)


def row_short_lvm(ctx: Context) -> Check:
    return refused(ctx.cli("frf", ctx.path(LVM_SHORT), "-o", "frf.uff"), "10 samples")


def row_case1_frf(ctx: Context) -> Check:
    frf = ctx.tmp / "case1_frf.uff"
    succeeded(ctx.cli("frf", ctx.path(CASE.format(1)), "-o", frf, *CASE_MAP))
    modes = ctx.tmp / "case1_modes.json"
    succeeded(ctx.cli("modal", frf, "-o", modes))
    return _dominant(ctx, modes, CASE1_PUBLISHED)


def row_case1_analyser_frf(ctx: Context) -> Check:
    modes = ctx.tmp / "case1_hf_modes.json"
    run = ctx.cli(
        "modal",
        ctx.path(CASE.format(1)),
        "-o",
        modes,
        "--channel",
        "Hf_chan_2=acceleration:m/s^2/N",
    )
    succeeded(run)
    return _dominant(ctx, modes, CASE1_PUBLISHED)


def _dominant(ctx: Context, modes: Path, ref: float) -> Check:
    """The mode of largest residue magnitude against the published frequency (0.05 %)."""
    doc = json.loads(modes.read_text("utf-8"))
    ms = doc["models"]["complex"]["modes"]
    amp = [abs(complex(*m["shape"][0])) * abs(complex(*m["participation"][0])) for m in ms]
    f = float(ms[int(np.argmax(amp))]["frequency_hz"])
    dev = abs(f - ref) / ref
    return Check(
        f"{len(ms)} modes; dominant {f:.3f} Hz",
        f"{100 * dev:.4f} % from {ref} Hz (tolerance 0.05 %)",
        dev <= 5e-4,
    )


def row_case1_no_map(ctx: Context) -> Check:
    return refused(
        ctx.cli("frf", ctx.path(CASE.format(1)), "-o", "f.uff"), "Time_chan_1", "--channel"
    )


def row_case2_quality(ctx: Context) -> Check:
    """No impulse on the force channel: the coherence is low, as the analyser's own says."""
    run = ctx.cli("check", "quality", ctx.path(CASE.format(2)), *CASE_MAP)
    succeeded(run)
    verdict = _first(run.out)
    ref = ctx.references["case2"]
    # the analyser's coherence (Hf_coh_chan_2) has median 0.32: both must call it low (< 0.9)
    ok = (
        verdict.startswith("quality: FAIL")
        and "coherence" in verdict
        and ref["median_coherence"] < 0.9
    )
    return Check(
        verdict,
        f"low coherence on both sides (analyser's median {ref['median_coherence']:.2f})"
        if ok
        else "tyredamp does not report the low coherence",
        ok,
    )


def row_output_only(rel: str, quantity: str) -> Callable[[Context], Check]:
    def run(ctx: Context) -> Check:
        return refused(
            ctx.cli("frf", ctx.path(rel), "-o", "f.uff"), "output-only", quantity, "--channel"
        )

    return run


def row_output_only_check(rel: str) -> Callable[[Context], Check]:
    def run(ctx: Context) -> Check:
        r = ctx.cli("check", "quality", ctx.path(rel))
        succeeded(r)
        ok = "output-only" in r.err + r.out and "dead_channels: 0" in r.out
        return Check(
            _first(r.out), "read; output-only noted, no dead channel" if ok else "not noted", ok
        )

    return run


def row_refused(rel: str, *expected: str, command: str = "check") -> Callable[[Context], Check]:
    def run(ctx: Context) -> Check:
        if command == "check":
            return refused(ctx.cli("check", "quality", ctx.path(rel)), *expected)
        return refused(ctx.cli(command, ctx.path(rel), "-o", "out.json"), *expected)

    return run


def row_poma(ctx: Context) -> Check:
    """The OMA tower: the .npy is not a format; saved as CSV (fs 256 Hz) it is output-only."""
    first = refused(
        ctx.cli("check", "quality", ctx.path(POMA + "measurement_1/measurement_1.npy")), ".npy"
    )
    data = np.load(ctx.path(POMA + "measurement_1/measurement_1.npy"))
    fs = 256.0  # setup_info.txt of the source
    p = ctx.tmp / "measurement_1.csv"
    t = np.arange(data.shape[0]) / fs
    np.savetxt(
        p,
        np.column_stack([t, data]),
        delimiter=",",
        header="time_s,"
        + ",".join(f"ch{k} [m/s]" if k < 3 else f"ch{k} [m/s^2]" for k in range(6)),
        comments="",
        fmt="%.9g",
    )
    second = refused(ctx.cli("frf", p, "-o", "f.uff"), "output-only", "--channel")
    return Check(
        f"{first.outcome} | as CSV: {second.outcome}",
        "refused as expected (output-only test, per the source)"
        if first.ok and second.ok
        else f"{first.agreement}; {second.agreement}",
        first.ok and second.ok,
    )


def row_beam_txt(ctx: Context) -> Check:
    return refused(ctx.cli("modal", ctx.path(BEAM.format(1)), "-o", "m.json"), "frequency")


def row_beam_point(k: int) -> Callable[[Context], Check]:
    def run(ctx: Context) -> Check:
        src = write_beam_csv(ctx, k)
        modes = ctx.tmp / f"beam{k}_modes.json"
        succeeded(ctx.cli("modal", src, "-o", modes))
        found = modes_hz(modes)
        ref = ctx.references["beam"][f"point{k}"]["frequency_hz"]
        confirm = beam_confirm(ctx, lambda f: {k})
        ok, agree = match_modes(found, ref, 0.005, confirm, of=" of sdypy-EMA")
        return Check(f"{len(found)} modes: {fmt_hz(found)}", agree, ok)

    return run


def row_beam_damping(ctx: Context) -> Check:
    """Roving hammer (3 inputs, 1 response, drive point at node 1): damping of 3 modes."""
    src = write_beam_roving(ctx)
    modes = ctx.tmp / "beam_roving_modes.json"
    succeeded(ctx.cli("modal", src, "-o", modes))
    out = ctx.tmp / "beam_damping.json"
    run = ctx.cli("damping", modes, "-o", out, "--modes", "1-3", "--samples", "0")
    if run.code != 0:
        # physics: at a true drive point every mode has a positive modal mass, and a
        # passive structure's C' is positive semi-definite; data that break either
        # cannot give a damping matrix, and the refusal must say which
        return refused(run, "negative modal mass", "drive point")
    doc = json.loads(out.read_text("utf-8"))
    cp = np.asarray(doc["modal"], dtype=float)
    eig = np.linalg.eigvalsh(0.5 * (cp + cp.T))
    # physics: a passive structure dissipates energy (C' positive semi-definite)
    ok = bool(eig.min() >= -1e-9 * abs(eig).max())
    used = ", ".join(f"{f:.1f}" for f in doc["modes"]["frequency_hz"])
    return Check(
        f"C' of the modes at {used} Hz at 3 points; "
        f"eigenvalues {', '.join(f'{e:.3g}' for e in eig)} 1/s",
        "passive (C' positive definite)" if ok else "C' not positive definite",
        ok,
    )


def write_beam_roving(ctx: Context) -> Path:
    """The three hammer points as one roving-hammer FRF (one response, three inputs), CSV."""
    rows = [np.genfromtxt(ctx.path(BEAM.format(k)), dtype=complex)[1:] for k in (1, 2, 3)]
    f = np.arange(1, rows[0].size + 1, dtype=float)
    from tyredamp.frf import FRF, Channel
    from tyredamp.io import write_frf

    frf = FRF(
        f,
        np.stack(rows)[None],
        kind="accelerance",
        outputs=[Channel(1, 3)],
        inputs=[Channel(k, 3) for k in (1, 2, 3)],
    )
    return Path(write_frf(frf, ctx.tmp / "beam_roving.uff"))


def row_beam_campaign(ctx: Context) -> Check:
    """A campaign over the three hammer points: families against sdypy-EMA."""
    files = [write_beam_csv(ctx, k) for k in (1, 2, 3)]
    tests = "".join(
        f'\n[[tests]]\nfiles = "{p.name}"\nnote = "hammer at node {k}"\n'
        for k, p in enumerate(files, start=1)
    )
    toml = ctx.tmp / "campaign.toml"
    toml.write_text(f'name = "measured beam"\n{tests}', encoding="utf-8")
    out = ctx.tmp / "campaign_out"
    run = ctx.cli("campaign", toml, "--out", out, "--serial")
    succeeded(run)
    fams = _families(out)
    ref = ctx.references["beam"]["roving"]["frequency_hz"]
    means = {float(np.mean([f for f, _ in v])): {t for _, t in v} for v in fams.values()}
    confirm = beam_confirm(ctx, lambda f: means[f])
    ok, agree = match_modes(list(means), ref, 0.005, confirm, of=" of sdypy-EMA")
    sizes = sorted({len(v) for v in fams.values()})
    return Check(
        f"{len(fams)} mode families (tests per family: {sizes}): {fmt_hz(sorted(means))}",
        agree,
        ok,
    )


def _families(out: Path) -> dict[str, list[tuple[float, int]]]:
    """Family -> (frequency, hammer point) of its modes, from the campaign's tidy
    mode table (CSV; the beam's files are named ``beam_point<k>.csv``)."""
    table = next(p for p in sorted(out.glob("*.csv")) if "mode" in p.name)
    fams: dict[str, list[tuple[float, int]]] = {}
    with table.open(encoding="utf-8") as fh:
        for r in csv.DictReader(fh):
            if r.get("family") and r.get("model", "complex") in ("complex", ""):
                point = int(re.findall(r"(\d+)\D*$", r.get("file", "") or "0")[0])
                fams.setdefault(r["family"], []).append((float(r["frequency_hz"]), point))
    return fams


def row_report(ctx: Context) -> Check:
    """``report`` of the beam's modes with its FRF: the page names every mode."""
    src = write_beam_csv(ctx, 1)
    modes = ctx.tmp / "beam1_modes.json"
    succeeded(ctx.cli("modal", src, "-o", modes))
    html = ctx.tmp / "report.html"
    succeeded(ctx.cli("report", modes, src, "-o", html, "--title", "measured beam"))
    text = html.read_text("utf-8")
    found = modes_hz(modes)
    shown = [f for f in found if f"{f:.2f}" in text or f"{f:.1f}" in text]
    ok = len(shown) == len(found) and ("<img" in text or "<svg" in text)
    return Check(
        f"report.html ({html.stat().st_size // 1024} kB), {len(shown)}/{len(found)} modes named",
        "every identified mode named, figures embedded" if ok else "modes or figures missing",
        ok,
    )


def row_uff55(ctx: Context) -> Check:
    """The anonymised UFF 55 record: damping reads its mode as pyuff does."""
    out = ctx.tmp / "d.json"
    run = ctx.cli(
        "damping", ctx.path(UFF + "uff55 sample_test record10.uff"), "-o", out, "--samples", "0"
    )
    succeeded(run)
    doc = json.loads(out.read_text("utf-8"))
    f = [float(x) for x in doc["modes"]["frequency_hz"]]
    ref = ctx.references["uff55"]["frequency_hz"]
    ok = len(f) == len(ref) and np.allclose(f, ref, rtol=1e-6)
    return Check(
        f"damping of {len(f)} mode at {fmt_hz(f)} (numbers anonymised: a parser fixture)",
        f"frequency as pyuff reads it ({fmt_hz(ref)}, within 1e-6)"
        if ok
        else "frequency differs from pyuff",
        ok,
    )


def row_tir(rel: str, keys: dict[str, float]) -> Callable[[Context], Check]:
    """A .tir property file: the CLI refuses it in one line; the Python reader gives its values."""

    def run(ctx: Context) -> Check:
        refusal = refused(
            ctx.cli("tyre-model", ctx.path(rel), "--radius", "0.5", "-o", ctx.tmp / "tm"),
            "modes JSON",
            "'.tir'",
        )
        from tyredamp.tyremodel import parse_tir

        parsed = parse_tir(ctx.path(rel).read_text("latin-1"))
        flat = {
            k.upper(): v for sec in parsed.values() if isinstance(sec, dict) for k, v in sec.items()
        }
        plain = parse_tir_plain(ctx.path(rel))
        # parse_tir must give the file's numbers exactly (a plain parse), and these the
        # catalogue's published values to their printed rounding (4 significant digits)
        bad = [
            k
            for k, v in keys.items()
            if not (
                float(flat.get(k, np.nan)) == plain.get(k)
                and np.isclose(plain.get(k, np.nan), v, rtol=5e-3)
            )
        ]
        values = ", ".join(f"{k} {flat.get(k)}" for k in keys)
        ok = refusal.ok and not bad
        agree = [refusal.agreement]
        agree.append(
            "parse_tir gives the published values" if not bad else f"differs: {', '.join(bad)}"
        )
        return Check(f"{refusal.outcome} | parse_tir: {values}", "; ".join(agree), ok)

    return run


def _rows() -> list[Row]:
    lvm = "LADISK impact test (hammer F, 2 accelerometers), LabVIEW LVM"
    ladisk = "ladisk/lvm_read (MIT)"
    pyuff = "ladisk/pyuff (MIT)"
    vt = "vibrationtoolbox (MIT)"
    sdypy = (
        "sdypy-EMA LSCF on an independent H1 (numpy, lvm_read), poles stable near the FRF's "
        "peaks; 0.5 %"
    )
    rows = [
        Row(
            "impact-lvm-modes",
            LVM_LONG,
            lvm,
            ladisk,
            sdypy,
            lambda c: impact_modes(c, LVM_LONG, "lvm"),
            subprocess=True,
            needs_references=True,
            long=True,
        ),
        Row(
            "impact-lvm-no-map",
            LVM_LONG,
            lvm + ", force channel not named",
            ladisk,
            "catalogue: F labelled g is the hammer force",
            row_lvm_refused,
            subprocess=True,
        ),
        Row(
            "impact-lvm-quality",
            LVM_LONG,
            lvm,
            ladisk,
            "physics: two clean hits, no clipping",
            row_lvm_check,
            subprocess=True,
        ),
    ]
    for ext in ("csv", "tdms", "mf4"):
        rel = f"{CONVERTED}.{ext}"
        rows.append(
            Row(
                f"impact-{ext}-frf",
                rel,
                f"the same impact test re-encoded as {ext.upper()}",
                ladisk,
                "the LVM's FRF through pyuff; peaks of an independent H1 (lvm_read, numpy)",
                (lambda r, e: lambda c: impact_same_frf(c, r, e))(rel, ext),
                needs_references=True,
            )
        )
    rows += [
        Row(
            "short-lvm",
            LVM_SHORT,
            "10-sample excerpt of a hammer test, LVM with decimal comma",
            ladisk,
            "catalogue: truncated (10 samples), good only for parsing",
            row_short_lvm,
        ),
        Row(
            "case1-frf-modal",
            CASE.format(1),
            "analyser export: hammer and response time data",
            vt,
            f"toolbox SDOF example: {CASE1_PUBLISHED} Hz; 0.05 %",
            row_case1_frf,
            subprocess=True,
        ),
        Row(
            "case1-analyser-frf",
            CASE.format(1),
            "the analyser's own FRF Hf_chan_2 in the same file",
            vt,
            f"toolbox SDOF example: {CASE1_PUBLISHED} Hz; 0.05 %",
            row_case1_analyser_frf,
        ),
        Row(
            "case1-no-map",
            CASE.format(1),
            "analyser export without a channel map",
            vt,
            "MAT files carry no units: refused, naming the channels",
            row_case1_no_map,
        ),
        Row(
            "case2-quality",
            CASE.format(2),
            "analyser export whose force channel holds no impulse",
            vt,
            "the analyser's own coherence Hf_coh_chan_2 (scipy.io)",
            row_case2_quality,
            needs_references=True,
        ),
        Row(
            "mps-frf",
            UFF + "MPSTD#Set001_2024_10_08_10_27_07.uff",
            "UFF 58b, 4 accelerations, no force (operational)",
            pyuff,
            "catalogue: no force channel",
            row_output_only(UFF + "MPSTD#Set001_2024_10_08_10_27_07.uff", "acceleration"),
            subprocess=True,
        ),
        Row(
            "mps-quality",
            UFF + "MPSTD#Set001_2024_10_08_10_27_07.uff",
            "UFF 58b, 4 accelerations, no force (operational)",
            pyuff,
            "catalogue: no force channel",
            row_output_only_check(UFF + "MPSTD#Set001_2024_10_08_10_27_07.uff"),
        ),
        Row(
            "mic-58b",
            UFF + "Sample_UFF58b_bin.uff",
            "UFF 58b microphone (Pa)",
            pyuff,
            "catalogue: one pressure channel",
            row_output_only(UFF + "Sample_UFF58b_bin.uff", "pressure"),
        ),
        Row(
            "catman-13",
            UFF + "time-history-not-all-columns-filled.uff",
            "HBM catman UFF 58, 13 samples, last line partly filled",
            pyuff,
            "catalogue: one acceleration, no force",
            row_output_only(UFF + "time-history-not-all-columns-filled.uff", "acceleration"),
        ),
        Row(
            "milestone-truncated",
            UFF + "dataset_milestone_in_header.uff",
            "UFF 58 header declaring 2508876 samples, 42 stored",
            pyuff,
            "catalogue: truncated",
            row_refused(UFF + "dataset_milestone_in_header.uff", "2508876", "42"),
        ),
        Row(
            "psd",
            UFF + "sample_dataset58_psd.uff",
            "shaker-controller PSD (UFF 58, function type 9)",
            pyuff,
            "catalogue: a PSD, not time data or an FRF",
            row_refused(UFF + "sample_dataset58_psd.uff", "PSD", "function type 1"),
        ),
    ]
    for name, sets in (
        ("TestLab 161 164 18 15 82.uff", "15"),
        ("Artemis export - Geometry RPBC_setup_05_14102016_105117.uff", "2412"),
        ("mesh_Oros-modal_uff15_uff2412.uff", "2412"),
    ):
        rows.append(
            Row(
                f"geometry-{name.split()[0].split('_')[0].lower()}",
                UFF + name,
                "test geometry only (UFF 15/18/82/2412)",
                pyuff,
                "catalogue: geometry, no data",
                row_refused(UFF + name, "geometry", sets, "--geometry"),
            )
        )
    rows += [
        Row(
            "uff55-anonymised",
            UFF + "uff55 sample_test record10.uff",
            "one UFF 55 complex mode, numbers anonymised",
            pyuff,
            "pyuff's reading of the record",
            row_uff55,
            subprocess=True,
            needs_references=True,
        ),
        Row(
            "uff55-as-data",
            UFF + "uff55 sample_test record10.uff",
            "one UFF 55 complex mode, given where data is read",
            pyuff,
            "catalogue: modes (data set 55), not time data or an FRF",
            row_refused(UFF + "uff55 sample_test record10.uff", "mode shapes", "tyredamp damping"),
        ),
        Row(
            "poma-tower",
            POMA + "measurement_1/measurement_1.npy",
            "output-only test of a steel tower (fans), NumPy .npy",
            "pyOMA-dev/pyOMA (GPL-3.0)",
            "source: output-only (OMA) data",
            row_poma,
        ),
        Row(
            "poma-grid",
            POMA + "grid.txt",
            "node coordinates (text)",
            "pyOMA-dev/pyOMA (GPL-3.0)",
            "not a measurement",
            row_refused(POMA + "grid.txt", "time", "frequency"),
        ),
        Row(
            "beam-txt",
            BEAM.format(1),
            "measured beam FRF, one complex per line, no frequency axis",
            pyuff,
            "catalogue: the frequency axis is only in the README",
            row_beam_txt,
        ),
    ]
    for k in (1, 2, 3):
        rows.append(
            Row(
                f"beam-point{k}-modal",
                BEAM.format(k),
                f"measured beam accelerance, hammer at node {k} (written as CSV with its axis)",
                pyuff,
                "sdypy-EMA LSCF on the same FRF; 0.5 %",
                row_beam_point(k),
                subprocess=(k == 1),
                needs_references=True,
            )
        )
    rows += [
        Row(
            "beam-roving-damping",
            BEAM.format("1..3"),
            "roving hammer (3 inputs), modes 1-3",
            pyuff,
            "physics: a passive structure (C' positive semi-definite, every modal mass "
            "positive at a true drive point)",
            row_beam_damping,
            subprocess=True,
        ),
        Row(
            "beam-campaign",
            BEAM.format("1..3"),
            "campaign over the three hammer points",
            pyuff,
            "sdypy-EMA LSCF on the three FRFs together; 0.5 %",
            row_beam_campaign,
            subprocess=True,
            needs_references=True,
        ),
        Row(
            "beam-report",
            BEAM.format(1),
            "HTML report of the beam's modes and FRF",
            pyuff,
            "the identified modes",
            row_report,
            subprocess=True,
        ),
    ]
    fed = {"40": (406.5e3, 16.9e3), "95": (848.6e3, 29.9e3)}
    for psi, (kz, fz) in fed.items():
        rows.append(
            Row(
                f"tir-fed-{psi}psi",
                TIR_FED.format(psi),
                f"Goodyear 335/65R22.5 truck tyre property file, {psi} psi",
                "projectchrono/chrono (BSD-3-Clause)",
                "catalogue (source file): VERTICAL_STIFFNESS, FNOMIN (its 3-4 digits)",
                row_tir(TIR_FED.format(psi), {"VERTICAL_STIFFNESS": kz, "FNOMIN": fz}),
                subprocess=(psi == "40"),
            )
        )
    rows.append(
        Row(
            "tir-mf62",
            TIR_MF62,
            "MF-Tyre 6.2 passenger-car property file",
            "matheusft/MFeval_julia (MIT)",
            "catalogue (source file): FREQ_LONG, VERTICAL_STIFFNESS",
            row_tir(
                TIR_MF62, {"FREQ_LONG": 80.0, "VERTICAL_STIFFNESS": 314931.0, "FNOMIN": 6752.0}
            ),
        )
    )
    return rows


ROWS: list[Row] = _rows()


# --------------------------------------------------------------------------- references


def load_references(path: Path = REFERENCES) -> dict[str, Any]:
    """The stored peer-tool references (empty when the file is absent)."""
    if not path.is_file():
        return {}
    return dict(json.loads(path.read_text("utf-8"))["references"])


def run_row(
    row: Row, real: Path, references: dict[str, Any], *, use_subprocess: bool
) -> tuple[Check, list[str], float]:
    """Run one row in a fresh scratch folder: its check, the commands run, the seconds taken."""
    with tempfile.TemporaryDirectory(prefix=f"gallery-{row.id}-") as tmp:
        ctx = Context(real, Path(tmp), references, subprocess=use_subprocess)
        t0 = time.perf_counter()
        try:
            check = row.run(ctx)
        except Exception as exc:  # a command that failed: the row's outcome, not a crash
            check = Check(f"error: {_strip_paths(str(exc))}", "no result", False)
        return check, ctx.commands, time.perf_counter() - t0


def _peaks(f: np.ndarray, h: np.ndarray, lo: float, hi: float, prominence: float) -> list[float]:
    """Peak-picked frequencies of sum |H| (log prominence), in ``lo..hi`` Hz (a reference)."""
    import scipy.signal

    a = np.log(np.abs(h).reshape(-1, f.size).sum(axis=0))
    band = (f >= lo) & (f <= hi)
    idx, _ = scipy.signal.find_peaks(a[band], prominence=prominence)
    return [float(x) for x in f[band][idx]]


def _sdypy(
    f: np.ndarray, h: np.ndarray, lo: float, hi: float, approx: list[float]
) -> dict[str, Any]:
    """sdypy-EMA LSCF poles (orders 1-60) stable near each peak-picked frequency.

    sdypy's own ``select_closest_poles`` takes the pole of the highest order
    only, which is sometimes a spurious one; here a mode is the median over
    the orders 30-60 of the pole nearest ``approx`` (within 2 %, damping
    ratio 0-10 %), kept when it appears in at least half of those orders (a
    stabilisation criterion).
    """
    import warnings

    import sdypy.EMA as ema

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = ema.Model(
            frf=np.atleast_2d(h), freq=f, lower=lo, upper=hi, pol_order_high=60, pyfrf=False
        )
        m.get_poles(show_progress=False)
    freqs, xis = [], []
    orders = [k for k in range(len(m.pole_freq)) if k >= len(m.pole_freq) // 2]
    for a in approx:
        fs_, xs_ = [], []
        for k in orders:
            pf, px = np.asarray(m.pole_freq[k], float), np.asarray(m.pole_xi[k], float)
            ok = (np.abs(pf - a) <= 0.02 * a) & (px > 0) & (px < 0.1)
            if ok.any():
                j = np.flatnonzero(ok)[np.argmin(np.abs(pf[ok] - a))]
                fs_.append(pf[j])
                xs_.append(px[j])
        if len(fs_) >= len(orders) / 2:
            freqs.append(float(np.median(fs_)))
            xis.append(float(np.median(xs_)))
    return {
        "approx_hz": [round(x, 4) for x in approx],
        "orders": [orders[0] + 1, orders[-1] + 1],
        "frequency_hz": [round(x, 4) for x in freqs],
        "damping_ratio": [round(x, 6) for x in xis],
    }


def make_references(real: Path) -> dict[str, Any]:
    """Peer-tool and independent references (sdypy-EMA, lvm_read, scipy.io, pyuff)."""
    import pyuff
    import scipy.io

    refs: dict[str, Any] = {}
    # the impact test: H1 of the two hits, read by lvm_read, records of 8100 samples
    f, fspec, xspec, n = impact_hit_spectra(real)
    h1 = (np.conj(fspec)[:, :, None] * xspec).sum(0) / (np.abs(fspec) ** 2).sum(0)[:, None]
    approx = _peaks(f, h1.T, 5.0, 500.0, 1.0)
    refs["impact"] = {
        "what": f"H1 of {len(fspec)} hits (records of {n} samples from 20 before each), lvm_read",
        "peaks_hz": [round(x, 3) for x in approx],
        "sdypy_ema": _sdypy(f, h1.T, 5.0, 500.0, approx),
    }
    # the measured beam: each point, and the three together
    beam: dict[str, Any] = {}
    hs = [np.genfromtxt(real / BEAM.format(k), dtype=complex) for k in (1, 2, 3)]
    fb = np.arange(hs[0].size, dtype=float)
    for k, h in enumerate(hs, start=1):
        approx = _peaks(fb[1:], h[1:], 5.0, 995.0, 1.0)
        beam[f"point{k}"] = _sdypy(fb, h[None], 5.0, 995.0, approx)
    allh = np.stack(hs)
    approx = _peaks(fb[1:], allh[:, 1:], 5.0, 995.0, 1.0)
    beam["roving"] = _sdypy(fb, allh, 5.0, 995.0, approx)
    beam["published_hz"] = BEAM_PUBLISHED
    refs["beam"] = beam
    # case2: the analyser's own coherence and FRF
    mat = scipy.io.loadmat(str(real / CASE.format(2)))
    coh = np.ravel(mat["Hf_coh_chan_2"]).real
    hf = np.ravel(mat["Hf_chan_2"])
    fr = np.ravel(mat["Freq_domain"]).real
    refs["case2"] = {
        "median_coherence": round(float(np.median(coh[1:])), 4),
        "frf_peak_hz": float(fr[1:][np.argmax(np.abs(hf[1:]))]),
    }
    # the UFF 55 record as pyuff reads it
    sets = pyuff.UFF(str(real / UFF / "uff55 sample_test record10.uff")).read_sets()
    sets = sets if isinstance(sets, list) else [sets]
    freqs = []
    for s in sets:
        if "eig" in s:
            lam = complex(s["eig"])
            freqs.append(abs(lam) / (2 * np.pi))
        elif "freq" in s:
            freqs.append(float(s["freq"]))
    refs["uff55"] = {"frequency_hz": freqs}
    return refs


def write_references(real: Path, path: Path = REFERENCES) -> None:
    """Compute and store the references with the command and tool versions."""
    from importlib.metadata import version

    doc = {
        "command": REFERENCES_COMMAND,
        "tools": {p: version(p) for p in ("sdypy-EMA", "lvm_read", "pyuff", "scipy", "numpy")},
        "references": make_references(real),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)


# --------------------------------------------------------------------------- table


def markdown(results: list[dict[str, Any]], real: Path) -> str:
    """The gallery page."""
    lines = [
        "# Real-data gallery",
        "",
        "Public files that real labs and other programs wrote, each run through the commands a",
        "user runs, and the outcome compared with a reference tyredamp did not compute: the",
        "source's own",
        "published values, a peer tool (sdypy-EMA) run on the same data, an independent reading of",
        "the file, or the physics. A file either gives a result that agrees with its reference, or",
        "a one-line refusal that says what is missing. Rows marked **known gap** are disagreements",
        "the current version still has; the tests expect them, and say so the day they are fixed.",
        "",
        "The files are not part of tyredamp: they sit beside the repository in",
        "`../shared/real-data` (its `CATALOGUE.md` gives each file's origin, licence and",
        "checksum).",
        "",
        "Regenerate this page (a few minutes; every command runs as a separate process):",
        "",
        "```",
        "python benchmarks/gallery.py --real-data ../shared/real-data --out docs/gallery.md \\",
        "    --json benchmarks/results/gallery.json",
        "```",
        "",
        "The peer-tool references are stored in `benchmarks/results/gallery_references.json`",
        f"with the command that made them (`{REFERENCES_COMMAND}`, needs",
        '`pip install "tyredamp[bench]"`); `tests/test_real_data.py` runs the same rows '
        "(a row whose identification takes half a minute or more with `pytest -m long`).",
        "",
        "| row | file | what it is | source (licence) | command run | outcome | reference "
        "| agreement |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def cell(s: str) -> str:
        return s.replace("|", "\\|").replace("\n", " ")

    for r in results:
        status = "agrees" if r["ok"] else ("**known gap**" if r["xfail"] else "**disagrees**")
        cmds = "<br>".join(f"`{cell(c)}`" for c in r["commands"])
        lines.append(
            f"| {r['id']} | `{cell(r['file'])}` | {cell(r['what'])} | {cell(r['source'])} "
            f"| {cmds} | "
            f"{cell(r['outcome'])} | {cell(r['reference'])} | {status}: {cell(r['agreement'])} |"
        )
    n_ok = sum(r["ok"] for r in results)
    gaps = [r for r in results if not r["ok"] and r["xfail"]]
    lines += ["", f"{n_ok} of {len(results)} rows agree with their reference."]
    if gaps:
        lines += ["", "Known gaps:", ""] + [f"* {r['id']}: {r['xfail']}." for r in gaps]
    lines += [
        "",
        "Notes: the measured beam's `.txt` files hold the FRF values only; the frequency axis",
        "(0 to 1000 Hz at 1 Hz) is written by the row as a plain CSV column (`freq_Hz`), as a user",
        "would. The OMA tower's `.npy` array is saved as CSV with its sample rate (256 Hz, from",
        "the source's `setup_info.txt`). The `.tir` files are tyre property files, not",
        "measurements.",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real-data", type=Path, default=REAL_DATA)
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "gallery.md")
    ap.add_argument("--json", type=Path, default=REPO / "benchmarks" / "results" / "gallery.json")
    ap.add_argument(
        "--make-references", action="store_true", help="recompute the peer-tool references"
    )
    ap.add_argument(
        "--rows", nargs="*", help="run only these row ids (the others kept from --json)"
    )
    ap.add_argument(
        "--in-process", action="store_true", help="run the CLI in this process (faster)"
    )
    args = ap.parse_args(argv)
    real = args.real_data.resolve()
    if not real.is_dir():
        print(f"gallery: the real-data folder {real} is absent", file=sys.stderr)
        return 2
    if args.make_references:
        write_references(real)
        print(f"wrote {REFERENCES}")
        return 0
    refs = load_references()
    results = []
    for row in ROWS:
        if args.rows and row.id not in args.rows:
            continue
        check, cmds, secs = run_row(row, real, refs, use_subprocess=not args.in_process)
        print(
            f"{row.id:24s} {'ok ' if check.ok else 'GAP' if row.xfail else 'BAD'} {secs:6.1f} s  "
            f"{check.agreement}",
            flush=True,
        )
        results.append(
            {
                "id": row.id,
                "file": row.file,
                "what": row.what,
                "source": row.source,
                "commands": cmds,
                "outcome": check.outcome,
                "reference": row.reference,
                "agreement": check.agreement,
                "ok": check.ok,
                "xfail": row.xfail,
                "seconds": round(secs, 2),
            }
        )
    if args.rows and args.json.is_file():
        # the other rows as the last full run left them, in the table's order
        fresh = {r["id"]: r for r in results}
        kept = {r["id"]: r for r in json.loads(args.json.read_text("utf-8"))["rows"]}
        kept.update(fresh)
        results = [kept[row.id] for row in ROWS if row.id in kept]
    if not args.rows or args.json.is_file():
        for path, text in (
            (args.out, markdown(results, real)),
            (
                args.json,
                json.dumps({"command": "python benchmarks/gallery.py", "rows": results}, indent=1)
                + "\n",
            ),
        ):
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(path.suffix + ".tmp")
            tmp.write_text(text, encoding="utf-8")
            tmp.replace(path)
            print(f"wrote {path}")
    return 0 if all(r["ok"] or r["xfail"] for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
