"""Running every test of a campaign: in-process, a local process pool, or Dask.

The runner plans each test from the cache (:mod:`.cache`): the steps whose
keys are stored are read back, the others are sent as one task per test to
:func:`execute`, which runs them with BLAS limited to one thread and returns
the new step documents, or the step that failed with its one-line reason. A
failing test never stops the others. A step that cannot run on a test's data
(:class:`.steps.StepSkipped`) comes back as a skip document: it is cached
under its key like a result and listed in :attr:`TestRun.skipped`, so a rerun
reads the skip from the cache instead of trying again; failures are not
cached. Results are stored in the cache as they
arrive, so an interruption loses nothing that finished. With Dask a task
whose worker dies is run again on another worker (the scheduler's
``allowed-failures``, and ``retries`` on the task); in the local pool a test
whose process dies is run again in a new pool (:mod:`.pool`).

Where the work runs (``mode``): ``"serial"`` in this process; ``"local"``
(the default) a pool of local processes (:mod:`.pool`) that starts in a
fraction of a second, or this process when one test or one worker is
left; ``"dask"`` a new local Dask cluster on 127.0.0.1 only
(:func:`.cluster.local_dask_cluster`); ``"scheduler"`` an existing, trusted
Dask cluster (:func:`.cluster.connect_scheduler`). On Dask every task
returns its outcome as JSON bytes, decoded and checked here
(:func:`outcome_from_json`).

A test file larger than ``max_file_bytes`` (default :data:`MAX_FILE_BYTES`)
fails that test before it is read; a test that runs out of memory fails
alone too.

Serial and parallel runs give identical results bit for bit: every task runs
the same function on the same bytes with one BLAS thread, and every document
is read back through the same strict-JSON round trip.
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..exceptions import InputError
from . import steps
from .cache import ResultCache, file_digest, step_key
from .spec import Campaign, TestSpec

__all__ = [
    "MAX_FILE_BYTES",
    "Outcome",
    "Task",
    "TestRun",
    "execute",
    "execute_json",
    "outcome_from_json",
    "plan_tests",
    "run_tests",
]

Mode = Literal["serial", "local", "dask", "scheduler"]

#: The largest test file a campaign reads (bytes): a larger one fails its test alone.
#: Each task holds the file's bytes and a copy on disk; the largest measured files the
#: readers take are well under 1 GiB.
MAX_FILE_BYTES = 2 << 30


@dataclass(frozen=True)
class Task:
    """What a worker needs to run the missing steps of one test (small and picklable).

    The worker reads the file itself (a cluster needs the files on a shared
    file system) and checks its SHA-256 against ``digest``.
    """

    test_id: str
    study: str
    path: str
    rel: str
    digest: str
    steps: tuple[str, ...]
    upstream: dict[str, dict[str, Any]]
    settings: dict[str, Any]
    conditions: dict[str, Any]
    step_keys: tuple[str, ...] = ()
    max_bytes: int = MAX_FILE_BYTES

    @property
    def key(self) -> str:
        """Dask key: the same only for the same computation (the cache keys of its steps)."""
        digest = hashlib.sha256("".join(self.step_keys).encode("ascii")).hexdigest()[:20]
        return f"tyredamp-campaign-{self.test_id}-{digest}"


@dataclass(frozen=True)
class Outcome:
    """What came back for one task: the new documents, or the failing step and reason."""

    test_id: str
    documents: dict[str, dict[str, Any]]
    failed_step: str | None = None
    reason: str | None = None
    seconds: float = 0.0
    cpu_seconds: float = 0.0


@dataclass
class TestRun:
    """One test of the campaign after the run.

    Attributes
    ----------
    spec : TestSpec
        The test.
    keys : dict of str to str
        Cache key of each (enabled) step.
    documents : dict of str to dict
        The step documents available (from the cache or computed now).
    skipped : dict of str to dict
        The skip document (:func:`.steps.skip_document`: ``reason``, ``why``,
        ``needs``) of every step that could not run on the test's data.
    computed, reused : list of str
        Steps computed (or found to be skipped) in this run and steps read from
        the cache (skips included).
    seconds, cpu_seconds : float
        Wall and CPU time of the task in this run (0 when nothing ran).
    failed_step, reason : str or None
        The failing step and its one-line reason (None when the test succeeded).
    """

    __test__ = False  # not a pytest class

    spec: TestSpec
    keys: dict[str, str] = field(default_factory=dict)
    documents: dict[str, dict[str, Any]] = field(default_factory=dict)
    skipped: dict[str, dict[str, Any]] = field(default_factory=dict)
    computed: list[str] = field(default_factory=list)
    reused: list[str] = field(default_factory=list)
    failed_step: str | None = None
    reason: str | None = None
    digest: str | None = None
    seconds: float = 0.0
    cpu_seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True when no step failed: every enabled step has its document or was skipped."""
        return self.reason is None and all(
            s in self.documents or s in self.skipped for s in self.keys
        )

    def outcome(self, step: str) -> str:
        """``"ran"``, ``"skipped"``, ``"failed"``, ``"not run"`` (after a failure) or ``"off"``."""
        if step not in self.keys and self.digest is not None:
            return "off"  # an optional step switched off in the settings
        if step in self.documents:
            return "ran"
        if step in self.skipped:
            return "skipped"
        if step == self.failed_step:
            return "failed"
        return "not run"

    def _put(self, step: str, doc: dict[str, Any]) -> None:
        if steps.is_skip(doc):
            self.skipped[step] = doc
        else:
            self.documents[step] = doc


