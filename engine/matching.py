"""Candidate search for patch-based synthesis: masked SSD against every sample position.

ALGORITHMS.md §0 and §2.2. For a block of existing content ``T`` (bh, bw, C) and non-negative
per-pixel weights ``W`` (the overlap mask, or any weighting), the error of the sample window
anchored at ``p`` is

    e(p) = Σ_u Σ_c W(u) (S_c(p + u) − T_c(u))²
         = Σ W·T²  −  2 Σ_c corr(S_c, W·T_c)(p)  +  corr(Σ_c S_c², W)(p).

Both correlations are computed for all positions at once by FFT. Because only *valid* positions
are wanted (the window inside the sample), a circular correlation of the sample's own size is
exact: no index wraps. The sample's spectra are computed once (:class:`SampleSpectrum`, float32,
real FFT, a fixed padded shape); each query costs one forward transform per channel of the kernel
and one inverse, the channels being summed in the frequency domain.

:class:`PCAMatcher` is the *fast* mode: the overlap is split into fixed parts (corner, left arm,
top arm), every sample position is described by its projections on a few principal components of
each part (computed for all positions at once by the same FFT correlation), the squared error is
estimated as ``‖f‖² − 2·proj(f)·proj(T) + ‖T‖²`` (``‖f‖²`` exact, from a summed-area table) and the
best few estimates are re-ranked by the exact SSD (:func:`ssd_at`).
"""

from __future__ import annotations

import math

import numpy as np

from engine import _jit as jit
from engine._jit import njit
from engine._validate import as_image, as_rng, positive_int
from engine.fft import default_backend, inverse, next_fast_len, spectra, transforms
from engine.spectral import product_sum
from engine.window_runs import mask_runs

__all__ = [
    "ZERO_ERROR_FRACTION",
    "PCAMatcher",
    "SampleSpectrum",
    "TiledSpectrum",
    "box_sums_float",
    "summed_area",
    "check_block",
    "error_floor",
    "kth_at_most",
    "least_and_count",
    "masked_ssd",
    "select_within_tolerance",
    "smallest_indices",
    "ssd_at",
]


WEIGHT_CACHE_BYTES = 32 * 2**20
"""Memory a spectrum may spend on the weight terms of recurring overlap masks."""


def _workers(threads: int | None) -> int:
    return 1 if threads is None else max(1, int(threads))


