"""numpy twins of :mod:`engine.stitch`'s dp kernels, for small jobs that should load no numba.

A whole ``quilt-studio synth`` process of a few hundred small blocks spends longer starting
numba (~0.6 s: the import and its first call) than cutting every overlap with these. Each
function returns exactly what its numba kernel returns (the same float64 sums in the same
order, the same tie-breaking), so a caller may take either; ``tests/engine/test_stitch_numpy.py``
checks them against the kernels on random maps. :func:`engine.stitch.l_cut` takes them while
:func:`engine._jit.loaded` is false and the block is small (:data:`SMALL_CUT_PIXELS`), and
:meth:`engine.quilting.core.Quilter.precut` cuts a batch of blocks in one pass (:func:`dp_l_cuts`).
"""

from __future__ import annotations

import numpy as np

from engine import _jit as jit

__all__ = [
    "NUMBA_BLOCKS",
    "SMALL_CUT_PIXELS",
    "dp_l_cut",
    "dp_l_cuts",
    "dp_to_bottom",
    "old_side_of_barrier",
    "trace_down",
    "use_numba_for",
]

SMALL_CUT_PIXELS = 64 * 64
"""Largest block (pixels) cut with numpy while numba is not loaded: ~0.3 ms per 32² block here
(numba's kernels: ~0.02 ms, after ~0.6 s of start-up)."""

NUMBA_BLOCKS = 1000
"""A quilting or transfer run of more blocks loads numba before it starts (:func:`use_numba_for`):
over that many cuts its kernels repay their start-up."""


def use_numba_for(blocks: int) -> None:
    """Load numba now when a run will cut more than :data:`NUMBA_BLOCKS` blocks (the results
    are the same either way; only the time differs)."""
    if blocks > NUMBA_BLOCKS:
        jit.load()


