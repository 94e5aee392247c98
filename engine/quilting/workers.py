"""Worker processes for exact quilting on two or more cores (fork + a shared canvas).

Measured in session 7 (job B exact, 256² sample, 676 blocks, numba loaded): a block's search
and placement holds the GIL about a third of its time (py-spy --gil: numpy glue between ducc0's
transforms and the numba kernels), and two threads of one process handed the GIL back and forth
~10 times per block (perf: ~45 000 context switches per 7 runs against ~160 on one thread),
their CPU time per block up 40-60 % and ~0.5 ms per block spent waiting for the GIL: two
threads were no faster than one. So where ``fork`` exists,
:func:`engine.quilting.scheduler.run_levels` places such blocks in worker processes instead:

* the canvas and its ``filled`` mask move to shared memory (an anonymous ``MAP_SHARED``
  mapping, its pages mapped at once by each worker at its start: a fault per page otherwise)
  before the fork; the workers inherit everything else (the sample's spectra,
  the options) copy-on-write, the heap's free pages given back first (:func:`_trim_heap`);
* the calling process and ``threads - 1`` forked workers each take the lowest ready task (the
  ready set, a lock and a semaphore live in shared memory), run exactly the task a thread would
  run (:meth:`Quilter.run_batch` of a task's blocks, each searched alone, once their
  predecessors are placed) and release its
  dependents; the workers send their records and pixels back through a ring of shared memory
  each (:class:`_Mailbox`; a pipe for what does not fit), packed by :func:`pack_records`;
* every block is searched and placed by the same code on exactly the canvas its predecessors
  left: the records and the image are bit-identical to one thread's
  (``tests/engine/test_quilting_workers.py``).

No worker is forked while another thread loads the numba kernels, an FFT backend or compiles
(a child would inherit that lock held and wait for it forever): this process then runs every
task itself. Cancelling, an error in a worker or closing the generator kills the workers at once;
a worker that sends nothing for :data:`STUCK_S` while this process waits for it is taken as
stuck (a lock this process held at the fork that the list above misses) and the run fails with
that message rather than waiting forever.
``QUILT_STUDIO_WORKERS=threads`` keeps threads.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import gc
import math
import mmap
import os
import pickle
import signal
import struct
import sys
import threading
import time
from multiprocessing.connection import Pipe

import numpy as np

from engine.cancel import check
from engine.quilting.records import BlockRecord, read_only

__all__ = [
    "ENV",
    "WorkerPool",
    "available",
    "pack_records",
    "populate",
    "share",
    "unpack_records",
]

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


_POPULATE_WRITE = 23  # madvise's MADV_POPULATE_WRITE (Linux 5.14; the mmap module lacks it)


def populate(a: np.ndarray) -> None:
    """Map every page of shared memory ``a`` (made by :func:`share`) into this process in one
    call (allocating the pages no process has touched yet). A forked worker inherits no page
    table entries of shared mappings, and the canvas, its mask and the rings are new in every
    run: each process took a fault on its first touch of every page (job B on two workers:
    ~4 000 faults a run, several us each in this VM). Each worker maps the pool's shared
    arrays at its start, while the caller places the first blocks alone; the caller maps them
    lazily (mapping them before the fork, 4 ms for job B's 12 MB canvas, lengthened the part of
    the run before the workers start: 1.49-1.51x against 1.53-1.54x, 15 interleaved rounds
    twice). Nothing where the system lacks ``MADV_POPULATE_WRITE``."""
    base = a
    while isinstance(base, np.ndarray):
        base = base.base
    if isinstance(base, memoryview):  # np.frombuffer's
        base = base.obj
    if not isinstance(base, mmap.mmap) or not hasattr(base, "madvise"):
        return
    with contextlib.suppress(OSError, ValueError):
        base.madvise(_POPULATE_WRITE)


def _trim_heap() -> None:
    """Give the heap's free pages back to the system before a fork (glibc's ``malloc_trim``;
    nothing elsewhere). After the fork every page of this process is shared copy-on-write with
    the workers, and the first write to a freed chunk that is reused (the records of a run, the
    blocks' buffers) costs a fault and a copy of its page in whichever process writes it; a
    page given back is a fresh zero page of the writer's own."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@functools.cache
def _malloc_trim():
    try:
        import ctypes

        return ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError):  # not glibc
        return None