class SampleSpectrum:
    """Spectra of a sample for masked-SSD queries of any block size up to the sample's.

    Parameters
    ----------
    sample : (H, W, C) float32 ndarray
        The sample (already validated, [0, 1]).
    groups : sequence of sequences of int, optional
        Channel groups that share one weight map in :meth:`ssd` (default: one group with every
        channel). Texture transfer uses two groups: the colour channels and the correspondence
        channel.
    workers : int
        Threads of the transforms.
    backend : {"ducc0", "scipy", "numpy"}, optional
        Where the transforms come from (:mod:`engine.fft`; default
        :func:`engine.fft.default_backend`: ducc0 when installed). They round differently in
        the last bits.
    """

    def __init__(self, sample: np.ndarray, *, groups=None, workers: int = 1, backend=None):
        self._setup(sample, groups, workers, backend)
        chans = np.moveaxis(self.sample, 2, 0)
        sq = np.stack([np.sum(chans[list(g)] ** 2, axis=0) for g in self.groups])
        # -2 F(S_c): queries sum Σ_c conj(F(K_c)) · this (the kernels' conjugate spectra come
        # from the transforms of opposite sign; the factor is a power of two: exact)
        self._hs = self._forward(chans)
        self._hs *= np.float32(-2)
        self._fsq = self._forward(sq)
        self._wcache: dict = {}

    def _setup(self, sample, groups, workers, backend) -> None:
        s = np.ascontiguousarray(np.asarray(sample, dtype=np.float32))
        if s.ndim != 3:
            raise ValueError(f"sample must be (H, W, C), got shape {s.shape}")
        self.sample = s
        h, w, c = s.shape
        self.shape = (h, w)
        self.channels = c
        self.groups = tuple(tuple(int(i) for i in g) for g in (groups or (tuple(range(c)),)))
        if sorted(i for g in self.groups for i in g) != list(range(c)):
            raise ValueError(f"groups must partition the {c} channels, got {groups!r}")
        self.group_of = np.empty(c, dtype=np.intp)
        for gi, g in enumerate(self.groups):
            self.group_of[list(g)] = gi
        self.workers = int(workers)
        self.backend = default_backend() if backend is None else backend
        self.fft = transforms(self.backend)
        self.padded = (next_fast_len(h), next_fast_len(w))

    @property
    def nbytes(self) -> int:
        """Memory held by the spectra (the sample itself not counted)."""
        return self._hs.nbytes + self._fsq.nbytes

    def _forward(self, k: np.ndarray) -> np.ndarray:
        """2-D real FFT of arrays (..., kh, kw) zero-padded to ``padded``, half along the rows:
        (..., hp // 2 + 1, wp) (:func:`engine.fft.spectra`). On one thread whatever ``workers``
        says: ducc0 splits batched transforms by thread count and the last bits differ (a run
        on two threads then scored its blocks differently from one on one thread)."""
        return spectra(self.fft, k, self.padded, workers=1)

    def _conj_spectra(self, k: np.ndarray, workers: int | None = None) -> np.ndarray:
        """The conjugate of :meth:`_forward` for a query's kernels, in the thread's kept buffer
        (:meth:`engine.fft._Padded.spectra`): use it before the next call."""
        wk = self.workers if workers is None else workers
        return spectra(self.fft, k, self.padded, conj=True, workers=wk, reuse=True)

    def _inverse(
        self, x: np.ndarray, rows: int, cols: int, workers: int | None = None
    ) -> np.ndarray:
        """:meth:`_inverse_rows` as a contiguous array."""
        return np.ascontiguousarray(self._inverse_rows(x, rows, cols, workers))

    def _inverse_rows(
        self, x: np.ndarray, rows: int, cols: int, workers: int | None = None, out=None
    ) -> np.ndarray:
        """The first ``rows`` × ``cols`` values of the inverse of :meth:`_forward`'s spectra (a
        view; ``x`` is overwritten; ``out`` see :func:`engine.fft.inverse`)."""
        wk = self.workers if workers is None else workers
        return inverse(self.fft, x, self.padded, rows, cols, workers=wk, out=out)

    def correlate(self, kernels: np.ndarray) -> np.ndarray:
        """``Σ_c corr(S_c, K_c)`` at every valid position for a batch of kernels (n, C, kh, kw)."""
        k = np.asarray(kernels, dtype=np.float32)
        n, c, kh, kw = k.shape
        x = product_sum(self._conj_spectra(k), self._hs)
        x *= np.float32(-0.5)
        h, w = self.shape
        return self._inverse(x, h - kh + 1, w - kw + 1)

    def _weight_terms(self, wts: np.ndarray, workers) -> list[np.ndarray]:
        """``Σ_g conj(F(W_g)) F(Σ_{c∈g} S_c²)`` of each weight map (n, G, bh, bw), as a list.
        Quilting's blocks share a few overlap masks: each one's term is kept (up to
        :data:`WEIGHT_CACHE_BYTES`), so most queries transform only their kernels' colours."""
        keys = [(w.shape, w.tobytes()) for w in wts]
        out = [self._wcache.get(key) for key in keys]
        todo = [i for i, v in enumerate(out) if v is None]
        if todo:
            fresh = product_sum(self._conj_spectra(wts[todo], workers), self._fsq)
            for i, v in zip(todo, fresh, strict=True):
                out[i] = v
                if (len(self._wcache) + 1) * v.nbytes <= WEIGHT_CACHE_BYTES:
                    self._wcache[keys[i]] = v
        return out

    def ssd(self, targets: np.ndarray, weights: np.ndarray, *, workers: int | None = None):
        """Weighted SSD maps for a batch of blocks of one shape.

        Parameters
        ----------
        targets : (n, bh, bw, C) float32
            Existing content (only read where its weight is > 0).
        weights : (n, bh, bw) or (n, G, bh, bw) float32
            Non-negative weight of every block pixel, per channel group.

        Returns
        -------
        (n, H - bh + 1, W - bw + 1) float32
            ``e(p)`` for every anchor ``p`` (clipped at 0 against float round-off).
        ``workers`` overrides the spectrum's FFT workers for this call.
        """
        t = np.asarray(targets, dtype=np.float32)
        wts = np.asarray(weights, dtype=np.float32)
        if wts.ndim == 3:
            wts = wts[:, None]
        c = t.shape[3]
        if c != self.channels:
            raise ValueError(f"targets must have {self.channels} channels, got {c}")
        tt = t.transpose(0, 3, 1, 2)  # (n, C, bh, bw): np.moveaxis(t, 3, 1), a third the cost
        k = (wts if len(self.groups) == 1 else wts[:, self.group_of]) * tt  # broadcast: same
        return self.ssd_weighted(tt, wts, k, workers=workers)

    def ssd_weighted(self, tt, wts, k, *, workers: int | None = None) -> np.ndarray:
        """:meth:`ssd` of targets ``tt`` (n, C, bh, bw) float32, weights ``wts`` (n, G, bh, bw)
        float32 and the weighted targets ``k`` (n, C, bh, bw), given (quilting's
        :func:`engine.quilting.kernels.query_inputs` makes them in one pass)."""
        const = np.einsum("nchw,nchw->n", k, tt, dtype=np.float64)
        return self.ssd_terms(k, wts, const, workers=workers)

    def ssd_terms(self, kernels, weights, const, *, workers: int | None = None) -> np.ndarray:
        """``const − 2 Σ_c corr(S_c, K_c) + Σ_g corr(Σ_{c∈g} S_c², W_g)`` at every position.

        The general form behind :meth:`ssd`: any weighted sum of squared differences against
        several targets expands into it (texture transfer mixes the overlap, the previous
        iteration and the correspondence map). ``kernels`` (n, C, bh, bw), ``weights``
        (n, G, bh, bw), ``const`` (n,). Clipped at 0 against float round-off.
        """
        k = np.asarray(kernels, dtype=np.float32)
        wts = np.asarray(weights, dtype=np.float32)
        n, c, bh, bw = k.shape
        h, w = self.shape
        if c != self.channels or wts.shape != (n, len(self.groups), bh, bw):
            raise ValueError(
                f"kernels must be (n, {self.channels}, bh, bw) and weights "
                f"(n, {len(self.groups)}, bh, bw), got {k.shape} and {wts.shape}"
            )
        if bh > h or bw > w:
            raise ValueError(f"block {bw}x{bh} is larger than the sample {w}x{h}")
        const = np.asarray(const, dtype=np.float64).astype(np.float32)
        compiled = jit.loaded()
        y = self.terms(k, wts, workers, compiled=compiled)
        if not compiled:  # a small job without numba: the same values from numpy
            y += const[:, None, None]
            np.maximum(y, 0, out=y)
            return y
        e = np.empty((n, h - bh + 1, w - bw + 1), np.float32)
        _add_clip(y, const, e)
        return e

    def terms(self, k, wts, workers=None, *, compiled: bool) -> np.ndarray:
        """:meth:`ssd_terms` before its constant: ``Σ_c −2 corr(S_c, K_c) + Σ_g corr(Σ S_c²,
        W_g)`` (n, rows, cols) float32 for validated float32 ``k`` and ``wts`` (``compiled``:
        a view of the thread's kept buffer, valid until its next query)."""
        n, _, bh, bw = k.shape
        h, w = self.shape
        add = self._weight_terms(wts, workers)  # first: the kernels' spectra are a kept buffer
        fk = self._conj_spectra(k, workers)
        x = product_sum(fk, self._hs, add)
        if not compiled:
            return self._inverse(x, h - bh + 1, w - bw + 1, workers)
        # the inverse into the kernels' spectra, read by now (a thread's kept buffer, in cache;
        # each query's slab holds its (hp, w - bw + 1) real values)
        hp, cols = self.padded[0], w - bw + 1
        out = fk.reshape(n, -1).view(np.float32)[:, : hp * cols].reshape(n, hp, cols)
        return self._inverse_rows(x, h - bh + 1, cols, workers, out)


