"""Background jobs: the only module that uses superqt threading.

A :class:`Job` runs a function on the global thread pool. The function gets a
``cancel`` :class:`engine.cancel.CancelToken` keyword and either returns a value or
returns an engine event generator (``iter_*``), which the job drains in the worker
thread. Events are not sent to the GUI one by one: the worker puts them in a
buffer and wakes the GUI thread once; the GUI drains the buffer at most ~30 times a
second, keeping only the newest :class:`~engine.events.Snapshot` of each type (and of each
``which``, as the two overlaps of a seamless tile) and the newest
:class:`~engine.events.Progress`, and every :class:`~engine.events.Item`.

Jobs are registered by a *key* ("template", "candidates", "quilt" ...). Starting a
job whose key is running *supersedes* the old one: it is aborted and none of its
events or results reach a callback again, so a stale result is never drawn.

``Job.stop()`` cancels the token: anytime algorithms return their best result (the
``on_done`` callback still runs), others raise ``Cancelled`` (``on_cancel`` runs).
``Job.abort()`` also drops every later callback. :func:`shutdown` aborts all jobs
and waits for the pool (connected to ``aboutToQuit``).
"""

from __future__ import annotations

import inspect
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, QThreadPool, QTimer, Signal, Slot
from superqt.utils import create_worker

from engine.cancel import Cancelled, CancelToken
from engine.events import Item, Progress, Snapshot

log = logging.getLogger(__name__)

FRAME_MS = 33  # at most ~30 deliveries per second per job

__all__ = [
    "FRAME_MS",
    "Job",
    "JobError",
    "JobManager",
    "error_text",
    "manager",
    "shutdown",
    "start",
]


class Job(QObject):
    """One background computation; create with :meth:`JobManager.start`."""

    _ids = 0

    def __init__(
        self,
        key: str,
        fn: Callable,
        args: tuple,
        kwargs: dict,
        *,
        label: str,
        on_event,
        on_done,
        on_error,
        on_cancel,
        pass_cancel: bool,
        manager: JobManager,
    ) -> None:
        super().__init__()
        Job._ids += 1
        self.id = Job._ids
        self.key = key
        self.label = label or key
        self.token = CancelToken()
        self.state = "running"  # running | done | cancelled | failed | aborted
        self.progress: Progress | None = None
        self.estimate = ""  # the engine's own estimate, shown until the job's rate is known
        self.started_at = time.perf_counter()
        self.result: Any = None
        self.error: BaseException | None = None
        self._fn, self._args, self._kwargs = fn, args, dict(kwargs)
        if pass_cancel:
            self._kwargs["cancel"] = self.token
        self._on_event, self._on_done = on_event, on_done
        self._on_error, self._on_cancel = on_error, on_cancel
        self._manager = manager
        self._alive = True  # the GUI still wants callbacks
        self._aborted = False  # the worker must stop pumping
        self._lock = threading.Lock()
        self._buffer: list = []
        self._wake_pending = False
        self._last_drain = 0.0
        self._drain_timer = QTimer(self)
        self._drain_timer.setSingleShot(True)
        self._drain_timer.timeout.connect(self._drain)
        self._worker = create_worker(
            _pump,
            self,
            _connect={
                "yielded": self._on_yielded,
                "returned": self._on_returned,
                "errored": self._on_errored,
                "finished": self._on_finished,
            },
            _start_thread=False,
        )

    # ------------------------------------------------------------------ control
    @property
    def running(self) -> bool:
        return self.state == "running"

    @property
    def alive(self) -> bool:
        """True while the job's callbacks may still run (not aborted / superseded)."""
        return self._alive

    def stop(self) -> None:
        """Cancel the token; anytime algorithms still deliver their best result."""
        self.token.cancel()

    def abort(self) -> None:
        """Cancel and drop every later event and result of this job."""
        self._alive = False
        self._aborted = True
        self.token.cancel()
        self._drain_timer.stop()
        self._worker.quit()
        with self._lock:
            self._buffer.clear()

    def _start(self) -> None:
        self._worker.start()

    # ------------------------------------------------------------------ worker side
    def _push(self, event) -> bool:
        """Buffer ``event``; True when the GUI thread must be woken."""
        with self._lock:
            self._buffer.append(event)
            if self._wake_pending:
                return False
            self._wake_pending = True
            return True

    # ------------------------------------------------------------------ GUI side
    @Slot(object)
    def _on_yielded(self, _value) -> None:
        if not self._alive or self._drain_timer.isActive():
            return
        wait = self._last_drain + FRAME_MS / 1000.0 - time.perf_counter()
        if wait <= 0:
            self._drain()
        else:
            self._drain_timer.start(max(1, int(wait * 1000)))

    @Slot()
    def _drain(self) -> None:
        with self._lock:
            events, self._buffer = self._buffer, []
            self._wake_pending = False
        self._last_drain = time.perf_counter()
        if not self._alive or not events:
            return
        for event in coalesce(events):
            if not self._alive:
                return
            if isinstance(event, Progress):
                self.progress = event
                self._manager.progress.emit(self)
            if self._on_event is not None:
                self._on_event(event)

    @Slot(object)
    def _on_returned(self, result) -> None:
        self._drain_timer.stop()
        self._drain()
        if not self._alive:
            return
        self.result = result
        self.state = "done"
        if self._on_done is not None:
            self._on_done(result)

    @Slot(object)
    def _on_errored(self, exc) -> None:
        self._drain_timer.stop()
        self._drain()
        if not self._alive:
            return
        if isinstance(exc, Cancelled):
            self.state = "cancelled"
            if self._on_cancel is not None:
                self._on_cancel()
            return
        self.state = "failed"
        self.error = exc
        if self._on_error is not None:
            self._on_error(exc)
        else:
            log.error("job %s failed", self.label, exc_info=exc)

    @Slot()
    def _on_finished(self) -> None:
        if self.state == "running":
            self.state = "aborted" if self._aborted else "cancelled"
        self._alive = False
        self._manager._job_ended(self)


