"""Minimum error boundary cut by dynamic programming (Efros & Freeman).

One pixel per row, 8-connected: ``E[j,i] = e[j,i] + min(E[j-1,i-1..i+1])``,
backtracked with stored argmin pointers. Exact and O(3 w h).
"""

from __future__ import annotations

import numpy as np

from engine.seams._result import Seam, make_seam, mask_from_columns


def dp_columns(error: np.ndarray, *, start: int | None = None, end: int | None = None) -> np.ndarray:
    """Column of the optimal one-point-per-row path in every row."""
    h, w = error.shape
    cost = error[0].copy()
    if start is not None:
        cost[:] = np.inf
        cost[start] = error[0, start]
    back = np.zeros((h, w), dtype=np.int8)
    for j in range(1, h):
        left = np.concatenate(([np.inf], cost[:-1]))
        right = np.concatenate((cost[1:], [np.inf]))
        stack = np.stack([left, cost, right])
        k = np.argmin(stack, axis=0)  # 0: from i-1, 1: from i, 2: from i+1
        back[j] = k - 1
        cost = stack[k, np.arange(w)] + error[j]
    cols = np.empty(h, dtype=np.intp)
    cols[-1] = end if end is not None else int(np.argmin(cost))
    for j in range(h - 1, 0, -1):
        cols[j - 1] = cols[j] + back[j, cols[j]]
    return cols


def dp_seam(error: np.ndarray, *, start: int | None = None, end: int | None = None) -> Seam:
    cols = dp_columns(error, start=start, end=end)
    path = np.column_stack([np.arange(error.shape[0]), cols])
    return make_seam(error, path, "dp", mask_from_columns(cols, error.shape[1]))
