"""Exact quilting on worker processes (engine.quilting.workers) gives exactly one thread's result,
stops its workers when cancelled or failing, and threads stay available."""

from __future__ import annotations

import gc
import os
import sys
import time

import numpy as np
import pytest

from engine import _jit
from engine.cancel import Cancelled, CancelToken
from engine.quilting import iter_quilt, quilt, workers
from engine.quilting.core import Quilter
from engine.quilting.records import BlockPlaced

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="worker processes need fork")

SAMPLE = np.random.default_rng(6).random((210, 200, 3), dtype=np.float32)  # >= 200² pixels


def _poll(condition, seconds: float = 60) -> None:
    """Wait until ``condition()`` is true, for ``seconds`` at most (the caller asserts)."""
    end = time.monotonic() + seconds
    while not condition() and time.monotonic() < end:
        time.sleep(0.01)


def _records(result):
    return [
        (
            b.position,
            b.size,
            b.source,
            b.arms,
            b.criterion,
            b.peak,
            b.match_error,
            b.best_error,
            b.candidates,
            b.depth,
            None if b.error is None else b.error.tobytes(),
            None if b.keep_old is None else b.keep_old.tobytes(),
            np.asarray(b.path).tobytes(),
        )
        for b in result.blocks
    ]


@pytest.fixture
def pools(monkeypatch):
    """Counts the worker pools made."""
    made = []
    real = workers.WorkerPool

    class Counted(real):
        def __init__(self, *args, **kwargs):
            made.append(self)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(workers, "WorkerPool", Counted)
    return made


@pytest.mark.parametrize(
    "options",
    [
        {},
        dict(tileable=True),  # wrap-around blocks with bottom / right arms
        dict(adaptive_threshold=0.02),  # split blocks: children searched inside a task
        dict(mode="fast"),  # principal components + exact re-ranking
    ],
)
def test_worker_processes_give_one_threads_records_and_image(options, pools, monkeypatch):
    _jit.load()
    kw = {"block": 28, "overlap": 6, "rng": 3, "mode": "exact", **options}
    one = quilt(SAMPLE, (150, 170), threads=1, **kw)
    assert not pools
    runs = [quilt(SAMPLE, (150, 170), threads=t, **kw) for t in (2, 3)]
    assert len(pools) == 2
    monkeypatch.setenv(workers.ENV, "threads")
    runs.append(quilt(SAMPLE, (150, 170), threads=2, **kw))
    assert len(pools) == 2  # threads, no processes
    for run in runs:
        assert np.array_equal(run.image, one.image)
        assert _records(run) == _records(one)
        assert not run.image.flags.writeable
        for b in run.blocks:
            for a in (b.error, b.keep_old, b.path):
                assert a is None or not a.flags.writeable


def test_streamed_pixels_are_the_placed_blocks(pools):
    """The events of a run on worker processes carry each block's pixels as pasted (read from
    the shared canvas before any later block may overwrite them), in level order."""
    _jit.load()
    kw = dict(block=28, overlap=6, rng=5, mode="exact")
    mine, ref = (
        [e for e in iter_quilt(SAMPLE, (150, 170), threads=t, **kw) if isinstance(e, BlockPlaced)]
        for t in (2, 1)
    )
    assert pools
    assert len(mine) == len(ref)
    for a, b in zip(mine, ref, strict=True):
        assert a.position == b.position
        assert np.array_equal(a.pixels, b.pixels)


