"""The order in which quilting places its blocks, and the threads that search ahead.

Every block draws from its own generator seeded by (seed, block index). A block depends on the
earlier blocks (in raster order) whose footprints it touches; its *level* is one more than
theirs, and blocks are placed in (level, raster) order, which gives exactly the raster result
(blocks of one level neither read nor write each other's pixels). A block's search needs only
its predecessors placed, so with ``threads > 1`` the searches (FFTs and numba kernels, which
release the GIL) run ahead on a pool while blocks are placed — in worker processes sharing the
canvas where the per-block Python glue would hold the GIL too long for threads
(:func:`uses_processes`, :mod:`engine.quilting.workers`). Each block is searched alone on
exactly the canvas its predecessors left: the output is identical for any number of threads.
"""

from __future__ import annotations

import itertools
import threading
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from engine import _jit as jit
from engine.cancel import check
from engine.events import Progress
from engine.quilting import workers
from engine.quilting.block_rng import BlockRng
from engine.quilting.core import BlockWork, Quilter
from engine.quilting.records import BlockPlaced, BlockRecord

__all__ = ["POOL_MIN_SAMPLE_AREA", "PROCESS_BATCH", "dependencies", "run_levels", "uses_processes"]


def dependencies(rects, shape, torus: bool):
    """Predecessors and level of each rect (y, x, h, w), given in raster order.

    The predecessors of a block are the last earlier blocks written under its footprint (the
    earlier writers of those pixels precede them in turn); its level is one more than theirs.
    Blocks of one level neither read nor write each other's pixels. The canvas is cut into
    cells at every block edge, so each footprint is a set of whole cells.
    """
    cells = [
        _axis_cells([(r[a], r[a + 2]) for r in rects], n, torus)
        for a, n in ((0, shape[0]), (1, shape[1]))
    ]
    (ry, ny), (rx, nx) = cells
    last = [[-1] * nx for _ in range(ny)]  # lists: a block's few cells without numpy's calls
    preds, levels = [], []
    for k, (y, x, h, w) in enumerate(rects):
        cy, cx = ry[y, h], rx[x, w]
        rows = [last[r] for r in cy]
        p = sorted({row[c] for row in rows for c in cx} - {-1})
        preds.append(p)
        levels.append(1 + max((levels[j] for j in p), default=-1))
        for row in rows:
            for c in cx:
                row[c] = k
    return preds, levels


def _axis_cells(spans, n: int, torus: bool):
    """Cells of one canvas axis of length ``n`` cut at the ends of every span (start, length),
    and the cells each span covers (wrapping around on a torus; a range or a list of cell
    numbers): ({span: cells}, count)."""
    cuts = sorted({0, n} | {s % n for s, _ in spans} | {(s + k) % n for s, k in spans})
    cell_of = np.searchsorted(cuts, np.arange(n), side="right") - 1
    covered = {}
    for s, k in set(spans):
        if not torus and s + k > n:
            raise AssertionError("block outside a non-tileable canvas")
        if s + k <= n:  # no wrap: a run of cells
            covered[s, k] = range(int(cell_of[s]), int(cell_of[s + k - 1]) + 1)
        else:
            covered[s, k] = np.unique(cell_of[np.arange(s, s + k) % n]).tolist()
    return covered, len(cuts) - 1


POOL_MIN_SAMPLE_AREA = 200 * 200
"""Below this sample area a block's search is so cheap that handing blocks to other threads
costs more than it saves: such runs stay on one thread (same result either way)."""

BATCH_MAX_SAMPLE_AREA = 512 * 512
"""Up to this sample area, consecutive blocks of one level are searched together (up to
:data:`BATCH` per FFT call: the calls' overhead exceeds the transforms of a small sample); above
it one by one (batched transforms of a large sample only thrash the cache)."""

