"""Quilting's exact search through a colour lower bound: fewer transforms, the same candidates.

The masked SSD over the colour channels does not change when the colours are rotated by an
orthonormal matrix ``R`` (here the sample's principal colour axes, strongest first), and the
SSD of the first ``m`` rotated channels alone is a lower bound of the full SSD at every anchor.
Where the colours vary mostly along one axis (the bundled cobblestones: 95 % of the variance on
the first; grey samples stored as RGB: all of it) one channel bounds the error closely, and
where two are needed (lichen: 73 % + 27 %) two. A block's search then costs ``m`` forward
transforms instead of ``C`` (and one inverse, as before):

1. the bound ``b(p)`` at every anchor by FFT (:class:`BoundSpectrum`, float32 transforms);
2. the full SSD directly (float64) at the anchor of least bound: an upper bound ``u`` of the
   least error;
3. the anchors with ``b(p) − δ ≤ (1 + tolerance) · max(u, zero level)`` (``δ`` a margin for the
   transforms' float32 round-off, :func:`margin`), least bound first, each scored by the full
   SSD directly, stopping at the first whose bound passes the limit of the least error found.

Every anchor within the tolerance of the least error is scored, so the least error, the
candidate set and the choice are a brute-force search's (up to float round-off at the limit),
not the full FFT map's float32 approximation of it. A block whose bound keeps more than
:data:`CAP` anchors (a flat sample: every window a near copy) takes the full FFT map instead.
The result depends on the block and the sample only (never on the threads or the batch).

Both paths give the same bits: the compiled kernels (:func:`rotate_content`,
:func:`bounded_search`) and their numpy twins (:func:`rotate_content_numpy`,
:func:`bounded_search_numpy`) take the same operations in the same order (the sums of squares
in :data:`LANES` interleaved lanes, each added in order, then a fixed tree).
"""

from __future__ import annotations

import math

import numpy as np

from engine import _jit as jit
from engine._jit import njit
from engine.fft import next_fast_len
from engine.matching import SampleSpectrum
from engine.window_runs import mask_runs

__all__ = [
    "CAP",
    "LANES",
    "MAX_AREA",
    "MAX_FALLBACK",
    "PROBES",
    "RESIDUAL",
    "BoundSpectrum",
    "ColourBound",
    "bound_channels",
    "bounded_search",
    "bounded_search_numpy",
    "colour_axes",
    "extra_bytes",
    "lane_sums_numpy",
    "margin",
    "rotate_content",
    "rotate_content_numpy",
]

MAX_AREA = 1024 * 1024
"""Largest sample (pixels) whose exact quilting search goes through the bound: its spectra,
rotated copy and weight terms (:func:`extra_bytes`) stay small; larger samples keep the full
maps."""

RESIDUAL = 0.1
"""The bound takes the fewest leading colour axes that leave at most this fraction of the
sample's colour variance to the others (cobblestones: 1 axis, 4.6 % left; lichen: 2, 0.07 %)."""

CAP = 1024
"""Anchors a block's bound may keep before the block takes the full FFT map instead (scoring
one directly costs about 1/1000 of a full query of job B's size)."""

LANES = 16
"""Interleaved partial sums of a direct SSD (entry ``i`` of the overlap's values goes to lane
``i mod LANES``; vector registers add them side by side)."""

SAFETY = 8.0
"""Factor on the transforms' round-off estimate in :func:`margin`."""

PROBES = 9
"""Probe blocks of :meth:`ColourBound.fallback_share` (a square number)."""

MAX_FALLBACK = 0.25
"""A sample whose probes take the full map more often than this keeps the full maps."""

_EPS32 = float(np.finfo(np.float32).eps)
_SUBSAMPLE = 1 << 16