@pytest.mark.parametrize("ring", [4096, 1 << 16])
def test_messages_through_a_small_ring_and_the_pipe(ring, pools, monkeypatch):
    """The workers' records and pixels arrive whole whichever way they come: with a 4 kB ring
    every message (~9 kB) goes through the pipe; with 64 kB they wrap around the ring (and go
    through the pipe when the caller is behind); adaptive runs send several records a task."""
    _jit.load()
    monkeypatch.setattr(workers, "RING_BYTES", ring)

    class Waiting(workers.WorkerPool):  # the pools fixture's
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            # the caller runs nothing before a worker has taken a task: on a loaded machine the
            # caller once ran every task of this small job and nothing came through the ring
            done = len(self.state) - 1 - self.left
            _poll(lambda: (self.state[:-1] == workers.TAKEN).sum() > done)

    monkeypatch.setattr(workers, "WorkerPool", Waiting)
    kw = dict(block=28, overlap=6, rng=4, mode="exact", adaptive_threshold=0.02)
    ref = list(iter_quilt(SAMPLE, (200, 220), threads=1, **kw))
    for _ in range(5):  # the ring's path needs a caller that keeps up: a loaded machine
        mine = list(iter_quilt(SAMPLE, (200, 220), threads=2, **kw))  # (two suites at once)
        assert pools and pools[-1].boxes  # once piped every message of a run
        piped = sum(box.piped for box in pools[-1].boxes)
        through_ring = sum(box.read for box in pools[-1].boxes)
        if (piped if ring == 4096 else through_ring) > 0:
            break
    assert piped > 0 if ring == 4096 else through_ring > 0  # the path this size takes
    placed = [[e for e in run if isinstance(e, BlockPlaced)] for run in (mine, ref)]
    assert len(placed[0]) == len(placed[1])
    for a, b in zip(*placed, strict=True):
        assert np.array_equal(a.pixels, b.pixels)
        assert not a.pixels.flags.writeable
    done = [quilt(SAMPLE, (200, 220), threads=t, **kw) for t in (2, 1)]
    assert _records(done[0]) == _records(done[1])


def test_a_worker_that_dies_stops_the_run(pools, monkeypatch):
    """A worker process killed mid-run (no message, no error sent) ends the run with an error
    instead of waiting for its blocks forever."""
    _jit.load()
    real = Quilter.place
    parent = os.getpid()

    def place(self, wk):
        if os.getpid() != parent:
            os._exit(3)
        return real(self, wk)

    monkeypatch.setattr(Quilter, "place", place)
    with pytest.raises(RuntimeError, match="died"):
        quilt(SAMPLE, (200, 200), block=28, overlap=6, rng=1, mode="exact", threads=2)
    assert pools and not pools[0].procs


def test_cancel_stops_the_workers(pools):
    _jit.load()
    token = CancelToken()
    it = iter_quilt(SAMPLE, (300, 300), block=28, overlap=6, rng=1, threads=2, cancel=token)
    with pytest.raises(Cancelled):
        for n, _ in enumerate(it):
            if n == 40:
                token.cancel()
    assert pools and not pools[0].procs  # the workers were stopped


class Boom(Exception):
    pass


def test_an_error_in_a_worker_reaches_the_caller(pools, monkeypatch):
    """A block failing in a worker process (or here) raises the same exception from quilt."""
    _jit.load()
    real = Quilter.place

    def place(self, wk):
        if wk.index == 30:
            raise Boom(f"block {wk.index}")
        return real(self, wk)

    monkeypatch.setattr(Quilter, "place", place)
    with pytest.raises(Boom):
        quilt(SAMPLE, (200, 200), block=28, overlap=6, rng=1, mode="exact", threads=2)
    assert pools and not pools[0].procs


def test_closing_the_stream_early_stops_the_workers(pools):
    _jit.load()
    it = iter_quilt(SAMPLE, (300, 300), block=28, overlap=6, rng=1, threads=2)
    for n, _ in enumerate(it):
        if n == 30:
            break
    it.close()
    assert pools and not pools[0].procs


def test_small_samples_stay_on_threads(pools):
    _jit.load()
    quilt(SAMPLE[:150, :150], (150, 170), block=28, overlap=6, rng=3, threads=2)
    assert not pools


def test_without_shared_semaphores_quilting_keeps_threads(pools, monkeypatch):
    """Where the pool's lock cannot be made (no /dev/shm), a 2-thread run uses threads and
    gives one thread's result rather than failing."""
    import multiprocessing.synchronize

    _jit.load()
    kw = dict(block=28, overlap=6, rng=3, mode="exact")
    one = quilt(SAMPLE, (150, 170), threads=1, **kw)

    def no_semaphores(*args, **kwargs):
        raise OSError(38, "Function not implemented")

    monkeypatch.setattr(multiprocessing.synchronize.SemLock, "__init__", no_semaphores)
    workers._shared_locks_work.cache_clear()
    try:
        two = quilt(SAMPLE, (150, 170), threads=2, **kw)
    finally:
        workers._shared_locks_work.cache_clear()
    assert not pools
    assert np.array_equal(two.image, one.image)
    assert _records(two) == _records(one)


