"""Worker processes for exact quilting on two or more cores (fork + a shared canvas).

Measured in session 7 (job B exact, 256² sample, 676 blocks, numba loaded): a block's search
and placement holds the GIL about a third of its time (py-spy --gil: numpy glue between ducc0's
transforms and the numba kernels), and two threads of one process handed the GIL back and forth
~10 times per block (perf: ~45 000 context switches per 7 runs against ~160 on one thread),
their CPU time per block up 40-60 % and ~0.5 ms per block spent waiting for the GIL: two
threads were no faster than one. So where ``fork`` exists,
:func:`engine.quilting.scheduler.run_levels` places such blocks in worker processes instead:

* the canvas and its ``filled`` mask move to shared memory (an anonymous ``MAP_SHARED``
  mapping) before the fork; the workers inherit everything else (the sample's spectra, the
  options) copy-on-write;
* the calling process and ``threads - 1`` forked workers each take the lowest ready task (the
  ready set, a lock and a semaphore live in shared memory), run exactly the task a thread would
  run (:meth:`Quilter.run_batch` of one block whose predecessors are placed) and release its
  dependents; the workers send their records and pixels back through a pipe;
* every block is searched and placed by the same code on exactly the canvas its predecessors
  left: the records and the image are bit-identical to one thread's
  (``tests/engine/test_quilting_workers.py``).

No worker is forked while another thread loads the numba kernels, an FFT backend or compiles
(a child would inherit that lock held and wait for it forever): this process then runs every
task itself. Cancelling, an error in a worker or closing the generator kills the workers at once.
``QUILT_STUDIO_WORKERS=threads`` keeps threads.
"""

from __future__ import annotations

import contextlib
import functools
import mmap
import os
import signal
import sys
import threading
from multiprocessing.connection import Pipe, wait

import numpy as np

from engine.cancel import check
from engine.quilting.records import read_only

__all__ = ["ENV", "WorkerPool", "available", "share"]

ENV = "QUILT_STUDIO_WORKERS"
"""Environment variable: ``threads`` keeps the search on threads of one process (no fork)."""


def available() -> bool:
    """Whether worker processes can be used here: ``fork`` exists, this is not a daemonic
    process of :mod:`multiprocessing` (which may not have children), :data:`ENV` does not
    say ``threads`` and the pool's shared lock can be made (containers without ``/dev/shm``
    have no POSIX semaphores: quilting then keeps threads instead of failing)."""
    from multiprocessing import current_process

    return (
        hasattr(os, "fork")
        and not current_process().daemon
        and os.environ.get(ENV, "").strip().lower() != "threads"
        and _shared_locks_work()
    )


@functools.cache
def _shared_locks_work() -> bool:
    from multiprocessing import get_context

    try:
        get_context("fork").Lock()
    except OSError:
        return False
    return True


def share(a: np.ndarray) -> np.ndarray:
    """A copy of ``a`` in anonymous shared memory (seen by processes forked after this)."""
    buf = mmap.mmap(-1, max(1, a.nbytes))  # zero-filled
    out = np.frombuffer(buf, dtype=a.dtype, count=a.size).reshape(a.shape)
    if a.any():
        out[...] = a
    return out