def colour_axes(sample: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(R, share): the sample's principal colour axes as the rows of an orthonormal (C, C)
    float64 matrix, strongest first, and each one's share of the colour variance. From at most
    :data:`_SUBSAMPLE` pixels on a fixed stride (any orthonormal ``R`` keeps the bound exact;
    the axes only decide how tight it is)."""
    s = np.asarray(sample)
    c = s.shape[2]
    px = s.reshape(-1, c)
    px = px[:: max(1, px.shape[0] // _SUBSAMPLE)].astype(np.float64)
    px -= px.mean(axis=0)
    lam, vec = np.linalg.eigh(px.T @ px)
    order = np.argsort(lam)[::-1]
    lam = np.maximum(lam[order], 0.0)
    total = lam.sum()
    share = lam / total if total > 0 else np.eye(c)[0]
    return np.ascontiguousarray(vec[:, order].T), share


def extra_bytes(sample: np.ndarray) -> int:
    """Memory the bound of ``sample`` holds besides the full search's (for the peak estimate):
    the rotated copy and its spectra; 0 where :meth:`ColourBound.build` gives None. (Its
    cached weight terms take the place of the full search's, which only the blocks that take
    the full map add to.)"""
    h, w, c = sample.shape
    if c < 2:
        return 0
    m = bound_channels(colour_axes(sample)[1])
    if m >= c:
        return 0
    plane = (next_fast_len(h) // 2 + 1) * next_fast_len(w) * 8
    return h * w * m * 4 + (m + 1) * plane


def bound_channels(share: np.ndarray) -> int:
    """The fewest leading axes whose complement holds at most :data:`RESIDUAL` of the variance."""
    for m in range(1, len(share) + 1):
        if share[m:].sum() <= RESIDUAL:
            return m
    return len(share)


class BoundSpectrum(SampleSpectrum):
    """A :class:`SampleSpectrum` of the rotated sample's leading channels that answers with the
    inverse rows of a query (without the constant term: :meth:`rows`)."""

    def rows(self, k: np.ndarray, wts: np.ndarray, workers: int | None = None) -> np.ndarray:
        """``Σ_j −2 corr(S'_j, K_j) + corr(Σ_j S'_j², W)`` (n, rows, cols) float32 for kernels
        ``k`` (n, m, bh, bw) and weights ``wts`` (n, 1, bh, bw): :meth:`SampleSpectrum.terms`
        (with numba: a view of the thread's kept buffer, valid until its next query)."""
        return self.terms(k, wts, workers, compiled=jit.loaded())


def margin(norm_s: float, norm_q: float, norm_k: float, count: int, const: float, fft_size):
    """``δ``: a bound on the float32 transforms' error in a bound value. The error of an FFT
    correlation grows with the 2-norms of its operands and the transforms' depth (log2 of the
    size) times float32's epsilon; :data:`SAFETY` times that for the sample term
    (``2 ‖S'‖ ‖K‖``) and the weight term (``‖Σ S'²‖ ‖W‖``), plus the constant's rounding."""
    depth = math.log2(max(2, fft_size[0] * fft_size[1]))
    terms = 2.0 * norm_s * norm_k + norm_q * math.sqrt(count)
    return SAFETY * _EPS32 * depth * terms + 4.0 * _EPS32 * const


class ColourBound:
    """The exact search of one colour sample through its colour bound (see the module).

    ``build`` gives None where the bound saves nothing (one channel, or every axis needed)."""

    def __init__(self, sample: np.ndarray, axes: np.ndarray, m: int, *, backend=None):
        s = np.ascontiguousarray(sample, dtype=np.float32)
        self.sample = s
        self.m = int(m)
        self.lead = np.ascontiguousarray(axes[: self.m])
        h, w, c = s.shape
        rot = np.empty((h, w, self.m), np.float32)
        for y in range(0, h, 256):  # strips: no float64 copy of a large sample
            part = s[y : y + 256].astype(np.float64)
            rot[y : y + 256] = part @ self.lead.T
        self.spec = BoundSpectrum(rot, backend=backend)
        self.norm_s = math.sqrt(np.einsum("ijk,ijk->", rot, rot, dtype=np.float64))
        q = np.einsum("ijk,ijk->ij", rot, rot)
        self.norm_q = math.sqrt(np.einsum("ij,ij->", q, q, dtype=np.float64))

    @classmethod
    def build(cls, sample: np.ndarray, *, backend=None) -> ColourBound | None:
        if sample.shape[2] < 2:
            return None
        axes, share = colour_axes(sample)
        m = bound_channels(share)
        return None if m >= sample.shape[2] else cls(sample, axes, m, backend=backend)

    def fallback_share(self, block, overlap: int, *, tolerance: float, zero_level: float) -> float:
        """The share of :data:`PROBES` probe blocks that would take the full FFT map: windows of
        the sample itself on a fixed grid (each has an exact copy, as many quilting blocks
        do) with quilting's L overlap. A flat sample (most windows near copies of each other)
        keeps too many anchors nearly everywhere, and the bound's transforms are then spent
        on top of the full map's (job B with 90 % of its sample flat: 0.78 s against 0.49 s)."""
        bh, bw = block
        h, w = self.sample.shape[:2]
        filled = np.zeros((bh, bw), np.bool_)
        filled[:overlap] = True
        filled[:, :overlap] = True
        side = math.isqrt(PROBES)
        ys = np.linspace(0, h - bh, side).astype(int)
        xs = np.linspace(0, w - bw, side).astype(int)
        full = sum(
            self.search(
                self.sample[y : y + bh, x : x + bw],
                filled,
                None,
                tolerance=tolerance,
                zero_level=zero_level,
            )
            is None
            for y in ys
            for x in xs
        )
        return full / (side * side)

    def search(self, old, filled, valid, *, tolerance: float, zero_level: float, workers=None):
        """The scored anchors of a block: (flat anchor indices ascending, their full SSDs
        float64), among them every candidate within the tolerance; None when the block should
        take the full FFT map (more than :data:`CAP` anchors kept, or none valid).

        ``old`` (bh, bw, C) the canvas under the block, ``filled`` (bh, bw) bool its overlap,
        ``valid`` the allowed anchors (bool, rows × cols) or None."""
        bh, bw = filled.shape
        compiled = jit.loaded()
        rotate = rotate_content if compiled else rotate_content_numpy
        k, wts, const, count = rotate(old, filled, self.lead)
        rows = self.spec.rows(k, wts, workers)[0]
        delta = margin(
            self.norm_s, self.norm_q, math.sqrt(const), int(count), const, self.spec.padded
        )
        flat_valid = np.ones(0, np.bool_) if valid is None else valid.reshape(-1)
        find = bounded_search if compiled else bounded_search_numpy
        status, idx, errs = find(
            rows.reshape(-1) if compiled else rows.ravel(),
            const,
            flat_valid,
            delta,
            float(tolerance),
            float(zero_level),
            self.sample,
            np.ascontiguousarray(old, dtype=np.float32),
            np.ascontiguousarray(filled, dtype=np.bool_),
            rows.shape[1],
            CAP,
        )
        return (idx, errs) if status == 0 else None


# ---------------------------------------------------------------------------- kernels
@njit(cache=True, nogil=True)
def rotate_content(old, filled, lead):  # pragma: no cover - compiled
    """The block's rotated weighted content (1, m, bh, bw) float32 (``Σ_c lead[j, c] old_c``
    added in channel order in float64, 0 outside ``filled``), its weights (1, 1, bh, bw)
    float32, Σ of the content's squares (float64, in order: channel, row, column) and the
    number of filled pixels."""
    bh, bw, c = old.shape
    m = lead.shape[0]
    k = np.zeros((1, m, bh, bw), np.float32)
    wts = np.zeros((1, 1, bh, bw), np.float32)
    count = 0
    for u in range(bh):
        for v in range(bw):
            if filled[u, v]:
                count += 1
                wts[0, 0, u, v] = 1.0
                for j in range(m):
                    acc = lead[j, 0] * np.float64(old[u, v, 0])
                    for ch in range(1, c):
                        acc = acc + lead[j, ch] * np.float64(old[u, v, ch])
                    k[0, j, u, v] = np.float32(acc)
    const = 0.0
    for j in range(m):
        for u in range(bh):
            for v in range(bw):
                x = np.float64(k[0, j, u, v])
                const = const + x * x
    return k, wts, const, count


def rotate_content_numpy(old, filled, lead):
    """:func:`rotate_content` from numpy (the same operations: the same bits)."""
    o = np.asarray(old, np.float32).astype(np.float64)
    f = np.asarray(filled, bool)
    m, c = lead.shape
    k = np.zeros((1, m, *f.shape), np.float32)
    for j in range(m):
        acc = lead[j, 0] * o[:, :, 0]
        for ch in range(1, c):
            acc = acc + lead[j, ch] * o[:, :, ch]
        k[0, j][f] = acc[f].astype(np.float32)
    wts = f.astype(np.float32)[None, None]
    sq = k.astype(np.float64).ravel()
    const = float(np.cumsum(sq * sq)[-1]) if sq.size else 0.0  # in order, as the kernel
    return k, wts, const, int(f.sum())


@njit(cache=True, nogil=True)
def _ssd_at(flat, base, runs, values, buf):  # pragma: no cover - compiled
    """Σ (flat[base + run offsets] − values)² in float64: the squares in order into ``buf``
    (its tail past the values stays 0), then :data:`LANES` lanes added in order and a fixed
    tree (:func:`lane_sums_numpy`'s arithmetic)."""
    j = 0
    for r in range(runs.shape[0]):
        length = runs[r, 1]
        seg = flat[base + runs[r, 0] : base + runs[r, 0] + length]  # views: loops over range
        val = values[j : j + length]  # indices vectorise (no negative-index wrap-around)
        out = buf[j : j + length]
        for t in range(length):
            d = np.float64(seg[t]) - val[t]
            out[t] = d * d
        j += length
    a0 = a1 = a2 = a3 = a4 = a5 = a6 = a7 = 0.0
    a8 = a9 = a10 = a11 = a12 = a13 = a14 = a15 = 0.0
    for i in range(0, buf.size, 16):
        a0 += buf[i]
        a1 += buf[i + 1]
        a2 += buf[i + 2]
        a3 += buf[i + 3]
        a4 += buf[i + 4]
        a5 += buf[i + 5]
        a6 += buf[i + 6]
        a7 += buf[i + 7]
        a8 += buf[i + 8]
        a9 += buf[i + 9]
        a10 += buf[i + 10]
        a11 += buf[i + 11]
        a12 += buf[i + 12]
        a13 += buf[i + 13]
        a14 += buf[i + 14]
        a15 += buf[i + 15]
    lo = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7))
    hi = ((a8 + a9) + (a10 + a11)) + ((a12 + a13) + (a14 + a15))
    return lo + hi


