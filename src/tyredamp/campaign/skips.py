"""Steps that cannot run on a test's data: the reason, and the document that stands in.

A step that cannot run on a test's data is *skipped*, not failed: it raises
:class:`StepSkipped` with the reason in words (which step, why, what data
would let it run) before any computation, and the campaign records a *skip
document* (:func:`skip_document`) in the step's place, cached under the
step's key like a result (:mod:`.steps` has the rules, :mod:`.runner` the
caching). :func:`damping_skip_reason` holds the preconditions of the radial
damping step.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

__all__ = [
    "SKIP_KIND",
    "StepSkipped",
    "damping_skip_reason",
    "is_skip",
    "skip_document",
    "upstream_skip",
]

#: ``kind`` of the document that stands in for a skipped step.
SKIP_KIND = "tyredamp-campaign-skip"


class StepSkipped(Exception):  # a signal, not an error: the test goes on
    """A step that cannot run on this test's data; not an error of the test.

    Parameters
    ----------
    why : str
        Why the step cannot run, in words (for example ``"1 response point
        for 8 modes"``).
    needs : str
        What data would let it run.
    """

    def __init__(self, why: str, needs: str) -> None:
        super().__init__(f"{why}; {needs}")
        self.why = why
        self.needs = needs


def skip_document(study: str, step: str, why: str, needs: str) -> dict[str, Any]:
    """The document that stands in for a skipped step (cached like a result).

    Keys: ``kind`` (:data:`SKIP_KIND`), ``version``, ``study``, ``step``,
    ``why``, ``needs`` and ``reason`` (one line: ``"<step> step skipped: <why>;
    <needs>"``).
    """
    return {
        "kind": SKIP_KIND,
        "version": 1,
        "study": study,
        "step": step,
        "why": why,
        "needs": needs,
        "reason": f"{step} step skipped: {why}; {needs}",
    }


def is_skip(doc: Any) -> bool:
    """True for the document of a skipped step (:func:`skip_document`)."""
    return isinstance(doc, dict) and doc.get("kind") == SKIP_KIND


def upstream_skip(chain: Sequence[str], step: str, docs: Mapping[str, Any]) -> StepSkipped | None:
    """A skip of ``step`` of the study ``chain`` because a step before it was skipped.

    None when no step before it (in ``docs``, by step name) was skipped.
    """
    for before in chain[: chain.index(step)]:
        if is_skip(docs.get(before)):
            return StepSkipped(
                f"it needs the {before} step, which was skipped", docs[before]["needs"]
            )
    return None


def _drive_point(model_doc: Mapping[str, Any]) -> bool:
    """True when an output and an input of a modes-document model share node and direction."""

    def ids(chs: Any) -> set[tuple[Any, int]]:
        out = set()
        for c in chs or []:
            if c.get("node") is not None:
                out.add((c.get("node"), abs(int(c.get("direction") or 0))))
        return out

    return bool(ids(model_doc.get("outputs")) & ids(model_doc.get("inputs")))


def damping_skip_reason(modes_doc: Mapping[str, Any], model: str) -> StepSkipped | None:
    """Why the damping step cannot run on the ``model`` of a modes document (None: it can).

    The damping matrix in physical coordinates needs at least as many
    response points as modes (it inverts ``Re Psi^``, N x m, eq. [14]-[18]),
    and mass-normalised shapes, which need a response measured at an
    excitation point (a drive point, spec eq. [10]). Checked from the
    document's channels, before any computation.
    """
    models = modes_doc.get("models") or {}
    m = models.get(model)
    if m is None:
        return None  # a wrong setting: the step fails with its message
    n_modes = len(m.get("modes") or [])
    n_points = len(m.get("outputs") or [])
    why: list[str] = []
    needs: list[str] = []
    if n_modes and n_points < n_modes:
        pts = f"{n_points} response point{'' if n_points == 1 else 's'}"
        why.append(
            "the damping matrix in physical coordinates needs at least as many response "
            f"points as modes, and this test has {pts} for {n_modes} modes"
        )
        needs.append(
            f"at least {n_modes} response points (or a band holding at most {n_points} "
            f"mode{'' if n_points == 1 else 's'})"
        )
    if n_modes and not _drive_point(m):
        why.append(
            "the mode shapes are not mass-normalised, as no response was measured at an "
            "excitation point (no drive point)"
        )
        needs.append("a response measured at an excitation point, in its direction")
    if why:
        return StepSkipped("; ".join(why), "it runs on a test with " + " and ".join(needs))
    return None