def _shared(n: int, dtype) -> np.ndarray:
    """``n`` zeros in anonymous shared memory of their own. Not multiprocessing's RawArray: its
    heap hands a freed block to the next array, and a worker of a finished pool that had not
    yet seen its stop flag then read the next pool's memory as its own (a test failed once:
    the next pool's message counts overwritten)."""
    return np.frombuffer(mmap.mmap(-1, max(1, n * np.dtype(dtype).itemsize)), dtype, n)


class WorkerPool:
    """Runs every task once, each as soon as the tasks it ``needs`` have run, in this process
    and ``workers - 1`` forked ones; :meth:`result` returns one task's result (``run(task)``'s,
    through ``receive`` when it ran in a worker; it must pickle unless ``pack`` packs it). Tasks
    before ``done`` count
    as run.

    The tasks must write their effects only to memory shared before the pool was made (see
    :func:`share`). Which tasks are ready lives in shared memory too (a lock, a semaphore
    counting the ready tasks, each task's count of unfinished needs): whoever finishes a task
    releases its dependents at once and any idle process takes the lowest ready one, so no
    task waits for this process to hand it out. This process is one of the workers (a third
    process on two cores would wait for a core: measured 1.27x one thread against 1.30x, 15
    interleaved rounds); it collects the workers' results between its own tasks."""

    def __init__(
        self, run, receive, needs, workers: int, cancel=None, *, done=0, pack=None, shared=()
    ):
        from multiprocessing import get_context

        ctx = get_context("fork")
        self.run, self.receive, self.cancel = run, receive, cancel
        # pack(result) -> uint8 arrays sent one after the other; receive then gets the message's
        # bytes (a memoryview, valid during the call) instead of the unpickled result
        self.pack = pack
        self.shared = tuple(shared)  # arrays of share() each worker maps at its start (populate)
        self.results: dict[int, object] = {}
        n = len(needs)
        self.dependents: list[list[int]] = [[] for _ in needs]
        for k, p in enumerate(needs):
            for j in p:
                self.dependents[j].append(k)
        self.lock, self.ready = ctx.Lock(), ctx.Semaphore(0)
        self.procs = []
        self.guard = _Holding(self.lock, self.procs, os.getpid())
        self.waiting = _shared(n, np.int32)
        self.waiting[:] = [sum(j >= done for j in p) for p in needs]
        self.state = _shared(n + 1, np.int8)  # last: stop
        self.state[:done] = TAKEN
        first = [k for k in range(done, n) if not self.waiting[k]]
        self.state[first] = READY
        for _ in first:
            self.ready.release()
        self.left = n - done  # tasks whose results are not in yet
        self.news = ctx.Semaphore(0)  # released by a worker after each message
        self.heard = time.monotonic()  # when a message last came in (or this process last ran one)
        self.boxes: list[_Mailbox] = []
        self.conns = []
        owner = os.getpid()
        held = _take_loading_locks()
        self.frozen = held is not None and workers > 1
        if self.frozen:
            # the objects alive now are left out of the garbage collector's passes in the workers
            # (for good) and in this process while it forks and runs or waits for tasks
            # (result()): a full pass writes to every object, and after the fork every page
            # written is copied (a pass in this process took 57 ms instead of ~25 ms)
            _GC_FREEZE.enter()
        try:
            if held is not None and workers > 1:
                _trim_heap()
            # with a loading lock held by another thread (the editor's kernel warm-up), a forked
            # worker would inherit it held by no one and wait for it forever: no fork then, this
            # process runs every task (the same results)
            for _ in range(workers - 1 if held is not None else 0):
                parent, child = Pipe()
                box = _Mailbox(ctx, child, owner)
                proc = ctx.Process(
                    target=self._serve, args=(box, owner, list(self.conns), held), daemon=True
                )
                proc.start()
                child.close()
                box.conn = parent
                box.guard.procs.append(proc)
                self.boxes.append(box)
                self.conns.append(parent)
                self.procs.append(proc)
        except BaseException:
            self.shutdown(kill=True)
            raise
        finally:
            if self.frozen:
                _GC_FREEZE.leave()
            _release(held)

    def _take(self) -> int:
        """The lowest ready task, marked taken (the caller holds one count of ``ready``)."""
        with self.guard:
            k = int(np.flatnonzero(self.state[:-1] == READY)[0])
            self.state[k] = TAKEN
        return k

    def _finish(self, k: int) -> None:
        released = 0
        with self.guard:
            for d in self.dependents[k]:
                self.waiting[d] -= 1
                if not self.waiting[d]:
                    self.state[d] = READY
                    released += 1
        for _ in range(released):
            self.ready.release()

    def _serve(self, box: _Mailbox, owner: int, others, held) -> None:
        """A worker's loop: take tasks until told to stop (or the caller is gone); each result
        goes to the calling process through ``box``."""
        _release(held)  # this process's copies, taken by the parent around the fork
        # the editor collects in its GUI thread only (quilt_gui.gc_thread: automatic collection
        # off); a worker has no GUI and no Qt object but the frozen ones alive at the fork
        gc.enable()
        for other in others:  # the other workers' pipes
            other.close()
        for a in (*self.shared, box.ring):
            populate(a)
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
                self._finish(k)
                parts = self.pack(out) if self.pack is not None else [_bytes(_dumps(out))]
            except SystemExit:  # the parent is gone (_Holding): no one will collect
                raise
            except BaseException as exc:
                try:
                    data = _dumps(exc)
                except Exception:  # an exception that does not pickle
                    data = _dumps(RuntimeError(repr(exc)))
                box.put([_bytes(_HEAD.pack(k, ERROR)), _bytes(data)], pipe=True)
                self.news.release()
                return
            box.put([_bytes(_HEAD.pack(k, OK)), *parts])
            self.news.release()

    def _collect(self, timeout: float) -> None:
        """Take in the workers' messages (waiting up to ``timeout`` for one when none is in)."""
        if self._take_messages() or not timeout:
            return
        while self.news.acquire(block=False):  # the news of messages taken in already
            pass
        if self._take_messages():
            return
        if self.news.acquire(timeout=timeout):
            self._take_messages()
        elif any(proc.exitcode is not None for proc in self.procs):  # no message, one gone
            self._take_messages()  # (its error, if it sent one)
            raise RuntimeError("a quilting worker process died")
        elif time.monotonic() - self.heard > STUCK_S:
            raise RuntimeError(
                f"a quilting worker process sent nothing for {STUCK_S:.0f} s: it is stuck"
            )

    def _take_messages(self) -> bool:
        got = False
        for box in self.boxes:
            got |= box.take(self._handle)
        if got:
            self.heard = time.monotonic()
        return got

    def _handle(self, data) -> None:
        """Take in one message (``receive`` must copy what it keeps of a packed one)."""
        k, kind = _HEAD.unpack_from(data)
        body = memoryview(data)[_HEAD.size :]
        if kind == ERROR:
            raise pickle.loads(body)
        self.results[k] = self.receive(pickle.loads(body) if self.pack is None else body)
        self.left -= 1

    def result(self, k: int):
        """Task ``k``'s result (running tasks here and collecting the workers' until it is in).
        Frozen only meanwhile: a caller's generator abandoned in a reference cycle between two
        calls is still collected (and its ``finally`` shuts the pool down)."""
        if not self.frozen:
            return self._result(k)
        _GC_FREEZE.enter()
        try:
            return self._result(k)
        finally:
            _GC_FREEZE.leave()

    def _result(self, k: int):
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
                self.heard = time.monotonic()  # the workers' silence counts from here
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