CHUNK = 64
"""Anchors per chunk of :func:`_chunk_least` (later passes skip chunks by their least)."""


@njit(cache=True, nogil=True)
def _chunk_least(rows, valid):  # pragma: no cover - compiled
    """The least of ``rows`` (float32) in each chunk of :data:`CHUNK` entries, where ``valid``
    (empty: everywhere), inf where none: eight independent running minima a chunk (a chain of
    compares waits on itself; 23 -> 7 us for job B's 209² bounds), then their least."""
    n = rows.size
    inf = np.float32(np.inf)
    out = np.empty((n + CHUNK - 1) // CHUNK, np.float32)
    r = rows
    if valid.size:  # invalid anchors as inf (a copy: rare, excluded regions only)
        r = np.where(valid, rows, inf)
    whole = n // CHUNK
    for i in range(whole):
        l0 = l1 = l2 = l3 = l4 = l5 = l6 = l7 = inf
        for j in range(i * CHUNK, i * CHUNK + CHUNK, 8):
            v = r[j]
            l0 = v if v < l0 else l0
            v = r[j + 1]
            l1 = v if v < l1 else l1
            v = r[j + 2]
            l2 = v if v < l2 else l2
            v = r[j + 3]
            l3 = v if v < l3 else l3
            v = r[j + 4]
            l4 = v if v < l4 else l4
            v = r[j + 5]
            l5 = v if v < l5 else l5
            v = r[j + 6]
            l6 = v if v < l6 else l6
            v = r[j + 7]
            l7 = v if v < l7 else l7
        out[i] = min(min(min(l0, l1), min(l2, l3)), min(min(l4, l5), min(l6, l7)))
    if whole < out.size:
        low = inf
        for j in range(whole * CHUNK, n):
            low = r[j] if r[j] < low else low
        out[whole] = low
    return out


@njit(cache=True, nogil=True)
def bounded_search(
    rows, const, valid, delta, tolerance, zero_level, sample, target, mask, cols, cap
):  # pragma: no cover - compiled
    """Steps 2-3 of the module's search for one block, given its bound rows (flat, float32,
    without ``const``): (status, scored flat indices ascending, their full SSDs). Status 0;
    1 when more than ``cap`` anchors pass the first limit or none is valid."""
    n = rows.size
    none = np.empty(0, np.int64), np.empty(0, np.float64)
    has_valid = valid.size > 0
    least = _chunk_least(rows, valid)
    low32 = np.float32(np.inf)
    for i in range(least.size):
        low32 = least[i] if least[i] < low32 else low32
    if not low32 < np.inf:
        return 1, none[0], none[1]
    first = 0  # the first valid anchor of the least bound
    for i in range(least.size):
        if least[i] == low32:
            for j in range(i * CHUNK, min(i * CHUNK + CHUNK, n)):
                if (not has_valid or valid[j]) and rows[j] == low32:
                    first = j
                    break
            break
    runs, values = mask_runs(sample, target, mask)
    c = sample.shape[2]
    sw = sample.shape[1]
    flat = sample.ravel()
    buf = np.zeros((values.size + 15) // 16 * 16, np.float64)
    ub = _ssd_at(flat, ((first // cols) * sw + first % cols) * c, runs, values, buf)
    limit = (1.0 + tolerance) * (zero_level if zero_level > ub else ub)
    # rows[j] <= coarse wherever the exact test below can hold (float32, a little above)
    coarse = np.float32((limit + delta - const) * (1.0 + 1e-6) + 1e-6 * abs(const) + 1e-30)
    keep = np.empty(cap + 1, np.int64)
    bounds = np.empty(cap + 1, np.float64)
    kept = 0
    for i in range(least.size):
        if not least[i] <= coarse:
            continue
        for j in range(i * CHUNK, min(i * CHUNK + CHUNK, n)):
            b = np.float64(rows[j]) + const
            if b - delta <= limit and (not has_valid or valid[j]):
                if kept == cap:
                    return 1, none[0], none[1]
                keep[kept] = j
                bounds[kept] = b
                kept += 1
    order = np.argsort(bounds[:kept], kind="mergesort")
    idx = np.empty(kept + 1, np.int64)
    errs = np.empty(kept + 1, np.float64)
    idx[0], errs[0] = first, ub
    got = 1
    best = ub
    for r in range(kept):
        j = keep[order[r]]
        if j == first:
            continue
        if bounds[order[r]] - delta > limit:
            break
        e = _ssd_at(flat, ((j // cols) * sw + j % cols) * c, runs, values, buf)
        idx[got], errs[got] = j, e
        got += 1
        if e < best:
            best = e
            limit = (1.0 + tolerance) * (zero_level if zero_level > best else best)
    pos = np.argsort(idx[:got], kind="mergesort")
    return 0, idx[:got][pos], errs[:got][pos]


def lane_sums_numpy(sq: np.ndarray) -> np.ndarray:
    """:func:`_ssd_at`'s sum of squares ``sq`` (n, k) per row: zero-padded to whole groups of
    :data:`LANES`, each lane added in order (``np.add.reduce`` over a non-contiguous axis goes
    row by row), then the kernel's tree."""
    n, k = sq.shape
    pad = np.zeros((n, -(-k // LANES) * LANES), np.float64)
    pad[:, :k] = sq
    a = np.add.reduce(pad.reshape(n, -1, LANES), axis=1)
    lo = ((a[:, 0] + a[:, 1]) + (a[:, 2] + a[:, 3])) + ((a[:, 4] + a[:, 5]) + (a[:, 6] + a[:, 7]))
    hi = ((a[:, 8] + a[:, 9]) + (a[:, 10] + a[:, 11])) + (
        (a[:, 12] + a[:, 13]) + (a[:, 14] + a[:, 15])
    )
    return lo + hi


def bounded_search_numpy(
    rows, const, valid, delta, tolerance, zero_level, sample, target, mask, cols, cap
):
    """:func:`bounded_search` from numpy: the same status, indices and bits (every kept anchor
    scored at once, then the kernel's walk replayed to keep the ones it scores)."""
    b = rows.astype(np.float64) + const
    ok = np.ones(b.size, bool) if valid.size == 0 else valid
    rv = np.where(ok, rows, np.float32(np.inf))
    first = int(np.argmin(rv))
    if not rv[first] < np.inf:
        return 1, None, None
    sw, c = sample.shape[1], sample.shape[2]
    uu, vv = np.nonzero(mask)
    offs = ((uu * sw + vv) * c)[:, None] + np.arange(c)[None, :]
    values = np.asarray(target, np.float64)[uu, vv].ravel()
    flat = sample.ravel()

    def score(js):
        base = ((js // cols) * sw + js % cols) * c
        d = flat[base[:, None] + offs.ravel()[None, :]].astype(np.float64) - values[None, :]
        return lane_sums_numpy(d * d)

    ub = float(score(np.array([first]))[0])
    limit = (1.0 + tolerance) * (zero_level if zero_level > ub else ub)
    keep = np.flatnonzero((b - delta <= limit) & ok)
    if keep.size > cap:
        return 1, None, None
    bounds = b[keep]
    order = np.argsort(bounds, kind="mergesort")
    errs_all = score(keep[order]) if keep.size else np.empty(0)
    idx, errs = [first], [ub]
    best = ub
    for r, j in enumerate(keep[order]):
        if j == first:
            continue
        if bounds[order[r]] - delta > limit:
            break
        e = float(errs_all[r])
        idx.append(int(j))
        errs.append(e)
        if e < best:
            best = e
            limit = (1.0 + tolerance) * (zero_level if zero_level > best else best)
    idx_a = np.array(idx, np.int64)
    pos = np.argsort(idx_a, kind="mergesort")
    return 0, idx_a[pos], np.array(errs, np.float64)[pos]
