"""Wang tile sets (Cohen, Shade, Hiller & Deussen 2003; ALGORITHMS.md §6).

Every tile edge carries a colour; K colours for the north/south edges (axis ``"h"``) and K for
the east/west edges (axis ``"v"``). Two tiles join wherever their touching edges have the same
colour, because both show the same *edge sample* there: a diamond of the source centred on the
edge, whose halves lie in the two tiles. The complete set has one tile per edge signature
(N, E, S, W), K⁴ tiles (16 for K = 2, 81 for K = 3), optionally several variants each.

1. **Edge samples** (:func:`choose_sample`). Each colour is a source position. In a tile, an
   N/S sample meets an E/W sample along a diagonal, so the samples are chosen by the quilting
   matcher (:class:`engine.matching.SampleSpectrum`, masked SSD by FFT over every source
   position): each new sample is the best match (drawn within ``tolerance``) for the samples of
   the other axis over the four diagonal bands where they meet, at least ``min_distance``
   from every earlier sample (variety: no sample repeats another or continues it). The first
   is drawn at random; after one round each sample of the first axis is chosen again against
   the whole other axis.
2. **The frame** (:mod:`engine.tiles.wang_cut`): the four edge layers joined by four
   minimum-error cuts from the corners to a junction (any seam method), so the tile's edge
   pixels are exactly the edge samples' own.
3. **The interior** (``interior="patch"``, default [REC]): a source window chosen by the same
   matcher against the frame's ring (offsets ``margin .. patch_overlap - 1``), drawn within
   ``tolerance`` and away from the samples and the other tiles' windows, stitched in along a
   closed cut inside that ring (:func:`engine.stitch.patch_cut`; the outer ``margin`` pixels
   stay the frame's), blended in the gradient domain (``interior_blend``) so that its tone
   continues the shared ring's. Without it (``interior="diamonds"``, Cohen's construction)
   every pixel of a tile is one of its four samples: a tile repeats a quarter of every tile of
   the same colour, which a large layout shows as a lattice of repeated diamonds. With it only
   the thin ring outside the cut is shared, and ``variants`` tiles per signature differ inside.

Tiles stream as :class:`WangTile` items (after one :class:`WangSamples` item); tile ``k`` is
seeded from ``(seed, k)`` and its interior avoids the windows of tiles ``0 .. k-1`` only, so the
same seed gives the same set on 1 or 2 workers. Material maps follow every cut
(:func:`engine.materials.apply_cut`: normals renormalised); with hard cuts (``seam`` blend
"none") every pixel is a copy of the source (16-bit values stay exact); the gradient-domain
interior changes the values its correction reaches (the edge pixels stay the samples' own).
"""

from __future__ import annotations

import warnings
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from engine._validate import choice, positive_int
from engine.cancel import AnyCancel, Cancelled, CancelToken, is_cancelled
from engine.completions import Completions
from engine.events import Progress, drain
from engine.tiles.candidates import base_seed
from engine.tiles.wang_setup import WangSetup
from engine.tiles.wang_types import (
    AXES,
    INTERIOR_BLENDS,
    INTERIORS,
    WANG_DEFAULTS,
    WangSample,
    WangSamples,
    WangSet,
    WangTile,
    canonical_signatures,
    de_bruijn,
    from_candidate,
    samples_from_record,
    wang_record,
    wang_seed,
)

__all__ = [
    "AXES",
    "INTERIORS",
    "INTERIOR_BLENDS",
    "WANG_DEFAULTS",
    "WangSample",
    "WangSamples",
    "WangSet",
    "WangSetup",
    "WangTile",
    "canonical_signatures",
    "choose_sample",
    "de_bruijn",
    "from_candidate",
    "iter_wang_set",
    "make_wang_tile",
    "samples_from_record",
    "wang_record",
    "wang_seed",
    "wang_set",
]