BATCH = 3
"""Blocks per batch on samples between :data:`POOL_MIN_SAMPLE_AREA` and
:data:`BATCH_MAX_SAMPLE_AREA` on more than one thread (one thread: one block per batch, but
see below). Such
batches search each block alone (:attr:`Quilter.alone`: ducc0's batched transforms differ in the
last bits with the batch, so the output would otherwise depend on the batches and so on the
threads). Batches chain level by level, so larger ones lengthen the run's critical path on two
threads (a unit-cost schedule of job B's 676 blocks: 1.99x one thread with batches of 1, 1.90x
with 3, 1.83x with 4, 1.65x with 6). Job B on one thread, measured in session 6 under load:
blocks one by one 1.15x faster than batches of 3 searched together; on two threads batches of 3
searched block by block 1.05x faster than searched together. The fast (principal components)
search takes batches of 3 on one thread too: its blocks' estimates share one pass over its
index (:func:`engine.matching._estimates`), and its results do not depend on the batch."""

PROCESS_BATCH = 2
"""Blocks per task in worker processes (:func:`uses_processes`; each block searched alone, so
the same records as one thread's one block per task). Job B exact, 2 workers, 12 interleaved
rounds under load 10-11 (other engineers' runs at nice 15, this at nice -10): 1 block a task
0.399 s, 2 blocks 0.341 s, 3 blocks 0.346 s, 4 blocks 0.349 s (one thread 0.572 s): a task's
bookkeeping (taking it, releasing its dependents, its message) costs each process ~70 us, and
a process that places two neighbours in a row finds the canvas between them in its cache;
larger tasks lengthen the chain of levels."""

BATCH_ONE_THREAD = 8
"""Batch size below :data:`POOL_MIN_SAMPLE_AREA` (one thread whatever ``threads`` says): fewer,
larger FFT calls (job A: ~5 % faster than batches of 4; the same result)."""


def run_levels(q: Quilter, rects, total_label: str):
    """Place ``rects`` (top-level blocks, raster order); yields events, returns the records.

    Blocks go in level order (level, then raster index), in fixed batches of consecutive blocks
    of one level (:data:`BATCH`, one on one thread, :data:`PROCESS_BATCH` in worker processes;
    :data:`BATCH_ONE_THREAD` on small samples, one on large ones; where the batches depend on
    the threads, each block is searched alone). A
    batch is loaded (the canvas under it read), searched and placed as one task as soon as its
    blocks' predecessors are placed; with ``threads > 1`` the tasks run on a pool (FFTs and numba
    kernels release the GIL), and blocks of one level are placed side by side (their footprints
    are disjoint). Records and events come out in level order whatever the number of threads,
    every block sees exactly the canvas its predecessors left and draws from its own generator,
    and a block's search does not depend on the batch it is in: the result does not depend on
    the number of threads.
    """
    area = q.sample.shape[0] * q.sample.shape[1]
    # each block's search a query of its own: ducc0's batched transforms differ in the last
    # bits with the batch, so only then may the batches depend on the threads (known before
    # prepare: the colour bound serves only such searches)
    q.alone = area >= POOL_MIN_SAMPLE_AREA
    q.prepare()  # shared search structures, built once before any thread reads them
    preds, levels = dependencies(rects, q.out_shape, q.tileable)
    order = sorted(range(len(rects)), key=lambda k: (levels[k], k))
    size = BATCH if area >= POOL_MIN_SAMPLE_AREA else BATCH_ONE_THREAD
    processes = q.threads > 1 and uses_processes(q)
    if area >= POOL_MIN_SAMPLE_AREA:
        if q.threads == 1 and q.plan.search != "pca":
            size = 1  # the fast search's batches share a pass over its index (BATCH)
        elif processes:
            size = PROCESS_BATCH
    if area > BATCH_MAX_SAMPLE_AREA:
        size = 1
    batches: list[list[int]] = []
    for k in order:
        if batches and len(batches[-1]) < size and levels[batches[-1][0]] == levels[k]:
            batches[-1].append(k)
        else:
            batches.append([k])
    batch_of = {k: b for b, members in enumerate(batches) for k in members}
    needs = [sorted({batch_of[j] for k in members for j in preds[k]}) for members in batches]

    def run(b: int):
        rng = BlockRng if jit.loaded() else _default_rng  # the same generators
        works = [BlockWork(k, *rects[k], rng=rng(q.seed, k)) for k in batches[b]]
        return q.run_batch(works)

    if processes:
        q.canvas, q.filled = workers.share(q.canvas), workers.share(q.filled)
        # the first blocks run here until one with a top and a left arm is placed: the numba
        # kernels of every common block are then loaded before the fork (else every worker
        # would load them again, in every run)
        head = []
        while len(head) < len(batches) and not any(
            rec.arms[0] and rec.arms[1] for out in head for rec, _ in out
        ):
            head.append(run(len(head)))

        placed = workers.WorkerPool(
            run,
            workers.unpack_records,
            needs,
            q.threads,
            q.cancel,
            done=len(head),
            pack=workers.pack_records,
            shared=(q.canvas, q.filled),
        )
        outcomes = itertools.chain(head, (placed.result(b) for b in range(len(head), len(batches))))
    elif q.threads > 1 and area >= POOL_MIN_SAMPLE_AREA:
        placed = _DependencyPool(run, needs, q.threads)
        outcomes = (placed.result(b) for b in range(len(batches)))
    else:
        placed = None
        outcomes = (run(b) for b in range(len(batches)))
    records: list[BlockRecord] = []
    done = 0
    try:
        for b, out in enumerate(outcomes):
            check(q.cancel)
            for rec, pixels in out:
                # numbered here, in level order, before anyone else sees the record
                object.__setattr__(rec, "index", len(records))
                records.append(rec)
                if q.stream:
                    yield BlockPlaced(rec, pixels)
            done += len(batches[b])
            last = b + 1 == len(batches) or levels[batches[b + 1][0]] != levels[batches[b][0]]
            if q.stream and last:
                yield Progress(done, len(rects), total_label)
    finally:
        if placed is not None:
            placed.shutdown()
    return records


