"""What a quilting run will cost before it starts: the search it uses, its time and peak memory.

:func:`plan` turns checked options (:func:`engine.quilting.options.check_options`) into a
:class:`Plan`: ``mode="auto"`` becomes the exhaustive FFT search where it is cheap and the
coarse-to-fine search (:mod:`engine.pyramid`) above :data:`AUTO_EXACT_SECONDS`; an exact search
whose whole-sample spectra would not fit :data:`SEARCH_BUDGET` runs on tiles of the sample
(:class:`engine.matching.TiledSpectrum`); a run whose peak would exceed the memory this machine
can give (:func:`engine.budget.memory_limit`) is refused before any work
(:class:`engine.budget.MemoryBudgetError`, naming the way out).

Time is a cost model per block (FFT sizes, exact SSD counts, cut and paste) with constants
measured on the development machine (2 cores), scaled by a reference FFT timed when the plan is
made (so a busy machine gets a longer estimate); progress events refine it while the job runs.
Memory counts every buffer the run allocates that grows with the sample, the output or the
threads (the tests compare it with ``tracemalloc``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from engine import colour_bound
from engine.budget import check_memory, format_bytes
from engine.events import Item
from engine.fft import BUFFER_BYTES, default_backend, next_fast_len
from engine.matching import WEIGHT_CACHE_BYTES
from engine.pyramid import (
    CHILDREN,
    SEED_NEIGHBOURS,
    pyramid_levels,
    quilt_keeps,
)
from engine.quilting.layout import grid_rects

__all__ = [
    "AUTO_EXACT_SECONDS",
    "SMALL_FFT_WORK",
    "SEARCH_BUDGET",
    "Estimated",
    "Plan",
    "check_plan",
    "format_duration",
    "exact_query_bytes",
    "machine_factor",
    "plan",
]

AUTO_EXACT_SECONDS = 10.0
"""``mode="auto"`` searches exhaustively when the cost model (at the development machine's
speed, whatever this machine's load) gives it at most this long or no longer than the fast
search, else it takes the coarse-to-fine search."""

SEARCH_BUDGET = 2 * 2**30
"""Memory the run plans to stay under (bytes): above it an exact search works on tiles of the
sample and ``auto`` prefers the pyramid. Only the machine's limit
(:func:`engine.budget.memory_limit`) refuses a run."""

TILE = 1024
"""Anchors per side of one tile of a tiled exact search."""

#: cost model constants, seconds (thread time on the 2-core development machine)
FFT_NS = 0.62e-9  # per channel x N log2 N of a query's transforms (N = padded rows x half cols)
BLOCK_OVERHEAD = 0.25e-3  # Python work per block: load, choose, records, events
PASTE_PER_PIXEL = 0.12e-6  # error map, cut, composite, per block pixel (dp)
GATHER_NS = 1.7e-9  # one weighted squared difference of an exact SSD at a candidate
PYRAMID_OVERHEAD = 1.5e-3  # reduction of the target and bookkeeping per pyramid query
#: quilting's pyramid search (2026-11-25, 4096² cobblestones, block 96, overlap 16): its gathers
#: took 1.24 ns per squared difference on one thread at machine_factor 0.49 (scattered windows
#: of a large sample: they do not speed up with the reference FFT, nor fully with a second
#: thread), and about 0.45 µs per scored candidate went to bounds, best child and distinct
#: places; the gather figure is set so that L4's estimate meets its 2-thread time (7.1 s)
PYRAMID_GATHER_NS = 3.8e-9
ANCHOR_NS = 0.9e-6
REFERENCE_SECONDS = 4.1e-3  # the reference FFT (machine_factor) on the development machine
#: seam methods slower than dp, relative cost of one cut
SEAM_COST = {"dijkstra": 8.0, "minimax": 12.0, "oscillating": 3.0, "oscillating-optimal": 6.0}
#: memory of a run whatever its sizes: scheduler, events, numba's buffers
BASE_BYTES = 2 * 2**20
#: speed-up of the block pool on 2 threads (GIL-bound glue between the FFTs and kernels)
THREAD_GAIN = 1.6
SMALL_FFT_WORK = 2000 * 128 * 128
"""Blocks x padded sample pixels up to which an exact dp quilting run that needs nothing else
of scipy is estimated at the development machine's speed: timing the reference transform
(:func:`machine_factor`) imports scipy.fft (~0.25 s), more than such a run's FFTs take, which
come from scipy's pocketfft loaded by itself (:mod:`engine.fft`, a few ms). (numpy's
transforms, taken here before, are about twice slower: ~0.1 ms more a block of a 128² sample.)"""


@dataclass(frozen=True)
class Plan:
    """How a run will search and what it will cost.

    Attributes
    ----------
    mode : {"exact", "fast"}
        The search ``mode`` resolved (``auto`` chooses one).
    search : {"fft", "tiled fft", "pca", "pyramid", "none"}
        Exhaustive FFT on the whole sample or on tiles of it, principal components (small
        samples in fast mode), coarse-to-fine, or none (random and Bhatia selections).
    levels : int
        Pyramid reductions (``search == "pyramid"``).
    blocks : int
        Blocks on the grid (adaptive splitting adds more).
    seconds : float
        Estimated wall time on this machine now.
    peak_bytes : int
        Estimated peak of the memory the run allocates (the caller's sample not counted).
    fft : {"ducc0", "scipy", "numpy"}
        Where an exact search's transforms come from: :func:`engine.fft.default_backend`
        (ducc0 when installed, else scipy's pocketfft) for every plan.
    """

    mode: str
    search: str
    levels: int
    blocks: int
    seconds: float
    peak_bytes: int
    fft: str = "scipy"

    def describe(self) -> str:
        """One line for a status bar or a terminal."""
        how = {
            "fft": "exact FFT search",
            "tiled fft": "exact FFT search on tiles",
            "pca": "fast principal-component search",
            "pyramid": f"coarse-to-fine search ({self.levels} levels)",
            "none": "no search",
        }[self.search]
        return (
            f"{self.blocks} blocks, {how}: about {format_duration(self.seconds)}, "
            f"peak memory about {format_bytes(self.peak_bytes)}"
        )


@dataclass(frozen=True, slots=True)
class Estimated(Item):
    """The first event of a run: its :class:`Plan` (shown before the first block)."""

    plan: Plan


def check_plan(p: Plan, what: str) -> None:
    """Refuse a run whose planned peak exceeds the memory this machine can give
    (:class:`engine.budget.MemoryBudgetError`)."""
    check_memory(
        p.peak_bytes,
        what=f"{what} ({p.blocks} blocks, {p.search} search)",
        way_out="use a smaller sample (crop or downscale it), a smaller output or fewer threads",
    )


def format_duration(seconds: float) -> str:
    """``75`` -> ``"1 min 15 s"``; under 10 s with a decimal."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 60:
        return f"{seconds:.0f} s"
    m, s = divmod(int(round(seconds)), 60)
    if m < 60:
        return f"{m} min {s} s"
    h, m = divmod(m, 60)
    return f"{h} h {m} min"


_factor_cache: list[tuple[float, float]] = []


def machine_factor() -> float:
    """This machine's speed now relative to the development machine's (> 1: slower), from a
    reference FFT timed a few times (median; remembered for 30 s)."""
    now = time.monotonic()
    if _factor_cache and now - _factor_cache[0][0] < 30:
        return _factor_cache[0][1]
    import scipy.fft as sfft

    a = np.random.default_rng(0).random((4, 256, 256), dtype=np.float32)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        sfft.irfft2(sfft.rfft2(a, workers=1), s=(256, 256), workers=1)
        times.append(time.perf_counter() - t0)
    factor = max(0.25, sorted(times)[2] / REFERENCE_SECONDS)
    _factor_cache[:] = [(now, factor)]
    return factor


def _fft_shape(h: int, w: int) -> tuple[int, int]:
    return next_fast_len(h), next_fast_len(w)


def _fft_query_seconds(shape, channels: int) -> float:
    hp, wp = _fft_shape(*shape)
    n = hp * (wp // 2 + 1)
    cache = 1 + max(0.0, math.log2(n) - 21) / 2  # past a few MB the transforms wait on memory
    return FFT_NS * channels * n * math.log2(n) * cache


def spectra_bytes(shape, channels: int) -> int:
    """Memory of :class:`engine.matching.SampleSpectrum`'s spectra for a sample ``shape``."""
    hp, wp = _fft_shape(*shape)
    return channels * (hp // 2 + 1) * wp * 8


def exact_query_bytes(shape, channels: int) -> int:
    """Temporaries of one exhaustive query on a sample ``shape``: the kernels' spectra, their
    channel sum, the inverse transform and the error map; and the padded kernels' buffer a
    thread keeps between queries when it is small (:data:`engine.fft.BUFFER_BYTES`)."""
    hp, wp = _fft_shape(*shape)
    half = (hp // 2 + 1) * wp * 8
    kept = channels * half if channels * half <= BUFFER_BYTES else 0
    return (channels + 2) * half + 2 * hp * wp * 4 + kept


def plan(
    opts: dict, threads: int, *, channels_extra: int = 0, terms: str = "overlap", extra_bytes=0
) -> Plan:
    """The :class:`Plan` of a run with checked options ``opts`` on ``threads`` threads.

    ``channels_extra``: channels the search matches besides the colours (texture transfer's
    correspondence map); ``terms``: ``"overlap"`` (quilting: the overlap only) or ``"block"``
    (transfer: every pixel of the block weighs); ``extra_bytes``: the caller's own buffers.
    """
    sample = opts["sample"]
    H, W = sample.shape[:2]
    C = min(sample.shape[2], 3) if sample.shape[2] != 2 else 1
    cm = C + channels_extra
    groups = 1 + (channels_extra > 0)
    (bh, bw), ov = opts["block"], opts["overlap"]
    out_h, out_w = opts["out_shape"]
    if opts["select"] == "bhatia":
        n_blocks = math.ceil(out_h / bh) * math.ceil(out_w / bw)
    else:
        n_blocks = len(grid_rects(opts["out_shape"], opts["block"], ov, opts["tileable"]))
    conc = max(1, threads)
    gain = min(conc, THREAD_GAIN) if conc > 1 else 1.0
    overlap_px = (bh * bw) if terms == "block" else (bh * ov + bw * ov - ov * ov)

    # what every run holds: the canvas, masks, records and streamed pixels, the sample copy
    fixed = BASE_BYTES + extra_bytes + out_h * out_w * (sample.shape[2] * 4 + 1)
    fixed += n_blocks * bh * bw * 5  # error maps and keep masks of the records
    if not sample.flags.c_contiguous or sample.shape[2] not in (1, 3):
        fixed += H * W * C * 4  # the matched colour channels, contiguous
    if channels_extra:
        fixed += H * W * cm * 4  # transfer: colours and correspondence stacked
    seam = opts["seam"]
    place = n_blocks * (
        BLOCK_OVERHEAD + PASTE_PER_PIXEL * bh * bw * SEAM_COST.get(seam.method, 1.0)
    )

    def finish(mode, search, levels, seconds, peak):
        secs = (place + seconds) / gain  # the model's seconds; shown scaled by the machine
        return Plan(mode, search, levels, n_blocks, secs, int(fixed + peak), default_backend())

    if opts["select"] in ("random", "bhatia"):
        return finish("exact", "none", 0, 0.0, 0)
    if opts["select"] == "sampled":
        k = opts["candidates"]
        return finish("exact", "none", 0, n_blocks * k * overlap_px * cm * GATHER_NS, 0)

    # exhaustive: whole-sample spectra, or tiles when they do not fit the budget
    whole = spectra_bytes((H, W), cm + groups) + conc * exact_query_bytes((H, W), cm + groups)
    entry = spectra_bytes((H, W), 1)  # the cached weight term of one overlap mask
    whole += entry * min(10, WEIGHT_CACHE_BYTES // entry)  # up to ten masks, within the cap
    if terms == "overlap" and not channels_extra and H * W <= colour_bound.MAX_AREA:
        whole += colour_bound.extra_bytes(sample[:, :, :C])  # quilting's colour bound
    if whole + fixed <= SEARCH_BUDGET:
        exact = ("fft", n_blocks * _fft_query_seconds((H, W), cm + groups), whole)
    else:
        t = TILE
        th, tw = min(H, t + bh - 1), min(W, t + bw - 1)
        tiles = math.ceil((H - bh + 1) / t) * math.ceil((W - bw + 1) / t)
        per = tiles * _fft_query_seconds((th, tw), 2 * (cm + groups))
        mem = conc * (2 * spectra_bytes((th, tw), cm + groups) + exact_query_bytes((th, tw), cm))
        mem += conc * (H - bh + 1) * (W - bw + 1) * 4  # the error map of the whole sample
        exact = ("tiled fft", n_blocks * per, mem)

    if terms == "overlap":
        levels = pyramid_levels((H, W), (bh, bw), ov)
    else:  # transfer matches every pixel of a block: reduce as far as the block allows
        levels = pyramid_levels((H, W), (bh, bw), min(bh, bw), min_block=2)
    if levels:
        lh, lw = H >> levels, W >> levels
        coarse = _fft_query_seconds((lh, lw), cm + groups)
        if terms == "overlap":  # quilting: the exact SSDs of every level, per level's pixels
            kids = len(CHILDREN)
            keep, coarse_keep = quilt_keeps(levels)
            # per level from full resolution up: the kept candidates' children, the top level's
            # places' children one level below it, and the seeds' neighbourhoods
            scored = [kids * keep] * (levels - 1) + [kids * coarse_keep]
            scored[0] += 2 * len(SEED_NEIGHBOURS)
            gathers = sum(n / 4**lev for lev, n in enumerate(scored)) * overlap_px * cm
            search = gathers * PYRAMID_GATHER_NS + sum(scored) * ANCHOR_NS
        else:
            anchors = 64 + len(CHILDREN) * 24 * levels + 2 * len(SEED_NEIGHBOURS)
            search = anchors * overlap_px * cm * (1 + 1 / 3) * GATHER_NS
        per = PYRAMID_OVERHEAD + coarse + search
        mem = sum(H * W * cm * 4 // 4**lev for lev in range(1, levels + 1))
        mem += spectra_bytes((lh, lw), cm + groups) + conc * exact_query_bytes((lh, lw), cm)
        mem += out_h * out_w * 8  # the origin of every output pixel (the seeds)
        fast = ("pyramid", levels, n_blocks * per, mem)
    elif terms == "block":  # transfer's whole-block cost has no principal-component index
        fast = (exact[0], 0, exact[1], exact[2])
    else:
        na = (H - bh + 1) * (W - bw + 1)
        k = 24
        per = na * k * 2e-9 + opts["candidates"] * overlap_px * cm * GATHER_NS
        mem = spectra_bytes((H, W), cm + 1) + na * (k + 3) * 4 + conc * na * 4
        fast = ("pca", 0, n_blocks * (per + _fft_query_seconds((H, W), 0)), mem)

    as_exact = finish("exact", exact[0], 0, exact[1], exact[2])
    as_fast = finish("fast", fast[0], fast[1], fast[2], fast[3])
    chosen = as_exact if opts["mode"] == "exact" else as_fast
    if opts["mode"] == "auto":
        # decided on the model alone, never on the machine's load: the same inputs always take
        # the same search (and so give the same output for a seed)
        cheap = exact[0] == "fft" and (
            as_exact.seconds <= AUTO_EXACT_SECONDS or as_exact.seconds <= as_fast.seconds
        )
        chosen = as_exact if cheap else as_fast
    hp, wp = _fft_shape(H, W)
    if (
        chosen.search == "fft"
        and terms == "overlap"
        and seam.method in ("dp", "straight")
        and seam.blend == "none"
        and n_blocks * hp * wp <= SMALL_FFT_WORK
    ):
        # a small run that needs nothing else of scipy: shown at the development machine's
        # speed (timing the reference transform would cost it more than it tells)
        return chosen
    return replace(chosen, seconds=chosen.seconds * machine_factor())
