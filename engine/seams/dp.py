"""Minimum error boundary cut by dynamic programming (Efros & Freeman, ALGORITHMS §2.3).

One pixel per row, 8-connected: ``E[j,i] = e[j,i] + min(E[j-1,i-1..i+1])``, backtracked with
stored argmin pointers. Exact and O(3 w h). Every row may be restricted to a column interval
(``lo[j]..hi[j]``): pinned end points and waypoints are intervals of one column. ``cyclic``
makes rows 0 and h-1 neighbours (``|c_0 - c_{h-1}| <= 1``), solved exactly by fixing c_0 to
each allowed column in turn, cheapest open-path bound first, until the bound exceeds the best
closed cost: O(3 w h) per start tried, O(3 w² h) at worst, a few starts on real overlaps.
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit
from engine.seams._result import Seam, make_seam, mask_from_columns


@njit(cache=True, nogil=True)
def _dp_pass(error, lo, hi, s, back, cols):
    """One DP with row 0 limited to ``lo[0]..hi[0]`` (or to column ``s`` when s >= 0).

    Fills ``back`` (h, w) int8 with the step from the row above (-1, 0, +1) and ``cols`` with
    the optimal path; with s >= 0 the last row is limited to s-1..s+1 (the cyclic closure).
    Returns the path cost (inf when no path satisfies the constraints).
    """
    h, w = error.shape
    inf = np.inf
    cost = np.full(w, inf)
    new = np.empty(w)
    a0, b0 = lo[0], hi[0]
    if s >= 0:
        a0, b0 = s, s
    for i in range(a0, b0 + 1):
        cost[i] = error[0, i]
    for j in range(1, h):
        for i in range(w):
            new[i] = inf
        for i in range(lo[j], hi[j] + 1):
            best = cost[i]
            k = 0
            if i > 0 and cost[i - 1] < best:
                best = cost[i - 1]
                k = -1
            if i + 1 < w and cost[i + 1] < best:
                best = cost[i + 1]
                k = 1
            back[j, i] = k
            new[i] = best + error[j, i]
        cost, new = new, cost
    a, b = lo[h - 1], hi[h - 1]
    if s >= 0:
        a, b = max(a, s - 1), min(b, s + 1)
    best = inf
    arg = -1
    for i in range(a, b + 1):
        if cost[i] < best:
            best = cost[i]
            arg = i
    if arg < 0:
        return inf
    cols[h - 1] = arg
    for j in range(h - 1, 0, -1):
        cols[j - 1] = cols[j] + back[j, cols[j]]
    return best


@njit(cache=True, nogil=True)
def _open_costs(error, lo, hi):
    """Cost of the best path (within the row intervals, open ends) from every column of row 0
    down to the last row: a lower bound of the closed path starting there."""
    h, w = error.shape
    inf = np.inf
    cost = np.full(w, inf)
    new = np.empty(w)
    for i in range(lo[h - 1], hi[h - 1] + 1):
        cost[i] = error[h - 1, i]
    for j in range(h - 2, -1, -1):
        for i in range(w):
            new[i] = inf
        for i in range(lo[j], hi[j] + 1):
            best = cost[i]
            if i > 0 and cost[i - 1] < best:
                best = cost[i - 1]
            if i + 1 < w and cost[i + 1] < best:
                best = cost[i + 1]
            new[i] = best + error[j, i]
        cost, new = new, cost
    return cost


@njit(cache=True, nogil=True)
def _dp_kernel(error, lo, hi, cyclic, cols):
    """Optimal one-pixel-per-row path within the row intervals; returns its cost (or inf).

    Cyclic: one constrained pass per start column s, taken in the order of the open-path
    bound and stopped once the bound exceeds the best closed cost (the same path as trying
    every s in turn: ties go to the smallest s). Usually a few passes instead of w.
    """
    h, w = error.shape
    back = np.zeros((h, w), dtype=np.int8)
    if not cyclic or h == 1:
        return _dp_pass(error, lo, hi, -1, back, cols)
    bound = _open_costs(error, lo, hi)
    starts = np.arange(lo[0], hi[0] + 1)
    starts = starts[np.argsort(bound[lo[0] : hi[0] + 1], kind="mergesort")]
    best = np.inf
    best_s = -1
    for s in starts:
        if bound[s] > best + 1e-9 * abs(best) + 1e-300 or bound[s] == np.inf:
            break  # summation order aside, no later start can beat or tie the best
        c = _dp_pass(error, lo, hi, s, back, cols)
        if c < best or (c == best and s < best_s):
            best = c
            best_s = s
    if best_s < 0:
        return np.inf
    return _dp_pass(error, lo, hi, best_s, back, cols)


def dp_columns(error: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, cyclic: bool = False):
    """Column of the optimal path in every row, or None when the constraints admit no path."""
    h = error.shape[0]
    cols = np.zeros(h, dtype=np.int64)
    cost = _dp_kernel(error, lo, hi, bool(cyclic), cols)
    return None if not np.isfinite(cost) else cols


def dp_seam(error: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, cyclic: bool = False) -> Seam:
    """Minimum error boundary cut within per-row column intervals ``lo..hi`` (validated input)."""
    cols = dp_columns(error, lo, hi, cyclic=cyclic)
    if cols is None:
        raise ValueError(
            "method 'dp': no one-pixel-per-row 8-connected path satisfies start/end/waypoints"
            + (" with cyclic=True" if cyclic else "")
        )
    path = np.column_stack([np.arange(error.shape[0]), cols])
    return make_seam(error, path, "dp", mask_from_columns(cols, error.shape[1]))
