"""Worker processes for exact quilting on two or more cores (fork + a shared canvas).

Measured in session 7 (job B exact, 256² sample, 676 blocks): a block's search and placement
holds the GIL about a third of its time (numpy glue between ducc0's transforms and the numba
kernels), and two threads of one process handed the GIL back and forth ~10 times per block:
~45 000 context switches per 7 runs against ~160 on one thread, each block's thread CPU time up
by 40-60 % and about 0.5 ms per block spent waiting for the GIL, so two threads were no faster
than one. Two *processes* running the same loop lost only 10-25 % each. So on POSIX, where
``fork`` exists, :func:`engine.quilting.scheduler.run_levels` hands the blocks of an exact
search to worker processes instead of threads:

* the canvas and its ``filled`` mask move to shared memory (an anonymous ``MAP_SHARED``
  mapping) before the fork; the workers inherit everything else (the sample's spectra, the
  options) copy-on-write, so nothing is sent but task numbers and the records;
* each worker runs exactly the task a thread would run (:meth:`Quilter.run_batch` of one batch
  whose predecessors are placed) and sends back the records and pixels; the parent dispatches a
  task as soon as the tasks it needs have come back (their pixels are then on the shared canvas);
* every block is searched and placed by the same code on exactly the canvas its predecessors
  left: the records and the image are bit-identical to one thread's
  (``tests/engine/test_quilting_workers.py``).

The parent only dispatches and collects (a few tens of microseconds per block); cancelling,
an error in a worker or closing the generator kills the workers at once.
"""

from __future__ import annotations

import contextlib
import heapq
import mmap
import os
import signal
import threading
from multiprocessing.connection import Pipe, wait

import numpy as np

from engine.cancel import check
from engine.quilting.records import read_only

__all__ = ["ENV", "WorkerPool", "available", "share"]

ENV = "QUILT_STUDIO_WORKERS"
"""Environment variable: ``threads`` keeps the search on threads of one process (no fork)."""


def available() -> bool:
    """Whether worker processes can be used here (``os.fork`` exists; not turned off by
    :data:`ENV`)."""
    return hasattr(os, "fork") and os.environ.get(ENV, "").strip().lower() != "threads"


def share(a: np.ndarray) -> np.ndarray:
    """A copy of ``a`` in anonymous shared memory (seen by processes forked after this)."""
    buf = mmap.mmap(-1, max(1, a.nbytes))  # zero-filled
    out = np.frombuffer(buf, dtype=a.dtype, count=a.size).reshape(a.shape)
    if a.any():
        out[...] = a
    return out


