"""The local scheduler: a pool of worker processes, one photo at a time each.

A small pool of our own rather than ``concurrent.futures``: it knows which photo each worker
holds, so a worker that dies (killed, out of memory, a crash in native code) fails only that
photo and is replaced, and stopping sends SIGINT to the workers (their photo's temporary folder
is removed as the exception unwinds), then SIGKILL to any that do not stop in time. Workers
die with the batch process (Linux parent-death signal), so a ``kill -9`` of the batch leaves
no worker behind to write into the library.

Workers are started with ``spawn`` (no fork of a process that may hold threads) and read each
photo from its path: they share the machine, and so the file system, with the batch.
"""

from __future__ import annotations

import contextlib
import os
import signal
from collections import deque
from collections.abc import Iterator

from engine.batch.inputs import Photo
from engine.batch.settings import BatchSettings
from engine.batch.task import PhotoRecord, store_failed

STOP_GRACE = 10.0  # seconds a worker gets to unwind after SIGINT before SIGKILL
INTERRUPTED = 130  # a worker's exit code after Ctrl-C: the batch stops, the photo is not failed


def default_jobs() -> int:
    """The cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _die_with_parent(parent: int) -> None:
    """Ask Linux to SIGKILL this process when its parent dies (no-op elsewhere)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before the request took effect
        raise SystemExit(1)


def _interrupt_once(signum, frame):
    """Ctrl-C (or SIGTERM) reaches a worker from the terminal and again from the batch
    stopping it: the second must not interrupt the clean-up of the first."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise KeyboardInterrupt


def _worker_main(conn, parent: int, settings: BatchSettings, library: str, threads: int) -> None:
    from engine.batch.task import run_photo

    _die_with_parent(parent)
    signal.signal(signal.SIGINT, _interrupt_once)
    signal.signal(signal.SIGTERM, _interrupt_once)
    try:
        _unblock_stops()  # a Ctrl-C of the worker's start-up lands here (see _Worker)
        while True:
            photo = conn.recv()
            if photo is None:
                return
            conn.send(run_photo(photo, settings, library, threads=threads))
    except (EOFError, BrokenPipeError):
        return
    except KeyboardInterrupt:
        raise SystemExit(INTERRUPTED) from None


def _death(code: int | None) -> str:
    if code is not None and code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        hint = " (out of memory?)" if -code == signal.SIGKILL else ""
        return f"the worker process was killed by {name}{hint}"
    return f"the worker process died (exit code {code})"


_STOPS = {signal.SIGINT, signal.SIGTERM}


def _unblock_stops() -> None:
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOPS)


class _Worker:
    """One worker process. It starts with Ctrl-C and SIGTERM blocked (the signal mask is
    inherited through the spawn): one that comes while its interpreter starts waits until
    :func:`_worker_main` handles it (exit 130, no photo failed) instead of a traceback of the
    start-up on the user's terminal and a worker dead with code 1. This process's own signal
    waits those few milliseconds of the start, not more."""

    def __init__(self, ctx, settings, library, threads):
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(
            target=_worker_main,
            args=(child, os.getpid(), settings, str(library), threads),
            daemon=True,
            name="quilt-batch-worker",
        )
        mask = None
        if hasattr(signal, "pthread_sigmask"):
            from multiprocessing import resource_tracker

            resource_tracker.ensure_running()  # its start unblocks the signals: done first
            mask = signal.pthread_sigmask(signal.SIG_BLOCK, _STOPS)
        self.photo: Photo | None = None
        try:
            try:
                self.process.start()
            finally:
                if mask is not None:
                    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
            child.close()
        except BaseException:  # e.g. the Ctrl-C that waited for the unblock: no orphan
            if self.process.pid is not None:
                self.process.kill()
                self.process.join(5)
            raise


def iter_local(
    photos, settings: BatchSettings, library, *, jobs: int | None = None
) -> Iterator[PhotoRecord]:
    """Make every photo's folder in ``library`` on ``jobs`` worker processes (default: the
    cores); yields each :class:`PhotoRecord` as its photo finishes. Closing the generator
    (or an exception in the caller, e.g. Ctrl-C) stops the workers. Each photo's set is made
    on the cores over the jobs threads (at least one)."""
    import multiprocessing as mp
    from multiprocessing.connection import wait

    todo = deque(photos)
    if not todo:
        return
    n = min(jobs or default_jobs(), len(todo))
    threads = max(1, default_jobs() // n)
    ctx = mp.get_context("spawn")
    workers: list[_Worker] = []
    clean = False
    try:
        for _ in range(n):
            workers.append(_Worker(ctx, settings, library, threads))
        while True:
            for w in workers:
                if w.photo is None and todo:
                    w.photo = todo.popleft()
                    w.conn.send(w.photo)
            busy = [w for w in workers if w.photo is not None]
            if not busy:
                break
            ready = wait([w.conn for w in busy] + [w.process.sentinel for w in busy])
            for w in busy:
                record = None
                if w.conn in ready or w.process.sentinel in ready:
                    try:
                        if w.conn.poll():
                            record = w.conn.recv()
                    except (EOFError, OSError):
                        pass
                if record is None and not w.process.is_alive():
                    w.process.join()
                    if w.process.exitcode == INTERRUPTED:  # Ctrl-C reached the worker first
                        raise KeyboardInterrupt
                    photo = w.photo
                    record = PhotoRecord(
                        photo.key, photo.path, "failed", _death(w.process.exitcode)
                    )
                    store_failed(library, photo, settings, record)
                    w.conn.close()
                    workers[workers.index(w)] = _Worker(ctx, settings, library, threads)
                if record is not None:
                    w.photo = None
                    yield record
        clean = True
    finally:
        _stop(workers, clean)


def _stop(workers, clean: bool) -> None:
    """End every worker: politely when the batch is done, else SIGINT then SIGKILL."""
    for w in workers:
        if clean:
            with contextlib.suppress(OSError):
                w.conn.send(None)
        elif w.process.is_alive():
            with contextlib.suppress(OSError):
                os.kill(w.process.pid, signal.SIGINT)
    for w in workers:
        w.process.join(STOP_GRACE)
        if w.process.is_alive():
            w.process.kill()
            w.process.join()
        w.conn.close()