# --------------------------------------------------------------------------- API
def _check_samples(setup: WangSetup, samples) -> list[WangSample]:
    K = setup.K
    try:
        samples = list(samples)
    except TypeError:
        raise TypeError("samples must be a list of WangSample") from None
    if len(samples) != 2 * K or not all(isinstance(s, WangSample) for s in samples):
        raise ValueError(f"samples must be {2 * K} WangSample (h colours, then v colours)")
    for i, s in enumerate(samples):
        axis, colour = AXES[i // K], i % K
        if (s.axis, s.colour) != (axis, colour):
            raise ValueError(
                f"samples[{i}] must be the {axis!r} sample of colour {colour}, got "
                f"{(s.axis, s.colour)}"
            )
    for s in samples:
        setup.check_origin(s.axis, s.origin)
    return samples


def _check_indices(indices, count: int) -> list[int]:
    if indices is None:
        return list(range(count))
    out = sorted({int(i) for i in indices})
    if out and (out[0] < 0 or out[-1] >= count):
        raise ValueError(f"tile indices must lie in [0, {count - 1}], got {out}")
    return out


def _signature(K: int, index: int) -> tuple[tuple[int, int, int, int], int]:
    sigs = canonical_signatures(K)
    return sigs[index % len(sigs)], index // len(sigs)


def iter_wang_set(
    source,
    *,
    tile_size: int,
    samples=None,
    tiles=None,
    avoid=(),
    rng=None,
    workers: int = 2,
    cancel=None,
    **options,
):
    """Stream a Wang tile set; the generator's value is the :class:`WangSet`.

    Parameters
    ----------
    source : (H, W[, C]) array
    tile_size : int
        T (square tiles, >= 8).
    samples : list of WangSample or None
        Use these edge samples (h colours 0..K-1 then v colours) instead of choosing them.
    tiles : iterable of int or None
        Build only these tile indices (default all).
    avoid : iterable of (row, col)
        Interior windows (top-left) of tiles kept from elsewhere, which new interiors avoid.
    rng : int, Generator or None
        The run's seed.
    workers : int
        Threads (1 runs in the calling thread).
    cancel : CancelToken or None
        Stops the run; the tiles already finished are kept in the returned set.

    Options (defaults in :data:`WANG_DEFAULTS`)
    -------------------------------------------
    colours : int
        K, colours per edge direction; the set has ``variants * K**4`` tiles.
    band : int or None
        Half-width of the diagonal bands the corner cuts run in (default ≈ T / 10).
    variants : int
        Tiles per edge signature (each with its own interior patch).
    interior : {"patch", "diamonds"}
        A matched source window inside each tile (default) or Cohen's four diamonds alone.
    interior_blend : {"auto", "none", "feather", "adaptive", "poisson"}
        How the interior patch is blended along its closed cut: ``"auto"`` (default) in the
        gradient domain (:mod:`engine.poisson`, screened: the step between the window and
        the shared ring is spread over both sides, so tone continues across the tile lines)
        unless ``seam`` asks for hard cuts (blend "none"); otherwise that blend for the
        interior alone (the frame's corner cuts always take ``seam``'s).
    patch_overlap, margin
        The ring the interior's closed cut runs in (default as the Somol set's w_P for a
        template overlap of T / 10) and the outer pixels that always stay the edge samples'
        (>= 1).
    outward : float
        Bias of the interior's cut towards the margin (its error is weighted
        ``1 + outward`` at the ring's inner edge, 1 at the margin), so the part every tile
        of an edge colour shares stays thin; the interior is matched with the inverse weights.
    min_distance : float or None
        Least distance (px) between samples and interior windows (default T / 2; halved when
        the source cannot hold them, with a note).
    tolerance : float
        Samples and interiors are drawn among the positions within ``(1 + tolerance)`` of
        the best match.
    corner_match : bool
        Draw the h samples also where their corner pixels meet the v samples' end pixels
        (columns 0 and T-1 at rows 1 and T-2, which sit between two pixels of the h layer
        where four tiles meet: :meth:`WangSetup.hv_corner_errors`), under the same bound as
        the h samples' own corner steps (default True since session 10, with the interiors'
        detail balance; README "Session 8" and "Session 10").
    seam : SeamSpec
        Seam method and options, error metric and blending of every cut (default
        :data:`engine.stitch.PATCH_SEAM`: dp, adaptive blending).
    excluded : (H, W) bool or None
        Source pixels no sample or patch may contain.
    maps, weights
        Extra material maps ({name: image of the source's size}) and the seam error weights.

    Yields :class:`Progress`, one :class:`WangSamples` and the :class:`WangTile` items as they
    finish (any order; each has its ``index``).
    """
    setup = WangSetup(source, tile_size=tile_size, **options)
    given = None if samples is None else _check_samples(setup, samples)
    count = setup.variants * setup.K**4
    indices = _check_indices(tiles, count)
    avoid = [(int(y), int(x)) for y, x in avoid]
    workers = positive_int(workers, "workers")
    base = base_seed(rng)
    for note in setup.notes:
        warnings.warn(note, stacklevel=2)
    return _iter_wang_set(setup, given, indices, avoid, base, workers, cancel)


def _iter_wang_set(setup: WangSetup, samples, indices, avoid, base, workers, cancel):
    n = len(indices)
    yield Progress(0, n, "Wang tiles")
    notes_before = len(setup.notes)
    if samples is None:
        try:
            samples = setup.choose_all(base, cancel)
        except Cancelled:
            yield Progress(0, n, "Wang tiles: cancelled")
            return _result(setup, [], [], {})
    yield WangSamples(tuple(samples))
    made: dict[int, WangTile] = {}
    stop = CancelToken()
    token = AnyCancel(cancel, stop)
    pool = (
        ThreadPoolExecutor(max_workers=workers, thread_name_prefix="wang") if workers > 1 else None
    )

    completions = Completions()  # a Ctrl+C while waiting never wedges a worker

    def submit(fn, *args) -> Future:
        if pool is not None:
            return completions.watch(pool.submit(fn, *args))
        f: Future = Future()
        try:
            f.set_result(fn(*args))
        except BaseException as exc:  # noqa: BLE001 - handed to the consumer like a pool's
            f.set_exception(exc)
        return completions.watch(f)

    def stage_a(k):
        sig, _ = _signature(setup.K, k)
        fr, framed = setup.frame(samples, sig, token)
        errs = setup.patch_errors(framed) if setup.interior == "patch" else None
        return fr, framed, errs

    def stage_c(k, fr, framed, origin, band_error):
        sig, variant = _signature(setup.K, k)
        return setup.finish(
            k, sig, variant, fr, framed, origin, band_error, wang_seed(base, 1, k), token
        )

    try:
        ahead = workers  # frames made ahead of the ordered choice (a finish waits behind them)
        firsts: dict[int, Future] = {}
        finishing: dict[Future, int] = {}
        placed = list(avoid)
        nxt = 0

        def fill():
            nonlocal nxt
            while nxt < n and len(firsts) < ahead:
                firsts[indices[nxt]] = submit(stage_a, indices[nxt])
                nxt += 1

        fill()
        for k in indices:
            if is_cancelled(cancel):
                break
            fut = firsts[k]
            while not completions.is_done(fut):  # hand out finished tiles while k's frame is made
                done = completions.wait([fut, *finishing])
                yield from _collect(done, finishing, made, n)
            try:
                fr, framed, errs = fut.result()
            except Cancelled:
                break
            del firsts[k]
            fill()
            origin, band_error = None, None
            if errs is not None:
                rng = np.random.default_rng(wang_seed(base, 1, k))
                origin, band_error, _ = setup.patch_anchor(errs, samples, placed, rng)
                placed.append(origin)
            finishing[submit(stage_c, k, fr, framed, origin, band_error)] = k
            done = [f for f in finishing if completions.is_done(f)]
            yield from _collect(done, finishing, made, n)
        while finishing and not is_cancelled(cancel):
            done = completions.wait(finishing)
            yield from _collect(done, finishing, made, n)
    finally:
        stop.cancel()
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
    if len(made) < n:
        yield Progress(len(made), n, "Wang tiles: cancelled")
    for note in setup.notes[notes_before:]:
        warnings.warn(note, stacklevel=2)
    return _result(setup, samples, [made[k] for k in sorted(made)], {})


def _collect(done, finishing: dict, made: dict, n: int):
    for f in sorted(done, key=lambda f: finishing.get(f, -1)):
        k = finishing.pop(f, None)
        if k is None:
            continue
        try:
            t = f.result()
        except Cancelled:
            continue
        made[k] = t
        yield t
        yield Progress(len(made), n, f"Wang tile {k}")


def _result(setup: WangSetup, samples, tiles, extra) -> WangSet:
    return WangSet(
        colours=setup.K,
        tile_size=setup.T,
        band=setup.band,
        variants=setup.variants,
        samples=tuple(samples),
        tiles=tuple(tiles),
        parameters={**setup.parameters(), **extra},
        notes=tuple(dict.fromkeys(setup.notes)),
        suggested_size=setup.suggested_size,
        suggested_note=setup.suggested_note,
    )


def wang_set(source, **options) -> WangSet:
    """Drain :func:`iter_wang_set` and return the :class:`WangSet`."""
    return drain(iter_wang_set(source, **options))


def choose_sample(source, samples, axis: str, colour: int, *, tile_size: int, rng=None, **options):
    """Choose edge sample ``colour`` of ``axis`` again (a re-roll): the best match for the
    other axis's samples within tolerance, away from the others. ``samples`` is the current
    list (h colours then v colours); the others stay. Options as :func:`iter_wang_set`."""
    setup = WangSetup(source, tile_size=tile_size, **options)
    current = _check_samples(setup, samples)
    choice(axis, "axis", AXES)
    colour = positive_int(colour, "colour", minimum=0)
    if colour >= setup.K:
        raise ValueError(f"colour must be < {setup.K}, got {colour}")
    other = "v" if axis == "h" else "h"
    others = [s for s in current if s.axis == other]
    same = [s for s in current if s.axis == axis and s.colour != colour]
    placed = setup.role_anchors([s for s in current if (s.axis, s.colour) != (axis, colour)])
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    return setup.choose(axis, colour, others, placed, gen, same)


def make_wang_tile(
    source,
    samples,
    index: int,
    *,
    tile_size: int,
    patch_origin=None,
    seed: int | None = None,
    avoid=(),
    cancel=None,
    **options,
) -> WangTile:
    """Make tile ``index`` of a set with these ``samples``: its interior from ``patch_origin``
    (row, col) when given, else drawn from ``seed`` away from ``avoid`` (other tiles'
    interior windows). Options as :func:`iter_wang_set`."""
    setup = WangSetup(source, tile_size=tile_size, **options)
    current = _check_samples(setup, samples)
    count = setup.variants * setup.K**4
    (index,) = _check_indices([index], count)
    sig, variant = _signature(setup.K, index)
    fr, framed = setup.frame(current, sig, cancel)
    origin, band_error = None, None
    if setup.interior == "patch":
        T = setup.T
        H, W = setup.S.shape[:2]
        if patch_origin is not None:
            try:
                origin = (int(patch_origin[0]), int(patch_origin[1]))
            except (TypeError, ValueError, IndexError):
                raise TypeError(f"patch_origin must be (row, col), got {patch_origin!r}") from None
            if not (0 <= origin[0] <= H - T and 0 <= origin[1] <= W - T):
                raise ValueError(
                    f"patch_origin {origin} puts the {T}x{T} patch outside the {W}x{H} source"
                )
            errs = setup.patch_errors(framed)
            band_error = float(errs[origin]) / (float(setup.ring_mask.sum()) * setup.S.shape[2])
        else:
            errs = setup.patch_errors(framed)
            rng = np.random.default_rng(seed)
            origin, band_error, _ = setup.patch_anchor(
                errs, current, [(int(y), int(x)) for y, x in avoid], rng
            )
    return setup.finish(index, sig, variant, fr, framed, origin, band_error, seed, cancel)