class WorkerPool:
    """Runs every task once, each as soon as the tasks it ``needs`` have run: in this process
    (``run(task)``, while waiting for a result) and in ``workers - 1`` forked processes
    (``remote(task)``, whose result comes back through a pipe and goes through
    ``receive(result)`` before any task that depended on it is sent out: ``receive`` may read the
    shared memory the task wrote). :meth:`result` returns one task's result. Tasks before
    ``done`` count as run.

    The tasks must write their effects only to memory shared before the pool was made (see
    :func:`share`); ``remote``'s results must pickle. This process is one of the workers (a
    third process on two cores would wait for a core to hand out every task), and each forked
    worker gets up to :data:`QUEUE` tasks ahead, so it does not idle while this one runs a
    task."""

    QUEUE = 2

    def __init__(self, run, remote, receive, needs, workers: int, cancel=None, *, done=0):
        self.run, self.receive, self.cancel = run, receive, cancel
        self.results: dict[int, object] = {}
        self.waiting = [sum(j >= done for j in p) for p in needs]
        self.dependents: list[list[int]] = [[] for _ in needs]
        for k, p in enumerate(needs):
            for j in p:
                self.dependents[j].append(k)
        self.ready = [k for k, n in enumerate(self.waiting) if not n and k >= done]
        heapq.heapify(self.ready)
        self.conns, self.pids, self.sent = [], [], []
        owner = os.getpid()
        try:
            for _ in range(workers - 1):
                parent, child = Pipe()
                pid = os.fork()
                if pid == 0:  # the worker: serve tasks until told to stop, never return
                    code = 0
                    try:
                        parent.close()
                        for other in self.conns:  # the other workers' pipes
                            other.close()
                        _serve(child, remote, owner)
                    except BaseException:
                        code = 1
                    finally:
                        os._exit(code)
                child.close()
                self.conns.append(parent)
                self.pids.append(pid)
                self.sent.append(0)
        except BaseException:
            self.shutdown(kill=True)
            raise

    def _done(self, k: int, value) -> None:
        self.results[k] = value
        for d in self.dependents[k]:
            self.waiting[d] -= 1
            if not self.waiting[d]:
                heapq.heappush(self.ready, d)

    def _dispatch(self) -> None:
        for i, conn in enumerate(self.conns):
            while self.sent[i] < self.QUEUE and self.ready:
                conn.send(heapq.heappop(self.ready))
                self.sent[i] += 1

    def _collect(self, timeout: float) -> None:
        busy = [c for c, n in zip(self.conns, self.sent, strict=True) if n]
        if timeout:
            busy = wait(busy, timeout) if busy else ()
        for conn in busy:  # Connection.poll: far cheaper than wait()'s selector per call
            i = self.conns.index(conn)
            while conn.poll():
                try:
                    kind, k, value = conn.recv()
                except EOFError:
                    raise RuntimeError("a quilting worker process died") from None
                self.sent[i] -= 1
                if kind == "error":
                    raise value
                self._done(k, self.receive(value))

    def result(self, k: int):
        """Task ``k``'s result (running, handing out and collecting tasks until it is in)."""
        while k not in self.results:
            check(self.cancel)
            self._collect(0)
            self._dispatch()
            if k in self.results:
                break
            if self.ready:
                j = heapq.heappop(self.ready)
                self._done(j, self.run(j))
            elif any(self.sent):
                self._collect(0.05)
            else:  # pragma: no cover - a task whose needs never run
                raise RuntimeError(f"quilting task {k} can never run")
        return self.results.pop(k)

    def shutdown(self, kill: bool = False) -> None:
        """Stop the workers (at once with ``kill``, or when tasks are still out)."""
        kill = kill or any(self.sent)
        for conn, pid in zip(self.conns, self.pids, strict=True):
            try:
                if kill:
                    os.kill(pid, signal.SIGKILL)
                else:
                    conn.send(None)
            except OSError:
                pass
        for conn, pid in zip(self.conns, self.pids, strict=True):
            conn.close()
            # reaped on a thread of its own: a worker's exit takes milliseconds
            threading.Thread(target=_reap, args=(pid,), daemon=True).start()
        self.conns, self.pids, self.sent = [], [], []


def _reap(pid: int) -> None:
    with contextlib.suppress(ChildProcessError):
        os.waitpid(pid, 0)


def _serve(conn, run, owner: int) -> None:
    with contextlib.suppress(ValueError):  # a Ctrl+C is the parent's (it kills its workers)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    while True:
        while not conn.poll(1.0):
            if os.getppid() != owner:  # the parent is gone (killed): no one will ask
                return
        k = conn.recv()
        if k is None:
            return
        try:
            conn.send(("ok", k, run(k)))
        except BaseException as exc:
            try:
                conn.send(("error", k, exc))
            except Exception:  # an exception that does not pickle
                conn.send(("error", k, RuntimeError(repr(exc))))


def records_in(recs, pixels_of):
    """A task's records as received, with their arrays read-only again (pickling drops the
    flag), paired with their pixels (``pixels_of(record)``, read from the shared canvas: the
    workers do not send them)."""
    out = []
    for rec in recs:
        for name in ("error", "keep_old", "path", "territory"):
            a = getattr(rec, name)
            if a is not None:
                read_only(a)
        out.append((rec, read_only(pixels_of(rec))))
    return out