def uses_processes(q: Quilter) -> bool:
    """Whether a run on more than one thread places its blocks in worker processes
    (:mod:`engine.quilting.workers`) rather than threads: the whole-sample exact search and
    the fast (principal components) search of quilting (not transfer) on samples between
    :data:`POOL_MIN_SAMPLE_AREA` and :data:`BATCH_MAX_SAMPLE_AREA`, where a block's Python glue
    holds the GIL for about a third of its time (larger samples' transforms release the GIL
    long enough for threads), on a system with ``fork``. Same records and image either way
    (every block is searched alone, whether a task holds one block, on one thread, or
    :data:`PROCESS_BATCH` blocks, on workers). Job B fast, interleaved with
    threads under load 9-10: 2 threads 0.461 s (slower than one, 0.422 s), 2 workers 0.307 s."""
    area = q.sample.shape[0] * q.sample.shape[1]
    return (
        q.worker_processes
        and q.select == "best"
        and q.plan.search in ("fft", "pca")
        and q.origin is None
        and POOL_MIN_SAMPLE_AREA <= area <= BATCH_MAX_SAMPLE_AREA
        and workers.available()
    )


def _default_rng(seed: int, index: int) -> np.random.Generator:
    return np.random.default_rng([seed, index])


class _DependencyPool:
    """Runs ``run(task)`` for every task on ``threads`` workers, each as soon as the tasks it
    ``needs`` have run; :meth:`result` waits for one task's result."""

    def __init__(self, run, needs, threads: int):
        self.run = run
        self.done = [Future() for _ in needs]
        self.waiting = [len(p) for p in needs]
        self.dependents = [[] for _ in needs]
        for k, p in enumerate(needs):
            for j in p:
                self.dependents[j].append(k)
        self.lock = threading.Lock()
        self.stopped = False
        self.pool = ThreadPoolExecutor(threads)
        for k in [k for k, n in enumerate(self.waiting) if not n]:  # before any task runs
            self.pool.submit(self._run, k)

    def _run(self, k: int) -> None:
        if self.stopped:
            return
        try:
            self.done[k].set_result(self.run(k))
        except BaseException as exc:  # handed to the consumer by result()
            self.done[k].set_exception(exc)
            return
        ready = []
        with self.lock:
            for d in self.dependents[k]:
                self.waiting[d] -= 1
                if not self.waiting[d]:
                    ready.append(d)
            for d in ready:
                if not self.stopped:
                    self.pool.submit(self._run, d)

    def result(self, k: int):
        return self.done[k].result()

    def shutdown(self) -> None:
        with self.lock:
            self.stopped = True
        self.pool.shutdown(wait=True, cancel_futures=True)
