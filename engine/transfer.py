"""Texture transfer (Efros & Freeman 2001; CS194), ALGORITHMS.md §2.4 and §5.

The output has the target's size and is quilted from the sample; each block is chosen by

    cost = α · (overlap SSD / (|M|·C)  [+ SSD to the previous iteration / (h·w·C), i > 1])
         + (1 − α) · SSD(C_S window, C_T at the block) / (h·w)

with C_S, C_T the correspondence maps (luminance, or luminance blurred by ``sigma``) of sample
and target. Every SSD is normalised by its pixel × channel count, else α would be meaningless
(§2.4 [FIX]; the CS194 author had to add such a weight). All three terms are computed for every
sample position at once by one FFT masked-SSD query (:meth:`engine.matching.SampleSpectrum.
ssd_terms`: the correspondence map is one more channel of the sample spectrum).

Iterations: ``B_i = round(B_1 (2/3)^(i-1))`` (from B_1, never compounded [FIX]),
``ov_i = B_i / 6`` (or ``overlap`` scaled likewise), ``α_i = 0.1 + 0.8 (i-1)/(N-1)``; each
iteration is a full raster pass on a fresh canvas and, from i = 2, matches whole blocks against
the *frozen* result of iteration i − 1 (a separate read-only array, never overwritten [FIX]).

With α = 1 and one iteration the correspondence and previous terms vanish: the cost is the
plain overlap SSD and the output of the exact search is exactly :func:`engine.quilting.quilt`'s
for the same seed.

Large samples (``mode="auto"``/``"fast"``) take the coarse-to-fine search of
:mod:`engine.pyramid`, the correspondence map reduced with the colours as one more channel:
the same three-term cost, written as a weighted SSD against one target per pixel plus a
constant, ranks the candidates at every level and re-ranks them exactly at full resolution.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage

from engine._validate import as_image, as_rng, choice, positive_int
from engine.cancel import check
from engine.errormap import colour_channels
from engine.events import Progress, Snapshot, drain
from engine.matching import ZERO_ERROR_FRACTION, error_floor
from engine.pyramid import PyramidSearch
from engine.quilting.core import BlockWork, Quilter
from engine.quilting.estimate import Estimated, check_plan, plan
from engine.quilting.layout import grid_rects
from engine.quilting.names import CORRESPONDENCES
from engine.quilting.options import check_options, resolve_threads, sample_array
from engine.quilting.records import BlockRecord
from engine.quilting.scheduler import run_levels
from engine.stitch_numpy import use_numba_for

PYRAMID_KEEP = 12
"""Candidates the coarse-to-fine search carries per level in transfer (quilting: 24). Every
pixel of a transfer block weighs in its exact re-ranking, so each candidate costs the whole
block; the correspondence term is smooth, and half the candidates give the same result."""

__all__ = [
    "CORRESPONDENCES",
    "IterationDone",
    "TransferResult",
    "correspondence_map",
    "iter_transfer",
    "transfer",
    "transfer_schedule",
]


@dataclass(frozen=True, slots=True)
class IterationDone(Snapshot):
    """One full pass finished: its output, parameters and correspondence error.

    ``correspondence_error`` is the mean squared difference between the correspondence map of
    ``image`` and the target's.
    """

    iteration: int
    image: np.ndarray
    block: int
    overlap: int
    alpha: float
    correspondence_error: float


@dataclass(frozen=True)
class TransferResult:
    """Final image, every iteration's summary, and the last iteration's block records.

    In these records ``match_error`` and ``best_error`` are the transfer cost scaled so that the
    overlap term has weight 1 (the correspondence term's weight when a block has no overlap).
    """

    image: np.ndarray
    iterations: tuple[IterationDone, ...]
    blocks: tuple[BlockRecord, ...]


def correspondence_map(image, *, kind: str = "luminance", sigma: float = 2.0) -> np.ndarray:
    """(H, W) float32 correspondence map: Rec. 601 luminance, optionally Gaussian-blurred."""
    choice(kind, "correspondence", CORRESPONDENCES)
    img = colour_channels(as_image(image, "image"))
    rec601 = np.array([0.299, 0.587, 0.114], np.float32)
    lum = img @ rec601 if img.shape[2] == 3 else img[:, :, 0]
    lum = np.ascontiguousarray(lum, dtype=np.float32)
    if kind == "blurred":
        lum = ndimage.gaussian_filter(lum, float(sigma), mode="reflect")
    return lum


def transfer_schedule(block: int, iterations: int, *, alpha=None, overlap=None):
    """``[(B_i, ov_i, α_i), ...]`` for ``iterations`` passes (§2.4).

    ``alpha``: None → ``0.1 + 0.8 (i-1)/(N-1)`` (0.1 for a single pass); a number → that α in
    every pass; a pair (a, b) → linear from a to b.
    """
    b1 = positive_int(block, "block")
    n = positive_int(iterations, "iterations")
    sched = []
    for i in range(1, n + 1):
        b = int(math.floor(b1 * (2.0 / 3.0) ** (i - 1) + 0.5))
        ov = max(1, b // 6) if overlap is None else max(1, int(math.floor(overlap * b / b1 + 0.5)))
        if alpha is None:
            a = 0.1 if n == 1 else 0.1 + 0.8 * (i - 1) / (n - 1)
        elif isinstance(alpha, tuple | list):
            a0, a1 = (float(v) for v in alpha)
            a = a0 if n == 1 else a0 + (a1 - a0) * (i - 1) / (n - 1)
        else:
            a = float(alpha)
        sched.append((b, ov, a))
    return sched


def _check_alpha(alpha):
    values = () if alpha is None else (alpha if isinstance(alpha, tuple | list) else (alpha,))
    if isinstance(alpha, tuple | list) and len(alpha) != 2:
        raise ValueError(f"alpha must be a number or a pair (first, last), got {alpha!r}")
    for v in values:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise TypeError(f"alpha must be a number in [0, 1] or a pair of them, got {alpha!r}")
        if not 0 <= v <= 1:
            raise ValueError(f"alpha must lie in [0, 1], got {alpha!r}")


class _TransferQuilter(Quilter):
    """One transfer pass: the quilting engine with the α-weighted three-term cost."""

    worker_processes = False  # threads only (not measured with worker processes)

    def __init__(self, *, corr_sample, corr_target, previous, alpha, corr_floor, shared, **kw):
        super().__init__(**kw)
        self.corr_sample = corr_sample
        self.corr_target = corr_target
        self.previous = previous
        self.alpha = alpha
        self.corr_floor = corr_floor
        self.shared = shared  # what every pass searches alike: stack, floor, pyramid
        self.floor = shared.get("floor", 0.0)

    def prepare(self) -> None:
        super().prepare()
        self.shared["floor"] = self.floor

    def search_sample(self):
        c = self.match_sample.shape[2]
        if "stack" not in self.shared:
            self.shared["stack"] = np.concatenate(
                [self.match_sample, self.corr_sample[:, :, None]], axis=2
            )
        return self.shared["stack"], (tuple(range(c)), (c,))

    def make_pyramid(self):
        """One pyramid, as deep as the deepest pass needs, shared by the passes."""
        if "pyramid" not in self.shared:
            stack, groups = self.search_sample()
            self.shared["pyramid"] = PyramidSearch(
                stack,
                levels=self.shared["levels"],
                groups=groups,
                keep=PYRAMID_KEEP,
                workers=self.threads,
            )
        return self.shared["pyramid"].shallower(self.plan.levels)

    def load(self, wk: BlockWork) -> None:
        super().load(wk)
        ix = self.idx(wk.y, wk.x, wk.h, wk.w)
        wk.extra["corr"] = self.corr_target[ix]
        if self.previous is not None:
            wk.extra["prev"] = colour_channels(self.previous[ix])
        a = self.alpha
        n_m = int(wk.filled.sum())
        c = self.match_sample.shape[2]
        hw = wk.h * wk.w
        w_ov = a / (n_m * c) if n_m else 0.0
        w_prev = a / (hw * c) if self.previous is not None else 0.0
        w_corr = (1.0 - a) / hw
        ref = w_ov or max(w_prev, w_corr)
        wk.extra["weights"] = (0.0, 0.0) if ref == 0 else (w_prev / ref, w_corr / ref)
        wk.extra["searched"] = ref > 0
        r_prev, r_corr = wk.extra["weights"]
        base = ZERO_ERROR_FRACTION * self.floor * n_m * c if w_ov else 0.0
        wk.extra["zero"] = base + ZERO_ERROR_FRACTION * (
            r_prev * self.floor * hw * c + r_corr * self.corr_floor * hw
        )

    def zero_level_for(self, wk: BlockWork) -> float:
        return wk.extra["zero"]

    def _pyramid_terms(self, wk: BlockWork, kern, wts, const: float):
        """The coarse-to-fine search on the cost ``const - 2 Σ corr(S, kern) + Σ corr(S², wts)``
        written as ``Σ_g W_g (S - T)² + R``: weights W = ``wts``, targets T = kern / W, and the
        constant R added to the re-ranked errors."""
        c = self.match_sample.shape[2]
        group_of = np.array([0] * c + [1])
        w = wts[group_of]
        t = np.divide(kern, w, out=np.zeros_like(kern), where=w > 0)
        rest = const - float(np.einsum("chw,chw->", w * t, t, dtype=np.float64))
        v, _ = self.valid(wk.h, wk.w)
        anchors, errors = self._pyramid.query(
            np.moveaxis(t, 0, 2),
            np.moveaxis(wts, 0, 2),
            valid=v,
            seeds=self.seeds(wk),
            workers=self.fft_workers,
        )
        return anchors, np.maximum(errors + rest, 0.0)

    def search(self, works: list[BlockWork]) -> None:
        groups: dict[tuple[int, int], list[BlockWork]] = {}
        for wk in works:
            if wk.extra["searched"]:
                groups.setdefault((wk.h, wk.w), []).append(wk)
        for (h, w), group in groups.items():
            check(self.cancel)
            c = self.match_sample.shape[2]
            n = len(group)
            kern = np.zeros((n, c + 1, h, w), np.float32)
            wts = np.zeros((n, 2, h, w), np.float32)
            old = np.stack(
                [wk.old if wk.old is not None else np.zeros((h, w, c), np.float32) for wk in group]
            )
            m = np.stack([wk.filled for wk in group]).astype(np.float32)
            tt = np.moveaxis(old, 3, 1)
            k = m[:, None] * tt  # the overlap term exactly as in plain quilting
            const = np.einsum("nchw,nchw->n", k, tt, dtype=np.float64)
            kern[:, :c] = k
            wts[:, 0] = m
            for i, wk in enumerate(group):
                r_prev, r_corr = wk.extra["weights"]
                if r_prev:
                    p = np.moveaxis(wk.extra["prev"], 2, 0)
                    kern[i, :c] += r_prev * p
                    wts[i, 0] += r_prev
                    const[i] += r_prev * float(np.sum(p.astype(np.float64) ** 2))
                if r_corr:
                    t = wk.extra["corr"]
                    kern[i, c] = r_corr * t
                    wts[i, 1] = r_corr
                    const[i] += r_corr * float(np.sum(t.astype(np.float64) ** 2))
            if self._pyramid is not None:
                for i, wk in enumerate(group):
                    wk.found = ("list", *self._pyramid_terms(wk, kern[i], wts[i], const[i]))
                continue
            maps = self.spectrum.ssd_terms(kern, wts, const, workers=self.fft_workers)
            v, _ = self.valid(h, w)
            for wk, e in zip(group, maps, strict=True):
                if v is not None:
                    e[~v] = np.inf
                wk.found = ("map", e)


def iter_transfer(
    sample,
    target,
    *,
    block,
    overlap=None,
    alpha=None,
    iterations: int = 3,
    correspondence: str = "luminance",
    sigma: float = 2.0,
    tolerance: float = 0.1,
    seam=None,
    excluded=None,
    mode: str = "auto",
    rng=None,
    cancel=None,
    threads: int | None = None,
):
    """Texture transfer of ``sample`` onto ``target``'s layout, streaming events.

    Parameters
    ----------
    sample : (H, W[, C]) array_like
        The texture.
    target : (Ht, Wt[, C']) array_like
        The image to imitate; the output is Ht × Wt with the sample's channels.
    block : int
        Block size of the first iteration (later ones shrink by 2/3 each).
    overlap : int, optional
        Overlap of the first iteration (default block / 6), scaled with the block.
    alpha : float, (float, float) or None
        Weight of the texture terms against correspondence: None → 0.1 … 0.9 over the
        iterations (0.1 for one); a number → every iteration; a pair → linear ramp.
    iterations : int
        Number of passes N.
    correspondence : {"luminance", "blurred"}
        Correspondence maps; ``sigma`` is the blur of ``"blurred"``.
    tolerance, seam, excluded, mode, rng, cancel, threads
        As in :func:`engine.quilting.iter_quilt`; ``mode`` is planned per pass (the
        coarse-to-fine search matches the correspondence map as one more channel).

    Returns
    -------
    generator
        Yields :class:`engine.quilting.Estimated` first (the passes' total time and largest
        peak), then :class:`engine.quilting.BlockPlaced`, :class:`IterationDone` and
        :class:`~engine.events.Progress`; returns a :class:`TransferResult`.
    """
    s = sample_array(sample)
    t = as_image(target, "target")
    sched, plans = transfer_plans(
        s,
        t.shape[:2],
        block=block,
        overlap=overlap,
        alpha=alpha,
        iterations=iterations,
        correspondence=correspondence,
        sigma=sigma,
        tolerance=tolerance,
        seam=seam,
        excluded=excluded,
        mode=mode,
    )
    threads = resolve_threads(threads)
    passes = [
        plan(o, threads, channels_extra=1, terms="block", extra_bytes=_transfer_bytes(s, t))
        for o in plans
    ]
    total = replace(
        passes[0],
        blocks=sum(p.blocks for p in passes),
        seconds=sum(p.seconds for p in passes),
        peak_bytes=max(p.peak_bytes for p in passes),
    )
    check_plan(total, f"texture transfer ({len(sched)} passes)")
    use_numba_for(total.blocks)
    gen = as_rng(rng)
    seed = int(gen.integers(2**63))
    return _iter_transfer(
        s, t, plans, passes, total, sched, correspondence, float(sigma), seed, cancel, threads
    )


def transfer_plans(
    sample,
    out_shape,
    *,
    block,
    overlap,
    alpha,
    iterations,
    correspondence,
    sigma,
    tolerance,
    seam,
    excluded,
    mode,
):
    """The options of :func:`iter_transfer` checked: ``(schedule, plans)``, each pass's
    :func:`~engine.quilting.options.check_options` dict; ValueError / TypeError when they
    cannot run (the editor checks them on a stand-in of the sample before clearing its
    output)."""
    s = sample_array(sample)
    choice(correspondence, "correspondence", CORRESPONDENCES)
    _check_alpha(alpha)
    if isinstance(sigma, bool) or not isinstance(sigma, numbers.Real) or not sigma > 0:
        raise ValueError(f"sigma must be a positive number, got {sigma!r}")
    n_iter = positive_int(iterations, "iterations")
    b1 = positive_int(block, "block")
    if overlap is not None:
        overlap = positive_int(overlap, "overlap")
    sched = transfer_schedule(b1, n_iter, alpha=alpha, overlap=overlap)
    plans = []
    for i, (b, ov, _) in enumerate(sched, start=1):
        if b < 4 or ov >= b:
            also = f" and overlap {overlap} to {ov} px" if ov >= b else ""
            raise ValueError(
                f"iterations={n_iter} shrinks block {b1} to {b} px{also} at iteration {i}: "
                "use fewer iterations, a larger block" + (" or a smaller overlap" if also else "")
            )
        plans.append(
            check_options(
                s,
                out_shape,
                block=b,
                overlap=ov,
                select="best",
                tolerance=tolerance,
                candidates=None,
                seam=seam,
                excluded=excluded,
                tileable=False,
                adaptive_threshold=None,
                min_block=None,
                mode=mode,
            )
        )
    return sched, plans


def _transfer_bytes(sample, target) -> int:
    """Transfer's own buffers: both correspondence maps, the frozen previous pass."""
    (h, w), (ht, wt) = sample.shape[:2], target.shape[:2]
    return 4 * (h * w + ht * wt + ht * wt * sample.shape[2])


def _iter_transfer(s, t, plans, passes, total, sched, kind, sigma, seed, cancel, threads):
    yield Estimated(total)
    corr_s = correspondence_map(s, kind=kind, sigma=sigma)
    corr_t = correspondence_map(t, kind=kind, sigma=sigma)
    corr_floor = error_floor(corr_s[:, :, None])
    shared = {"levels": max(p.levels for p in passes)}
    previous = None
    done_iters = []
    records: tuple = ()
    total = sum(len(grid_rects(p["out_shape"], p["block"], p["overlap"], False)) for p in plans)
    done = 0
    for i, (opts, (b, ov, a)) in enumerate(zip(plans, sched, strict=True), start=1):
        check(cancel)
        it_seed = seed if i == 1 else int(np.random.SeedSequence([seed, i]).generate_state(1)[0])
        q = _TransferQuilter(
            corr_sample=corr_s,
            corr_target=corr_t,
            previous=previous,
            alpha=a,
            corr_floor=corr_floor,
            shared=shared,
            seed=it_seed,
            cancel=cancel,
            threads=threads,
            plan=passes[i - 1],
            **opts,
        )
        rects = grid_rects(q.out_shape, q.block, q.overlap, False)
        gen = run_levels(q, rects, f"blocks (iteration {i})")
        while True:
            try:
                ev = next(gen)
            except StopIteration as stop:
                records = tuple(stop.value)
                break
            if isinstance(ev, Progress):
                ev = Progress(done + ev.done, total, ev.message)
            yield ev
        done += len(rects)
        image = q.canvas
        image.setflags(write=False)  # frozen: the next pass only reads it
        err = float(np.mean((correspondence_map(image, kind=kind, sigma=sigma) - corr_t) ** 2))
        ev = IterationDone(i, image, b, ov, a, err)
        done_iters.append(ev)
        yield ev
        previous = image
    return TransferResult(image=previous, iterations=tuple(done_iters), blocks=records)


def transfer(sample, target, **options) -> TransferResult:
    """Drain :func:`iter_transfer` and return its :class:`TransferResult`."""
    return drain(iter_transfer(sample, target, **options))
