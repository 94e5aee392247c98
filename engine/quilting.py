"""Image quilting: Efros & Freeman 2001 and the variants of Long & Mould, Bhatia, CS194, Core S2.

ALGORITHMS.md §0, §2, §3, §4, §5. ``iter_quilt`` synthesizes an output of any size from a
sample, streaming a :class:`BlockPlaced` item per block and :class:`~engine.events.Progress`;
``quilt`` drains it and returns the :class:`QuiltResult`.

Layout and order
    Blocks of ``block`` pixels lie on a grid with a step of ``block - overlap``; per axis
    ``ceil((N - overlap) / step)`` blocks, the last ones cropped (only their valid part is
    compared). ``tileable=True`` places ``ceil(N / step)`` evenly spaced blocks on a torus, so the
    last column and row overlap the first ones (wrap-around overlaps) and the output tiles.
    ``adaptive_threshold`` splits a block whose best overlap error is too high into four smaller
    overlapping blocks (recursively, down to ``min_block``), as in the hybrid framework Long &
    Mould built on.

Selection (``select``)
    ``"best"``: every sample position is scored by the masked SSD over the overlap (the *union* of
    the left and top strips, no double-counted corner; §2.2 FIX), computed for all positions at
    once by FFT (:mod:`engine.matching`); the block is drawn uniformly among the positions within
    ``1 + tolerance`` of the best. ``mode="fast"`` ranks positions by a principal-component
    estimate and re-ranks the ``candidates`` best exactly. ``"sampled"``: the best of
    ``candidates`` uniformly random positions (CS194: several hundred; Core S2: a dozen).
    ``"random"``: any position (CS194's naive baseline). ``"bhatia"``: Bhatia's random blocks on a
    non-overlapping grid whose neighbours' source *extensions* fill territories cut by minimum
    resistance lines (§4).

Boundary (``seam``)
    ``"straight"``: the new block covers the whole overlap (``blend="feather"`` cross-fades it);
    otherwise a cut by any :mod:`engine.seams` method through the overlap error map: the L-shaped
    overlap is cut as one path joined in the corner (:func:`engine.stitch.l_cut`), wrap-around
    arms get a cut each. ``blend`` softens the cut (``"feather"``: ``blend_width`` pixels;
    ``"adaptive"``: ρ-adaptive half-widths, §1.3).

Determinism and threads
    Every block draws from its own generator seeded by (seed, block index). A block depends on
    the earlier blocks (in raster order) whose footprints it touches; its *level* is one more
    than theirs, and blocks are placed in (level, raster) order, which gives exactly the raster
    result (blocks of one level neither read nor write each other's pixels). A block's search
    needs only its predecessors placed, so with ``threads > 1`` the searches (FFTs and numba
    kernels, which release the GIL) run ahead on a pool while blocks are placed. Each block is
    searched alone on exactly the canvas its predecessors left: the output is identical for any
    number of threads.
"""

from __future__ import annotations

import inspect
import math
import numbers
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage

from engine import seams as _seams
from engine._validate import as_image, as_rng, choice, non_negative_number, positive_int
from engine.blend import BLEND_MODES, ramp_from_mask
from engine.cancel import check
from engine.errormap import METRICS, colour_channels, error_map
from engine.events import Item, Progress, drain
from engine.exclusion import valid_anchors
from engine.matching import (
    ZERO_ERROR_FRACTION,
    PCAMatcher,
    SampleSpectrum,
    check_block,
    error_floor,
    select_within_tolerance,
    ssd_at,
)
from engine.stitch import from_canonical, l_cut, map_points, to_canonical

SELECTIONS = ("best", "random", "sampled", "bhatia")
MODES = ("exact", "fast")
SEAMS = ("straight", *_seams.METHODS)
DEFAULT_SAMPLED = 200
DEFAULT_RERANK = 32

__all__ = [
    "MODES",
    "SEAMS",
    "SELECTIONS",
    "BlockPlaced",
    "BlockRecord",
    "QuiltResult",
    "grid_border_ratio",
    "iter_quilt",
    "quilt",
]


# ------------------------------------------------------------------------------ results
@dataclass(frozen=True, slots=True)
class BlockRecord:
    """Everything about one placed block, small enough to keep for every block.

    Attributes
    ----------
    index : int
        Placement number (0, 1, ...), in the order the blocks were placed and streamed (the
        dependency order of the module docstring; sort by ``position`` for raster order).
    position : (int, int)
        (row, col) of the block's top-left pixel in the output (on a tileable output, pixels
        past the right or bottom edge wrap around).
    size : (int, int)
        (h, w) of the placed (possibly cropped) block.
    source : (int, int, int, int)
        (x, y, w, h) of the sample window copied.
    arms : (int, int, int, int)
        Overlap widths (top, left, bottom, right); bottom and right only on wrap-around.
    error : (h, w) float32 ndarray or None
        Error map of the overlap (old content vs the new block, ``metric``); 0 outside it.
    keep_old : (h, w) bool ndarray or None
        True where the cut kept the old content (the new block fills the rest).
    path : (N, 2) int ndarray
        The cut's pixels (row, col) in block coordinates (empty for a straight overlap).
    criterion, peak : float
        Sum and maximum of ``error`` over the path (nan without a cut).
    match_error : float
        Overlap SSD of the chosen window (nan without an overlap or search).
    best_error : float
        Smallest overlap SSD among the candidates searched (nan without a search).
    candidates : int
        Number of windows the choice was drawn from.
    depth : int
        Adaptive split depth (0 = a full block).
    territory : (h, w) int8 ndarray or None
        Bhatia only: 0 own block, 1 left neighbour's extension, 2 top neighbour's extension,
        3 diagonal neighbour's extension.
    """

    index: int
    position: tuple[int, int]
    size: tuple[int, int]
    source: tuple[int, int, int, int]
    arms: tuple[int, int, int, int]
    error: np.ndarray | None
    keep_old: np.ndarray | None
    path: np.ndarray
    criterion: float
    peak: float
    match_error: float
    best_error: float
    candidates: int
    depth: int = 0
    territory: np.ndarray | None = None

    @property
    def overlap(self) -> np.ndarray:
        """(h, w) bool: the pixels that overlapped existing content."""
        h, w = self.size
        t, left, b, r = self.arms
        m = np.zeros((h, w), dtype=bool)
        m[:t] = True
        m[:, :left] = True
        if b:
            m[h - b :] = True
        if r:
            m[:, w - r :] = True
        return m


