"""Coarse-to-fine block search whose cost does not grow with the sample's area.

The exact search (:class:`engine.matching.SampleSpectrum`) scores every sample position by FFT:
its cost and memory grow with the sample's area, about a second per block at 4096². Here the
sample is reduced by 2 × 2 box averages into a pyramid until its top level holds at most
:data:`COARSE_AREA` pixels (or the overlap would shrink below one pixel); a block's target and
weights are reduced alike, so the weighted SSD at level ``l`` approximates the full-resolution
one over ``4^l``.

1. **Coarse**: the exact weighted SSD of every position of the top level (one small FFT query),
   and its ``keep`` best positions at least two coarse pixels apart (so they are ``keep``
   different places of the sample, not one place and its shifts).
2. **Refine**: each level down, the 3 × 3 children around ``2p`` of every candidate ``p`` are
   scored exactly at that level, the best child of each is kept, and the ``keep`` best of
   those go on.
3. **Exact re-ranking** at full resolution: every child of the last level's candidates, plus the
   *seeds* (the caller's guesses: the positions that continue the neighbouring blocks' source
   windows, PatchMatch's propagation) and their 3 × 3 neighbourhoods, scored by the exact
   weighted SSD in float64 (:func:`weighted_ssd_at`, the same sum as
   :func:`engine.matching.ssd_at` for 0/1 weights).

The caller draws among the re-ranked candidates exactly as the exhaustive search draws among
all positions. Per block this costs one query of a ≤ ``COARSE_AREA`` sample plus
``keep × 9`` exact SSDs per level: independent of the sample's area beyond the pyramid's
construction (linear, once) and its memory (a third of the sample's).

Why this search (README, "How the large search works and why"): the principal-component index
of the fast mode stores K numbers per sample position (1.6 GB at 4096², K = 24) and scans them all
per block, so it grows with the area; the pyramid's top level is a small exhaustive search, so no
region of the sample is missed, and its candidates are exact after re-ranking. The measured
choices (the 2-pixel floor of the overlap, 128 top-level places, 3 × 3 children) are in the
README.
"""

from __future__ import annotations

import math

import numpy as np

from engine._jit import njit
from engine.matching import SampleSpectrum, smallest_indices

__all__ = [
    "COARSE_AREA",
    "quilt_keeps",
    "PyramidSearch",
    "box_reduce",
    "pyramid_levels",
    "reduce_target",
    "weighted_ssd_at",
]

COARSE_AREA = 256 * 256
"""Largest top level of the pyramid (pixels): its exhaustive FFT query is a fraction of a
millisecond per block."""

MIN_COARSE_OVERLAP = 2
"""The top level keeps at least this many pixels of the overlap: a 1-pixel strip of 16 × 16
means ranks the true best window among the first few hundred of a 4096² sample only about
half the time (brick, measured), a 2-pixel strip most of the time."""

MAX_COARSE_AREA = 1024 * 1024
"""A top level larger than this (the overlap too thin to reduce further) is reduced anyway."""

CHILDREN = np.array([(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)], np.int64)
"""Offsets of a candidate's children one level down, around ``2p``: a window at ``2p + 1``
lies half a coarse pixel from both ``p`` and ``p + 1``, so each parent covers one position on
either side (16 children, up to ``2p + 2``, found the same windows in twice the time)."""

DEEP_LEVELS = 3
"""Pyramids at least this deep (a 4096² sample with a 16-pixel overlap) keep more candidates in
quilting's search (:func:`quilt_keeps`)."""


def quilt_keeps(levels: int) -> tuple[int, int]:
    """Quilting's ``(keep, coarse_keep)`` for a pyramid of ``levels`` reductions.

    Measured (2048² outputs from 4096² samples, 3 levels, block 96, overlap 16, grid border
    ratio against the exact search's, seed 0): with 128 top-level places and 24 kept per level,
    cobblestones came 5.4 % and coffee-wood 5.6 % above the exact search; with 512 and 32, 1.7 %
    and 3.6 % (every other sample within 5 % too) and the chosen windows' mean error 2 % and 8 %
    lower; 1024 places found no better ones, 64 kept cost 1.4 s more for little. Over seeds 0-5
    the ratio moves by more than this change (README, "How the large search works and why").
    Shallower pyramids, whose top level keeps more of the overlap, keep 24 and 128: 512 places'
    children scored at full resolution would cost more than the exhaustive search there."""
    return (32, 512) if levels >= DEEP_LEVELS else (24, 128)


SEED_NEIGHBOURS = np.array([(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)], np.int64)