def dp_to_bottom(e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``cost[..., j, i]``: cheapest one-pixel-per-row 8-connected path from (j, i) to the last
    row, and ``step`` (-1, 0, 1) to the next row; for one map (h, w) or a stack (..., h, w).
    The straight step wins ties, then the left one (as ``engine.stitch._dp_to_bottom``).

    Only the sums run row by row (the least of three neighbours is the same value whichever
    wins a tie); the steps are read off the finished table at once."""
    h, w = e.shape[-2:]
    padded = np.full((*e.shape[:-1], w + 2), np.inf)  # inf columns: no step leaves the map
    cost = padded[..., 1:-1]
    cost[..., h - 1, :] = e[..., h - 1, :]
    best = np.empty((*e.shape[:-2], w))
    for j in range(h - 2, -1, -1):
        below = padded[..., j + 1, :]
        np.minimum(below[..., :-2], below[..., 1:-1], out=best)
        np.minimum(best, below[..., 2:], out=best)
        np.add(e[..., j, :], best, out=cost[..., j, :])
    below = padded[..., 1:, :]
    left, straight, right = below[..., :-2], below[..., 1:-1], below[..., 2:]
    go_left = left < straight
    go_right = right < np.where(go_left, left, straight)
    step = np.zeros(e.shape, np.int8)
    step[..., :-1, :] = go_right
    step[..., :-1, :] -= go_left & ~go_right
    return np.ascontiguousarray(cost), step


def trace_down(step: np.ndarray, r: int, c: int) -> np.ndarray:
    """Columns of the dp path from (r, c) down to the last row (rows r .. h - 1)."""
    rows = step[r:-1].tolist()
    cols = [c]
    for row in rows:
        c += row[c]
        cols.append(c)
    return np.array(cols, np.intp)


def dp_l_cuts(errors: np.ndarray, ovl: int, ovt: int) -> list[tuple]:
    """:func:`dp_l_cut` of a stack of equally shaped float64 maps (n, bh, bw) at once: the row
    by row sums and the flood fills run once for the whole stack (a batch of quilting blocks).

    Each map's two arms are stacked for one :func:`dp_to_bottom` pass: the left strip and the
    transposed top strip, the shorter one padded with rows above it and both with ``inf``
    columns on the right, which no path ever takes. Returns one (path, old side, qr, qc) per
    map."""
    nb, bh, bw = errors.shape
    n, m = max(bh, bw), max(ovl, ovt)
    arms = np.full((nb, 2, n, m), np.inf)
    arms[:, 0, n - bh :, :ovl] = errors[:, :, :ovl]
    arms[:, 1, n - bw :, :ovt] = errors[:, :ovt].transpose(0, 2, 1)
    cost, step = dp_to_bottom(arms)
    v_cost, v_step = cost[:, 0, n - bh :, :ovl], step[:, 0, n - bh :, :ovl]
    h_cost, h_step = cost[:, 1, n - bw :, :ovt], step[:, 1, n - bw :, :ovt]
    # where the arms join: the first (row-major) corner pixel of least E_v + E_h - e
    joint = v_cost[:, :ovt] + h_cost[:, :ovl].transpose(0, 2, 1) - errors[:, :ovt, :ovl]
    meets = np.argmin(joint.reshape(nb, -1), axis=1)
    barriers = np.zeros((nb, bh, bw), bool)
    paths, corners = [], []
    for b in range(nb):
        qr, qc = divmod(int(meets[b]), ovl)
        down = trace_down(v_step[b], qr, qc)  # columns of rows qr .. bh - 1
        right = trace_down(h_step[b], qc, qr)  # rows of columns qc .. bw - 1
        # up the left arm to q, then right along the top arm, each pixel once (first visit)
        rows = np.concatenate([np.arange(bh - 1, qr - 1, -1), right])
        cols = np.concatenate([down[::-1], np.arange(qc, bw)])
        flat = rows * bw + cols
        _, first = np.unique(flat, return_index=True)
        first.sort()
        paths.append(np.column_stack([rows[first], cols[first]]).astype(np.intp))
        corners.append((qr, qc))
        barriers[b].flat[flat] = True
    olds = old_side_of_barrier(barriers, True, True)
    return [(p, o, qr, qc) for p, o, (qr, qc) in zip(paths, olds, corners, strict=True)]


def dp_l_cut(e: np.ndarray, ovl: int, ovt: int):
    """The dp L-cut of an (bh, bw) float64 error map with both arms: path, old side, meeting
    point (as ``engine.stitch._dp_l_cut``: up the left arm to the corner pixel q of least
    ``E_v(q) + E_h(q) - e(q)``, then right along the top arm, each pixel once)."""
    return dp_l_cuts(e[None], ovl, ovt)[0]


def _fill(free: np.ndarray, seeds: np.ndarray) -> np.ndarray:
    """Every pixel of ``free`` (..., h, w) 4-connected to ``seeds`` within ``free``, per map (a
    flood fill by whole runs: a row sweep, then a column sweep, until neither adds a pixel)."""
    *lead, h, w = free.shape
    k = int(np.prod(lead, dtype=np.int64))
    wall = ~free
    row_run = np.cumsum(wall, axis=-1) + (w + 1) * np.arange(k * h).reshape(*lead, h, 1)
    col_run = np.cumsum(wall, axis=-2) + (h + 1) * np.arange(k * w).reshape(*lead, 1, w)
    region = seeds & free
    n = int(region.sum())
    while True:
        for run, size in ((row_run, k * h * (w + 1)), (col_run, k * w * (h + 1))):
            hit = np.zeros(size, bool)
            hit[run[region]] = True
            region = hit[run] & free
        grown = int(region.sum())
        if grown == n:
            return region
        n = grown


def old_side_of_barrier(barrier: np.ndarray, seed_left: bool, seed_top: bool) -> np.ndarray:
    """Old region of a cut given as a barrier (h, w) bool, or of a stack of them (..., h, w)
    (as ``engine.stitch._old_side_of_barrier``): the barrier, every pixel 4-connected to the
    left (``seed_left``) or top (``seed_top``) edge without crossing it, and every pocket of the
    rest not 4-connected to the block's border."""
    edge = np.zeros(barrier.shape, bool)
    if seed_left:
        edge[..., :, 0] = True
    if seed_top:
        edge[..., 0, :] = True
    free = ~barrier
    old = _fill(free, edge)
    border = np.zeros(barrier.shape, bool)
    border[..., [0, -1], :] = True
    border[..., :, [0, -1]] = True
    return ~_fill(free & ~old, border)