@dataclass(frozen=True, slots=True)
class BlockPlaced(Item):
    """A block was placed: its record and its composited pixels as written to the output."""

    record: BlockRecord
    pixels: np.ndarray

    @property
    def position(self) -> tuple[int, int]:
        return self.record.position

    @property
    def size(self) -> tuple[int, int]:
        return self.record.size

    @property
    def source(self) -> tuple[int, int, int, int]:
        return self.record.source


@dataclass(frozen=True)
class QuiltResult:
    """The synthesized image and the record of every block (see :class:`BlockRecord`).

    ``step`` is the block grid's period (block - overlap; the block for Bhatia), ``band`` the
    width of the strip after each grid line in which the cuts run (the overlap, or Bhatia's
    cut band).
    """

    image: np.ndarray
    blocks: tuple[BlockRecord, ...]
    block: tuple[int, int]
    overlap: int
    step: tuple[int, int]
    band: int
    tileable: bool
    select: str
    seam: str
    params: dict = field(default_factory=dict)


def grid_border_ratio(result: QuiltResult, *, reduce: str = "max") -> float:
    """Border ratio of ``result.image`` along its block grid (DESIGN.md quality metric).

    The joints are not straight lines after a cut, so the ratio is measured on the grid lines
    shifted by every offset 0..band (the strip the cuts run in) and the largest (``"max"``) or
    the mean (``"mean"``) is returned; a straight overlap's joint lies at offset 0.

    A tileable output is measured as the torus it is (the image tiled 2 × 2): at the real
    block positions (evenly spaced, not multiples of ``step``), the wrap line included.
    """
    from engine.metrics import grid_border_ratio as gbr

    choice(reduce, "reduce", ("max", "mean"))
    vals = []
    for k in range(result.band + 1):
        if getattr(result, "tileable", False):
            vals.append(_torus_grid_ratio(result.image, _torus_lines(result), k))
            continue
        try:
            vals.append(gbr(result.image, result.step, offset=(k, k)))
        except ValueError:  # no grid line inside the image at this offset
            continue
    if not vals:
        raise ValueError("the output has no block grid line inside it")
    return float(max(vals) if reduce == "max" else np.mean(vals))


def _torus_lines(result: QuiltResult) -> tuple[np.ndarray, np.ndarray]:
    """Row and column positions where the blocks of a tileable result start."""
    (H, W), (bh, bw) = result.image.shape[:2], result.block
    if result.select == "bhatia":
        return np.arange(0, H, bh), np.arange(0, W, bw)
    return (
        np.array(axis_positions(H, bh, result.overlap, True)),
        np.array(axis_positions(W, bw, result.overlap, True)),
    )


def _torus_grid_ratio(image: np.ndarray, lines, offset: int) -> float:
    """Mean |step| across the lines ``lines + offset`` (rows, cols; modulo the size, so the
    wrap joint counts) over the mean |step| between every other pair of neighbours."""
    x = colour_channels(image).astype(np.float64)
    ratios = []
    for a, starts in ((x, lines[1]), (x.transpose(1, 0, 2), lines[0])):
        n = a.shape[1]
        steps = np.abs(np.roll(a, -1, axis=1) - a).mean(axis=2)  # i: column i -> (i + 1) % n
        on = np.zeros(n, dtype=bool)
        on[(starts + offset - 1) % n] = True
        if on.any() and (~on).any():
            den = steps[:, ~on].mean()
            ratios.append(steps[:, on].mean() / den if den > 0 else 1.0)
    return float(np.mean(ratios))


# ------------------------------------------------------------------------------ helpers
def _ro(a: np.ndarray) -> np.ndarray:
    """Mark an array this module just created read-only (it is handed out in events)."""
    a.setflags(write=False)
    return a


_EMPTY_PATH = _ro(np.zeros((0, 2), dtype=np.intp))


def _resolve_threads(threads) -> int:
    if threads is None:
        return max(1, os.cpu_count() or 1)
    return positive_int(threads, "threads")


def _out_shape(out_shape) -> tuple[int, int]:
    try:
        h, w = out_shape
    except (TypeError, ValueError):
        raise TypeError(f"out_shape must be (height, width), got {out_shape!r}") from None
    for v in (h, w):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral):
            raise TypeError(f"out_shape must hold two integers, got {out_shape!r}")
    if h < 1 or w < 1:
        raise ValueError(f"out_shape must be at least 1x1, got {w}x{h} (width x height)")
    return int(h), int(w)


