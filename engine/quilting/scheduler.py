"""The order in which quilting places its blocks, and the threads that search ahead.

Every block draws from its own generator seeded by (seed, block index). A block depends on the
earlier blocks (in raster order) whose footprints it touches; its *level* is one more than
theirs, and blocks are placed in (level, raster) order, which gives exactly the raster result
(blocks of one level neither read nor write each other's pixels). A block's search needs only
its predecessors placed, so with ``threads > 1`` the searches (FFTs and numba kernels, which
release the GIL) run ahead on a pool while blocks are placed. Each block is searched alone on
exactly the canvas its predecessors left: the output is identical for any number of threads.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from engine.cancel import check
from engine.events import Progress
from engine.quilting.core import BlockWork, Quilter
from engine.quilting.records import BlockPlaced, BlockRecord

__all__ = ["POOL_MIN_SAMPLE_AREA", "SEARCH_CHUNK", "dependencies", "run_levels"]


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
    last = np.full((ny, nx), -1, dtype=np.int64)
    preds, levels = [], []
    for k, (y, x, h, w) in enumerate(rects):
        idx = np.ix_(ry[y, h], rx[x, w])
        p = sorted({int(v) for v in last[idx].ravel()} - {-1})
        preds.append(p)
        levels.append(1 + max((levels[j] for j in p), default=-1))
        last[idx] = k
    return preds, levels


def _axis_cells(spans, n: int, torus: bool):
    """Cells of one canvas axis of length ``n`` cut at the ends of every span (start, length),
    and the cells each span covers (wrapping around on a torus): ({span: cells}, count)."""
    cuts = sorted({0, n} | {s % n for s, _ in spans} | {(s + k) % n for s, k in spans})
    cell_of = np.searchsorted(cuts, np.arange(n), side="right") - 1
    covered = {}
    for s, k in set(spans):
        if not torus and s + k > n:
            raise AssertionError("block outside a non-tileable canvas")
        covered[s, k] = np.unique(cell_of[np.arange(s, s + k) % n])
    return covered, len(cuts) - 1


POOL_MIN_SAMPLE_AREA = 200 * 200
"""Below this sample area a block's search is so cheap (< 0.1 ms) that handing it to another
thread costs more than it saves: such runs stay on one thread (same result either way)."""


SEARCH_CHUNK = 4
"""Blocks of one level searched in one batch (fixed: batches never depend on the threads)."""


def run_levels(q: Quilter, rects, total_label: str):
    """Place ``rects`` (top-level blocks, raster order); yields events, returns the records.

    Blocks are placed one by one in level order (level, then raster index) and searched in fixed
    batches of up to :data:`SEARCH_CHUNK` consecutive blocks of one level. A batch's search needs
    only its blocks' predecessors placed, so with ``threads > 1`` the searches run ahead on a pool
    (FFTs and numba kernels release the GIL) while this thread places blocks. Every batch is the
    same and sees exactly the canvas its predecessors left whatever the number of threads, and
    every block has its own generator: the result does not depend on the number of threads.
    """
    q.prepare()  # shared search structures, built once before any thread reads them
    preds, levels = dependencies(rects, q.out_shape, q.tileable)
    order = sorted(range(len(rects)), key=lambda k: (levels[k], k))
    works = [BlockWork(k, *r, rng=np.random.default_rng([q.seed, k])) for k, r in enumerate(rects)]
    chunks: list[list[int]] = []
    for k in order:
        if chunks and len(chunks[-1]) < SEARCH_CHUNK and levels[chunks[-1][0]] == levels[k]:
            chunks[-1].append(k)
        else:
            chunks.append([k])
    waiting, dependents = [], [[] for _ in rects]
    for c, members in enumerate(chunks):
        needed = {j for k in members for j in preds[k]}
        waiting.append(len(needed))
        for j in needed:
            dependents[j].append(c)
    heavy = q.sample.shape[0] * q.sample.shape[1] >= POOL_MIN_SAMPLE_AREA
    pool = ThreadPoolExecutor(max(1, q.threads - 1)) if q.threads > 1 and heavy else None
    futures = {}

    def loaded(c):  # the batch's predecessors are placed: read what lies under it now
        batch = [works[k] for k in chunks[c]]
        for wk in batch:
            q.load(wk)
        return batch

    records: list[BlockRecord] = []
    try:
        if pool is not None:
            futures = {
                c: pool.submit(q.search, loaded(c)) for c in range(len(chunks)) if not waiting[c]
            }
        done = 0
        for c, members in enumerate(chunks):
            check(q.cancel)
            if pool is None:
                q.search(loaded(c))
            else:
                futures.pop(c).result()
            for k in members:
                for rec, pixels in q.place(works[k]):
                    rec = replace(rec, index=len(records))
                    records.append(rec)
                    if q.stream:
                        yield BlockPlaced(rec, pixels)
                works[k] = None  # its arrays live on in the records
                for d in dependents[k]:
                    waiting[d] -= 1
                    if not waiting[d] and pool is not None:
                        futures[d] = pool.submit(q.search, loaded(d))
            done += len(members)
            last = c + 1 == len(chunks) or levels[chunks[c + 1][0]] != levels[members[0]]
            if q.stream and last:
                yield Progress(done, len(rects), total_label)
    finally:
        if pool is not None:
            for f in futures.values():
                f.cancel()
            pool.shutdown(wait=True, cancel_futures=True)
    return records
