"""Bhatia's minimum resistance cut line as a top-to-bottom walk (ALGORITHMS §4).

From the start pixel the walk repeatedly steps to the cheapest allowed neighbour among down,
down-left, down-right, left and right (never up). A step's cost is the error of the pixel
stepped on, or, given the new block's colours ``image``, the colour distance between the two
pixels (Bhatia's intra-block step; ALGORITHMS §4 makes that the default and the error the
option: the error map is all a seam method is given, so here it is the default). Allowed:
inside the map, not visited before, no more than ``max_run`` consecutive pixels in one row or
one column, and — towards a pinned point (end or waypoint) — inside the cone of pixels from
which it stays reachable. When nothing is allowed the
walk steps down (diagonally towards a pinned point when the cone demands it). The walk ends on
reaching the bottom row, or the pinned end point.

One walk from the top row down, not §4's two lines from the block's corners that meet: an
overlap strip's ends are free, so nothing has to meet; ``start`` / ``end`` pin a corner-to-corner
cut (as :mod:`engine.quilting` does for Bhatia's blocks).
"""

from __future__ import annotations

import numpy as np
from numba import njit

_DR = np.array([1, 1, 1, 0, 0], dtype=np.int64)
_DC = np.array([0, -1, 1, -1, 1], dtype=np.int64)


@njit(cache=True, nogil=True)
def _step_cost(error, image, use_image, r, c, nr, nc):
    if not use_image:
        return error[nr, nc]
    s = 0.0
    for k in range(image.shape[2]):
        d = image[nr, nc, k] - image[r, c, k]
        s += d * d
    return np.sqrt(s)


@njit(cache=True, nogil=True)
def _walk(error, image, use_image, start, trow, tcol, max_run, path):
    """Walk through the targets (trow[k], tcol[k]); tcol = -1 means any pixel of that row.

    ``start`` < 0 picks the cheapest pixel of row 0 inside the first target's cone.
    Writes the pixels to ``path`` and returns their number.
    """
    h, w = error.shape
    visited = np.zeros((h, w), dtype=np.bool_)
    r = 0
    c = start
    if c < 0:
        best = np.inf
        for i in range(w):
            if tcol[0] >= 0 and abs(i - tcol[0]) > trow[0]:
                continue
            if error[0, i] < best:
                best = error[0, i]
                c = i
    n = 0
    path[n, 0] = r
    path[n, 1] = c
    n += 1
    visited[r, c] = True
    row_run = 1
    col_run = 1
    for k in range(trow.shape[0]):
        tr = trow[k]
        tc = tcol[k]
        while not (r == tr and (tc < 0 or c == tc)):
            best = np.inf
            pick = -1
            for d in range(5):
                nr = r + _DR[d]
                nc = c + _DC[d]
                if nr > tr or nc < 0 or nc >= w or visited[nr, nc]:
                    continue
                rr = row_run + 1 if _DR[d] == 0 else 1
                cr = col_run + 1 if _DC[d] == 0 else 1
                if rr > max_run or cr > max_run:
                    continue
                outside = tc >= 0 and (tr - nr) < abs(nc - tc)
                # outside the target's cone only a sideways step that gets closer is allowed
                if outside and not (_DR[d] == 0 and abs(nc - tc) < abs(c - tc)):
                    continue
                v = _step_cost(error, image, use_image, r, c, nr, nc)
                if v < best:
                    best = v
                    pick = d
            if pick >= 0:
                nr = r + _DR[pick]
                nc = c + _DC[pick]
            elif r < tr:
                nr = r + 1
                nc = c
                if tc >= 0 and (tr - nr) < abs(tc - c):
                    nc = c + (1 if tc > c else -1)
            else:
                nr = r
                nc = c + (1 if tc > c else -1)
            if nr == r:
                row_run += 1
                col_run = 1
            elif nc == c:
                col_run += 1
                row_run = 1
            else:
                row_run = 1
                col_run = 1
            r = nr
            c = nc
            visited[r, c] = True
            path[n, 0] = r
            path[n, 1] = c
            n += 1
    return n


_NO_IMAGE = np.zeros((1, 1, 1))


def resistance_path(error: np.ndarray, pins: np.ndarray, *, max_run: int, image=None):
    """The walk's pixels ((N, 2) intp, top to bottom) honouring the pinned rows of ``pins``."""
    h, w = error.shape
    trow = np.flatnonzero(pins[1:] >= 0) + 1  # pinned rows below the top, in order
    tcol = pins[trow]
    if pins[h - 1] < 0 or h == 1:  # end free: stop anywhere in the bottom row
        trow, tcol = np.append(trow, h - 1), np.append(tcol, -1)
    start = int(pins[0])
    use_image = image is not None
    img = _NO_IMAGE if image is None else image
    path = np.empty((h * w, 2), dtype=np.int64)
    n = _walk(
        error, img, use_image, start, trow.astype(np.int64), tcol.astype(np.int64), max_run, path
    )
    return path[:n].copy()