def _size_text(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} GiB"  # pragma: no cover


def _too_large(rel: str, size: int, limit: int) -> str:
    return (
        f"{rel}: the file is {_size_text(size)}, larger than the {_size_text(limit)} "
        "a campaign reads per test file"
    )


def execute(task: Task) -> Outcome:
    """Run the missing steps of one test (on a worker or in-process); never raises for a bad test.

    BLAS is limited to one thread inside the task (threadpoolctl): the
    matrices are small and several threads per worker on shared cores slow
    everything down (:mod:`tyredamp._blas`). A file larger than the task's
    limit, or one whose processing runs out of memory, fails this test only.
    """
    from .._blas import single_threaded_blas
    from .scratch import sweep_once

    sweep_once()
    t0, c0 = time.perf_counter(), time.process_time()
    first = task.steps[0]
    try:
        size = os.stat(task.path).st_size
        if size > task.max_bytes:
            return Outcome(task.test_id, {}, first, _too_large(task.rel, size, task.max_bytes))
        data = Path(task.path).read_bytes()
    except MemoryError:
        return Outcome(task.test_id, {}, first, f"{task.rel}: not enough memory to read the file")
    except OSError as exc:
        where = socket.gethostname()
        return Outcome(
            task.test_id,
            {},
            first,
            f"{task.rel}: cannot read on {where} ({exc.strerror}; a cluster needs the test "
            "files at the same path on every worker, e.g. a shared file system)",
        )
    if hashlib.sha256(data).hexdigest() != task.digest:
        return Outcome(task.test_id, {}, first, f"{task.rel}: the file changed during the campaign")
    try:
        with single_threaded_blas():
            docs, failure = steps.run_steps_from_bytes(
                task.study,
                task.rel,
                data,
                task.steps,
                task.upstream,
                task.settings,
                task.conditions,
            )
    except MemoryError:
        del data
        return Outcome(task.test_id, {}, first, f"{task.rel}: ran out of memory")
    dt, dc = time.perf_counter() - t0, time.process_time() - c0
    if failure is not None:
        return Outcome(task.test_id, docs, failure[0], failure[1], dt, dc)
    return Outcome(task.test_id, docs, None, None, dt, dc)


def execute_json(task: Task) -> bytes:
    """:func:`execute` with the outcome as strict JSON bytes (what a Dask worker sends back)."""
    from ..documents.jsonfile import json_text

    out = execute(task)
    doc = {
        "test_id": out.test_id,
        "documents": out.documents,
        "failed_step": out.failed_step,
        "reason": out.reason,
        "seconds": out.seconds,
        "cpu_seconds": out.cpu_seconds,
    }
    return json_text(doc, indent=0).encode("utf-8")