LOCK_SCENARIO = """
import os, sys, threading, time
from engine import _jit
from engine.quilting.workers import WorkerPool

def run(k):  # a task that loads the kernels' lock, as a worker's first kernel call does
    with _jit.LOADING_LOCK:
        time.sleep(0.05)  # 2 s in all: time enough for both processes to take tasks
        return os.getpid()

def pids(made=lambda: None):
    pool = WorkerPool(run, lambda pid: pid, [[] for _ in range(40)], 2)
    made()
    try:
        return {pool.result(k) for k in range(40)}
    finally:
        pool.shutdown()

started, stop = threading.Event(), threading.Event()
def warm_up():  # another thread holding the lock while the pool forks (the editor's warm-up)
    with _jit.LOADING_LOCK:
        started.set()
        stop.wait()
threading.Thread(target=warm_up, daemon=True).start()
started.wait()
busy = pids(stop.set)  # made while the lock is held; the warm-up ends before the tasks run
free = pids()
print(busy == {os.getpid()}, len(free))
"""


def test_no_worker_is_forked_while_another_thread_loads_the_kernels():
    """A worker forked while another thread holds a loading lock would wait for it forever (the
    run never ended: the editor's quilting during its kernel warm-up, and CI once). Then this
    process runs every task; with the locks free the workers are forked and may take them."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", LOCK_SCENARIO], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "2"]


def test_a_stuck_worker_fails_the_run_instead_of_waiting_forever(monkeypatch):
    """A worker that sends nothing (stuck, e.g. on a lock inherited held) ends the run with an
    error after :data:`workers.STUCK_S` instead of holding it forever."""
    import time

    monkeypatch.setattr(workers, "STUCK_S", 1.0)
    parent = os.getpid()

    def run(k):
        if os.getpid() != parent:
            time.sleep(60)  # stuck (killed at shutdown)
        time.sleep(0.05)  # 2 s in all: time enough for the worker to take a task
        return k

    pool = workers.WorkerPool(run, lambda k: k, [[] for _ in range(40)], 2)
    try:
        assert pool.procs  # a worker was forked
        with pytest.raises(RuntimeError, match="stuck"):
            for k in range(40):
                pool.result(k)
    finally:
        pool.shutdown(kill=True)


def test_one_pools_end_does_not_end_anothers_gc_freeze(monkeypatch):
    """``gc.freeze`` is the process's: with two pools at once (the editor's two jobs) the
    objects stay frozen while either runs tasks, not only until the first one's call ends. (No
    loading lock counts as held: another test's warm-up thread in this process must not stop
    the forks.)"""
    import threading

    monkeypatch.setattr(workers, "_take_loading_locks", lambda: [])
    assert gc.get_freeze_count() == 0
    go = workers.share(np.zeros(1, np.int8))

    def held_until_go(k):  # pool a's task ends when the test says so (a margin of 60 s)
        _poll(lambda: go[0])
        return k

    a = workers.WorkerPool(held_until_go, lambda k: k, [[]], 2)
    b = workers.WorkerPool(lambda k: k, lambda k: k, [[] for _ in range(4)], 2)
    try:
        assert a.frozen and b.frozen  # both forked their workers
        assert gc.get_freeze_count() == 0  # frozen only while running tasks
        inside = threading.Thread(target=a.result, args=(0,))
        inside.start()
        _poll(gc.get_freeze_count)  # a's call has frozen the objects
        assert [b.result(k) for k in range(4)] == [0, 1, 2, 3]
        assert gc.get_freeze_count() > 0  # a still runs its task: still frozen
        go[0] = 1
        inside.join(60)
        assert gc.get_freeze_count() == 0
    finally:
        go[0] = 1
        a.shutdown(kill=True)
        b.shutdown(kill=True)


def test_a_pool_abandoned_in_a_reference_cycle_is_still_shut_down(monkeypatch):
    """A stream that made a pool, dropped between two events inside a reference cycle: the
    collector finds it (its objects are not frozen between the pool's calls) and its
    ``finally`` shuts the pool and its workers down; frozen, it would be kept, and with it
    the freeze and the workers, for good."""

    monkeypatch.setattr(workers, "_take_loading_locks", lambda: [])
    pools = []

    def stream():
        pool = workers.WorkerPool(lambda k: k, lambda k: k, [[] for _ in range(4)], 2)
        pools.append(pool)
        try:
            for k in range(4):
                yield pool.result(k)
        finally:
            pool.shutdown()

    class Holder:
        pass

    holder = Holder()
    holder.me, holder.stream = holder, stream()
    assert next(holder.stream) == 0
    (pool,) = pools
    procs = list(pool.procs)
    assert procs and pool.frozen
    del holder
    gc.collect()
    try:
        assert pool.state[-1] == 1  # stopped by the stream's finally
        assert gc.get_freeze_count() == 0
        # killed and joined (on threads of the pool's) at once
        _poll(lambda: all(proc.exitcode is not None for proc in procs))
        assert all(proc.exitcode is not None for proc in procs)
    finally:
        pool.shutdown(kill=True)


def test_a_workers_own_error_wins_over_a_slow_lock(monkeypatch):
    """A worker that fails sends its error and ends by itself (exit code 0, its locks released).
    When the caller then waits over a second for that mailbox's lock (held by another, e.g. a
    process slowed down by load), the worker's end is no held lock: the caller waits on and
    raises the worker's own error, not "ended while a shared lock was held"."""
    import threading

    monkeypatch.setattr(workers, "_take_loading_locks", lambda: [])
    parent = os.getpid()

    def run(k):
        if os.getpid() != parent:
            raise ValueError("the worker's own error")
        return k

    pool = workers.WorkerPool(run, lambda k: k, [[]], 2)
    try:
        (proc,) = pool.procs
        proc.join(60)
        assert proc.exitcode == 0  # it took the task, sent its error and ended
        box = pool.boxes[0]
        lock, held, waited = box.guard.lock, threading.Event(), threading.Event()

        class Watched:  # the mailbox's lock, telling when the caller waited a second for it
            def acquire(self, block=True, timeout=None):
                got = lock.acquire(block, timeout)
                if timeout is not None and not got:
                    waited.set()
                return got

            def release(self):
                lock.release()

        def other_holder():
            with lock:
                held.set()
                waited.wait(60)

        box.guard.lock = Watched()
        holder = threading.Thread(target=other_holder)
        holder.start()
        held.wait(60)
        with pytest.raises(ValueError, match="own error"):
            pool.result(0)
        holder.join(60)
    finally:
        pool.shutdown(kill=True)