class _GcFreeze:
    """``gc.freeze()`` while any pool forks or runs tasks (:meth:`WorkerPool.result`). The
    freeze is the process's: with two pools at once (the editor's two jobs, the batch's threads)
    the first one's leaving must not end the other's freeze, so they are counted and the last
    one to leave unfreezes. Entering freezes every object alive then (moving the collector's
    lists: no pass)."""

    def __init__(self):
        self.lock = threading.Lock()  # never taken by a forked worker
        self.pools = 0

    def enter(self) -> None:
        with self.lock:
            self.pools += 1
            gc.freeze()

    def leave(self) -> None:
        with self.lock:
            self.pools -= 1
            if not self.pools:
                gc.unfreeze()


_GC_FREEZE = _GcFreeze()


READY, TAKEN = 1, 2
OK, ERROR = 0, 1
STUCK_S = 120.0
"""Seconds without a message from a worker, while this process has nothing to run, after which
the worker counts as stuck (a task takes milliseconds; this is a margin for a loaded machine)."""
RING_BYTES = 1 << 20
"""Each worker's ring of shared memory for its messages (job B's are ~40 kB)."""


class _Mailbox:
    """One worker's messages to the calling process: written into a ring of shared memory
    (:data:`RING_BYTES`) where they fit, else (larger than a quarter of the ring, the caller
    behind, an error) sent through the pipe ``conn``. Shared counts of the bytes written and
    read and of the messages piped say what is in, read under a lock of the box's own (its
    memory barriers order the bytes before the counts on every processor). Measured on job B
    (2 workers, ~670 messages of ~40 kB): through the pipe a message cost the worker 30-130 us
    to send and the caller 80-200 us to read under load (it slept in the read while the worker
    wrote); the ring needs no system call."""

    def __init__(self, ctx, conn, owner: int):
        self.ring = np.frombuffer(mmap.mmap(-1, RING_BYTES), np.uint8)
        self.counts = _shared(3, np.int64)  # written, read, piped
        self.lock = ctx.Lock()
        self.conn = conn
        self.guard = _Holding(self.lock, [], owner)  # its worker added when started
        self.read, self.piped = 0, 0  # the caller's own counts

    def put(self, parts: list[np.ndarray], pipe: bool = False) -> None:
        """(Worker) Send one message: the bytes of ``parts`` (uint8 arrays) one after another."""
        n = sum(len(p) for p in parts)
        need = _MSG.size + -(-n // _ALIGN) * _ALIGN
        with self.guard:
            written, read = int(self.counts[0]), int(self.counts[1])
        at = written % RING_BYTES
        skip = RING_BYTES - at if at + need > RING_BYTES else 0
        if pipe or need > RING_BYTES // 4 or written + skip + need - read > RING_BYTES:
            with self.guard:
                self.counts[2] += 1  # counted first: the reader then waits for all its bytes
            self.conn.send_bytes(b"".join(parts))
            return
        if skip:
            _MSG.pack_into(self.ring, at, -1, 0)
            at = 0
        _MSG.pack_into(self.ring, at, n, 0)
        at += _MSG.size
        for p in parts:
            self.ring[at : at + len(p)] = p
            at += len(p)
        with self.guard:
            self.counts[0] = written + skip + need

    def take(self, handle) -> bool:
        """(Caller) Hand the messages in, oldest first, to ``handle`` (a message in the ring is
        a view of it, valid during the call); whether there were any."""
        with self.guard:
            written, piped = int(self.counts[0]), int(self.counts[2])
        r = self.read
        if r == written and self.piped == piped:
            return False
        while r < written:
            at = r % RING_BYTES
            n, _ = _MSG.unpack_from(self.ring, at)
            if n < 0:  # the rest of the ring skipped
                r += RING_BYTES - at
                continue
            handle(memoryview(self.ring[at + _MSG.size : at + _MSG.size + n]))
            r += _MSG.size + -(-n // _ALIGN) * _ALIGN
        if r != self.read:
            self.read = r
            with self.guard:
                self.counts[1] = r
        while self.piped < piped:
            self.piped += 1
            handle(_recv(self.conn))
        return True


class _Holding:
    """``with`` it: ``lock``, held. The processes hold their shared locks for microseconds, but
    one killed meanwhile (the OOM killer, a user's kill) leaves its lock held for ever. In the
    calling process (``owner``): when the lock does not come within a second and one of
    ``procs`` (the workers that take it) was killed, or after :data:`STUCK_S`, the run fails with
    that instead of waiting for ever. In a worker (a fork of ``owner``): when the lock does not
    come within a second and the caller is gone, the worker ends (SystemExit)."""

    __slots__ = ("lock", "procs", "owner")

    def __init__(self, lock, procs: list, owner: int):
        self.lock, self.procs, self.owner = lock, procs, owner

    def __enter__(self) -> None:
        if self.lock.acquire(False):  # the usual case; and macOS emulates timed waits by polling
            return
        in_worker = os.getpid() != self.owner
        t0 = time.monotonic()
        while not self.lock.acquire(timeout=1.0):
            if in_worker:
                if os.getppid() != self.owner:
                    raise SystemExit(0)
                continue
            # killed (a signal: exit code < 0); one that ended by itself released its locks, and
            # its error, if it sent one, is read once the lock comes
            if any(proc.exitcode is not None and proc.exitcode < 0 for proc in self.procs):
                raise RuntimeError("a quilting worker process ended while a shared lock was held")
            if time.monotonic() - t0 > STUCK_S:
                raise RuntimeError(f"a quilting worker process held a lock for {STUCK_S:.0f} s")

    def __exit__(self, *exc) -> None:
        self.lock.release()


def _recv(conn) -> bytes:
    """The next piped message (counted by the worker just before it sends it)."""
    try:
        if not conn.poll(STUCK_S):  # e.g. a copy of the pipe's end kept open by another fork
            raise RuntimeError(f"a quilting worker process sent nothing for {STUCK_S:.0f} s")
        return conn.recv_bytes()
    except EOFError:
        raise RuntimeError("a quilting worker process died") from None


_MSG = struct.Struct("<qq")
"""A message in a ring starts with its length (-1: skip to the ring's start) and 8 spare bytes."""
_HEAD = struct.Struct("<qq")
"""A worker's message starts with the task and OK or ERROR (then the result or the exception)."""


def _dumps(obj) -> bytes:
    from multiprocessing.reduction import ForkingPickler

    return bytes(ForkingPickler.dumps(obj))


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


_FIELDS = tuple(f.name for f in dataclasses.fields(BlockRecord))
_ARRAYS = tuple(i for i, f in enumerate(_FIELDS) if f in ("error", "keep_old", "path", "territory"))
_LEN = struct.Struct("<q")
_ALIGN = 16


def _start(n: int) -> int:
    """Where the arrays start in a message whose pickled part has ``n`` bytes."""
    return -(-(_LEN.size + n) // _ALIGN) * _ALIGN


def pack_records(out) -> list[np.ndarray]:
    """A task's (record, pixels) pairs as one message, in parts (byte arrays, to be joined or
    copied one after the other): a small pickle of the records' other fields and of the
    arrays' dtypes and shapes, then the arrays' bytes. Pickling the records whole took ~40 us
    a block (~65 us in a worker) and unpickling them ~30 us; this, 5-10 us each (job B)."""
    arrays, rows = [], []
    for rec, pixels in out:
        values = [getattr(rec, name) for name in _FIELDS]
        for i in _ARRAYS:
            if values[i] is not None:
                arrays.append(np.ascontiguousarray(values[i]))
                values[i] = len(arrays) - 1  # the array's number (array fields hold no ints)
        arrays.append(np.ascontiguousarray(pixels))
        rows.append((values, len(arrays) - 1))
    specs, size = [], 0
    for a in arrays:
        specs.append((a.dtype.str, a.shape, size))
        size += -(-a.nbytes // _ALIGN) * _ALIGN
    head = pickle.dumps((rows, specs), protocol=pickle.HIGHEST_PROTOCOL)
    parts = [_bytes(_LEN.pack(len(head)) + head), _PAD[: _start(len(head)) - _LEN.size - len(head)]]
    for a in arrays:
        parts.append(a.reshape(-1).view(np.uint8))
        parts.append(_PAD[: -a.nbytes % _ALIGN])
    return parts


def _bytes(b: bytes) -> np.ndarray:
    return np.frombuffer(b, np.uint8)


_PAD = np.zeros(_ALIGN, np.uint8)


def unpack_records(data) -> list:
    """The (record, pixels) pairs of a :func:`pack_records` message (a bytes-like object);
    their arrays are copies, read-only as a record's arrays are (the message's memory is
    reused, and a record keeps no more memory than one made here)."""
    (n,) = _LEN.unpack_from(data)
    rows, specs = pickle.loads(data[_LEN.size : _LEN.size + n])
    start = _start(n)
    arrays = [
        read_only(np.frombuffer(data, dt, math.prod(shape), start + off).reshape(shape).copy())
        for dt, shape, off in specs
    ]
    out = []
    for values, pixels in rows:
        for i in _ARRAYS:
            if values[i] is not None:
                values[i] = arrays[values[i]]
        out.append((BlockRecord(*values), arrays[pixels]))
    return out
