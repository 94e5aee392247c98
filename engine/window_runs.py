"""A block's mask as runs along its rows, for direct SSDs against sample windows.

A window's pixels along a row are contiguous in the (H, W, C) sample, so a direct SSD reads
each run of masked pixels as one stretch of the sample's flat values (the exact re-ranking of
:func:`engine.matching.ssd_at` and the colour bound's scoring, :mod:`engine.colour_bound`).
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit

__all__ = ["mask_runs"]


@njit(cache=True, nogil=True)
def mask_runs(sample, target, mask):  # pragma: no cover - compiled
    """(runs, values): each run of set pixels of ``mask`` (h, w) along its rows as (offset in
    a sample window's flat values, length in values, index of its first value), and the
    target's (h, w, C) values there (float64, row-major, channels innermost)."""
    h, w = mask.shape
    sw, c = sample.shape[1], sample.shape[2]
    runs = np.empty((h * w, 3), np.int64)
    values = np.empty(h * w * c, np.float64)
    nr = nv = 0
    for u in range(h):
        v = 0
        while v < w:
            if not mask[u, v]:
                v += 1
                continue
            v1 = v
            while v1 < w and mask[u, v1]:
                for ch in range(c):
                    values[nv] = target[u, v1, ch]
                    nv += 1
                v1 += 1
            runs[nr, 0], runs[nr, 1] = (u * sw + v) * c, (v1 - v) * c
            runs[nr, 2] = nv - (v1 - v) * c
            nr += 1
            v = v1
    return runs[:nr], values[:nv]
