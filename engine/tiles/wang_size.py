"""A Wang tile size that holds whole periods of a periodic texture (``--tile-size auto``).

A Wang tile whose W and E colours are equal continues the same edge sample across both of its
vertical edges; on a texture periodic along x that is only possible when the tile holds a
whole number of periods. Otherwise every vertical tile line of a layout breaks the pattern
(measured on the evaluation set's planks, boards every 48 px: 128 px tiles hold 2.67 boards,
so every vertical tile line has a board of another width, frame 1.21 over seeds 0-2; 144 px
holds three and the boards run straight through the layout, frame 1.11; README, Wang).
:func:`whole_period_size` moves a requested size to the nearest one within
:data:`SNAP_RANGE` of it that holds whole periods along every periodic axis whose period it
holds at least once (:func:`engine.reference_crops.phase_axes`' test, the one the set's phase
and the benchmark use); :func:`auto_tile_size` does so for a source, within the sizes the
source allows. [REC: our design; measured on the evaluation set, README]
"""

from __future__ import annotations

import math

__all__ = [
    "SNAP_RANGE",
    "STRUCTURE_FRACTION",
    "auto_tile_size",
    "large_structure_note",
    "periods_held",
    "source_fits",
    "whole_period_size",
]

#: an automatic size stays within this fraction of the requested one (128 -> 96..160)
SNAP_RANGE = 0.25
#: a Wang set warns when a decorrelation length (no period) of
#: :func:`engine.tiles.scale.structure_scale` exceeds this fraction of the tile: the blobs it
#: measures are at least about 1.5 times as large (0.58-0.73 of the cell size on Voronoi blobs
#: of 24-96 px; stones with grain of their own more: about 300 px stones at 89 px on a
#: 4000x3000 upscale of the bundled cobblestones), so the tiles fall inside single structures
#: (128 px there: a blurry layout without a whole stone). Not the tile set's third
#: (:data:`engine.tiles.scale.STRUCTURES_PER_TILE`): the evaluation set's retina (54x63 px),
#: cell (49x47) and coins (71x60 px periods) meet every line of the Wang table at 128 px
STRUCTURE_FRACTION = 0.6


def _whole_axes(scale, T: int) -> list[int]:
    """Axes (0 = y, 1 = x) along which ``scale`` is periodic with a period T holds at least
    once (within :func:`engine.reference_crops.phase_axes`' slack): the axes a T px tile must
    hold whole."""
    from engine.tiles.scale import WHOLE_SLACK

    top = T + max(1.0, WHOLE_SLACK * T)
    return [i for i in range(2) if scale.periodic[i] and 0 < float(scale.size[i]) <= top]


def periods_held(scale, n: int, T: int | None = None) -> list[tuple[int, float, str]]:
    """(count, period px, "tall"/"wide") of the periods an ``n`` px tile holds along every axis
    a ``T`` px tile (default ``n``) must hold whole (:func:`whole_period_size`'s axes; count
    rounded): [(5, 48.0, "wide")] for 240 px over 48 px boards; [] when there is no such axis."""
    axes = _whole_axes(scale, n if T is None else T)
    out = []
    for i in axes:
        p = float(scale.size[i])
        out.append((round(n / p), p, ("tall", "wide")[i]))
    return out


def whole_period_size(scale, T: int, fits=None) -> int | None:
    """The tile size nearest to ``T`` (ties: the larger) within ``T`` ± :data:`SNAP_RANGE`
    that holds a whole number of periods along every axis where ``scale`` (a
    :class:`engine.tiles.scale.Scale`) is periodic with a period T holds at least once, and
    that ``fits(size)`` accepts (every size when None); None when T already holds whole
    periods (or there is no such axis) or no size in the range does.

    >>> from engine.tiles.scale import Scale
    >>> whole_period_size(Scale(25.6, 48.0, (False, True)), 128)  # planks: 3 boards
    144
    >>> whole_period_size(Scale(64.0, 32.0, (True, True)), 128) is None  # already whole
    True
    """
    from engine.reference_crops import phase_axes

    axes = _whole_axes(scale, T)

    def whole(n: int) -> bool:
        ok = phase_axes(scale, (n, n))
        return all(ok[i] for i in axes)

    if not axes or whole(T):
        return None
    lo, hi = max(8, math.ceil(T * (1 - SNAP_RANGE))), math.floor(T * (1 + SNAP_RANGE))
    # the multiples themselves, not the edge of the test's slack (142 px for 48 px boards)
    sizes = {round(k * float(scale.size[i])) for i in axes for k in range(1, hi + 1)}
    for n in sorted((n for n in sizes if lo <= n <= hi), key=lambda n: (abs(n - T), -n)):
        if whole(n) and (fits is None or fits(n)):
            return n
    return None