def outcome_from_json(data: Any, task: Task) -> Outcome:
    """The :class:`Outcome` in the JSON bytes a worker sent for ``task``, checked.

    Only plain JSON is decoded (:func:`json.loads`); an answer that is not
    bytes, not JSON, for another test, or with documents of steps the task
    did not ask for becomes a failure of that test.
    """
    bad = Outcome(task.test_id, {}, task.steps[0], "the worker sent a malformed result")
    if not isinstance(data, bytes | bytearray):
        return bad
    try:
        doc = json.loads(data)
    except (ValueError, RecursionError):
        return bad
    if not isinstance(doc, dict) or doc.get("test_id") != task.test_id:
        return bad
    docs = doc.get("documents")
    failed, reason = doc.get("failed_step"), doc.get("reason")
    secs = [doc.get("seconds"), doc.get("cpu_seconds")]
    if not isinstance(docs, dict) or not set(docs) <= set(task.steps):
        return bad
    ok = all(isinstance(v, dict) for v in docs.values())
    ok = ok and (failed is None or (failed in task.steps and isinstance(reason, str)))
    times = [float(x) for x in secs if isinstance(x, int | float) and not isinstance(x, bool)]
    if not ok or len(times) != 2:
        return bad
    return Outcome(task.test_id, docs, failed, reason, times[0], times[1])


def plan_tests(
    campaign: Campaign, cache: ResultCache, max_bytes: int = MAX_FILE_BYTES
) -> tuple[list[TestRun], list[Task]]:
    """Key every step of every test, read what the cache holds, list the tasks still to run.

    A test whose file cannot be read or is larger than ``max_bytes`` fails here.
    """
    runs: list[TestRun] = []
    tasks: list[Task] = []
    for spec in campaign.tests:
        run = TestRun(spec)
        runs.append(run)
        settings = campaign.settings[spec.study]
        try:
            size = os.stat(spec.path).st_size
            if size > max_bytes:
                run.failed_step = steps.STUDIES[spec.study].steps[0]
                run.reason = _too_large(spec.rel, size, max_bytes)
                continue
            run.digest = file_digest(spec.path)
        except OSError as exc:
            run.failed_step = steps.STUDIES[spec.study].steps[0]
            run.reason = f"{spec.rel}: cannot read ({exc.strerror})"
            continue
        upstream: str | None = None
        todo: list[str] = []
        for step in steps.STUDIES[spec.study].steps:
            if not steps.step_enabled(spec.study, step, settings):
                continue
            key = step_key(
                spec.study,
                step,
                run.digest,
                steps.step_settings(spec.study, step, settings),
                steps.step_conditions(spec.study, step, spec.conditions),
                upstream,
            )
            run.keys[step] = key
            upstream = key
            doc = None if todo else cache.get(key)
            if doc is None:
                todo.append(step)
            else:
                run._put(step, doc)
                run.reused.append(step)
        if todo:
            tasks.append(
                Task(
                    spec.test_id,
                    spec.study,
                    str(spec.path),
                    spec.rel,
                    run.digest,
                    tuple(todo),
                    {s: run.documents.get(s) or run.skipped[s] for s in run.reused},
                    settings,
                    dict(spec.conditions),
                    tuple(run.keys[s] for s in todo),
                    max_bytes,
                )
            )
    return runs, tasks


def _record(run: TestRun, out: Outcome, cache: ResultCache) -> None:
    for step, doc in out.documents.items():
        cache.put(
            run.keys[step], doc, {"test": run.spec.rel, "study": run.spec.study, "step": step}
        )
        run._put(step, doc)
        run.computed.append(step)
    run.failed_step, run.reason = out.failed_step, out.reason
    run.seconds, run.cpu_seconds = out.seconds, out.cpu_seconds


def _serial(tasks: Iterable[Task]) -> Iterable[Outcome]:
    for task in tasks:
        yield execute(task)


def _broken(task: Task) -> Outcome:
    return Outcome(
        task.test_id,
        {},
        task.steps[0],
        f"{task.rel}: the worker process died on this test (out of memory?)",
    )


def _pool(tasks: list[Task], workers: int) -> Iterable[Outcome]:
    from .pool import run_in_pool

    for _task, out in run_in_pool(execute, tasks, workers, _broken):
        yield out


def _dask(tasks: list[Task], client: Any) -> Iterable[Outcome]:
    from distributed import as_completed

    futures = {client.submit(execute_json, t, key=t.key, retries=2): t for t in tasks}
    for fut in as_completed(list(futures), loop=client.loop):
        task = futures[fut]
        try:
            data = fut.result()
        except Exception as exc:  # KilledWorker after the allowed failures, lost scheduler ...
            reason = " ".join(str(exc).split()) or type(exc).__name__
            yield Outcome(task.test_id, {}, task.steps[0], f"worker failed: {reason}")
            continue
        yield outcome_from_json(data, task)


