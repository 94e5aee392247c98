"""Where quilting's blocks go: the block grid (plain or on a torus) and a block's overlap arms.

ALGORITHMS §2.2 layout: blocks of ``block`` pixels with a step of ``block - overlap``; per axis
``ceil((N - overlap) / step)`` blocks, the last ones cropped. A tileable output places
``ceil(N / step)`` evenly spaced blocks on a torus.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "arms_of",
    "axis_positions",
    "canvas_index",
    "check_torus_axis",
    "grid_rects",
    "torus_fits",
    "torus_overlap",
]


def axis_positions(n_out: int, block: int, overlap: int, tileable: bool) -> list[int]:
    """Block offsets along one axis (ALGORITHMS §2.2 layout, or evenly spaced on a torus)."""
    step = block - overlap
    if not tileable:
        n = max(1, math.ceil((n_out - overlap) / step))
        return [i * step for i in range(n)]
    n = max(2, math.ceil(n_out / step))
    return [(i * n_out) // n for i in range(n)]


def grid_rects(out_shape, block, overlap: int, tileable: bool) -> list[tuple[int, int, int, int]]:
    """(y, x, h, w) of every block of the quilting grid in raster order (cropped at the
    output's edges unless ``tileable``)."""
    (ho, wo), (bh, bw) = out_shape, block
    rects = []
    for y in axis_positions(ho, bh, overlap, tileable):
        for x in axis_positions(wo, bw, overlap, tileable):
            h = bh if tileable else min(bh, ho - y)
            w = bw if tileable else min(bw, wo - x)
            rects.append((y, x, h, w))
    return rects


def torus_fits(n_out: int, block: int, overlap: int) -> bool:
    """Evenly spaced blocks on a torus: each overlaps its two neighbours and no further one."""
    spacing = np.diff([*axis_positions(n_out, block, overlap, True), n_out])
    return block < n_out and spacing.max() < block and 2 * spacing.min() > block


def torus_overlap(n_out: int, block: int, overlap: int) -> int:
    """The largest overlap <= ``overlap`` that fits a tileable axis (``overlap`` if none does)."""
    return next((o for o in range(overlap, -1, -1) if torus_fits(n_out, block, o)), overlap)


def check_torus_axis(n_out: int, block: int, overlap: int, axis: str) -> None:
    """Raise a ValueError that says what to change if a tileable axis does not fit."""
    if torus_fits(n_out, block, overlap):
        return
    if block < n_out and (fitting := torus_overlap(n_out, block, overlap)) != overlap:
        raise ValueError(
            f"a tileable output {axis} of {n_out} px with blocks of {block} px and overlap "
            f"{overlap} puts blocks half a block or less apart (each would overlap more than its "
            f"two neighbours): use an overlap of at most {fitting}"
        )
    raise ValueError(
        f"a tileable output {axis} of {n_out} px does not fit blocks of {block} px with "
        f"overlap {overlap}: choose an output {axis} of at least {2 * block} px"
    )


def canvas_index(y, x, h, w, shape, torus):
    """Index of the canvas pixels under a block (wrapping around on a torus)."""
    H, W = shape
    if y + h <= H and x + w <= W:
        return slice(y, y + h), slice(x, x + w)
    if not torus:
        raise AssertionError("block outside a non-tileable canvas")
    return np.ix_(np.arange(y, y + h) % H, np.arange(x, x + w) % W)


def arms_of(filled: np.ndarray) -> tuple[int, int, int, int]:
    """(top, left, bottom, right) widths of the fully filled strips at a block's edges."""
    h, w = filled.shape
    rows = filled.all(axis=1)
    cols = filled.all(axis=0)
    if rows.all():  # the whole block (then every column is full too)
        return h, w, 0, 0
    t, left = int(rows.argmin()), int(cols.argmin()) if not cols.all() else w
    b = int(rows[::-1].argmin())
    r = int(cols[::-1].argmin()) if left < w else 0
    return t, left, b, r