def source_fits(shape, T: int, *, band=None, seam=None, patch_overlap=None) -> bool:
    """Whether a source of ``shape`` (H, W[, C]) takes T px Wang tiles with these options
    (the size checks of :class:`engine.tiles.wang_setup.WangSetup`, without its spectra)."""
    from engine.seams.spec import as_seam_spec
    from engine.stitch import PATCH_SEAM
    from engine.tiles.candidates import default_patch_overlap
    from engine.tiles.template import default_overlap
    from engine.tiles.wang_cut import frame_reach, ramp_reach

    b = max(2, default_overlap(T)) if band is None else int(band)
    reach = frame_reach(T, b, ramp_reach(as_seam_spec(seam, default=PATCH_SEAM)))
    ring = default_patch_overlap(default_overlap(T)) if patch_overlap is None else patch_overlap
    return 4 * b <= T and 2 * ring <= T and min(shape[0], shape[1]) >= max(T, 2 * reach)


def auto_tile_size(source, T: int, **options) -> tuple[int, str]:
    """(size, what): ``T`` moved by :func:`whole_period_size` for ``source`` (H, W[, C],
    values in [0, 1]) within the sizes it takes (:func:`source_fits` with ``options``:
    band, seam, patch_overlap), and a sentence saying what was chosen and why."""
    from engine.reference_crops import phase_axes
    from engine.tiles.scale import structure_scale

    scale = structure_scale(source)
    shape = source.shape[:2]
    n = whole_period_size(scale, T, lambda n: source_fits(shape, n, **options))
    axes = _whole_axes(scale, T)
    periods = " and ".join(f"{float(scale.size[i]):.0f} px {('tall', 'wide')[i]}" for i in axes)
    if n is not None:
        return n, (
            f"{n} px instead of {T} px: the texture repeats about every {periods} (measured by "
            f"autocorrelation) and {n} px holds whole periods, so the pattern continues across "
            "the tile lines"
        )
    if not axes:
        return T, f"{T} px (no period the tile holds: nothing to keep whole)"
    if all(phase_axes(scale, (T, T))[i] for i in axes):
        return T, f"{T} px (holds whole periods of {periods})"
    return T, (
        f"{T} px: the texture repeats about every {periods}, and no size within "
        f"{SNAP_RANGE:.0%} of {T} px that the source takes holds whole periods"
    )


def _structure_axes(scale, T: int) -> list[int]:
    """Axes (0 = y, 1 = x) whose structures a T px Wang tile cannot hold: a period larger
    than the tile (a shorter one is :func:`whole_period_size`'s), or a decorrelation length
    above :data:`STRUCTURE_FRACTION` of it."""
    from engine.tiles.scale import WHOLE_SLACK

    top = T + max(1.0, WHOLE_SLACK * T)  # a period the tile holds once (as _whole_axes)
    out = []
    for i in range(2):
        p = float(scale.size[i])
        if p > (top if scale.periodic[i] else STRUCTURE_FRACTION * T):
            out.append(i)
    return out


def large_structure_note(scale, T: int, shape, fits=None) -> tuple[str | None, int | None]:
    """(note, size): a note when the structures of ``scale`` (a
    :class:`engine.tiles.scale.Scale`, the tile set's estimate) are too large for T px Wang
    tiles (:func:`_structure_axes`: a decorrelation length above :data:`STRUCTURE_FRACTION`
    of T, or a period longer than T), naming the least size by the tile set's rule — the
    structures at most a third of the tile (:data:`engine.tiles.scale.STRUCTURES_PER_TILE`;
    a whole number of periods along a periodic axis) — or, when ``fits(size)`` refuses it, the
    largest size it accepts that no longer warns, and a photo scaled down by the same factor;
    (None, None) when the tile holds them. ``shape``: the source's (H, W). The least size: on
    the 4000x3000 cobblestones (89 px) 267 px shows whole stones, still cut at the tile lines."""
    from engine.tiles.scale import STRUCTURES_PER_TILE

    axes = _structure_axes(scale, T)
    if not axes:
        return None, None
    need = T
    for i in axes:
        p = float(scale.size[i])
        k = math.ceil(STRUCTURES_PER_TILE - 1e-9)
        need = max(need, round(k * p) if scale.periodic[i] else math.ceil(STRUCTURES_PER_TILE * p))
    fits = fits or (lambda n: True)
    size = next((n for n in range(need, T, -1) if fits(n) and not _structure_axes(scale, n)), None)
    what = " and ".join(
        f"{float(scale.size[i]):.0f} px {('tall', 'wide')[i]}"
        f"{' (a period)' if scale.periodic[i] else ''}"
        for i in axes
    )
    H, W = (int(v) for v in shape[:2])
    f = need / T
    smaller = f"a photo scaled down to about {W / f:.0f}x{H / f:.0f} or less (1/{f:.1f})"
    if size is None:
        todo = f"the source takes no tile that holds them: use {smaller}"
    else:
        held = f"of at least {size} px" if size >= need else f"of {size} px, the largest it takes,"
        todo = f"use a tile size {held} (--tile-size {size}, or Tile size in the editor), or "
        todo += smaller
    note = (
        f"the texture's structures measure about {what} (measured by autocorrelation), too "
        f"large for "
        f"{T} px Wang tiles: every tile falls inside single structures and a layout shows none "
        f"whole (a blurry, even tone); {todo}"
    )
    return note, size