def box_reduce(a: np.ndarray) -> np.ndarray:
    """One pyramid step: 2 × 2 means of ``a`` (h, w, C), the last odd row/column dropped."""
    h, w = a.shape[0] // 2 * 2, a.shape[1] // 2 * 2
    x = a[:h, :w]
    out = x[0::2, 0::2] + x[1::2, 0::2]
    out += x[0::2, 1::2]
    out += x[1::2, 1::2]
    out *= np.float32(0.25)
    return out


def pyramid_levels(
    shape, block, overlap: int, *, coarse_area: int = COARSE_AREA, min_block: int = 4
) -> int:
    """Number of 2× reductions for a sample of ``shape`` (H, W) and blocks ``block`` (bh, bw)
    with ``overlap`` (0: search exactly).

    Enough to bring the sample to ``coarse_area`` pixels, but no more than keeps
    :data:`MIN_COARSE_OVERLAP` pixels of the overlap and ``min_block`` of the block (texture
    transfer, which matches whole blocks, passes the block as the overlap and 2); if the top
    level is then still over :data:`MAX_COARSE_AREA` (a thin overlap on a huge sample), as many as
    bring it down while the block keeps 2 pixels (the overlap's weights become fractions of a
    pixel: a weaker top level, but a bounded one)."""
    h, w = int(shape[0]), int(shape[1])

    def most(overlap_px: float, block_px: int) -> int:
        lev = 0
        while (
            need > lev
            and overlap / 2 ** (lev + 1) >= overlap_px
            and min(block) >> (lev + 1) >= block_px
        ):
            lev += 1
        return lev

    need = 0
    while (h >> need) * (w >> need) > coarse_area:
        need += 1
    lev = most(MIN_COARSE_OVERLAP, min_block)
    if (h >> lev) * (w >> lev) > MAX_COARSE_AREA:
        lev = max(lev, most(0, 2))
    return lev


def reduce_target(target: np.ndarray, weights: np.ndarray, group_of: np.ndarray):
    """One pyramid step of a block's target (h, w, C) and weights (h, w, G): weights are 2 × 2
    means (a partly covered cell weighs less), the target the weighted mean of each cell. Odd
    sizes are padded with zero weight, so the reduced block covers the whole block."""
    h, w = weights.shape[:2]
    ph, pw = h + h % 2, w + w % 2
    if (ph, pw) != (h, w):
        target = np.pad(target, ((0, ph - h), (0, pw - w), (0, 0)))
        weights = np.pad(weights, ((0, ph - h), (0, pw - w), (0, 0)))
    wsum = box_reduce(weights) * np.float32(4)
    num = box_reduce(target * weights[:, :, group_of]) * np.float32(4)
    wc = wsum[:, :, group_of]
    t = np.divide(num, wc, out=np.zeros_like(num), where=wc > 0)
    return t, wsum * np.float32(0.25)


@njit(cache=True, nogil=True)
def _weighs(weights, u, v) -> bool:  # pragma: no cover - compiled
    """Whether pixel (u, v) has a nonzero weight in any channel."""
    for ch in range(weights.shape[2]):  # noqa: SIM110 (numba: no generator in any())
        if weights[u, v, ch] != 0:
            return True
    return False


@njit(cache=True, nogil=True)
def _gather_weighted_ssd(sample, anchors, weights, target, out):  # pragma: no cover - compiled
    """out[k] = Σ_{u, v, c} weights[u, v, c] (sample[anchor k + (u, v), c] − target[u, v, c])²
    in float64, summed row-major over the pixels of nonzero weight, channels innermost (for
    0/1 weights the very sum :func:`engine.matching.ssd_at` computes)."""
    h, w, c = target.shape
    sw = sample.shape[1]
    flat = sample.ravel()
    runs = np.empty((h * w, 3), np.int64)  # (offset in a sample window, length, first entry)
    wts = np.empty(h * w * c, np.float64)
    vals = np.empty(h * w * c, np.float64)
    nr = nv = 0
    for u in range(h):
        v = 0
        while v < w:
            if not _weighs(weights, u, v):
                v += 1
                continue
            v1 = v
            start = nv
            while v1 < w and _weighs(weights, u, v1):
                for ch in range(c):
                    wts[nv] = weights[u, v1, ch]
                    vals[nv] = target[u, v1, ch]
                    nv += 1
                v1 += 1
            runs[nr, 0], runs[nr, 1], runs[nr, 2] = (u * sw + v) * c, nv - start, start
            nr += 1
            v = v1
    for k in range(anchors.shape[0]):
        base = (anchors[k, 0] * sw + anchors[k, 1]) * c
        acc = 0.0
        for r in range(nr):
            off, length, first = runs[r, 0], runs[r, 1], runs[r, 2]
            for t in range(length):
                d = np.float64(flat[base + off + t]) - vals[first + t]
                acc += wts[first + t] * (d * d)
        out[k] = acc