class TiledSpectrum(SampleSpectrum):
    """:class:`SampleSpectrum`'s queries with memory bounded by a tile instead of the sample.

    The anchors are cut into tiles of ``tile`` × ``tile``; each query transforms the sample
    region a tile's windows cover (``tile + block - 1`` pixels a side) and queries it, so no
    spectrum of the whole sample is ever held: memory grows with the tile, time about doubles
    (every query transforms the sample's tiles again). The errors equal the whole-sample
    query's up to float round-off.
    """

    def __init__(self, sample: np.ndarray, *, groups=None, workers: int = 1, tile: int = 1024):
        self._setup(sample, groups, workers, None)
        self.tile = positive_int(tile, "tile")

    @property
    def nbytes(self) -> int:
        return 0

    def correlate(self, kernels: np.ndarray) -> np.ndarray:
        raise NotImplementedError("a tiled spectrum answers ssd queries only")

    def ssd_terms(self, kernels, weights, const, *, workers: int | None = None) -> np.ndarray:
        k = np.asarray(kernels, dtype=np.float32)
        n, _, bh, bw = k.shape
        h, w = self.shape
        if bh > h or bw > w:
            raise ValueError(f"block {bw}x{bh} is larger than the sample {w}x{h}")
        t = self.tile
        out = np.empty((n, h - bh + 1, w - bw + 1), np.float32)
        wk = self.workers if workers is None else workers
        for y0 in range(0, h - bh + 1, t):
            for x0 in range(0, w - bw + 1, t):
                region = self.sample[y0 : y0 + t + bh - 1, x0 : x0 + t + bw - 1]
                spec = SampleSpectrum(region, groups=self.groups, workers=wk, backend=self.backend)
                part = spec.ssd_terms(k, weights, const, workers=wk)
                out[:, y0 : y0 + part.shape[1], x0 : x0 + part.shape[2]] = part
        return out