KILLED_HOLDING_SCENARIO = """
import os, signal, time
import numpy as np
from engine.quilting.workers import WorkerPool, share

parent = os.getpid()
killed = share(np.zeros(1, np.int8))  # set by the worker as it dies holding the lock

class Pool(WorkerPool):
    def _finish(self, k):
        if os.getpid() != parent:  # a worker killed inside its critical section
            self.lock.acquire()
            killed[0] = 1
            os.kill(os.getpid(), signal.SIGKILL)
        super()._finish(k)

def run(k):  # this process's first task ends once the worker has died (a margin of 60 s)
    t0 = time.monotonic()
    while os.getpid() == parent and not killed[0] and time.monotonic() - t0 < 60:
        time.sleep(0.01)
    return k

pool = Pool(run, lambda k: k, [[] for _ in range(40)], 2)
try:
    assert pool.procs  # a worker was forked
    for k in range(40):
        pool.result(k)
    print("finished")
except RuntimeError as exc:
    print(exc)
finally:
    pool.shutdown(kill=True)
"""


def test_a_worker_killed_holding_the_pools_lock_fails_the_run():
    """A worker killed (OOM killer, a user's kill) while it holds the pool's shared lock: the
    run fails with that instead of waiting for the lock for ever (in a process of its own,
    which would hang without the fix)."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", KILLED_HOLDING_SCENARIO], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "a quilting worker process ended while a shared lock was held"


CALLER_KILLED_HOLDING_SCENARIO = """
import os, signal, sys, time
import numpy as np
from engine.quilting.workers import WorkerPool, share

parent = os.getpid()
locked = share(np.zeros(1, np.int8))  # set once this process holds the pool's lock

def run(k):  # the worker's task ends once this process holds the lock (a margin of 60 s)
    t0 = time.monotonic()
    while os.getpid() != parent and not locked[0] and time.monotonic() - t0 < 60:
        time.sleep(0.01)
    return k

pool = WorkerPool(run, lambda k: k, [[] for _ in range(40)], 2)
with open(sys.argv[1], "w") as f:
    f.write(" ".join(str(proc.pid) for proc in pool.procs))
