"""The block loop of image quilting: search, choose, cut and paste one block on the canvas.

ALGORITHMS.md §2.2, §3, §5. The selections ``"best"`` (exact FFT search or ``mode="fast"``),
``"sampled"`` and ``"random"`` and the adaptive split of a block whose best overlap error is too
high (Long & Mould's hybrid framework) are described in :mod:`engine.quilting`; the cut and blend
are :mod:`engine.quilting.cut`'s; the order of the blocks and the threads are
:mod:`engine.quilting.scheduler`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from engine import _jit as jit
from engine.cancel import check
from engine.colour_bound import MAX_AREA, MAX_FALLBACK, ColourBound
from engine.errormap import colour_channels, error_map_of
from engine.exclusion import valid_anchors
from engine.matching import (
    ZERO_ERROR_FRACTION,
    PCAMatcher,
    SampleSpectrum,
    TiledSpectrum,
    error_floor,
    select_within_tolerance,
    ssd_at,
)
from engine.pyramid import PyramidSearch, quilt_keeps
from engine.quilting.block_rng import BlockRng
from engine.quilting.cut import Cut, blend_alpha, cut_overlap, straight_alpha
from engine.quilting.estimate import TILE, Plan
from engine.quilting.kernels import (
    PAIRWISE_BLOCK,
    SQUARE_SUM_MAX,
    dp_cut_paste,
    footprint,
    query_inputs,
    square_sum_is_einsums,
)
from engine.quilting.layout import arms_of, canvas_index
from engine.quilting.records import EMPTY_PATH, BlockRecord, read_only
from engine.stitch_numpy import SMALL_CUT_PIXELS, dp_l_cuts

__all__ = ["BlockWork", "Quilter"]


@dataclass
class BlockWork:
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
    count: int = 0  # filled (overlap) pixels
    found: tuple | None = None  # search result: ("map", e) | ("list", anchors, errors) | None
    extra: dict = field(default_factory=dict)  # per-algorithm data (texture transfer)


class Quilter:
    """Shared state of one synthesis: sample, spectra, canvas, valid anchors, options.

    :func:`engine.quilting.scheduler.run_levels` drives it: :meth:`prepare` once, then per
    batch of blocks :meth:`run_batch`: :meth:`load` (read the canvas under them), :meth:`search`
    and :meth:`place` (choose, cut, paste), on any thread. Texture transfer subclasses it and
    overrides :meth:`search_sample`, :meth:`make_pyramid`, :meth:`load`, :meth:`zero_level_for`
    and :meth:`search` (its α-weighted cost).
    """

    worker_processes = True
    """Whether its blocks may be placed in worker processes on more than one thread
    (:func:`engine.quilting.scheduler.uses_processes`): everything a task writes is the canvas
    and ``filled``."""

    def __init__(self, *, seed: int, cancel, threads: int, plan: Plan, **options):
        # options: the validated keywords of iter_quilt, as returned by check_options (sample,
        # out_shape, block, overlap, select, tolerance, candidates, seam (a SeamSpec), excluded,
        # tileable, adaptive_threshold, min_block, mode)
        self.__dict__.update(options)
        self.seed, self.cancel, self.threads, self.plan = seed, cancel, threads, plan
        self.mode = plan.mode  # "auto" resolved
        sample, out_shape = self.sample, self.out_shape
        self.match_sample = np.ascontiguousarray(colour_channels(sample))
        self.canvas = np.zeros((*out_shape, sample.shape[2]), np.float32)
        self.filled = np.zeros(out_shape, dtype=bool)
        self.floor = 0.0  # error_floor, measured in prepare (after the plan is out) if not given
        self._valid: dict[tuple[int, int], tuple[np.ndarray | None, np.ndarray]] = {}
        self._spectrum = None
        self._pca = None
        self._pyramid = None
        self._bound = None  # the exact search's colour bound (make_bound)
        self.origin = None  # (H, W, 2) int32: the sample pixel each canvas pixel came from
        self.fft_workers = 1 if threads > 1 else threads  # the pool already uses every thread
        self.stream = True  # False: no events (the benchmark's streaming-overhead reference)
        self.alone = False  # True: each block's exact search is a query of its own (scheduler)
        seam = self.seam
        # the common cut, done by one compiled call per block (same pixels as the general path)
        self.dp_paste = seam.method == "dp" and seam.blend == "none" and seam.metric == "ssd"

    def prepare(self) -> None:
        """Build the structures every search shares (before any thread reads them)."""
        self.floor = self.floor or error_floor(self.match_sample)
        if self.select != "best":
            return
        if self.plan.search == "pyramid":
            self._pyramid = self.make_pyramid()
            self.origin = np.full((*self.out_shape, 2), -1, np.int32)
            return
        _ = self.spectrum
        if self.plan.search == "pca":
            self.pca()
        self._bound = self.make_bound()

    def run_batch(self, works: list[BlockWork]) -> list[tuple[BlockRecord, np.ndarray]]:
        """Load, search and place blocks of one level whose predecessors are placed (their
        footprints are disjoint); their records in order."""
        check(self.cancel)
        for wk in works:
            self.load(wk)
        self.search(works)
        self.precut(works)
        out = []
        for wk in works:
            out.extend(self.place(wk))
        return out

    def precut(self, works: list[BlockWork]) -> None:
        """A small job without numba: choose the batch's blocks and cut their L-shaped dp
        overlaps in one numpy pass (:func:`engine.stitch_numpy.dp_l_cuts`, the same cuts as one
        by one); :meth:`place` and :meth:`paste` take them from ``extra``."""
        if jit.loaded() or self.seam.method != "dp" or self.adaptive_threshold is not None:
            return
        groups: dict[tuple, list[BlockWork]] = {}
        for wk in works:
            t, left, b, r = wk.arms
            if wk.old is None or not (t and left) or b or r or wk.h * wk.w > SMALL_CUT_PIXELS:
                continue
            wk.extra["choice"] = choice = self.choose(wk)
            (ay, ax) = choice[0]
            err = error_map_of(
                wk.old,
                colour_channels(self.sample[ay : ay + wk.h, ax : ax + wk.w]),
                self.seam.metric,
            )
            err[~wk.filled] = 0
            wk.extra["err"] = err
            if err.any():
                groups.setdefault((wk.h, wk.w, left, t), []).append(wk)
        for (_, _, left, t), group in groups.items():
            if len(group) < 2:
                continue  # one block: the general path
            errs = np.stack([wk.extra["err"] for wk in group]).astype(np.float64)
            cuts = dp_l_cuts(errs, left, t)
            for wk, e, (path, keep, _, _) in zip(group, errs, cuts, strict=True):
                values = e[path[:, 0], path[:, 1]]  # as l_cut scores its path
                wk.extra["cut"] = Cut(keep, path, float(values.sum()), float(values.max()))

    # ---------------------------------------------------------------- sample helpers
    @property
    def spectrum(self) -> SampleSpectrum:
        if self._spectrum is None:
            self._spectrum = self.make_spectrum()
        return self._spectrum

    def make_spectrum(self) -> SampleSpectrum:
        stack, groups = self.search_sample()
        if self.plan.search == "tiled fft":
            return TiledSpectrum(stack, groups=groups, workers=self.threads, tile=TILE)
        return SampleSpectrum(stack, groups=groups, workers=self.threads, backend=self.plan.fft)

    def make_pyramid(self) -> PyramidSearch:
        stack, groups = self.search_sample()
        keep, coarse_keep = quilt_keeps(self.plan.levels)
        return PyramidSearch(
            stack,
            levels=self.plan.levels,
            groups=groups,
            keep=keep,
            coarse_keep=coarse_keep,
            workers=self.threads,
        )

    def make_bound(self) -> ColourBound | None:
        """The exact search's colour bound (:mod:`engine.colour_bound`: the same candidates from
        fewer transforms) for a colour sample of up to ``MAX_AREA`` pixels searched by
        quilting's own exact search; only where each block is searched alone (``alone``, set
        by the scheduler before :meth:`prepare`), the one search it serves."""
        h, w = self.match_sample.shape[:2]
        if (
            not self.alone
            or self.plan.search != "fft"
            or type(self).search is not Quilter.search
            or type(self).search_sample is not Quilter.search_sample
            or h * w > MAX_AREA
            or type(self.tolerance) is not float
        ):
            return None
        bound = ColourBound.build(self.match_sample, backend=self.plan.fft)
        if bound is None:
            return None
        ov = self.overlap
        count = self.block[0] * ov + self.block[1] * ov - ov * ov
        share = bound.fallback_share(
            self.block, ov, tolerance=self.tolerance, zero_level=self.zero_level(count)
        )
        return None if share > MAX_FALLBACK else bound  # a flat sample: the full maps

    def search_sample(self) -> tuple[np.ndarray, tuple | None]:
        """The channels the search matches and their groups (None: one group): the colours."""
        return self.match_sample, None

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

    def zero_level_for(self, wk: BlockWork) -> float:
        """Error below which a candidate counts as an exact copy (see ``tolerance``)."""
        return self.zero_level(wk.count)

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
        return canvas_index(y, x, h, w, self.out_shape, self.tileable)

    def load(self, wk: BlockWork) -> None:
        ix = self.idx(wk.y, wk.x, wk.h, wk.w)
        wk.filled = np.array(self.filled[ix])
        if jit.loaded():
            wk.count, *arms = footprint(wk.filled)
            wk.arms = tuple(arms)
        else:  # a small job without numba: the same figures from numpy
            wk.count = int(wk.filled.sum())
            wk.arms = arms_of(wk.filled) if wk.count else (0, 0, 0, 0)
        wk.old = colour_channels(self.canvas[ix]) if wk.count else None

    # ---------------------------------------------------------------- search
    def search(self, works: list[BlockWork]) -> None:
        """Fill ``found`` of every work that needs a search (batched per block shape)."""
        need = [wk for wk in works if wk.old is not None and self.select in ("best", "sampled")]
        if self.select == "sampled":
            for wk in need:
                wk.found = self._sampled(wk)
            return
        if self._pyramid is not None:
            for wk in need:
                wk.found = ("list", *self._pyramid_query(wk))
            return
        exact = need
        if self.plan.search == "pca":
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

    def _pyramid_query(self, wk: BlockWork):
        v, _ = self.valid(wk.h, wk.w)
        return self._pyramid.query(
            wk.old, wk.filled[:, :, None], valid=v, seeds=self.seeds(wk), workers=self.fft_workers
        )

    def seeds(self, wk: BlockWork) -> np.ndarray:
        """Anchors that continue the source windows of the content under the block's arms
        (PatchMatch's propagation): from the middle pixel of every arm."""
        t, left, b, r = wk.arms
        h, w = wk.h, wk.w
        pts = [(t // 2, w // 2)] if t else []
        pts += [(h // 2, left // 2)] if left else []
        pts += [(h - 1 - b // 2, w // 2)] if b else []
        pts += [(h // 2, w - 1 - r // 2)] if r else []
        H, W = self.out_shape
        out = []
        for u, v in pts:
            oy, ox = self.origin[(wk.y + u) % H, (wk.x + v) % W]
            if oy >= 0:
                out.append((oy - u, ox - v))
        return np.array(out, np.int64).reshape(-1, 2)

    def _exact(self, works: list[BlockWork]) -> None:
        groups: dict[tuple[int, int], list[BlockWork]] = {}
        for wk in works:
            groups.setdefault((wk.h, wk.w), []).append(wk)
        for (h, w), group in groups.items():
            check(self.cancel)
            v, _ = self.valid(h, w)
            if self._bound is not None and self.alone:
                group = [wk for wk in group if not self._bounded(wk, v)]
            # alone: the same transforms however the blocks are batched
            maps = [self._ssd([wk])[0] for wk in group] if self.alone else self._ssd(group)
            for wk, e in zip(group, maps, strict=True):
                if v is not None:
                    e[~v] = np.inf
                wk.found = ("map", e)

    def _bounded(self, wk: BlockWork, valid) -> bool:
        """Search ``wk`` through the colour bound; False when it should take the full map."""
        got = self._bound.search(
            wk.old,
            wk.filled,
            valid,
            tolerance=self.tolerance,
            zero_level=self.zero_level_for(wk),
            workers=self.fft_workers,
        )
        if got is None:
            return False
        wk.found = ("scored", *got, self.match_sample.shape[1] - wk.w + 1)
        return True

    def _ssd(self, group: list[BlockWork]) -> np.ndarray:
        """The exact search's error maps of blocks of one shape (their canvas loaded)."""
        spec = self.spectrum
        H, W = self.out_shape
        h, w = group[0].h, group[0].w
        if (
            jit.loaded()
            and len(spec.groups) == 1
            and type(self).load is Quilter.load
            and all(wk.y + h <= H and wk.x + w <= W for wk in group)
        ):  # what load read, gathered in one compiled pass (no wrap-around)
            ys = np.array([wk.y for wk in group], np.int64)
            xs = np.array([wk.x for wk in group], np.int64)
            wts, k, const = query_inputs(self.canvas, self.filled, ys, xs, h, w, spec.channels)
            k = k.transpose(0, 3, 1, 2)
            if h * w * spec.channels <= SQUARE_SUM_MAX and square_sum_is_einsums():
                return spec.ssd_terms(k, wts, const, workers=self.fft_workers)
            return spec.ssd_weighted(k, wts, k, workers=self.fft_workers)  # k·content = k²
        return spec.ssd(
            np.stack([wk.old for wk in group]),
            np.stack([wk.filled for wk in group]),
            workers=self.fft_workers,
        )

    def _sampled(self, wk: BlockWork):
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
    def choose(self, wk: BlockWork):
        """(anchor (y, x), match error, best error, number of candidates)."""
        if wk.found is None:
            y, x = self.random_anchor(wk.h, wk.w, wk.rng)
            if wk.old is None or self.select != "random":
                return (y, x), math.nan, math.nan, 1
            e = float(ssd_at(self.match_sample, np.array([[y, x]]), wk.old, wk.filled)[0])
            return (y, x), e, math.nan, 1
        zero = self.zero_level_for(wk)
        if wk.found[0] in ("map", "scored"):
            # the error map, or the bound's scored anchors (flat indices, errors, anchor width)
            e = wk.found[1] if wk.found[0] == "map" else wk.found[2]
            if isinstance(wk.rng, BlockRng):  # one compiled call
                k, e_min, n = wk.rng.select(e, tolerance=self.tolerance, zero_level=zero)
            else:
                k, e_min, n = select_within_tolerance(
                    e, tolerance=self.tolerance, zero_level=zero, rng=wk.rng
                )
            if wk.found[0] == "scored":
                return divmod(int(wk.found[1][k]), wk.found[3]), float(e[k]), e_min, n
            return divmod(k, e.shape[1]), float(e.flat[k]), e_min, n
        _, anchors, errs = wk.found
        if self.select == "sampled":
            i = int(np.argmin(errs))
            return tuple(int(v) for v in anchors[i]), float(errs[i]), float(errs[i]), len(errs)
        i, e_min, n = select_within_tolerance(
            errs, tolerance=self.tolerance, zero_level=zero, rng=wk.rng
        )
        return tuple(int(v) for v in anchors[i]), float(errs[i]), e_min, n

    def should_split(self, wk: BlockWork, e_min: float) -> bool:
        if self.adaptive_threshold is None or wk.old is None or not np.isfinite(e_min):
            return False
        child = self.child_size(wk.h), self.child_size(wk.w)
        if min(child) < self.min_block:
            return False
        per_pixel = e_min / (wk.count * self.match_sample.shape[2])
        return per_pixel > self.adaptive_threshold

    def child_size(self, n: int) -> int:
        return (n + self.overlap + 1) // 2

    def place(self, wk: BlockWork) -> list[tuple[BlockRecord, np.ndarray]]:
        """Choose, cut and paste one block (or its four children); returns its records."""
        check(self.cancel)
        anchor, e_match, e_min, n = wk.extra.pop("choice", None) or self.choose(wk)
        if self.should_split(wk, e_min):
            out = []
            ch, cw = self.child_size(wk.h), self.child_size(wk.w)
            for dy in (0, wk.h - ch):
                for dx in (0, wk.w - cw):
                    child = BlockWork(wk.index, wk.y + dy, wk.x + dx, ch, cw, wk.rng, wk.depth + 1)
                    self.load(child)
                    self.search([child])
                    out.extend(self.place(child))
            return out
        return [self.paste(wk, anchor, e_match, e_min, n)]

    def paste(self, wk: BlockWork, anchor, e_match, e_min, n):
        ay, ax = anchor
        h, w = wk.h, wk.w
        new = self.sample[ay : ay + h, ax : ax + w]
        err = keep = None
        path, crit, peak = EMPTY_PATH, math.nan, math.nan
        ix = self.idx(wk.y, wk.x, h, w)
        written = False  # whether the kernel wrote the canvas (a view of it: no wrap-around)
        if wk.old is None:
            pixels = new.copy()
        elif self.dp_paste and (wk.arms[0] or wk.arms[1]) and not any(wk.arms[2:]) and jit.loaded():
            written = isinstance(ix[0], slice)
            under = self.filled[ix] if written else wk.filled
            err, keep, path, pixels, values, crit, peak = dp_cut_paste(
                wk.old, new, wk.filled, wk.arms[1], wk.arms[0], self.canvas[ix], under, written
            )
            if len(values) > PAIRWISE_BLOCK:
                crit = float(values.sum())
            if len(path):
                read_only(path)
            else:
                path = EMPTY_PATH
            read_only(err)
            read_only(keep)
        else:
            old_full = self.canvas[ix]
            overlap = wk.filled
            err = wk.extra.pop("err", None)
            if err is None:
                err = error_map_of(wk.old, colour_channels(new), self.seam.metric)
                err[~overlap] = 0
            if not self.seam.cuts:
                keep = np.zeros((h, w), dtype=bool)
                alpha = straight_alpha(wk.arms, (h, w), self.seam.blend)
            elif not err.any():
                # old and new agree exactly over the overlap (a continued copy of the sample):
                # every cut gives the same pixels, so none is searched
                keep, crit, peak, alpha = overlap.copy(), 0.0, 0.0, None
            else:
                cut = wk.extra.pop("cut", None) or cut_overlap(
                    err, wk.arms, seam=self.seam, cancel=self.cancel
                )
                keep, path, crit, peak = cut.keep_old, read_only(cut.path), cut.criterion, cut.peak
                keep &= overlap
                alpha = None
                if self.seam.blend != "none":
                    alpha = blend_alpha(cut, err, overlap, seam=self.seam)
            if alpha is None:  # hard cut: exact copies of old and new
                pixels = new.copy()
                np.copyto(pixels, old_full, where=keep[:, :, None])
            else:
                a = alpha[:, :, None]
                pixels = a * old_full + (1 - a) * new
            read_only(err)
            read_only(keep)
        if not written:
            self.canvas[ix] = pixels
            self.filled[ix] = True
        if self.origin is not None:
            org = np.empty((h, w, 2), np.int32)
            org[:, :, 0] = np.arange(ay, ay + h)[:, None]
            org[:, :, 1] = np.arange(ax, ax + w)[None, :]
            if keep is not None:
                org[keep] = self.origin[ix][keep]
            self.origin[ix] = org
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
        return rec, read_only(pixels)
