"""Compiled per-block steps of quilting's common case, each one call without the GIL.

Job A of ``benchmarks/quilting.py`` places 400 blocks of 32² in about a tenth of a second: a
block's own work (an FFT search of a 128² sample, a dp cut of a 6-pixel overlap) is a few tens
of microseconds, so the dozens of numpy calls around it cost as much as the work. These kernels
do the steps around the search in one call each, with the same arithmetic as the general path
(:func:`engine.errormap.error_map_of`, :func:`engine.stitch.l_cut`, :func:`arms_of
<engine.quilting.layout.arms_of>`): the output is identical whichever path a block takes.
They are taken only once numba is loaded (:func:`engine._jit.loaded`): a small job without it
takes the numpy path, as :mod:`engine.stitch_numpy` explains.
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit
from engine.stitch import dp_arm_cut_kernel, dp_l_cut_kernel

__all__ = [
    "PAIRWISE_BLOCK",
    "dp_cut_paste",
    "footprint",
    "query_inputs",
    "SQUARE_SUM_MAX",
    "square_sum",
    "square_sum_is_einsums",
]


@njit(cache=True, nogil=True)
def footprint(filled):  # pragma: no cover - compiled
    """(number of filled pixels, top, left, bottom, right) of a block's filled mask (h, w):
    the arms as :func:`engine.quilting.layout.arms_of` gives them (all 0 when nothing is
    filled)."""
    h, w = filled.shape
    count = 0
    rows = np.ones(h, np.bool_)
    cols = np.ones(w, np.bool_)
    for u in range(h):
        for v in range(w):
            if filled[u, v]:
                count += 1
            else:
                rows[u] = False
                cols[v] = False
    if count == 0:
        return 0, 0, 0, 0, 0
    if count == h * w:
        return count, h, w, 0, 0
    t = 0
    while rows[t]:
        t += 1
    b = 0
    while rows[h - 1 - b]:
        b += 1
    left = 0
    while left < w and cols[left]:
        left += 1
    r = 0
    if left < w:
        while cols[w - 1 - r]:
            r += 1
    return count, t, left, b, r


@njit(cache=True, nogil=True)
def query_inputs(canvas, filled, ys, xs, h, w, c):  # pragma: no cover - compiled
    """An exact search's inputs for blocks (h, w) at (``ys[i]``, ``xs[i]``) inside the canvas:
    their overlaps as weights (n, 1, h, w) float32 (1 filled, 0 not), the weighted content
    (n, h, w, c) (the first ``c`` channels) and its sum of squares (n,) float64 — what
    ``np.stack`` of the blocks' ``filled`` and ``old``, the float32 cast, the product and the
    ``einsum`` give :meth:`engine.matching.SampleSpectrum.ssd` (the same values, the weighted
    content in the layout numpy's product gives it there), in one pass instead of five numpy
    calls. With weights 0 or 1, weighted content times content is weighted content squared,
    bit for bit (t², or +0 where the weight is 0); the sums are :func:`square_sum`'s."""
    n = len(ys)
    wts = np.empty((n, 1, h, w), np.float32)
    k = np.empty((n, h, w, c), np.float32)
    const = np.empty(n, np.float64)
    one, zero = np.float32(1), np.float32(0)
    for i in range(n):
        y0, x0 = ys[i], xs[i]
        for u in range(h):
            for v in range(w):
                f = one if filled[y0 + u, x0 + v] else zero
                wts[i, 0, u, v] = f
                for ch in range(c):
                    k[i, u, v, ch] = f * canvas[y0 + u, x0 + v, ch]
        const[i] = square_sum(k[i].ravel())
    return wts, k, const


@njit(cache=True, nogil=True)
def square_sum(x):  # pragma: no cover - compiled
    """Σ x² of a contiguous float32 array in float64, added as numpy's ``einsum("i,i->",
    x, x, dtype=np.float64)`` adds it on this machine when :func:`square_sum_is_einsums` says
    so: two lanes (even and odd entries), eight entries a step taken from the last pair to
    the first, the rest a pair at a time, then the two lanes added (its SIMD loop with 128-bit
    vectors; each float32 product is exact in float64, so its fused multiply-adds round as
    one addition)."""
    acc0 = acc1 = 0.0
    j, count = 0, x.size
    while count >= 8:
        for p in (6, 4, 2, 0):
            a, b = np.float64(x[j + p]), np.float64(x[j + p + 1])
            acc0 = a * a + acc0
            acc1 = b * b + acc1
        j += 8
        count -= 8
    while count > 0:
        a = np.float64(x[j])
        acc0 = a * a + acc0
        if count > 1:
            b = np.float64(x[j + 1])
            acc1 = b * b + acc1
        j += 2
        count -= 2
    return 0.0 + (acc0 + acc1)


SQUARE_SUM_MAX = 8192
"""Most values a block's :func:`square_sum` may add for quilting to take it instead of the
``einsum``: numpy's default buffer (its larger sums, 64² × 3 here, add in other chunks)."""

_SAME_SUMS: list[bool] = []


def square_sum_is_einsums() -> bool:
    """Whether :func:`square_sum` gives numpy's ``einsum`` sums bit for bit here for blocks of
    up to :data:`SQUARE_SUM_MAX` values (checked once per process on random L-masked blocks:
    another numpy build may add in another order; then quilting keeps the ``einsum``)."""
    if not _SAME_SUMS:
        rng = np.random.default_rng(0)
        same = np.getbufsize() >= SQUARE_SUM_MAX
        for n, h, w, c in ((1, 32, 32, 3), (3, 48, 45, 3), (2, 17, 9, 1), (8, 48, 48, 3)):
            k = rng.random((n, h, w, c), dtype=np.float32)
            k[:, h // 3 :, w // 4 :] = 0
            kt = k.transpose(0, 3, 1, 2)
            want = np.einsum("nchw,nchw->n", kt, kt, dtype=np.float64)
            same &= all(square_sum(k[i].ravel()) == want[i] for i in range(n))
        _SAME_SUMS.append(bool(same))
    return _SAME_SUMS[0]


@njit(cache=True, nogil=True)
def dp_cut_paste(old, new, filled, ovl, ovt, out, out_filled, write):  # pragma: no cover
    """One block's squared-error map, dp L-cut and hard paste (a top or a left arm or both,
    no blend).

    ``old`` (h, w, c) the colour channels under the block, ``new`` (h, w, C) the sample window
    (its first c channels compared), ``filled`` (h, w) the overlap, ``out`` (h, w, C) the
    canvas under the block (read where the cut keeps the old content; with ``write``, a view
    of the canvas that then receives the pixels, and ``out_filled`` the canvas's filled mask
    under the block, then set: two numpy assignments fewer per block). Returns the error map
    (float32, 0 outside the overlap, summed over channels in order as ``error_map_of``), the
    old side (bool), the path ((n, 2) intp, empty when old and new agree over the whole
    overlap: then the overlap is kept as it is, as in :meth:`Quilter.paste`), the pixels
    (h, w, C) float32 to write, the error along the path (float64), and its sum (left 0 for
    the caller to add beyond :data:`PAIRWISE_BLOCK` values) and maximum (0 without a path),
    the same bits as numpy's ``sum`` and ``max`` of those values (one call instead of five
    numpy calls per block).
    """
    h, w, c = old.shape
    err = np.zeros((h, w), np.float32)
    anything = False
    for u in range(h):
        for v in range(w):
            if filled[u, v]:
                d = old[u, v, 0] - new[u, v, 0]
                s = d * d
                for k in range(1, c):
                    d = old[u, v, k] - new[u, v, k]
                    s = s + d * d
                err[u, v] = s
                if s != 0:
                    anything = True
    pixels = new.copy()
    crit = peak = 0.0
    if anything:
        if ovl and ovt:
            path, keep, _, _ = dp_l_cut_kernel(err.astype(np.float64), ovl, ovt)
        else:
            path, keep = dp_arm_cut_kernel(err.astype(np.float64), ovl, ovt)
        values = np.empty(len(path), np.float64)
        for i in range(len(path)):
            values[i] = err[path[i, 0], path[i, 1]]
        if len(values) <= PAIRWISE_BLOCK:
            crit = _pairwise_sum(values)
        peak = _nan_max(values) if len(values) else 0.0
    else:
        path = np.zeros((0, 2), np.intp)
        keep = filled.copy()
        values = np.zeros(0, np.float64)
    for u in range(h):
        for v in range(w):
            if keep[u, v]:
                if filled[u, v]:
                    pixels[u, v] = out[u, v]
                else:
                    keep[u, v] = False
    if write:
        out[:] = pixels
        out_filled[:] = True
    return err, keep, path, pixels, values, crit, peak


PAIRWISE_BLOCK = 128
"""Longest run numpy adds in 8 interleaved sums (its ``PW_BLOCKSIZE``); a longer one it splits."""


@njit(cache=True, nogil=True)
def _pairwise_sum(a):  # pragma: no cover - compiled
    """``a.sum()`` of a contiguous float64 array of at most :data:`PAIRWISE_BLOCK` values as
    numpy adds it (its pairwise summation: up to 8 values in turn, then 8 interleaved sums
    joined pairwise, the rest in turn): the same bits. (Longer ones numpy splits in two; the
    caller sums those with numpy: a recursive kernel read from numba's cache crashes.)"""
    n = len(a)
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[0], a[1], a[2], a[3]
    r4, r5, r6, r7 = a[4], a[5], a[6], a[7]
    i = 8
    end = n - n % 8
    while i < end:
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[i]
        i += 1
    return res


@njit(cache=True, nogil=True)
def _nan_max(a):  # pragma: no cover - compiled
    """``a.max()`` of a non-empty float64 array (NaN if any value is NaN, as numpy's)."""
    m = a[0]
    for i in range(len(a)):
        v = a[i]
        if v != v:
            return v
        if v > m:
            m = v
    return m