def axis_positions(n_out: int, block: int, overlap: int, tileable: bool) -> list[int]:
    """Block offsets along one axis (ALGORITHMS §2.2 layout, or evenly spaced on a torus)."""
    step = block - overlap
    if not tileable:
        n = max(1, math.ceil((n_out - overlap) / step))
        return [i * step for i in range(n)]
    n = max(2, math.ceil(n_out / step))
    return [(i * n_out) // n for i in range(n)]


def grid_rects(out_shape, block, overlap: int, tileable: bool) -> list[tuple[int, int, int, int]]:
    """(y, x, h, w) of every block of the quilting grid in raster order (cropped at the
    output's edges unless ``tileable``)."""
    (ho, wo), (bh, bw) = out_shape, block
    rects = []
    for y in axis_positions(ho, bh, overlap, tileable):
        for x in axis_positions(wo, bw, overlap, tileable):
            h = bh if tileable else min(bh, ho - y)
            w = bw if tileable else min(bw, wo - x)
            rects.append((y, x, h, w))
    return rects


def _torus_fits(n_out: int, block: int, overlap: int) -> bool:
    """Evenly spaced blocks on a torus: each overlaps its two neighbours and no further one."""
    spacing = np.diff([*axis_positions(n_out, block, overlap, True), n_out])
    return block < n_out and spacing.max() < block and 2 * spacing.min() > block


def _torus_overlap(n_out: int, block: int, overlap: int) -> int:
    """The largest overlap <= ``overlap`` that fits a tileable axis (``overlap`` if none does)."""
    return next((o for o in range(overlap, -1, -1) if _torus_fits(n_out, block, o)), overlap)


def _check_torus_axis(n_out: int, block: int, overlap: int, axis: str) -> None:
    if _torus_fits(n_out, block, overlap):
        return
    if block < n_out and (fitting := _torus_overlap(n_out, block, overlap)) != overlap:
        raise ValueError(
            f"a tileable output {axis} of {n_out} px with blocks of {block} px and overlap "
            f"{overlap} puts blocks half a block or less apart (each would overlap more than its "
            f"two neighbours): use an overlap of at most {fitting}"
        )
    raise ValueError(
        f"a tileable output {axis} of {n_out} px does not fit blocks of {block} px with "
        f"overlap {overlap}: choose an output {axis} of at least {2 * block} px"
    )


def _dependencies(rects, shape, torus: bool):
    """Predecessors and level of each rect (y, x, h, w), given in raster order.

    The predecessors of a block are the last earlier blocks written under its footprint (the
    earlier writers of those pixels precede them in turn); its level is one more than theirs.
    Blocks of one level neither read nor write each other's pixels. The canvas is cut into
    cells at every block edge, so each footprint is a set of whole cells.
    """
    cells = [
        _axis_cells([(r[a], r[a + 2]) for r in rects], n, torus)
        for a, n in ((0, shape[0]), (1, shape[1]))
    ]
    (ry, ny), (rx, nx) = cells
    last = np.full((ny, nx), -1, dtype=np.int64)
    preds, levels = [], []
    for k, (y, x, h, w) in enumerate(rects):
        idx = np.ix_(ry[y, h], rx[x, w])
        p = sorted({int(v) for v in last[idx].ravel()} - {-1})
        preds.append(p)
        levels.append(1 + max((levels[j] for j in p), default=-1))
        last[idx] = k
    return preds, levels


def _axis_cells(spans, n: int, torus: bool):
    """Cells of one canvas axis of length ``n`` cut at the ends of every span (start, length),
    and the cells each span covers (wrapping around on a torus): ({span: cells}, count)."""
    cuts = sorted({0, n} | {s % n for s, _ in spans} | {(s + k) % n for s, k in spans})
    cell_of = np.searchsorted(cuts, np.arange(n), side="right") - 1
    covered = {}
    for s, k in set(spans):
        if not torus and s + k > n:
            raise AssertionError("block outside a non-tileable canvas")
        covered[s, k] = np.unique(cell_of[np.arange(s, s + k) % n])
    return covered, len(cuts) - 1


def _index(y, x, h, w, shape, torus):
    H, W = shape
    if y + h <= H and x + w <= W:
        return slice(y, y + h), slice(x, x + w)
    if not torus:
        raise AssertionError("block outside a non-tileable canvas")
    return np.ix_(np.arange(y, y + h) % H, np.arange(x, x + w) % W)


def arms_of(filled: np.ndarray) -> tuple[int, int, int, int]:
    """(top, left, bottom, right) widths of the fully filled strips at a block's edges."""
    h, w = filled.shape
    rows = filled.all(axis=1)
    cols = filled.all(axis=0)

    def lead(v):
        k = int(np.argmin(v)) if not v.all() else v.size
        return k

    t, left = lead(rows), lead(cols)
    b = lead(rows[::-1]) if t < h else 0
    r = lead(cols[::-1]) if left < w else 0
    return t, left, b, r


# ------------------------------------------------------------------------------ cutting
#: orientation (engine.stitch) of each overlap arm: where the new block (R2) lies from the old
#: content (R1) that the arm keeps on its outer side
_ARM_ORIENTATION = {"top": "bottom", "left": "right", "bottom": "top", "right": "left"}


def _arm_window(side: str, k: int, h: int, w: int) -> tuple[slice, slice]:
    return {
        "top": (slice(0, k), slice(0, w)),
        "left": (slice(0, h), slice(0, k)),
        "bottom": (slice(h - k, h), slice(0, w)),
        "right": (slice(0, h), slice(w - k, w)),
    }[side]


@dataclass
class _Cut:
    keep_old: np.ndarray
    path: np.ndarray
    criterion: float
    peak: float


def cut_overlap(err, arms, *, method: str, cancel=None, **options) -> _Cut:
    """Cut a block's overlap (arms = top, left, bottom, right widths) with a seam ``method``.

    The left and top arms are cut as one L joined in the corner (:func:`engine.stitch.l_cut`);
    wrap-around arms (bottom, right) get a seam each, oriented so the old content is R1; the old
    content is kept wherever one of the cuts keeps it. Returns the keep-old mask, the path pixels,
    criterion and peak.
    """
    h, w = err.shape
    t, left, b, r = arms
    keep = np.zeros((h, w), dtype=bool)
    paths, crit, peak = [], 0.0, 0.0
    if t or left:
        lc = l_cut(err, overlap_left=left, overlap_top=t, method=method, cancel=cancel, **options)
        keep |= np.asarray(lc.mask, dtype=bool)
        paths.append(np.asarray(lc.path, dtype=np.intp).reshape(-1, 2))
        crit, peak = float(lc.criterion), float(lc.peak)
    for side, k in (("bottom", b), ("right", r)):
        if not k:
            continue
        rows, cols = _arm_window(side, k, h, w)
        orient = _ARM_ORIENTATION[side]
        strip = err[rows, cols]
        seam = _seams.find_seam(
            np.ascontiguousarray(to_canonical(strip, orient)),
            method=method,
            cancel=cancel,
            **options,
        )
        keep[rows, cols] |= from_canonical(np.asarray(seam.mask), orient)
        pts = map_points(np.asarray(seam.path), orient, strip.shape, inverse=True)
        paths.append(pts + (rows.start, cols.start))
        crit += seam.criterion
        peak = max(peak, seam.peak)
    path = np.concatenate(paths).astype(np.intp) if paths else np.zeros((0, 2), np.intp)
    return _Cut(keep, path, crit, peak)


def _straight_alpha(arms, shape, blend: str) -> np.ndarray:
    """Weight of the old content over a straight overlap: 0 (hard), or a linear cross-fade."""
    h, w = shape
    alpha = np.zeros((h, w), np.float32)
    if blend == "none":
        return alpha
    t, left, b, r = arms
    yy = np.arange(h, dtype=np.float32)[:, None]
    xx = np.arange(w, dtype=np.float32)[None, :]
    for k, d in ((t, yy), (left, xx), (b, h - 1 - yy), (r, w - 1 - xx)):
        if k:
            alpha = np.maximum(alpha, np.clip(1 - (d + 0.5) / k, 0, 1))
    return alpha


def _adaptive_half_width_map(keep, path, err, overlap, rho: int) -> np.ndarray:
    """ρ-adaptive half-widths (§1.3) for any path: b = min(⌊ρ ẽ / Ē⌋, 2ρ) with ẽ the path error
    smoothed over ±ρ path pixels and Ē the mean error of the overlap; read at the nearest path
    pixel."""
    e = err[path[:, 0], path[:, 1]].astype(np.float64)
    k = np.ones(2 * rho + 1)
    sm = np.convolve(e, k, mode="same") / np.convolve(np.ones(e.size), k, mode="same")
    ebar = float(err[overlap].mean()) if overlap.any() else 0.0
    if ebar <= 0:
        return np.zeros(keep.shape)
    b = np.minimum(np.floor(rho * sm / ebar), 2 * rho)
    on = np.full(keep.shape, -1, dtype=np.intp)
    on[path[:, 0], path[:, 1]] = np.arange(len(path))
    _, idx = ndimage.distance_transform_edt(on < 0, return_indices=True)
    return b[on[idx[0], idx[1]]]


def blend_alpha(cut: _Cut, err, overlap, *, blend: str, width: float, rho: int) -> np.ndarray:
    """Weight of the old content for a cut: hard, feathered, or adaptive, 0 outside the overlap."""
    if blend == "none" or len(cut.path) == 0:
        alpha = cut.keep_old.astype(np.float32)
    elif blend == "feather":
        alpha = ramp_from_mask(cut.keep_old, width / 2.0)
    else:
        bmap = _adaptive_half_width_map(cut.keep_old, cut.path, err, overlap, rho)
        alpha = ramp_from_mask(cut.keep_old, bmap)
    alpha[~overlap] = 0
    return alpha


# ------------------------------------------------------------------------------ engine
@dataclass
class _Work:
    """A block being placed: footprint, content under it, and its generator."""

    index: int
    y: int
    x: int
    h: int
    w: int
    rng: np.random.Generator
    depth: int = 0
    old: np.ndarray | None = None
    filled: np.ndarray | None = None
    arms: tuple[int, int, int, int] = (0, 0, 0, 0)
    found: tuple | None = None  # search result: ("map", e) | ("list", anchors, errors) | None
    extra: dict = field(default_factory=dict)  # per-algorithm data (texture transfer)


class _Quilter:
    """Shared state of one synthesis: sample, spectra, canvas, valid anchors, options."""

    def __init__(self, *, seed: int, cancel, threads: int, **options):
        # options: the validated keywords of iter_quilt, as returned by _check_options (sample,
        # out_shape, block, overlap, select, tolerance, candidates, seam, blend, blend_width, rho,
        # metric, excluded, tileable, adaptive_threshold, min_block, mode, seam_options)
        self.__dict__.update(options)
        self.seed, self.cancel, self.threads = seed, cancel, threads
        sample, out_shape = self.sample, self.out_shape
        self.match_sample = np.ascontiguousarray(colour_channels(sample))
        self.canvas = np.zeros((*out_shape, sample.shape[2]), np.float32)
        self.filled = np.zeros(out_shape, dtype=bool)
        self.floor = error_floor(self.match_sample)
        self._valid: dict[tuple[int, int], tuple[np.ndarray | None, np.ndarray]] = {}
        self._spectrum = None
        self._pca = None
        self.fft_workers = 1 if threads > 1 else threads  # the pool already uses every thread
        self.stream = True  # False: no events (the benchmark's streaming-overhead reference)

    # ---------------------------------------------------------------- sample helpers
    @property
    def spectrum(self) -> SampleSpectrum:
        if self._spectrum is None:
            self._spectrum = self.make_spectrum()
        return self._spectrum

    def make_spectrum(self) -> SampleSpectrum:
        return SampleSpectrum(self.match_sample, workers=self.threads)

    def valid(self, h: int, w: int):
        """(valid anchor map or None if all valid, flat indices of valid anchors)."""
        key = (h, w)
        if key not in self._valid:
            if self.excluded is None:
                self._valid[key] = (None, None)
            else:
                v = valid_anchors(self.excluded, (h, w))
                self._valid[key] = (v, np.flatnonzero(v))
        return self._valid[key]

    def random_anchor(self, h: int, w: int, rng) -> tuple[int, int]:
        H, W = self.sample.shape[:2]
        _, flat = self.valid(h, w)
        nx = W - w + 1
        k = (
            int(rng.integers((H - h + 1) * nx))
            if flat is None
            else int(flat[rng.integers(flat.size)])
        )
        return divmod(k, nx)

    def zero_level_for(self, wk: _Work) -> float:
        """Error below which a candidate counts as an exact copy (see ``tolerance``)."""
        return self.zero_level(int(wk.filled.sum()))

    def zero_level(self, overlap_pixels: int) -> float:
        return ZERO_ERROR_FRACTION * self.floor * overlap_pixels * self.match_sample.shape[2]

    def pca(self) -> PCAMatcher:
        if self._pca is None:
            ov = self.overlap
            self._pca = PCAMatcher(
                self.spectrum,
                self.block,
                top=ov,
                left=ov,
                rng=np.random.default_rng([self.seed, 1]),
            )
        return self._pca

    # ---------------------------------------------------------------- canvas
    def idx(self, y, x, h, w):
        return _index(y, x, h, w, self.out_shape, self.tileable)

    def load(self, wk: _Work) -> None:
        ix = self.idx(wk.y, wk.x, wk.h, wk.w)
        wk.filled = self.filled[ix].copy()
        wk.old = colour_channels(self.canvas[ix]) if wk.filled.any() else None
        wk.arms = arms_of(wk.filled) if wk.old is not None else (0, 0, 0, 0)

    # ---------------------------------------------------------------- search
    def search(self, works: list[_Work]) -> None:
        """Fill ``found`` of every work that needs a search (batched per block shape)."""
        need = [wk for wk in works if wk.old is not None and self.select in ("best", "sampled")]
        if self.select == "sampled":
            for wk in need:
                wk.found = self._sampled(wk)
            return
        exact = need
        if self.mode == "fast":
            exact = []
            fast = []
            for wk in need:
                t, left, b, r = wk.arms
                if (wk.h, wk.w) == self.block and b == r == 0 and wk.depth == 0:
                    parts = self.pca().parts_for(t, left)
                    if parts:
                        fast.append((wk, parts))
                        continue
                exact.append(wk)
            if fast:
                pca = self.pca()
                v, _ = self.valid(*self.block)
                res = pca.query(
                    [wk.old for wk, _ in fast],
                    [p for _, p in fast],
                    v,
                    rerank=self.candidates,
                    mask_list=[wk.filled for wk, _ in fast],
                )
                for (wk, _), (anchors, errs) in zip(fast, res, strict=True):
                    wk.found = ("list", anchors, errs)
        self._exact(exact)

    def _exact(self, works: list[_Work]) -> None:
        groups: dict[tuple[int, int], list[_Work]] = {}
        for wk in works:
            groups.setdefault((wk.h, wk.w), []).append(wk)
        for (h, w), group in groups.items():
            check(self.cancel)
            maps = self.spectrum.ssd(
                np.stack([wk.old for wk in group]),
                np.stack([wk.filled for wk in group]),
                workers=self.fft_workers,
            )
            v, _ = self.valid(h, w)
            for wk, e in zip(group, maps, strict=True):
                if v is not None:
                    e[~v] = np.inf
                wk.found = ("map", e)

    def _sampled(self, wk: _Work):
        H, W = self.sample.shape[:2]
        _, flat = self.valid(wk.h, wk.w)
        nx = W - wk.w + 1
        total = (H - wk.h + 1) * nx if flat is None else flat.size
        k = min(self.candidates, total)
        pick = wk.rng.choice(total, size=k, replace=False)
        if flat is not None:
            pick = flat[pick]
        anchors = np.column_stack(np.divmod(pick, nx))
        errs = ssd_at(self.match_sample, anchors, wk.old, wk.filled)
        return ("list", anchors, errs)

    # ---------------------------------------------------------------- placing
    def choose(self, wk: _Work):
        """(anchor (y, x), match error, best error, number of candidates)."""
        if wk.found is None:
            y, x = self.random_anchor(wk.h, wk.w, wk.rng)
            if wk.old is None or self.select != "random":
                return (y, x), math.nan, math.nan, 1
            e = float(ssd_at(self.match_sample, np.array([[y, x]]), wk.old, wk.filled)[0])
            return (y, x), e, math.nan, 1
        zero = self.zero_level_for(wk)
        if wk.found[0] == "map":
            e = wk.found[1]
            k, e_min, n = select_within_tolerance(
                e, tolerance=self.tolerance, zero_level=zero, rng=wk.rng
            )
            return divmod(k, e.shape[1]), float(e.flat[k]), e_min, n
        _, anchors, errs = wk.found
        if self.select == "sampled":
            i = int(np.argmin(errs))
            return tuple(int(v) for v in anchors[i]), float(errs[i]), float(errs[i]), len(errs)
        i, e_min, n = select_within_tolerance(
            errs, tolerance=self.tolerance, zero_level=zero, rng=wk.rng
        )
        return tuple(int(v) for v in anchors[i]), float(errs[i]), e_min, n

    def should_split(self, wk: _Work, e_min: float) -> bool:
        if self.adaptive_threshold is None or wk.old is None or not np.isfinite(e_min):
            return False
        child = self.child_size(wk.h), self.child_size(wk.w)
        if min(child) < self.min_block:
            return False
        per_pixel = e_min / (wk.filled.sum() * self.match_sample.shape[2])
        return per_pixel > self.adaptive_threshold

    def child_size(self, n: int) -> int:
        return (n + self.overlap + 1) // 2

    def place(self, wk: _Work) -> list[tuple[BlockRecord, np.ndarray]]:
        """Choose, cut and paste one block (or its four children); returns its records."""
        check(self.cancel)
        anchor, e_match, e_min, n = self.choose(wk)
        if self.should_split(wk, e_min):
            out = []
            ch, cw = self.child_size(wk.h), self.child_size(wk.w)
            for dy in (0, wk.h - ch):
                for dx in (0, wk.w - cw):
                    child = _Work(wk.index, wk.y + dy, wk.x + dx, ch, cw, wk.rng, wk.depth + 1)
                    self.load(child)
                    if child.old is not None and self.select in ("best", "sampled"):
                        if self.select == "sampled":
                            child.found = self._sampled(child)
                        else:
                            self._exact([child])
                    out.extend(self.place(child))
            return out
        return [self.paste(wk, anchor, e_match, e_min, n)]

    def paste(self, wk: _Work, anchor, e_match, e_min, n):
        ay, ax = anchor
        h, w = wk.h, wk.w
        new = self.sample[ay : ay + h, ax : ax + w]
        err = keep = None
        path, crit, peak = _EMPTY_PATH, math.nan, math.nan
        if wk.old is None:
            pixels = new.copy()
        else:
            old_full = self.canvas[self.idx(wk.y, wk.x, h, w)]
            overlap = wk.filled
            err = error_map(wk.old, colour_channels(new), metric=self.metric)
            err[~overlap] = 0
            if self.seam == "straight":
                keep = np.zeros((h, w), dtype=bool)
                alpha = _straight_alpha(wk.arms, (h, w), self.blend)
            elif not err.any():
                # old and new agree exactly over the overlap (a continued copy of the sample):
                # every cut gives the same pixels, so none is searched
                keep, crit, peak, alpha = overlap.copy(), 0.0, 0.0, None
            else:
                cut = cut_overlap(
                    err, wk.arms, method=self.seam, cancel=self.cancel, **self.seam_options
                )
                keep, path, crit, peak = cut.keep_old, _ro(cut.path), cut.criterion, cut.peak
                keep &= overlap
                alpha = None
                if self.blend != "none":
                    alpha = blend_alpha(
                        cut, err, overlap, blend=self.blend, width=self.blend_width, rho=self.rho
                    )
            if alpha is None:  # hard cut: exact copies of old and new
                pixels = new.copy()
                np.copyto(pixels, old_full, where=keep[:, :, None])
            else:
                a = alpha[:, :, None]
                pixels = a * old_full + (1 - a) * new
            _ro(err)
            _ro(keep)
        ix = self.idx(wk.y, wk.x, h, w)
        self.canvas[ix] = pixels
        self.filled[ix] = True
        H, W = self.out_shape
        rec = BlockRecord(
            index=-1,
            position=(wk.y % H, wk.x % W),
            size=(h, w),
            source=(ax, ay, w, h),
            arms=wk.arms,
            error=err,
            keep_old=keep,
            path=path,
            criterion=crit,
            peak=peak,
            match_error=e_match,
            best_error=e_min,
            candidates=n,
            depth=wk.depth,
        )
        return rec, _ro(pixels)


POOL_MIN_SAMPLE_AREA = 200 * 200
"""Below this sample area a block's search is so cheap (< 0.1 ms) that handing it to another
thread costs more than it saves: such runs stay on one thread (same result either way)."""


SEARCH_CHUNK = 4
"""Blocks of one level searched in one batch (fixed: batches never depend on the threads)."""


def _run_levels(q: _Quilter, rects, total_label: str):
    """Place ``rects`` (top-level blocks, raster order); yields events, returns the records.

    Blocks are placed one by one in level order (level, then raster index) and searched in fixed
    batches of up to :data:`SEARCH_CHUNK` consecutive blocks of one level. A batch's search needs
    only its blocks' predecessors placed, so with ``threads > 1`` the searches run ahead on a pool
    (FFTs and numba kernels release the GIL) while this thread places blocks. Every batch is the
    same and sees exactly the canvas its predecessors left whatever the number of threads, and
    every block has its own generator: the result does not depend on the number of threads.
    """
    if q.select == "best":
        _ = q.spectrum  # built once, before any thread reads it
        if q.mode == "fast":
            q.pca()
    preds, levels = _dependencies(rects, q.out_shape, q.tileable)
    order = sorted(range(len(rects)), key=lambda k: (levels[k], k))
    works = [_Work(k, *r, rng=np.random.default_rng([q.seed, k])) for k, r in enumerate(rects)]
    chunks: list[list[int]] = []
    for k in order:
        if chunks and len(chunks[-1]) < SEARCH_CHUNK and levels[chunks[-1][0]] == levels[k]:
            chunks[-1].append(k)
        else:
            chunks.append([k])
    waiting, dependents = [], [[] for _ in rects]
    for c, members in enumerate(chunks):
        needed = {j for k in members for j in preds[k]}
        waiting.append(len(needed))
        for j in needed:
            dependents[j].append(c)
    heavy = q.sample.shape[0] * q.sample.shape[1] >= POOL_MIN_SAMPLE_AREA
    pool = ThreadPoolExecutor(max(1, q.threads - 1)) if q.threads > 1 and heavy else None
    futures = {}

    def loaded(c):  # the batch's predecessors are placed: read what lies under it now
        batch = [works[k] for k in chunks[c]]
        for wk in batch:
            q.load(wk)
        return batch

    records: list[BlockRecord] = []
    try:
        if pool is not None:
            futures = {
                c: pool.submit(q.search, loaded(c)) for c in range(len(chunks)) if not waiting[c]
            }
        done = 0
        for c, members in enumerate(chunks):
            check(q.cancel)
            if pool is None:
                q.search(loaded(c))
            else:
                futures.pop(c).result()
            for k in members:
                for rec, pixels in q.place(works[k]):
                    rec = _renumber(rec, len(records))
                    records.append(rec)
                    if q.stream:
                        yield BlockPlaced(rec, pixels)
                works[k] = None  # its arrays live on in the records
                for d in dependents[k]:
                    waiting[d] -= 1
                    if not waiting[d] and pool is not None:
                        futures[d] = pool.submit(q.search, loaded(d))
            done += len(members)
            last = c + 1 == len(chunks) or levels[chunks[c + 1][0]] != levels[members[0]]
            if q.stream and last:
                yield Progress(done, len(rects), total_label)
    finally:
        if pool is not None:
            for f in futures.values():
                f.cancel()
            pool.shutdown(wait=True, cancel_futures=True)
    return records


def _renumber(rec: BlockRecord, index: int) -> BlockRecord:
    return replace(rec, index=index)


# ------------------------------------------------------------------------------ Bhatia
def _iter_bhatia(q: _Quilter, band: int):
    """Bhatia 2004 (ALGORITHMS §4): random blocks on a non-overlapping grid, territories of the
    neighbours' source extensions cut by minimum resistance lines."""
    S = q.sample
    H, W = S.shape[:2]
    bh, bw = q.block
    Ho, Wo = q.out_shape
    # reflection padding where an extension runs out of the sample
    Sp = np.pad(S, ((0, band), (0, band), (0, 0)), mode="reflect")
    flat = (
        None if q.excluded is None else np.flatnonzero(_bhatia_anchors(q.excluded, q.block, band))
    )
    nx = W - bw + 1
    ys = list(range(0, Ho, bh))
    xs = list(range(0, Wo, bw))
    ny_, nx_ = len(ys), len(xs)
    anchors = {}
    sizes = {}
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            rng = np.random.default_rng([q.seed, i * nx_ + j])
            n = (H - bh + 1) * nx if flat is None else flat.size
            k = int(rng.integers(n))
            anchors[i, j] = divmod(k if flat is None else int(flat[k]), nx)
            sizes[i, j] = (min(bh, Ho - y), min(bw, Wo - x))

    def neighbour(i, j, di, dj):
        a, b = i + di, j + dj
        if q.tileable:
            return a % ny_, b % nx_
        return (a, b) if a >= 0 and b >= 0 else None

    def do_block(ij):
        check(q.cancel)
        i, j = ij
        h, w = sizes[ij]
        ay, ax = anchors[ij]
        own = Sp[ay : ay + h, ax : ax + w]
        srcs = [own]
        terr = np.zeros((h, w), np.int8)
        err = np.zeros((h, w), np.float32)
        paths, crit, peak = [], 0.0, 0.0
        arms = [0, 0, 0, 0]
        exts = [None, None, None]
        L, U = neighbour(i, j, 0, -1), neighbour(i, j, -1, 0)
        kb = min(band, w)
        if L is not None and w > 1:
            (ly, lx), (_, lw) = anchors[L], sizes[L]
            ext = own.copy()
            ext[:, :kb] = Sp[ly : ly + h, lx + lw : lx + lw + kb]
            e = error_map(ext[:, :kb], own[:, :kb], metric=q.metric)
            seam = _bhatia_seam(q, e, own[:, :kb])
            terr[:, :kb][seam.mask] |= 1
            err[:, :kb] = e
            paths.append(np.asarray(seam.path))
            crit, peak = crit + seam.criterion, max(peak, seam.peak)
            exts[0] = ext
            arms[1] = kb
        kt = min(band, h)
        if U is not None and h > 1:
            (uy, ux), (uh, _) = anchors[U], sizes[U]
            ext = own.copy()
            ext[:kt] = Sp[uy + uh : uy + uh + kt, ux : ux + w]
            e = error_map(ext[:kt], own[:kt], metric=q.metric)
            seam = _bhatia_seam(
                q, np.ascontiguousarray(e.T), np.ascontiguousarray(own[:kt].transpose(1, 0, 2))
            )
            terr[:kt][seam.mask.T] |= 2
            err[:kt] = np.maximum(err[:kt], e)
            paths.append(np.asarray(seam.path)[:, ::-1])
            crit, peak = crit + seam.criterion, max(peak, seam.peak)
            exts[1] = ext
            arms[0] = kt
        if (terr == 3).any():
            D = neighbour(i, j, -1, -1)
            (dy, dx), (dh, dw) = anchors[D], sizes[D]
            ext = own.copy()
            ext[:kt, :kb] = Sp[dy + dh : dy + dh + kt, dx + dw : dx + dw + kb]
            exts[2] = ext
        srcs += exts
        pixels = _territory_composite(terr, srcs, q.blend, q.blend_width)
        path = np.concatenate(paths).astype(np.intp) if paths else np.zeros((0, 2), np.intp)
        keep = terr != 0
        rec = BlockRecord(
            index=-1,
            position=(ys[i], xs[j]),
            size=(h, w),
            source=(ax, ay, w, h),
            arms=tuple(arms),
            error=_ro(err) if paths else None,
            keep_old=_ro(keep) if paths else None,
            path=_ro(path),
            criterion=crit if paths else math.nan,
            peak=peak if paths else math.nan,
            match_error=math.nan,
            best_error=math.nan,
            candidates=1,
            territory=_ro(terr),
        )
        return rec, pixels

    cells = [(i, j) for i in range(ny_) for j in range(nx_)]
    pool = ThreadPoolExecutor(q.threads) if q.threads > 1 else None
    records = []
    try:
        chunk = max(1, nx_)
        for s in range(0, len(cells), chunk):
            check(q.cancel)
            batch = cells[s : s + chunk]
            results = list(pool.map(do_block, batch)) if pool else [do_block(c) for c in batch]
            for (i, j), (rec, pixels) in zip(batch, results, strict=True):
                h, w = sizes[i, j]
                q.canvas[ys[i] : ys[i] + h, xs[j] : xs[j] + w] = pixels
                rec = _renumber(rec, len(records))
                records.append(rec)
                if q.stream:
                    yield BlockPlaced(rec, _ro(pixels))
            if q.stream:
                yield Progress(len(records), len(cells), "blocks")
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
    return records


def _bhatia_anchors(excluded: np.ndarray, block, band: int) -> np.ndarray:
    """Valid anchors of Bhatia's blocks: block plus its right/bottom extension clean, in the
    sample reflected where the extension runs out (the padding the synthesis reads)."""
    (H, W), (bh, bw) = excluded.shape, block
    padded = np.pad(excluded, ((0, band), (0, band)), mode="reflect")
    return valid_anchors(padded, block, extension=(band, band))[: H - bh + 1, : W - bw + 1]


def _bhatia_seam(q: _Quilter, e: np.ndarray, own_band: np.ndarray):
    """Corner-to-corner cut of one band (canonical: extension = R1 on the left)."""
    opts = dict(q.seam_options)
    if q.seam == "resistance" and "image" not in opts:
        opts["image"] = own_band  # Bhatia's step: colour difference inside the new block
    return _seams.find_seam(e, method=q.seam, start=0, end=0, cancel=q.cancel, **opts)


def _territory_composite(terr, srcs, blend: str, width: float) -> np.ndarray:
    """Composite the territories' sources: hard, or blurred one-hot weights renormalised."""
    h, w = terr.shape
    if blend == "none":
        out = srcs[0].copy()
        for t in (1, 2, 3):
            if srcs[t] is not None:
                m = terr == t
                out[m] = srcs[t][m]
        return out
    sigma = max(width / 2.0, 0.5)
    acc = np.zeros(srcs[0].shape, np.float32)
    tot = np.zeros((h, w), np.float32)
    for t in range(4):
        if t and srcs[t] is None:
            continue
        wt = ndimage.gaussian_filter((terr == t).astype(np.float32), sigma, mode="nearest")
        acc += wt[:, :, None] * srcs[t]
        tot += wt
    return acc / np.maximum(tot, 1e-12)[:, :, None]


# ------------------------------------------------------------------------------ public API
def _check_options(
    sample,
    out_shape,
    block,
    overlap,
    select,
    tolerance,
    candidates,
    seam,
    blend,
    blend_width,
    rho,
    metric,
    excluded,
    tileable,
    adaptive_threshold,
    min_block,
    mode,
    seam_options,
):
    s = as_image(sample, "sample")
    H, W = s.shape[:2]
    Ho, Wo = _out_shape(out_shape)
    bh, bw = check_block(block)
    choice(select, "select", SELECTIONS)
    choice(seam, "seam", SEAMS)
    choice(mode, "mode", MODES)
    choice(blend, "blend", BLEND_MODES)
    choice(metric, "metric", METRICS)
    if overlap is None:
        overlap = max(1, min(bh, bw) // (2 if seam == "minimax" else 6))
        if select == "bhatia":
            overlap = max(1, min(bh, bw) // 4)
        elif tileable:  # the torus spaces blocks evenly: keep them more than half a block apart
            overlap = min(_torus_overlap(Ho, bh, overlap), _torus_overlap(Wo, bw, overlap))
    overlap = positive_int(overlap, "overlap", minimum=0)
    if overlap >= min(bh, bw):
        raise ValueError(f"overlap must be smaller than the block ({min(bh, bw)}), got {overlap}")
    if select == "bhatia" and overlap < 1:
        raise ValueError("overlap (the cut band) must be >= 1 with select='bhatia'")
    if select == "bhatia" and seam == "straight":
        raise ValueError("select='bhatia' needs a cut: choose a seam method, e.g. 'resistance'")
    if bh > H or bw > W:
        raise ValueError(
            f"the sample ({W}x{H}) is smaller than the block ({bw}x{bh}); use a smaller block"
        )
    if bh > Ho or bw > Wo:
        raise ValueError(
            f"the block ({bw}x{bh}) is larger than the output ({Wo}x{Ho}); use a smaller block"
        )
    if tileable and select != "bhatia":
        _check_torus_axis(Ho, bh, overlap, "height")
        _check_torus_axis(Wo, bw, overlap, "width")
    tolerance = non_negative_number(tolerance, "tolerance")
    if candidates is None:
        candidates = DEFAULT_SAMPLED if select == "sampled" else DEFAULT_RERANK
    candidates = positive_int(candidates, "candidates")
    blend_width = non_negative_number(blend_width, "blend_width")
    rho = positive_int(rho, "rho", minimum=0)
    ex = None
    if excluded is not None:
        ex = np.asarray(excluded)
        if ex.shape != (H, W):
            raise ValueError(f"excluded must be shaped {(H, W)} like the sample, got {ex.shape}")
        ex = ex.astype(bool)
        if select == "bhatia":
            if not _bhatia_anchors(ex, (bh, bw), overlap).any():
                raise ValueError(
                    "every block position (with its extension) in the sample contains an "
                    "excluded pixel"
                )
        elif not valid_anchors(ex, (bh, bw)).any():
            raise ValueError("every block position in the sample contains an excluded pixel")
    if adaptive_threshold is not None:
        if isinstance(adaptive_threshold, bool) or not isinstance(adaptive_threshold, numbers.Real):
            raise TypeError(f"adaptive_threshold must be a number, got {adaptive_threshold!r}")
        if not (math.isfinite(adaptive_threshold) and adaptive_threshold > 0):
            raise ValueError(f"adaptive_threshold must be > 0, got {adaptive_threshold}")
    if min_block is None:
        min_block = max(2 * overlap + 1, min(bh, bw) // 4)
    min_block = positive_int(min_block, "min_block")
    if min_block <= overlap:
        raise ValueError(f"min_block must be larger than the overlap ({overlap}), got {min_block}")
    if seam != "straight":
        _seams.check_option_names(seam, seam_options, "seam")
    elif seam_options:
        raise TypeError(f"seam 'straight' takes no options, got {', '.join(seam_options)}")
    return dict(
        sample=s,
        out_shape=(Ho, Wo),
        block=(bh, bw),
        overlap=overlap,
        select=select,
        tolerance=tolerance,
        candidates=candidates,
        seam=seam,
        blend=blend,
        blend_width=blend_width,
        rho=rho,
        metric=metric,
        excluded=ex,
        tileable=tileable,
        adaptive_threshold=adaptive_threshold,
        min_block=min_block,
        mode=mode,
        seam_options=seam_options,
    )


def iter_quilt(
    sample,
    out_shape,
    *,
    block,
    overlap=None,
    select: str = "best",
    tolerance: float = 0.1,
    candidates: int | None = None,
    seam: str = "dp",
    blend: str = "none",
    blend_width: float = 4,
    rho: int = 3,
    metric: str = "ssd",
    excluded=None,
    tileable: bool = False,
    adaptive_threshold: float | None = None,
    min_block: int | None = None,
    mode: str = "exact",
    rng=None,
    cancel=None,
    threads: int | None = None,
    **seam_options,
):
    """Synthesize a texture of ``out_shape`` from ``sample`` by image quilting, streaming events.

    Parameters
    ----------
    sample : (H, W[, C]) array_like
        The texture sample (any dtype; alpha is copied but never compared).
    out_shape : (int, int)
        Output (height, width).
    block : int or (int, int)
        Block size (must fit in the sample and the output).
    overlap : int, optional
        Overlap of neighbouring blocks (< block). Default: block / 6 (Efros & Freeman), block / 2
        for ``seam="minimax"`` (Long & Mould), block / 4 as Bhatia's cut band.
    select : {"best", "random", "sampled", "bhatia"}
        See the module docstring.
    tolerance : float
        ``"best"``: draw among windows within ``(1 + tolerance) × e_min`` (0.1 in §2.2). When
        ``e_min`` is about 0 (an exact copy exists), ``e_min`` is replaced by a floor δ:
        half the sample's mean squared adjacent-pixel difference per overlap pixel and channel
        (:data:`engine.matching.ZERO_ERROR_FRACTION`).
    candidates : int, optional
        ``"sampled"``: windows drawn per block (default 200); ``mode="fast"``: windows re-ranked
        exactly (default 32).
    seam : str
        ``"straight"`` or a method of :data:`engine.seams.METHODS`.
    blend : {"none", "feather", "adaptive"}
        Softening of the cut; ``blend_width`` (feather, px) and ``rho`` (adaptive) tune it.
    metric : {"ssd", "euclid", "lab"}
        Error map the cut runs on (the block search always uses the SSD).
    excluded : (H, W) bool array_like, optional
        Sample pixels never to copy (:func:`engine.exclusion.exclusion_mask`).
    tileable : bool
        Wrap-around overlaps on the last column and row: the output tiles seamlessly.
    adaptive_threshold : float, optional
        Split a block into four when its best overlap error, per overlap pixel and channel
        (mean squared difference in [0, 1]² units), exceeds this.
    min_block : int, optional
        Smallest block adaptive splitting makes (default max(2 overlap + 1, block / 4)); children
        of a block of n pixels measure (n + overlap + 1) // 2 and overlap like the grid.
    mode : {"exact", "fast"}
        Exhaustive FFT search, or principal-component ranking with exact re-ranking.
    rng : int, Generator or None
        Seed; the same seed gives the same output for any ``threads``.
    cancel : CancelToken, optional
        Checked between and inside blocks; raises :class:`engine.cancel.Cancelled`.
    threads : int, optional
        Worker threads (default: every core).
    **seam_options
        Passed to the seam method (e.g. ``o_max``, ``variant``, ``max_run``).

    Returns
    -------
    generator
        Yields :class:`BlockPlaced` and :class:`~engine.events.Progress`; returns a
        :class:`QuiltResult`.
    """
    return _iter_quilt(
        _build_quilter(
            sample,
            out_shape,
            block=block,
            overlap=overlap,
            select=select,
            tolerance=tolerance,
            candidates=candidates,
            seam=seam,
            blend=blend,
            blend_width=blend_width,
            rho=rho,
            metric=metric,
            excluded=excluded,
            tileable=tileable,
            adaptive_threshold=adaptive_threshold,
            min_block=min_block,
            mode=mode,
            rng=rng,
            cancel=cancel,
            threads=threads,
            seam_options=seam_options,
        )
    )


def _build_quilter(sample, out_shape, *, rng, cancel, threads, seam_options, **options):
    opts = _check_options(sample, out_shape, seam_options=seam_options, **options)
    seed = int(as_rng(rng).integers(2**63))
    return _Quilter(seed=seed, cancel=cancel, threads=_resolve_threads(threads), **opts)


def _quilt_unstreamed(sample, out_shape, **options) -> QuiltResult:
    """:func:`quilt` without creating any event: the benchmark's reference for the streaming
    overhead (same blocks, same records, same image)."""
    bound = inspect.signature(iter_quilt).bind(sample, out_shape, **options)
    bound.apply_defaults()
    q = _build_quilter(**bound.arguments)
    q.stream = False
    return drain(_iter_quilt(q))


def _iter_quilt(q: _Quilter):
    bh, bw = q.block
    Ho, Wo = q.out_shape
    if q.select == "bhatia":
        records = yield from _iter_bhatia(q, q.overlap)
        step, band = (bh, bw), q.overlap
    else:
        rects = grid_rects(q.out_shape, q.block, q.overlap, q.tileable)
        records = yield from _run_levels(q, rects, "blocks")
        step, band = (bh - q.overlap, bw - q.overlap), q.overlap
    image = q.canvas
    image.setflags(write=False)
    return QuiltResult(
        image=image,
        blocks=tuple(records),
        block=q.block,
        overlap=q.overlap,
        step=step,
        band=band,
        tileable=q.tileable,
        select=q.select,
        seam=q.seam,
        params=dict(
            tolerance=q.tolerance,
            candidates=q.candidates,
            blend=q.blend,
            metric=q.metric,
            mode=q.mode,
            adaptive_threshold=q.adaptive_threshold,
            min_block=q.min_block,
            seam_options=dict(q.seam_options),
        ),
    )


def quilt(sample, out_shape, **options) -> QuiltResult:
    """Drain :func:`iter_quilt` and return its :class:`QuiltResult`."""
    return drain(iter_quilt(sample, out_shape, **options))
