"""The entry points of image quilting: :func:`iter_quilt` (streamed) and :func:`quilt`."""

from __future__ import annotations

import inspect

from engine._validate import as_rng
from engine.events import drain
from engine.quilting.bhatia import iter_bhatia
from engine.quilting.core import Quilter
from engine.quilting.estimate import Estimated, check_plan, plan
from engine.quilting.layout import grid_rects
from engine.quilting.options import check_options, resolve_threads
from engine.quilting.records import QuiltResult
from engine.quilting.scheduler import run_levels
from engine.stitch_numpy import use_numba_for

__all__ = ["iter_quilt", "quilt", "quilt_unstreamed", "warmup"]


def iter_quilt(
    sample,
    out_shape,
    *,
    block,
    overlap=None,
    select: str = "best",
    tolerance: float = 0.1,
    candidates: int | None = None,
    seam=None,
    excluded=None,
    tileable: bool = False,
    adaptive_threshold: float | None = None,
    min_block: int | None = None,
    mode: str = "auto",
    rng=None,
    cancel=None,
    threads: int | None = None,
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
        for a ``minimax`` seam (Long & Mould), block / 4 as Bhatia's cut band.
    select : {"best", "random", "sampled", "bhatia"}
        See :mod:`engine.quilting`.
    tolerance : float
        ``"best"``: draw among windows within ``(1 + tolerance) × e_min`` (0.1 in §2.2). When
        ``e_min`` is about 0 (an exact copy exists), ``e_min`` is replaced by a floor δ:
        half the sample's mean squared adjacent-pixel difference per overlap pixel and channel
        (:data:`engine.matching.ZERO_ERROR_FRACTION`).
    candidates : int, optional
        ``"sampled"``: windows drawn per block (default 200); ``mode="fast"``: windows re-ranked
        exactly (default 32).
    seam : SeamSpec, optional
        The cut through the overlap: method (or ``"straight"``: no cut) and its options, the
        error metric of the map it runs on (the block search always uses the SSD) and the blend
        after it. Default :data:`engine.quilting.options.QUILT_SEAM` (dp on the squared error,
        no blending); for ``select="bhatia"`` :data:`~engine.quilting.options.BHATIA_SEAM`
        (Bhatia's published minimum resistance cut, blended around the cut as in the paper).
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
    mode : {"auto", "exact", "fast"}
        ``"exact"``: every sample position is scored (FFT; on tiles of the sample when its
        whole spectra would not fit the memory budget). ``"fast"``: a coarse-to-fine search
        (:mod:`engine.pyramid`; principal components on samples under 256²) whose candidates
        are re-ranked exactly. ``"auto"``: exact where its estimate is at most
        :data:`engine.quilting.estimate.AUTO_EXACT_SECONDS`, else fast
        (:func:`engine.quilting.estimate.plan`).
    rng : int, Generator or None
        Seed; the same seed gives the same output for any ``threads``.
    cancel : CancelToken, optional
        Checked between and inside blocks; raises :class:`engine.cancel.Cancelled`.
    threads : int, optional
        Worker threads (default: every core).

    Returns
    -------
    generator
        Yields :class:`~engine.quilting.estimate.Estimated` first (the plan: search, time and
        peak memory), then :class:`BlockPlaced` and :class:`~engine.events.Progress`; returns
        a :class:`QuiltResult`.

    Raises
    ------
    engine.budget.MemoryBudgetError
        Before any work, when the run's estimated peak exceeds the memory available here.
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
            excluded=excluded,
            tileable=tileable,
            adaptive_threshold=adaptive_threshold,
            min_block=min_block,
            mode=mode,
            rng=rng,
            cancel=cancel,
            threads=threads,
        )
    )


def _build_quilter(sample, out_shape, *, rng, cancel, threads, **options):
    opts = check_options(sample, out_shape, **options)
    threads = resolve_threads(threads)
    p = plan(opts, threads)
    check_plan(p, "quilting")
    use_numba_for(p.blocks)
    seed = int(as_rng(rng).integers(2**63))
    return Quilter(seed=seed, cancel=cancel, threads=threads, plan=p, **opts)


def quilt_unstreamed(sample, out_shape, **options) -> QuiltResult:
    """:func:`quilt` without creating any event: the benchmark's reference for the streaming
    overhead (same blocks, same records, same image)."""
    bound = inspect.signature(iter_quilt).bind(sample, out_shape, **options)
    bound.apply_defaults()
    q = _build_quilter(**bound.arguments)
    q.stream = False
    return drain(_iter_quilt(q))


def _iter_quilt(q: Quilter):
    if q.stream:
        yield Estimated(q.plan)
    bh, bw = q.block
    Ho, Wo = q.out_shape
    if q.select == "bhatia":
        records = yield from iter_bhatia(q, q.overlap)
        step, band = (bh, bw), q.overlap
    else:
        rects = grid_rects(q.out_shape, q.block, q.overlap, q.tileable)
        records = yield from run_levels(q, rects, "blocks")
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
            mode=q.mode,
            search=q.plan.search,
            adaptive_threshold=q.adaptive_threshold,
            min_block=q.min_block,
        ),
    )


def warmup() -> None:
    """Load (or compile) the numba kernels of every search on tiny inputs: call it in a worker
    at start-up, so that the first quilting job is not held up by it (loading them holds the
    GIL for a noticeable time)."""
    import numpy as np

    from engine import _jit
    from engine.pyramid import PyramidSearch

    _jit.load()  # else these tiny runs would take the small jobs' numpy paths

    s = np.random.default_rng(0).random((72, 72, 3), dtype=np.float32)
    for mode in ("exact", "fast"):
        quilt(s, (40, 40), block=16, overlap=4, mode=mode, rng=0, threads=1)
    m = np.zeros((16, 16, 1), np.float32)
    m[:4] = 1
    PyramidSearch(s, levels=1, keep=2, coarse_keep=4).query(s[:16, :16], m, seeds=[(1, 1)])


def quilt(sample, out_shape, **options) -> QuiltResult:
    """Drain :func:`iter_quilt` and return its :class:`QuiltResult`."""
    return drain(iter_quilt(sample, out_shape, **options))