def local_workers(workers: int | None, n_tasks: int) -> int:
    """Local processes for ``n_tasks`` tasks: ``workers`` (default the usable cores), <= n_tasks."""
    if workers is None:
        try:
            workers = len(os.sched_getaffinity(0))
        except (AttributeError, OSError):  # pragma: no cover - not Linux
            workers = os.cpu_count() or 1
    return max(1, min(workers, n_tasks))


def run_tests(
    campaign: Campaign,
    out_dir: str | Path,
    *,
    mode: Mode = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    max_file_bytes: int = MAX_FILE_BYTES,
    on_start: Callable[[int], None] | None = None,
    on_outcome: Callable[[TestRun, int, int, int], None] | None = None,
    on_warning: Callable[[str], None] | None = None,
) -> list[TestRun]:
    """Run (or read from the cache) every step of every test of ``campaign``.

    Parameters
    ----------
    campaign : Campaign
        The parsed campaign file.
    out_dir : path
        Output folder; the cache is ``out_dir/cache``.
    mode : {"local", "serial", "dask", "scheduler"}
        A local process pool (this process when one test or one worker is
        left), in-process, a new local Dask cluster, or an existing one
        (module docstring).
    workers : int, optional
        Local processes for ``"local"`` and ``"dask"`` (default: the usable cores).
    scheduler : str, optional
        Scheduler address for ``mode="scheduler"`` (``tcp://`` only; a
        ``tls://`` cluster needs ``client`` made by
        :func:`.cluster.connect_scheduler` with its security).
    client : distributed.Client, optional
        Use this client instead (modes ``"dask"`` and ``"scheduler"``).
    max_file_bytes : int
        Largest test file read (bytes); a larger one fails its test.
    on_start : callable, optional
        ``on_start(total)`` with the number of tests to run (after the cache lookup).
    on_outcome : callable, optional
        ``on_outcome(run, done, failed, total)`` after each test that ran.
    on_warning : callable, optional
        ``on_warning(text)`` for each damaged cache entry (recomputed).

    Returns
    -------
    list of TestRun
        In campaign order; failed tests carry their reason.
    """
    from .scratch import sweep_scratch

    sweep_scratch()
    cache = ResultCache(Path(out_dir) / "cache")
    runs, tasks = plan_tests(campaign, cache, max_file_bytes)
    if on_warning is not None:
        for text in cache.damaged:
            on_warning(text)
    by_id = {r.spec.test_id: r for r in runs}
    total = len(tasks)
    done = failed = 0
    if on_start is not None:
        on_start(total)
    if not tasks:
        return runs
    own: tuple[Any, Any] = (None, None)
    n_local = local_workers(workers, total)
    if mode == "serial" or (mode == "local" and n_local == 1):
        outcomes: Iterable[Outcome] = _serial(tasks)
    elif mode == "local":
        outcomes = _pool(tasks, n_local)
    else:
        if client is None:
            own = _own_client(mode, n_local, scheduler)
            client = own[0]
        outcomes = _dask(tasks, client)
    try:
        for out in outcomes:
            run = by_id[out.test_id]
            _record(run, out, cache)
            done += 1
            failed += run.reason is not None
            if on_outcome is not None:
                on_outcome(run, done, failed, total)
    finally:
        if own[0] is not None:
            own[0].close()
        if own[1] is not None:
            own[1].close()
    return runs


def _own_client(mode: Mode, workers: int, scheduler: str | None) -> tuple[Any, Any]:
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise InputError(
            "the campaign on Dask needs dask and distributed: pip install 'tyredamp[campaign]' "
            "(or run without --dask and --scheduler)"
        ) from None
    from .cluster import connect_scheduler, local_dask_cluster, parse_scheduler

    if mode == "scheduler":
        return connect_scheduler(parse_scheduler(scheduler or "")), None
    return local_dask_cluster(workers)


def dask_client(
    mode: Mode, workers: int | None = None, scheduler: str | None = None
) -> tuple[Any, Any]:
    """A ``distributed.Client`` for ``mode`` (and the ``LocalCluster`` it owns, or None).

    ``"local"`` or ``"dask"``: a new loopback-only ``LocalCluster`` of
    ``workers`` processes (default the cores) with one thread each;
    ``"scheduler"``: the existing trusted cluster at ``scheduler``
    (``tcp://host:port``), checked first (:mod:`.cluster`).
    """
    n = workers if workers is not None else (os.cpu_count() or 1)
    return _own_client("dask" if mode == "local" else mode, n, scheduler)