@njit(cache=True, nogil=True)
def _add_clip(y, const, out):  # pragma: no cover - compiled
    """out[i] = max(y[i, :, :out_w] + const[i], 0) (float32), into a contiguous map."""
    n, rows, cols = out.shape
    for i in range(n):
        c = const[i]
        for u in range(rows):
            for v in range(cols):
                e = y[i, u, v] + c
                out[i, u, v] = e if e >= 0 or e != e else np.float32(0)


def masked_ssd(sample, target, mask, *, threads: int | None = None) -> np.ndarray:
    """Masked SSD of ``target`` against every window of ``sample`` (ALGORITHMS.md §0).

    Parameters
    ----------
    sample : (H, W[, C]) array_like
    target : (bh, bw[, C]) array_like
        Existing content; only its pixels where ``mask`` is set count.
    mask : (bh, bw) array_like of bool or float
        The overlap (or any non-negative weights).
    threads : int, optional
        FFT workers.

    Returns
    -------
    (H - bh + 1, W - bw + 1) float32 ndarray
        ``Σ_mask Σ_c (sample[y+u, x+v, c] − target[u, v, c])²`` at every anchor (y, x).
    """
    s = as_image(sample, "sample")
    t = as_image(target, "target")
    m = np.asarray(mask, dtype=np.float32)
    if m.shape != t.shape[:2]:
        raise ValueError(f"mask must be shaped like target {t.shape[:2]}, got {m.shape}")
    if t.shape[2] != s.shape[2]:
        raise ValueError(f"target has {t.shape[2]} channels, sample has {s.shape[2]}")
    if np.any(m < 0):
        raise ValueError("mask weights must be non-negative")
    spec = SampleSpectrum(s, workers=_workers(threads))
    return spec.ssd(t[None], m[None])[0]


@njit(cache=True, nogil=True)
def _gather_ssd(sample, anchors, mask, target, out):  # pragma: no cover - compiled
    """out[k] = Σ_{mask} Σ_ch (sample[anchor k + (u, v), ch] - target[u, v, ch])² in float64,
    summed in row-major order of the mask's pixels, channels innermost.

    The mask is read as runs of pixels along its rows, which are contiguous in the sample;
    four anchors share a pass, so their independent sums overlap in the pipeline instead of
    waiting on one another (the same additions in the same order, the same results)."""
    sw, c = sample.shape[1], sample.shape[2]
    flat = sample.ravel()
    runs, values = mask_runs(sample, target, mask)  # (offset in a window, length, first value)
    nr = runs.shape[0]
    n = anchors.shape[0]
    for k0 in range(0, n, 4):
        ks = (k0, min(k0 + 1, n - 1), min(k0 + 2, n - 1), min(k0 + 3, n - 1))
        b0 = (anchors[ks[0], 0] * sw + anchors[ks[0], 1]) * c
        b1 = (anchors[ks[1], 0] * sw + anchors[ks[1], 1]) * c
        b2 = (anchors[ks[2], 0] * sw + anchors[ks[2], 1]) * c
        b3 = (anchors[ks[3], 0] * sw + anchors[ks[3], 1]) * c
        a0 = a1 = a2 = a3 = 0.0
        for r in range(nr):
            off, length, first = runs[r, 0], runs[r, 1], runs[r, 2]
            for t in range(length):
                x = values[first + t]
                d0 = np.float64(flat[b0 + off + t]) - x
                d1 = np.float64(flat[b1 + off + t]) - x
                d2 = np.float64(flat[b2 + off + t]) - x
                d3 = np.float64(flat[b3 + off + t]) - x
                a0 += d0 * d0
                a1 += d1 * d1
                a2 += d2 * d2
                a3 += d3 * d3
        out[ks[0]] = a0
        out[ks[1]] = a1  # a repeated last anchor writes the same value again
        out[ks[2]] = a2
        out[ks[3]] = a3


def ssd_at(sample: np.ndarray, anchors: np.ndarray, target: np.ndarray, mask: np.ndarray):
    """Exact masked SSD at a few anchors ((k, 2) rows of (y, x)); float64 (k,).

    ``Σ_mask Σ_c (sample[y+u, x+v, c] − target[u, v, c])²`` accumulated in float64."""
    a = np.ascontiguousarray(np.asarray(anchors, dtype=np.int64).reshape(-1, 2))
    out = np.empty(len(a), np.float64)
    _gather_ssd(
        np.ascontiguousarray(sample),
        a,
        np.ascontiguousarray(mask, dtype=bool),
        np.asarray(target),
        out,
    )
    return out


