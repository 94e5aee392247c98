"""Minimum error boundary cut by dynamic programming (Efros & Freeman, ALGORITHMS §2.3).

One pixel per row, 8-connected: ``E[j,i] = e[j,i] + min(E[j-1,i-1..i+1])``, backtracked with
stored argmin pointers. Exact and O(3 w h). Every row may be restricted to a column interval
(``lo[j]..hi[j]``): pinned end points and waypoints are intervals of one column. ``cyclic``
makes rows 0 and h-1 neighbours (``|c_0 - c_{h-1}| <= 1``), solved exactly by fixing c_0 to
each allowed column in turn, cheapest open-path bound first, until the bound exceeds the best
closed cost: O(3 w h) per start tried, O(3 w² h) at worst, a few starts on real overlaps.
While numba is not loaded a small map (:data:`SMALL_DP_PIXELS`) takes the kernels' numpy twins
(row by row over the columns: the same sums, the same ties), so a small job starts no numba.
"""

from __future__ import annotations

import numpy as np

from engine import _jit as jit
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


SMALL_DP_PIXELS = 1 << 16
"""Largest map solved by the numpy twins while numba is not loaded (~10 µs a row and pass here;
numba's start-up costs ~0.3-0.6 s)."""


def _down(table, error, lo, hi, rows) -> None:
    """``table[j]`` (w + 2 wide, inf at both ends) from ``table[j ∓ 1]`` for j in ``rows``: the
    least of the three costs next to each column of ``lo..hi`` plus the error (the kernels'
    values: the least of three is the same whichever wins a tie)."""
    for j, p in rows:
        a, b = lo[j], hi[j] + 1
        prev = table[p]
        row = table[j, a + 1 : b + 1]
        np.minimum(prev[a:b], prev[a + 1 : b + 1], out=row)
        np.minimum(row, prev[a + 2 : b + 2], out=row)
        row += error[j, a:b]


def _dp_pass_numpy(error, lo, hi, s, cols) -> float:
    """:func:`_dp_pass` in numpy: the costs row by row, then the path traced back through them
    with the kernel's ties (straight, then left, then right)."""
    h, w = error.shape
    table = np.full((h, w + 2), np.inf)
    a0, b0 = (s, s) if s >= 0 else (lo[0], hi[0])
    table[0, a0 + 1 : b0 + 2] = error[0, a0 : b0 + 1]
    _down(table, error, lo, hi, ((j, j - 1) for j in range(1, h)))
    a, b = lo[h - 1], hi[h - 1]
    if s >= 0:
        a, b = max(a, s - 1), min(b, s + 1)
    last = table[h - 1, a + 1 : b + 2]
    if last.size == 0 or not last.min() < np.inf:
        return np.inf
    i = a + int(np.argmin(last))
    cols[h - 1] = i
    rows = table.tolist()
    for j in range(h - 1, 0, -1):
        prev = rows[j - 1]
        best, k = prev[i + 1], 0
        if prev[i] < best:
            best, k = prev[i], -1
        if prev[i + 2] < best:
            k = 1
        i += k
        cols[j - 1] = i
    return float(last.min())


def _open_costs_numpy(error, lo, hi):
    """:func:`_open_costs` in numpy."""
    h, w = error.shape
    table = np.full((h, w + 2), np.inf)
    table[h - 1, lo[h - 1] + 1 : hi[h - 1] + 2] = error[h - 1, lo[h - 1] : hi[h - 1] + 1]
    _down(table, error, lo, hi, ((j, j + 1) for j in range(h - 2, -1, -1)))
    return table[0, 1:-1]


def _dp_numpy(error, lo, hi, cyclic, cols) -> float:
    """:func:`_dp_kernel` in numpy: the same starts in the same order, the same path."""
    if not cyclic or error.shape[0] == 1:
        return _dp_pass_numpy(error, lo, hi, -1, cols)
    bound = _open_costs_numpy(error, lo, hi)
    starts = np.arange(lo[0], hi[0] + 1)
    starts = starts[np.argsort(bound[lo[0] : hi[0] + 1], kind="mergesort")]
    best, best_s = np.inf, -1
    for s in starts.tolist():
        if bound[s] > best + 1e-9 * abs(best) + 1e-300 or bound[s] == np.inf:
            break
        c = _dp_pass_numpy(error, lo, hi, s, cols)
        if c < best or (c == best and s < best_s):
            best, best_s = c, s
    if best_s < 0:
        return np.inf
    return _dp_pass_numpy(error, lo, hi, best_s, cols)


def dp_columns(error: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, cyclic: bool = False):
    """Column of the optimal path in every row, or None when the constraints admit no path."""
    h = error.shape[0]
    cols = np.zeros(h, dtype=np.int64)
    small = error.size <= SMALL_DP_PIXELS and not jit.loaded()
    cost = (_dp_numpy if small else _dp_kernel)(error, lo, hi, bool(cyclic), cols)
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