class JobError(Exception):
    """A RuntimeError raised by a job's function (superqt would swallow it as "worker deleted")."""


def error_text(exc: BaseException) -> str:
    """A one-line message for the user (no traceback)."""
    cause = exc.__cause__ if isinstance(exc, JobError) and exc.__cause__ else exc
    text = str(cause) or type(cause).__name__
    return text.splitlines()[0] if text else type(cause).__name__


def _pump(job: Job):
    """Worker-thread body: run the function, drain its generator into the job's buffer."""
    try:
        out = job._fn(*job._args, **job._kwargs)
        if not inspect.isgenerator(out):
            return out
        try:
            while True:
                if job._aborted:
                    return None
                try:
                    event = next(out)
                except StopIteration as stop:
                    return stop.value
                if job._aborted:
                    return None
                if job._push(event):
                    yield None  # wake the GUI thread (one queued signal per drain)
        finally:
            out.close()
    except RuntimeError as exc:
        raise JobError(f"{type(exc).__name__}: {exc}") from exc


def _snapshot_key(event) -> tuple:
    """Snapshots of one type supersede each other per ``which`` (e.g. the two overlaps of a
    seamless tile each keep their newest seam)."""
    return type(event), event.slot if isinstance(event, Snapshot) else None


def coalesce(events: list) -> list:
    """Keep every Item, the newest Snapshot of each type (and ``which``, if it has one) and
    the newest Progress, in order."""
    last: dict[tuple, int] = {}
    for i, ev in enumerate(events):
        if isinstance(ev, (Snapshot, Progress)) and not isinstance(ev, Item):
            last[_snapshot_key(ev)] = i
    return [
        ev
        for i, ev in enumerate(events)
        if not isinstance(ev, (Snapshot, Progress))
        or isinstance(ev, Item)
        or last[_snapshot_key(ev)] == i
    ]


class JobManager(QObject):
    """Registry of running jobs (one per key); emits when jobs start, progress and end."""

    started = Signal(object)  # Job
    progress = Signal(object)  # Job
    ended = Signal(object)  # Job

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._jobs: dict[str, Job] = {}  # current job per key
        self._running: set[Job] = set()  # every job whose worker has not finished
        pool = QThreadPool.globalInstance()
        pool.setMaxThreadCount(max(pool.maxThreadCount(), 4))

    def start(
        self,
        key: str,
        fn: Callable,
        *args,
        label: str = "",
        on_event=None,
        on_done=None,
        on_error=None,
        on_cancel=None,
        pass_cancel: bool = True,
        **kwargs,
    ) -> Job:
        """Run ``fn(*args, cancel=token, **kwargs)`` in the background, superseding ``key``."""
        old = self._jobs.get(key)
        if old is not None and old.alive:
            old.abort()
        job = Job(
            key,
            fn,
            args,
            kwargs,
            label=label,
            on_event=on_event,
            on_done=on_done,
            on_error=on_error,
            on_cancel=on_cancel,
            pass_cancel=pass_cancel,
            manager=self,
        )
        self._jobs[key] = job
        self._running.add(job)
        self.started.emit(job)
        job._start()
        return job

    def get(self, key: str) -> Job | None:
        """The current job of ``key`` if it is running and not aborted."""
        job = self._jobs.get(key)
        return job if job is not None and job.running and job.alive else None

    def running(self) -> list[Job]:
        """Jobs still computing whose results are wanted, oldest first."""
        return sorted((j for j in self._running if j.alive), key=lambda j: j.id)

    def stop(self, key: str) -> None:
        job = self._jobs.get(key)
        if job is not None:
            job.stop()

    def abort(self, key: str) -> None:
        job = self._jobs.get(key)
        if job is not None:
            job.abort()

    def abort_matching(self, prefix: str) -> None:
        """Abort every current job whose key starts with ``prefix``."""
        for key, job in list(self._jobs.items()):
            if key.startswith(prefix):
                job.abort()

    def stop_all(self) -> None:
        for job in list(self._running):
            job.stop()

    def busy(self) -> bool:
        return bool(self._running)

    def shutdown(self, timeout_ms: int = 5000) -> bool:
        """Abort every job and wait for the workers; False if some did not end in time."""
        for job in list(self._running):
            job.abort()
        ok = QThreadPool.globalInstance().waitForDone(timeout_ms)
        if not ok:
            log.warning("some background jobs did not stop within %d ms", timeout_ms)
        return ok

    def _job_ended(self, job: Job) -> None:
        self._running.discard(job)
        if self._jobs.get(job.key) is job:
            del self._jobs[job.key]
        self.ended.emit(job)


_manager: JobManager | None = None


def manager() -> JobManager:
    """The application's job manager (created on first use)."""
    global _manager
    if _manager is None:
        _manager = JobManager()
    return _manager


def start(key: str, fn: Callable, *args, **kwargs) -> Job:
    """Shortcut for ``manager().start(...)``."""
    return manager().start(key, fn, *args, **kwargs)


def shutdown(timeout_ms: int = 5000) -> bool:
    """Abort all jobs and wait for their threads (``aboutToQuit``)."""
    if _manager is None:
        return True
    return _manager.shutdown(timeout_ms)