def error_floor(sample: np.ndarray) -> float:
    """Mean squared difference of adjacent sample pixels per channel (the texture's own
    pixel-to-pixel variation), used to decide when an overlap error counts as zero."""
    s = np.asarray(sample, dtype=np.float32)
    h, w = s.shape[:2]
    sx = sy = 0.0
    for y in range(0, h, 256):  # strips: no temporary of the sample's size
        strip = s[y : y + 257]  # one row of overlap for the vertical steps
        if w > 1:
            d = strip[: min(256, h - y), 1:] - strip[: min(256, h - y), :-1]
            sx += float(np.einsum("ijk,ijk->", d, d, dtype=np.float64))
        if len(strip) > 1:
            d = strip[1:] - strip[:-1]
            sy += float(np.einsum("ijk,ijk->", d, d, dtype=np.float64))
    dx = sx / (h * (w - 1) * s.shape[2]) if w > 1 else 0.0
    dy = sy / ((h - 1) * w * s.shape[2]) if h > 1 else 0.0
    return float(max((dx + dy) / 2, 1e-12))


ZERO_ERROR_FRACTION = 0.5
"""δ of ALGORITHMS §2.2 ("if e_min ≈ 0 use e_min + δ") as a fraction of ``error_floor · |M| · C``:
a window whose overlap differs per pixel by half the texture's own adjacent-pixel variation is as
good as an exact copy. (On the bundled samples the best non-copy window of a 32 px block scores
about 1–4 × ``error_floor`` per pixel; 8–38 % of the blocks have an exact copy.)"""


def select_within_tolerance(errors: np.ndarray, *, tolerance: float, zero_level: float, rng):
    """Choose uniformly among the entries with ``e ≤ (1 + tolerance) · max(e_min, zero_level)``.

    ``errors`` is any array (``inf`` = forbidden). ``zero_level`` implements ALGORITHMS §2.2's
    "if e_min ≈ 0 use e_min + δ": without it only exact copies would ever qualify after a copy
    whose error is 0. Returns ``(flat index, e_min, number of qualifying entries)``.
    """
    flat = errors.ravel()
    small = not jit.loaded()  # the same result without starting numba (a small job)
    if not small and type(tolerance) is float and type(zero_level) is float:
        # the least error, the limit and the count in one call (the same float64 arithmetic;
        # numpy scalars may round in their own type: the general lines below)
        i_min, e_min, n, limit = least_and_count(flat, tolerance, zero_level)
        if not math.isfinite(e_min):
            raise ValueError("no valid candidate position (every position is excluded)")
        if n == 0:  # float round-off
            return i_min, e_min, 1
        return int(kth_at_most(flat, limit, rng.integers(n))), e_min, n
    i_min = _argmin_numpy(flat) if small else int(_argmin(flat))
    e_min = float(flat[i_min])
    if not math.isfinite(e_min):
        raise ValueError("no valid candidate position (every position is excluded)")
    limit = flat.dtype.type((1.0 + tolerance) * max(e_min, zero_level))  # compared in e's dtype
    if small:
        at_most = np.flatnonzero(flat <= limit)
        n = at_most.size
    else:
        n = int(_count_at_most(flat, limit))
    if n == 0:  # float round-off
        return i_min, e_min, 1
    k = rng.integers(n)
    return int(at_most[k] if small else kth_at_most(flat, limit, k)), e_min, n


def _argmin_numpy(flat: np.ndarray) -> int:
    """:func:`_argmin`'s answer: the first of equal minima, NaN skipped unless it comes first."""
    i = int(np.argmin(flat))
    if np.isnan(flat[i]) and not np.isnan(flat[0]):
        i = int(np.argmin(np.where(np.isnan(flat), np.inf, flat)))
    return i


@njit(cache=True, nogil=True)
def _argmin(flat):  # pragma: no cover - compiled
    """``np.argmin`` without the GIL (first of equal minima; NaN skipped unless it comes first).

    The least value first, in a loop of independent compares (no index carried: ~3x faster)
    kept in 8 lanes (every lane starts at ``flat[0]``; NaN never replaces a value; the least
    of the lanes is the least value: a chain of compares one lane long waits on the one
    before, so 8 lanes overlap: a 97² map 9.7 -> 3.5 us), then its first position."""
    n = flat.size
    lanes = np.empty(8, flat.dtype)
    lanes[:] = flat[0]
    m = (n - 1) // 8 * 8 + 1
    for j in range(1, m, 8):
        for q in range(8):
            v = flat[j + q]
            lanes[q] = v if v < lanes[q] else lanes[q]
    best = flat[0]
    for q in range(8):
        best = lanes[q] if lanes[q] < best else best
    for j in range(m, n):
        v = flat[j]
        best = v if v < best else best
    if best != best:  # NaN first
        return 0
    for j in range(n):
        if flat[j] == best:
            return j
    return 0