def weighted_ssd_at(sample, anchors, weights, target) -> np.ndarray:
    """Exact weighted SSD (float64, (k,)) of ``target`` (h, w, C) with per-channel ``weights``
    (h, w, C) against the sample windows at ``anchors`` ((k, 2) rows of (y, x))."""
    a = np.ascontiguousarray(np.asarray(anchors, dtype=np.int64).reshape(-1, 2))
    out = np.empty(len(a), np.float64)
    _gather_weighted_ssd(
        np.ascontiguousarray(sample),
        a,
        np.ascontiguousarray(weights, dtype=np.float32),
        np.ascontiguousarray(target, dtype=np.float32),
        out,
    )
    return out


@njit(cache=True, nogil=True)
def _spread_best(values, order, width, radius, keep):  # pragma: no cover - compiled
    """Walk ``order`` (indices of ``values`` ascending) and keep up to ``keep`` whose (row, col)
    in a map of ``width`` columns is more than ``radius`` from every kept one (a map of the kept
    places answers that in (2 radius + 1)² looks, not one per kept place: hundreds are kept)."""
    out = np.empty(keep, np.int64)
    height = values.size // width
    taken = np.zeros(values.size, np.bool_)
    n = 0
    for i in order:
        if not np.isfinite(values[i]):
            break
        y, x = i // width, i % width
        ok = True
        for yy in range(max(y - radius, 0), min(y + radius + 1, height)):
            for xx in range(max(x - radius, 0), min(x + radius + 1, width)):
                if taken[yy * width + xx]:
                    ok = False
        if ok:
            out[n] = i
            taken[i] = True
            n += 1
            if n == keep:
                break
    return out[:n]