pool.lock.acquire()  # killed inside a critical section: the lock stays held
locked[0] = 1
os.kill(os.getpid(), signal.SIGKILL)
"""


def _ended(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] == b"Z"
    except OSError:
        return True


def test_workers_end_when_their_caller_is_killed_holding_the_pools_lock(tmp_path):
    """The calling process killed while it holds the pool's shared lock: its workers, waiting
    for that lock, end (they check that the caller lives) instead of waiting for ever."""
    import signal
    import subprocess
    import sys
    import time

    if not os.path.isdir("/proc"):
        pytest.skip("needs /proc to see the workers end")
    listed, err = tmp_path / "pids", tmp_path / "stderr"
    with open(err, "wb") as f:  # not a pipe: a worker left waiting would hold it open
        out = subprocess.run(
            [sys.executable, "-c", CALLER_KILLED_HOLDING_SCENARIO, str(listed)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=f,
            timeout=120,
        )
    assert out.returncode == -signal.SIGKILL, err.read_text()
    pids = [int(p) for p in listed.read_text().split()]
    assert pids  # a worker was forked
    t0 = time.monotonic()
    try:
        while not all(_ended(p) for p in pids) and time.monotonic() - t0 < 60:  # a margin
            time.sleep(0.05)
        assert all(_ended(p) for p in pids), "a worker still waits for the dead caller's lock"
    finally:
        for p in pids:
            if not _ended(p):
                os.kill(p, signal.SIGKILL)


def test_workers_collect_garbage_when_the_caller_has_automatic_collection_off(tmp_path):
    """The editor turns automatic collection off (it collects in its GUI thread): the forked
    workers, which have no GUI thread, must collect their own cycles."""
    caller, marker = os.getpid(), tmp_path / "a worker ran"

    def run(k):
        if os.getpid() != caller:
            marker.write_text(str(gc.isenabled()))
        else:  # the caller waits for a worker's task (2 min at most): no race
            _poll(marker.exists, 120)
        return k

    was = gc.isenabled()
    gc.disable()
    try:
        pool = workers.WorkerPool(run, lambda k: k, [[] for _ in range(4)], 2)
        try:
            assert pool.procs  # a worker was forked
            assert [pool.result(k) for k in range(4)] == [0, 1, 2, 3]
        finally:
            pool.shutdown()
    finally:
        if was:
            gc.enable()
    assert marker.read_text() == "True"


def _faults() -> int:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


PAGES = 2048  # 8 MB of 4 kB pages


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="MADV_POPULATE_WRITE")
def test_workers_map_the_shared_memory_at_their_start():
    """A forked worker inherits no page table entries of shared mappings: without mapping the
    pool's shared arrays at its start it faults on every page it touches (the canvas, its mask
    and the rings are new in every run)."""
    a = workers.share(np.zeros(PAGES * 4096, np.uint8))
    parent = os.getpid()

    def run(k):
        before = _faults()
        a[k::4096] = 1
        return os.getpid(), _faults() - before

    pool = workers.WorkerPool(run, lambda r: r, [[]], 2, shared=[a])
    try:
        _poll(lambda: pool.state[0] == workers.TAKEN)  # taken by the worker
        pid, faults = pool.result(0)
    finally:
        pool.shutdown(kill=True)
    assert pid != parent
    assert faults < PAGES // 4
    assert a[::4096].all()


def test_the_heap_is_trimmed_before_the_workers_fork(monkeypatch):
    """After the fork every page is shared copy-on-write: the heap's free pages are given back
    first (a reused one would cost a fault and a copy in the process that writes it)."""
    made, workers_then = [], []
    real = workers._trim_heap

    def trim():
        workers_then.append(len(made[-1].procs))
        real()

    monkeypatch.setattr(workers, "_trim_heap", trim)

    class Pool(workers.WorkerPool):
        def __init__(self, *args, **kwargs):
            made.append(self)
            super().__init__(*args, **kwargs)

    pool = Pool(lambda k: k, lambda k: k, [[] for _ in range(4)], 2)
    try:
        assert [pool.result(k) for k in range(4)] == [0, 1, 2, 3]
        assert pool.procs
    finally:
        pool.shutdown()
    assert workers_then == [0]  # once, before any worker