class WorkerPool:
    """Runs every task once, each as soon as the tasks it ``needs`` have run, in this process
    and ``workers - 1`` forked ones; :meth:`result` returns one task's result (``run(task)``'s,
    through ``receive`` when it ran in a worker; it must pickle). Tasks before ``done`` count
    as run.

    The tasks must write their effects only to memory shared before the pool was made (see
    :func:`share`). Which tasks are ready lives in shared memory too (a lock, a semaphore
    counting the ready tasks, each task's count of unfinished needs): whoever finishes a task
    releases its dependents at once and any idle process takes the lowest ready one, so no
    task waits for this process to hand it out. This process is one of the workers (a third
    process on two cores would wait for a core: measured 1.27x one thread against 1.30x, 15
    interleaved rounds); it collects the workers' results between its own tasks."""

    def __init__(self, run, receive, needs, workers: int, cancel=None, *, done=0):
        from multiprocessing import get_context

        ctx = get_context("fork")
        self.run, self.receive, self.cancel = run, receive, cancel
        self.results: dict[int, object] = {}
        n = len(needs)
        self.dependents: list[list[int]] = [[] for _ in needs]
        for k, p in enumerate(needs):
            for j in p:
                self.dependents[j].append(k)
        self.lock, self.ready = ctx.Lock(), ctx.Semaphore(0)
        self.waiting = np.frombuffer(ctx.RawArray("i", max(1, n)), np.int32)[:n]
        self.waiting[:] = [sum(j >= done for j in p) for p in needs]
        self.state = np.frombuffer(ctx.RawArray("b", max(1, n) + 1), np.int8)  # last: stop
        self.state[:done] = TAKEN
        first = [k for k in range(done, n) if not self.waiting[k]]
        self.state[first] = READY
        for _ in first:
            self.ready.release()
        self.left = n - done  # tasks whose results are not in yet
        self.conns, self.procs = [], []
        owner = os.getpid()
        held = _take_loading_locks()
        try:
            # with a loading lock held by another thread (the editor's kernel warm-up), a forked
            # worker would inherit it held by no one and wait for it forever: no fork then, this
            # process runs every task (the same results)
            for _ in range(workers - 1 if held is not None else 0):
                parent, child = Pipe()
                proc = ctx.Process(
                    target=self._serve, args=(child, owner, list(self.conns), held), daemon=True
                )
                proc.start()
                child.close()
                self.conns.append(parent)
                self.procs.append(proc)
        except BaseException:
            self.shutdown(kill=True)
            raise
        finally:
            _release(held)

    def _take(self) -> int:
        """The lowest ready task, marked taken (the caller holds one count of ``ready``)."""
        with self.lock:
            k = int(np.flatnonzero(self.state[:-1] == READY)[0])
            self.state[k] = TAKEN
        return k

    def _finish(self, k: int) -> None:
        released = 0
        with self.lock:
            for d in self.dependents[k]:
                self.waiting[d] -= 1
                if not self.waiting[d]:
                    self.state[d] = READY
                    released += 1
        for _ in range(released):
            self.ready.release()

    def _serve(self, conn, owner: int, others, held) -> None:
        """A worker's loop: take tasks until told to stop (or the caller is gone)."""
        _release(held)  # this process's copies, taken by the parent around the fork
        for other in others:  # the other workers' pipes
            other.close()
        with contextlib.suppress(ValueError):  # a Ctrl+C is the parent's (it kills its workers)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        while True:
            if not self.ready.acquire(timeout=1.0):
                if os.getppid() != owner:  # the parent is gone (killed): no one will collect
                    return
                continue
            if self.state[-1]:  # stop
                return
            k = self._take()
            try:
                out = self.run(k)
            except BaseException as exc:
                try:
                    conn.send(("error", k, exc))
                except Exception:  # an exception that does not pickle
                    conn.send(("error", k, RuntimeError(repr(exc))))
                return
            self._finish(k)
            conn.send(("ok", k, out))

    def _collect(self, timeout: float) -> None:
        conns = wait(self.conns, timeout) if timeout else self.conns
        for conn in conns:  # Connection.poll: far cheaper than wait()'s selector per call
            while conn.poll():
                try:
                    kind, k, value = conn.recv()
                except EOFError:
                    raise RuntimeError("a quilting worker process died") from None
                if kind == "error":
                    raise value
                self.results[k] = self.receive(value)
                self.left -= 1

    def result(self, k: int):
        """Task ``k``'s result (running tasks here and collecting the workers' until it is in)."""
        while k not in self.results:
            check(self.cancel)
            self._collect(0)
            if k in self.results:
                break
            if self.ready.acquire(block=False):
                j = self._take()
                self.results[j] = self.run(j)
                self.left -= 1
                self._finish(j)
            elif self.conns:
                self._collect(0.05)
            else:  # pragma: no cover - a task whose needs never run
                raise RuntimeError(f"quilting task {k} can never run")
        return self.results.pop(k)

    def shutdown(self, kill: bool = False) -> None:
        """Stop the workers (at once with ``kill``, or when tasks are still out)."""
        kill = kill or self.left > 0
        self.state[-1] = 1
        for proc in self.procs:
            if kill:
                proc.kill()
            else:
                self.ready.release()
        for conn, proc in zip(self.conns, self.procs, strict=True):
            conn.close()
            # joined on a thread of its own: a worker's exit takes milliseconds
            threading.Thread(target=proc.join, daemon=True).start()
        self.conns, self.procs = [], []


READY, TAKEN = 1, 2


def _loading_locks() -> list:
    """The locks a worker may need that another thread may hold at the fork: loading the
    numba kernels (``engine._jit``), the FFT backends (``engine.fft``) and numba's compiler
    (it compiles or reads a kernel from its cache under one lock)."""
    from engine import _jit, fft

    locks = [_jit.LOADING_LOCK, fft.LOADING_LOCK]
    numba_lock = sys.modules.get("numba.core.compiler_lock")
    if numba_lock is not None:  # its lock object wraps an RLock (numba 0.59-0.6x)
        locks.append(getattr(numba_lock.global_compiler_lock, "_lock", None))
    return [lock for lock in locks if lock is not None]


def _take_loading_locks() -> list | None:
    """Every lock of :func:`_loading_locks`, taken without waiting; None (and none held) when
    another thread holds one."""
    held = []
    for lock in _loading_locks():
        if not lock.acquire(blocking=False):
            _release(held)
            return None
        held.append(lock)
    return held


def _release(held: list | None) -> None:
    for lock in reversed(held or []):
        lock.release()


def records_in(out):
    """A task's (record, pixels) pairs as received from a worker, their arrays read-only again
    (pickling drops the flag)."""
    for rec, pixels in out:
        for name in ("error", "keep_old", "path", "territory"):
            a = getattr(rec, name)
            if a is not None:
                read_only(a)
        read_only(pixels)
    return out
