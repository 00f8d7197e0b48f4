"""Running every test of a campaign: in-process, or on Dask (a local or an existing cluster).

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
``allowed-failures``, and ``retries`` on the task).

Serial and parallel runs give identical results bit for bit: every task runs
the same function on the same bytes with one BLAS thread, and every document
is read back through the same strict-JSON round trip.
"""

from __future__ import annotations

import hashlib
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

__all__ = ["Outcome", "Task", "TestRun", "execute", "plan_tests", "run_tests"]

Mode = Literal["serial", "local", "scheduler"]


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


def execute(task: Task) -> Outcome:
    """Run the missing steps of one test (on a worker or in-process); never raises for a bad test.

    BLAS is limited to one thread inside the task (threadpoolctl): the
    matrices are small and several threads per worker on shared cores slow
    everything down (:mod:`tyredamp._blas`).
    """
    from .._blas import single_threaded_blas

    t0, c0 = time.perf_counter(), time.process_time()
    try:
        data = Path(task.path).read_bytes()
    except OSError as exc:
        where = socket.gethostname()
        return Outcome(
            task.test_id,
            {},
            task.steps[0],
            f"{task.rel}: cannot read on {where} ({exc.strerror}; a cluster needs the test "
            "files at the same path on every worker, e.g. a shared file system)",
        )
    if hashlib.sha256(data).hexdigest() != task.digest:
        return Outcome(
            task.test_id, {}, task.steps[0], f"{task.rel}: the file changed during the campaign"
        )
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
    dt, dc = time.perf_counter() - t0, time.process_time() - c0
    if failure is not None:
        return Outcome(task.test_id, docs, failure[0], failure[1], dt, dc)
    return Outcome(task.test_id, docs, None, None, dt, dc)


def plan_tests(campaign: Campaign, cache: ResultCache) -> tuple[list[TestRun], list[Task]]:
    """Key every step of every test, read what the cache holds, list the tasks still to run."""
    runs: list[TestRun] = []
    tasks: list[Task] = []
    for spec in campaign.tests:
        run = TestRun(spec)
        runs.append(run)
        settings = campaign.settings[spec.study]
        try:
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


def _dask(tasks: list[Task], client: Any) -> Iterable[Outcome]:
    from distributed import as_completed

    futures = {client.submit(execute, t, key=t.key, retries=2): t for t in tasks}
    for fut in as_completed(list(futures)):
        task = futures[fut]
        try:
            yield fut.result()
        except Exception as exc:  # KilledWorker after the allowed failures, lost scheduler ...
            reason = " ".join(str(exc).split()) or type(exc).__name__
            yield Outcome(task.test_id, {}, task.steps[0], f"worker failed: {reason}")


def dask_client(
    mode: Mode, workers: int | None = None, scheduler: str | None = None
) -> tuple[Any, Any]:
    """A ``distributed.Client`` for ``mode`` (and the ``LocalCluster`` it owns, or None).

    ``"local"``: a new ``LocalCluster`` of ``workers`` processes (default the
    machine's cores) with one thread each; ``"scheduler"``: connect to the
    existing cluster at ``scheduler`` (``tcp://host:port``).
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError(
            "the campaign on Dask needs dask and distributed: pip install 'tyredamp[campaign]' "
            "(or run with --serial)"
        ) from None
    import logging
    import os

    if mode == "scheduler":
        if not scheduler:
            raise InputError("--scheduler: expected an address like tcp://host:8786")
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler: cannot connect to {scheduler} ({exc})") from None
    n = workers if workers is not None else (os.cpu_count() or 1)
    import dask

    # the workers' statistical profiler samples every thread every 10 ms; nobody looks
    # at it in a batch run, and on busy cores it costs the tasks CPU
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # the HTTP server always starts; any free port
            silence_logs=logging.ERROR,
        )
    return Client(cluster), cluster


def run_tests(
    campaign: Campaign,
    out_dir: str | Path,
    *,
    mode: Mode = "serial",
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    on_start: Callable[[int], None] | None = None,
    on_outcome: Callable[[TestRun, int, int, int], None] | None = None,
) -> list[TestRun]:
    """Run (or read from the cache) every step of every test of ``campaign``.

    Parameters
    ----------
    campaign : Campaign
        The parsed campaign file.
    out_dir : path
        Output folder; the cache is ``out_dir/cache``.
    mode : {"serial", "local", "scheduler"}
        In-process without Dask, a new local cluster, or an existing one.
    workers : int, optional
        Local workers (processes) for ``mode="local"`` (default: the cores).
    scheduler : str, optional
        Scheduler address for ``mode="scheduler"``.
    client : distributed.Client, optional
        Use this client instead (any mode but serial).
    on_start : callable, optional
        ``on_start(total)`` with the number of tests to run (after the cache lookup).
    on_outcome : callable, optional
        ``on_outcome(run, done, failed, total)`` after each test that ran.

    Returns
    -------
    list of TestRun
        In campaign order; failed tests carry their reason.
    """
    cache = ResultCache(Path(out_dir) / "cache")
    runs, tasks = plan_tests(campaign, cache)
    by_id = {r.spec.test_id: r for r in runs}
    total = len(tasks)
    done = failed = 0
    if on_start is not None:
        on_start(total)
    if not tasks:
        return runs
    own: tuple[Any, Any] = (None, None)
    if mode == "serial":
        outcomes: Iterable[Outcome] = _serial(tasks)
    else:
        if client is None:
            own = dask_client(mode, workers, scheduler)
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
