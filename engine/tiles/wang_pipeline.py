"""The Wang tile-set workflow in one call: edge samples, tiles, a random valid preview.

:func:`iter_wang_tileset` runs :func:`engine.tiles.wang.iter_wang_set` with the Wang fields of
one :class:`~engine.settings.TilesetSettings` (``wang`` = K colours, the tile size, variants,
interior...), then draws a random valid layout (:func:`engine.tiles.wang_layout.wang_layout`)
for the preview; ``quilt-studio tileset --wang K`` writes its result to files.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine.events import Progress
from engine.settings import TilesetSettings
from engine.tiles.layout import assemble_maps
from engine.tiles.seamless import MAIN
from engine.tiles.wang import WangSet, iter_wang_set
from engine.tiles.wang_layout import wang_layout

__all__ = ["WangTilesetResult", "iter_wang_tileset", "resolve_wang", "wang_options"]


@dataclass(frozen=True)
class WangTilesetResult:
    """What one run made: the resolved ``settings``, the :class:`WangSet`, the preview's
    index matrix over the set's tiles (``layout``) and the preview image per map
    (``"main"``: the source's)."""

    settings: TilesetSettings
    wang: WangSet
    layout: np.ndarray
    preview: dict[str, np.ndarray]
    warnings: tuple[str, ...] = field(default=())


def resolve_wang(settings: TilesetSettings, shape) -> TilesetSettings:
    """``settings`` with the Wang run's "from the source" values filled in: the square tile
    size (a quarter of the shorter side unless given), margin 1, the layout seed."""
    if settings.wang is None:
        raise ValueError("these settings make a Somol-Haindl set (wang is None)")
    lo, hi = settings.tile_range(shape)
    if settings.tile_min is None and settings.tile_max is None:
        hi = lo
    if lo != hi or lo[0] != lo[1]:
        raise ValueError(
            f"Wang tiles are square and of one size: give one tile size (--tile-size N), got "
            f"tile_min {lo} and tile_max {hi}"
        )
    return settings.replace(
        tile_min=lo,
        tile_max=hi,
        margin=1 if settings.margin is None else settings.margin,
        layout_seed=settings.seed if settings.layout_seed is None else settings.layout_seed,
    )


def wang_options(s: TilesetSettings) -> dict:
    """The options of :func:`engine.tiles.wang.iter_wang_set` that resolved settings give."""
    return dict(
        tile_size=s.tile_min[0],
        colours=s.wang,
        variants=s.wang_variants,
        interior=s.wang_interior,
        interior_blend=s.wang_interior_blend,
        band=s.wang_band,
        patch_overlap=s.patch_overlap,
        margin=s.margin,
        outward=s.wang_outward,
        tolerance=s.wang_tolerance,
        min_distance=s.wang_min_distance,
        seam=s.seam,
    )


def iter_wang_tileset(
    source,
    settings: TilesetSettings,
    *,
    maps=None,
    weights=None,
    excluded=None,
    workers: int = 2,
    cancel=None,
):
    """Run the Wang workflow; a generator of the set's events whose value is a
    :class:`WangTilesetResult`. Raises ValueError when cancelled before the set is complete
    (a preview needs every tile)."""
    if not isinstance(settings, TilesetSettings):
        raise TypeError(f"settings must be a TilesetSettings, got {type(settings).__name__}")
    s = resolve_wang(settings, np.shape(source)[:2])
    gen = iter_wang_set(
        source,
        **wang_options(s),
        excluded=excluded,
        maps=maps,
        weights=weights,
        rng=s.seed,
        workers=workers,
        cancel=cancel,
    )
    return _iter(gen, s)


def _iter(gen, s: TilesetSettings):
    ws = yield from gen
    if not ws.complete:
        raise ValueError(f"the Wang set is incomplete: {len(ws.tiles)} of {ws.count} tiles made")
    rows, cols = s.preview
    ids = wang_layout(
        ws.signatures,
        rows,
        cols,
        rng=s.layout_seed,
        no_equal_neighbours=s.no_equal_neighbours,
    )
    preview = assemble_maps(ws.tiles, ids, [MAIN, *ws.tiles[0].maps])
    yield Progress(1, 1, "Wang tile set: done")
    return WangTilesetResult(s, ws, ids, preview, ws.notes)