class PyramidSearch:
    """Coarse-to-fine candidates for blocks of one sample (see the module docstring).

    Parameters
    ----------
    sample : (H, W, C) float32 ndarray
        The matched channels (kept by reference: level 0 of the pyramid is never copied).
    levels : int
        Reductions (:func:`pyramid_levels`); must be >= 1.
    groups : sequence of sequences of int, optional
        Channel groups sharing one weight map (as :class:`engine.matching.SampleSpectrum`).
    keep : int
        Candidates kept per level (coarse places, then the best child of each).
    workers : int
        FFT workers of the coarse query.
    """

    def __init__(
        self, sample, *, levels: int, groups=None, keep: int = 24, coarse_keep: int = 128, workers=1
    ):
        if levels < 1:
            raise ValueError(f"levels must be >= 1, got {levels}")
        s = np.asarray(sample)
        if s.dtype != np.float32 or s.ndim != 3:
            raise ValueError("sample must be a float32 (H, W, C) array")
        self.levels = [s]
        for _ in range(levels):
            self.levels.append(box_reduce(self.levels[-1]))
        self._setup(groups, keep, coarse_keep, workers)

    def shallower(self, levels: int) -> PyramidSearch:
        """The same pyramid searched from level ``levels`` (<= :attr:`depth`): the levels are
        shared, only the top level's spectrum is new (texture transfer's passes, whose blocks
        shrink, reuse one pyramid)."""
        if not 1 <= levels <= self.depth:
            raise ValueError(f"levels must lie in 1..{self.depth}, got {levels}")
        if levels == self.depth:
            return self
        out = object.__new__(PyramidSearch)
        out.levels = self.levels[: levels + 1]
        out._setup(self.coarse.groups, self.keep, self.coarse_keep, self.coarse.workers)
        return out

    def _setup(self, groups, keep, coarse_keep, workers) -> None:
        self.coarse = SampleSpectrum(self.levels[-1], groups=groups, workers=workers)
        self.group_of = self.coarse.group_of
        self.n_groups = len(self.coarse.groups)
        self.keep = int(keep)
        self.coarse_keep = int(coarse_keep)

    @property
    def depth(self) -> int:
        return len(self.levels) - 1

    @property
    def nbytes(self) -> int:
        """Memory held besides the sample itself."""
        return sum(a.nbytes for a in self.levels[1:]) + self.coarse.nbytes

    def query(self, target, weights, *, valid=None, seeds=(), workers: int = 1):
        """Candidate anchors of one block and their exact weighted SSDs.

        ``target`` (h, w, C) and ``weights`` (h, w, G) as in :meth:`SampleSpectrum.ssd_terms`
        (per group); ``valid`` the block's allowed full-resolution anchors (bool, or None);
        ``seeds`` guessed anchors ((n, 2), e.g. continuations of the neighbours' sources).
        Returns ``(anchors (k, 2) int64, errors (k,) float64)``, sorted by error (stable), every
        anchor distinct and allowed.
        """
        t = np.ascontiguousarray(target, dtype=np.float32)
        wg = np.ascontiguousarray(weights, dtype=np.float32)
        h, w = wg.shape[:2]
        pyr = [(t, wg)]
        for _ in range(self.depth):
            pyr.append(reduce_target(*pyr[-1], self.group_of))
        valids = self._valid_levels(valid, (h, w))
        top = self.depth
        tt, ww = pyr[top]
        cand = self._coarse(tt, ww, valids[top], workers)
        for lev in range(top - 1, 0, -1):
            tl, wl = pyr[lev]
            kids = 2 * cand[:, None, :] + CHILDREN[None]  # (n, 16, 2)
            ok = _inside(kids.reshape(-1, 2), tl.shape[:2], self.levels[lev].shape[:2], valids[lev])
            if not ok.any():
                break
            err = np.full(ok.size, np.inf)
            err[ok] = weighted_ssd_at(
                self.levels[lev], kids.reshape(-1, 2)[ok], wl[:, :, self.group_of], tl
            )
            cand = _best_per_parent(kids, err.reshape(kids.shape[:2]), self.keep)
        final = (2 * cand[:, None, :] + CHILDREN[None]).reshape(-1, 2)
        seeds = np.asarray(seeds, dtype=np.int64).reshape(-1, 2)
        if len(seeds):
            around = (seeds[:, None, :] + SEED_NEIGHBOURS[None]).reshape(-1, 2)
            final = np.concatenate([final.reshape(-1, 2), around])
        final = _allowed(np.unique(final, axis=0), (h, w), self.levels[0].shape[:2], valids[0])
        if not len(final):
            raise ValueError("no valid candidate position (every position is excluded)")
        err = weighted_ssd_at(self.levels[0], final, wg[:, :, self.group_of], t)
        order = np.argsort(err, kind="stable")
        return final[order], err[order]

    # ---------------------------------------------------------------- steps
    def _coarse(self, t, w, valid, workers):
        tt = np.moveaxis(t, 2, 0)[None]
        ww = np.moveaxis(w, 2, 0)[None]
        k = ww[:, self.group_of] * tt
        const = np.einsum("nchw,nchw->n", k, tt, dtype=np.float64)
        e = self.coarse.ssd_terms(k, ww, const, workers=workers)[0]
        if valid is not None:
            e[~valid] = np.inf
        flat = e.ravel()
        m = min(flat.size, 8 * self.coarse_keep)
        best = smallest_indices(flat, m)
        picks = _spread_best(flat, best, e.shape[1], 1, self.coarse_keep)
        if not len(picks):
            raise ValueError("no valid candidate position (every position is excluded)")
        return np.column_stack(np.divmod(picks, e.shape[1]))

    def _valid_levels(self, valid, shape):
        """Allowed anchors per level: a coarse anchor is allowed if any full-resolution anchor
        it stands for is (None: all)."""
        if valid is None:
            return [None] * (self.depth + 1)
        out = [np.asarray(valid, bool)]
        for lev in range(1, self.depth + 1):
            hl = self.levels[lev].shape[0] - math.ceil(shape[0] / 2**lev) + 1
            wl = self.levels[lev].shape[1] - math.ceil(shape[1] / 2**lev) + 1
            prev = out[-1]
            ph, pw = 2 * max(hl, 0), 2 * max(wl, 0)
            p = np.zeros((ph, pw), bool)
            ch, cw = min(ph, prev.shape[0]), min(pw, prev.shape[1])
            p[:ch, :cw] = prev[:ch, :cw]
            out.append(p[0::2, 0::2] | p[1::2, 0::2] | p[0::2, 1::2] | p[1::2, 1::2])
        return out


def _inside(anchors, block_shape, sample_shape, valid) -> np.ndarray:
    """Which anchors (n, 2) put a ``block_shape`` window inside the sample and are allowed."""
    y, x = anchors[:, 0], anchors[:, 1]
    ok = (y >= 0) & (x >= 0)
    ok &= (y <= sample_shape[0] - block_shape[0]) & (x <= sample_shape[1] - block_shape[1])
    if valid is not None:
        ok &= (y < valid.shape[0]) & (x < valid.shape[1])
        ok[ok] = valid[y[ok], x[ok]]
    return ok


def _allowed(anchors, block_shape, sample_shape, valid) -> np.ndarray:
    return anchors[_inside(anchors, block_shape, sample_shape, valid)]


def _best_per_parent(kids: np.ndarray, err: np.ndarray, keep: int) -> np.ndarray:
    """The best child of every parent (``kids`` (n, m, 2), ``err`` (n, m)), the ``keep`` best
    of those (finite errors, distinct)."""
    i = np.argmin(err, axis=1)
    rows = np.arange(len(kids))
    best, e = kids[rows, i], err[rows, i]
    order = np.argsort(e, kind="stable")
    order = order[np.isfinite(e[order])]
    _, first = np.unique(best[order], axis=0, return_index=True)
    return best[order[np.sort(first)][:keep]]