@njit(cache=True, nogil=True)
def least_and_count(flat, tolerance, zero_level):  # pragma: no cover - compiled
    """:func:`select_within_tolerance`'s first steps for float ``tolerance`` and ``zero_level``:
    (first index of the least value, that value, the number of values <= the limit, the limit
    in ``flat``'s dtype); the count is 0 when the least value is not finite."""
    i = _argmin(flat)
    e = np.float64(flat[i])
    lim = np.empty(1, flat.dtype)  # the limit rounded to flat's dtype, as numpy's scalar does
    if not np.isfinite(e):
        lim[0] = e
        return i, e, 0, lim[0]
    lim[0] = (1.0 + tolerance) * (zero_level if zero_level > e else e)  # Python's max(e, z)
    return i, e, _count_at_most(flat, lim[0]), lim[0]


@njit(cache=True, nogil=True)
def _count_at_most(flat, limit):  # pragma: no cover - compiled
    n = 0
    for j in range(flat.size):
        n += np.int64(flat[j] <= limit)  # branch-free: vectorised
    return n


@njit(cache=True, nogil=True)
def kth_at_most(flat, limit, k):  # pragma: no cover - compiled
    """Index of the ``k``-th (0-based) entry ``<= limit``."""
    for j in range(flat.size):
        if flat[j] <= limit:
            if k == 0:
                return j
            k -= 1
    return -1


# ---------------------------------------------------------------------------- fast mode
@njit(cache=True, nogil=True, fastmath=True)
def _estimates(q, features, base, base_row, invalid, out):  # pragma: no cover - compiled
    """out[i, j] = base[base_row[i], j] - 2 Σ_k q[i, k] features[k, j]; inf where invalid[j].

    A plain loop: single-threaded and bit-identical whatever the batch (a threaded BLAS
    product is both slower at this size on small machines and batch dependent). Each feature
    row serves every target of the batch while it is in cache (job B's index is 4 MB, read
    once a batch instead of once a target: a batch of 3 in 336 instead of 449 us); every
    estimate is still its base plus the components in order, the same bits."""
    n, kk = q.shape
    nn = features.shape[1]
    for i in range(n):
        row = out[i]
        b = base[base_row[i]]
        for j in range(nn):
            row[j] = b[j]
    for k in range(kk):
        f = features[k]
        for i in range(n):
            c = np.float32(-2.0) * q[i, k]  # float32 products: twice the vector width
            if c == 0.0:
                continue
            row = out[i]
            for j in range(nn):
                row[j] += c * f[j]
    for i in range(n):
        row = out[i]
        for j in range(nn):
            if invalid[j]:
                row[j] = np.inf


@njit(cache=True, nogil=True)
def _rank(
    q, features, base, base_row, invalid, m, anchor_w, sample, targets, masks
):  # pragma: no cover - compiled
    """Everything of a fast query after the projections ``q``, in one call without the GIL:
    the estimates, the ``m`` best finite ones per target, their exact SSDs and their order.

    Returns anchors (n, m, 2), exact errors (n, m) sorted ascending (stable) and the number
    of valid rows per target (the rest is padding)."""
    n = q.shape[0]
    nn = features.shape[1]
    est = np.empty((n, nn), np.float32)
    _estimates(q, features, base, base_row, invalid, est)
    anchors = np.zeros((n, m, 2), np.int64)
    errors = np.full((n, m), np.inf)
    counts = np.zeros(n, np.int64)
    for i in range(n):
        idx = smallest_indices(est[i], m)
        idx = idx[np.isfinite(est[i][idx])]
        a = np.empty((idx.size, 2), np.int64)
        for r in range(idx.size):
            a[r, 0], a[r, 1] = idx[r] // anchor_w, idx[r] % anchor_w
        exact = np.empty(idx.size, np.float64)
        _gather_ssd(sample, a, masks[i], targets[i], exact)
        order = np.argsort(exact, kind="mergesort")
        counts[i] = idx.size
        for r in range(idx.size):
            anchors[i, r] = a[order[r]]
            errors[i, r] = exact[order[r]]
    return anchors, errors, counts


@njit(cache=True, nogil=True, fastmath=True)
def _matmul(a, b):  # pragma: no cover - compiled
    """``a @ b`` on one thread. The PCA's products are a few million multiply-adds; a threaded
    BLAS spends longer waking its helper thread than computing them when the machine is busy."""
    n, d = a.shape
    r = b.shape[1]
    out = np.zeros((n, r))
    for i in range(n):
        for k in range(d):
            aik = a[i, k]
            for j in range(r):
                out[i, j] += aik * b[k, j]
    return out


