"""The old side of a dp L-cut (:func:`engine.stitch.l_cut`), filled over the L only."""

from __future__ import annotations

import numpy as np

from engine._jit import njit

__all__ = ["old_side_of_l_cut", "spread"]


@njit(cache=True, nogil=True)
def spread(state, stack, n, fill):  # pragma: no cover - compiled
    """Flood ``fill`` from the ``n`` pixels on ``stack`` (flat indices) over the 4-connected
    unvisited (0) pixels of ``state``: one step of the cut-side fills here and in
    ``engine.stitch``."""
    h, w = state.shape
    while n:
        n -= 1
        r, c = divmod(stack[n], w)
        for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= rr < h and 0 <= cc < w and state[rr, cc] == 0:
                state[rr, cc] = fill
                stack[n] = rr * w + cc
                n += 1


@njit(cache=True, nogil=True)
def old_side_of_l_cut(barrier, ovl, ovt):  # pragma: no cover - compiled
    """The old side of an L-cut's barrier as ``engine.stitch._old_side_of_barrier`` (both
    edges seeded) gives it, filling the L only (a third of a 48² block's pixels).

    The cut runs inside the L (``ovt`` top rows, ``ovl`` left columns) from the bottom edge to
    the right edge, and a 4-connected fill does not cross an 8-connected path: the old side
    stays in the L, and the rest of the block is new. So the interior is new at once, and an L
    pixel is new when it connects to the border or to the interior (its pixels next to the
    interior are seeds too); the same regions as the fill over the whole block."""
    h, w = barrier.shape
    state = np.zeros((h, w), np.uint8)  # 0 unvisited, 1 barrier, 2 old side, 3 new side
    for r in range(ovt, h):
        for c in range(ovl, w):
            state[r, c] = 3
    for r in range(h):
        for c in range(w if r < ovt else ovl):
            if barrier[r, c]:
                state[r, c] = 1
    stack = np.empty(h * w, np.int64)
    for fill in (2, 3):
        n = 0
        for r in range(h):
            for c in range(w if r < ovt else ovl):
                if state[r, c] != 0:
                    continue
                if fill == 2:
                    seed = c == 0 or r == 0
                else:
                    seed = (
                        r == 0
                        or c == 0
                        or r == h - 1
                        or c == w - 1
                        or (r >= ovt and c == ovl - 1)
                        or (r == ovt - 1 and c >= ovl)
                    )
                if seed:
                    state[r, c] = fill
                    stack[n] = r * w + c
                    n += 1
        spread(state, stack, n, fill)
    return state != 3