@njit(cache=True, nogil=True)
def smallest_indices(values, m):  # pragma: no cover - compiled
    """Indices of the ``m`` smallest of ``values`` (1-D), ascending; ties by index.

    A threshold from a strided sample keeps about 8 ``m`` candidates in one pass, then only
    those are sorted (falls back to a full sort when the threshold keeps fewer than ``m``).
    Runs without the GIL, unlike ``np.argpartition``.
    """
    nn = values.shape[0]
    if m >= nn:
        return np.argsort(values, kind="mergesort")[:m]
    step = max(1, nn // 2048)
    sample = values[::step].copy()
    k = min(sample.shape[0] - 1, (8 * m * sample.shape[0]) // nn + 1)
    tau = np.partition(sample, k)[k]
    cap = 32 * m + 256
    keep = np.empty(cap, np.int64)
    c = 0
    for j in range(nn):
        if values[j] <= tau:
            if c == cap:  # a threshold far too loose (many ties): sort everything
                return np.argsort(values, kind="mergesort")[:m]
            keep[c] = j
            c += 1
    if c < m:
        return np.argsort(values, kind="mergesort")[:m]
    keep = keep[:c]
    order = np.argsort(values[keep], kind="mergesort")
    return keep[order[:m]]


def _orthonormal(y: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the columns of ``y`` (n, r) via the tiny r×r Gram matrix."""
    lam, v = np.linalg.eigh(_matmul(np.ascontiguousarray(y.T), y))
    keep = lam > lam.max() * 1e-10
    return _matmul(y, np.ascontiguousarray(v[:, keep] / np.sqrt(lam[keep])))


def _randomized_pca(x: np.ndarray, k: int, rng, *, power: int = 1) -> np.ndarray:
    """Top ``k`` principal directions (k, d) of the rows of ``x`` (Halko et al. range finder).

    Only products with ``x`` (single-threaded, :func:`_matmul`) and eigen-decompositions of
    r×r matrices (r = k + 8).
    """
    x = np.ascontiguousarray(x - x.mean(axis=0), dtype=np.float64)
    xt = np.ascontiguousarray(x.T)
    r = min(k + 8, min(x.shape))
    y = _matmul(x, rng.standard_normal((x.shape[1], r)))
    for _ in range(power):
        y = _matmul(x, _matmul(xt, _orthonormal(y)))
    b = _matmul(np.ascontiguousarray(_orthonormal(y).T), x)  # (r', d)
    lam, u = np.linalg.eigh(_matmul(b, np.ascontiguousarray(b.T)))
    order = np.argsort(lam)[::-1][:k]
    comps = _matmul(np.ascontiguousarray(u[:, order].T), b)
    comps /= np.sqrt(np.maximum(lam[order], 1e-30))[:, None]
    return np.ascontiguousarray(comps, dtype=np.float32)


class PCAMatcher:
    """Approximate nearest candidates for an L-shaped overlap, then exact re-ranking.

    The overlap of a ``block`` = (bh, bw) block with arms ``top`` rows and ``left`` columns is cut
    into three disjoint parts: the corner (top × left), the rest of the left arm and the rest of
    the top arm. Each part gets ``components`` principal components (randomized PCA of ≤ 128
    random sample windows); the projections of every sample window on them are computed by FFT
    correlation. A query with the parts it has (left arm only, top arm only, or both) ranks all
    windows by ``‖f‖² − 2·proj(f)·proj(T)`` (``‖f‖²`` exact, from a summed-area table; the
    constant ``‖T‖²`` dropped) and re-ranks the ``rerank`` best by the exact SSD.
    """

    def __init__(
        self, spectrum: SampleSpectrum, block, *, top: int, left: int, components: int = 8, rng=None
    ):
        self.spec = spectrum
        s = spectrum.sample
        bh, bw = int(block[0]), int(block[1])
        self.block = (bh, bw)
        self.top, self.left = int(top), int(left)
        h, w, c = s.shape
        self.anchor_shape = (h - bh + 1, w - bw + 1)
        rng = as_rng(rng)
        rects = {
            "corner": (0, 0, self.top, self.left),
            "left": (self.top, 0, bh - self.top, self.left),
            "top": (0, self.left, self.top, bw - self.left),
        }
        self.rects = {k: r for k, r in rects.items() if r[2] > 0 and r[3] > 0}
        na = self.anchor_shape[0] * self.anchor_shape[1]
        picks = rng.choice(na, size=min(na, 128), replace=False)
        py, px = np.divmod(picks, self.anchor_shape[1])
        sat = summed_area(np.sum(s.astype(np.float64) ** 2, axis=2))
        self.bases: dict[str, np.ndarray] = {}
        self.norms: dict[str, np.ndarray] = {}
        self.offsets: dict[str, tuple[int, int]] = {}
        kernels = []
        i = 0
        for name, (y0, x0, rh, rw) in self.rects.items():
            win = s[
                py[:, None, None] + y0 + np.arange(rh)[None, :, None],
                px[:, None, None] + x0 + np.arange(rw)[None, None, :],
            ]
            x = win.reshape(len(picks), -1)
            k = min(int(components), x.shape[1], max(len(picks) - 1, 1))
            basis = _randomized_pca(x, k, rng)
            self.bases[name] = basis
            self.offsets[name] = (i, i + k)
            i += k
            kern = np.zeros((k, c, bh, bw), np.float32)
            kern[:, :, y0 : y0 + rh, x0 : x0 + rw] = np.moveaxis(basis.reshape(k, rh, rw, c), 3, 1)
            kernels.append(kern)
            self.norms[name] = box_sums_float(sat, (rh, rw), (y0, x0), self.anchor_shape).astype(
                np.float32
            )
        proj = spectrum.correlate(np.concatenate(kernels))
        self.features = np.ascontiguousarray(proj.reshape(i, -1))  # (K, N)
        # ‖f‖² of every window summed over the parts of each overlap that parts_for knows
        shapes = {self.parts_for(*a) for a in ((top, left), (0, left), (top, 0))} - {()}
        self._base_row = {parts: r for r, parts in enumerate(sorted(shapes))}
        self._base = np.zeros((len(shapes), na), np.float32)
        for parts, r in self._base_row.items():
            for name in parts:
                self._base[r] += self.norms[name].ravel()

    def parts_for(self, top: int, left: int) -> tuple[str, ...]:
        """Parts covered by an overlap with ``top`` rows and ``left`` columns, or () if the
        overlap is not one this index describes."""
        if (top, left) == (self.top, self.left):
            return tuple(self.rects)
        if top == 0 and left == self.left:
            return tuple(n for n in ("corner", "left") if n in self.rects)
        if left == 0 and top == self.top:
            return tuple(n for n in ("corner", "top") if n in self.rects)
        return ()

    def query(self, targets, parts_list, valid, *, rerank: int, mask_list):
        """Best ``rerank`` anchors by the exact SSD for each target.

        ``targets`` (n, bh, bw, C); ``parts_list`` the parts of each; ``valid`` the allowed
        anchors (bool, anchor_shape) or None; ``mask_list`` each target's overlap mask.
        Returns a list of ``(anchors (k, 2), exact errors (k,))`` sorted by error.
        """
        n = len(targets)
        nn = self.features.shape[1]
        q = np.zeros((n, self.features.shape[0]), np.float32)
        base_row = np.empty(n, np.intp)
        for i, (t, parts) in enumerate(zip(targets, parts_list, strict=True)):
            for name in parts:
                y0, x0, rh, rw = self.rects[name]
                a, b = self.offsets[name]
                q[i, a:b] = self.bases[name] @ t[y0 : y0 + rh, x0 : x0 + rw].ravel()
            base_row[i] = self._base_row[tuple(parts)]
        invalid = np.zeros(nn, bool) if valid is None else ~valid.ravel()
        anchors, errors, counts = _rank(
            q,
            self.features,
            self._base,
            base_row,
            invalid,
            min(int(rerank), nn),
            self.anchor_shape[1],
            self.spec.sample,
            np.stack(targets),
            np.stack(mask_list).astype(bool, copy=False),
        )
        return [(a[:k], e[:k]) for a, e, k in zip(anchors, errors, counts, strict=True)]


def summed_area(values: np.ndarray) -> np.ndarray:
    """Summed-area table (H + 1, W + 1) float64 of a 2-D array."""
    h, w = values.shape
    sat = np.zeros((h + 1, w + 1), np.float64)
    np.cumsum(np.cumsum(values, axis=0), axis=1, out=sat[1:, 1:])
    return sat


def box_sums_float(sat: np.ndarray, box, offset=(0, 0), shape=None) -> np.ndarray:
    """Sums over ``box`` = (bh, bw) windows from a summed-area table, for the windows whose
    top-left corners are ``offset + (0..shape)`` (default: every window that fits)."""
    bh, bw = box
    y0, x0 = offset
    if shape is None:
        shape = (sat.shape[0] - bh - y0, sat.shape[1] - bw - x0)
    ys, xs = slice(y0, y0 + shape[0]), slice(x0, x0 + shape[1])
    ye, xe = slice(y0 + bh, y0 + bh + shape[0]), slice(x0 + bw, x0 + bw + shape[1])
    return sat[ye, xe] - sat[ys, xe] - sat[ye, xs] + sat[ys, xs]


def check_block(block, name: str = "block") -> tuple[int, int]:
    """``block`` as (bh, bw) from an int or a pair of ints."""
    if isinstance(block, tuple | list):
        if len(block) != 2:
            raise ValueError(f"{name} must be an int or (height, width), got {block!r}")
        return positive_int(block[0], name), positive_int(block[1], name)
    b = positive_int(block, name)
    return b, b
