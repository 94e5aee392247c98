"""Atlas images: every tile of one map in a grid, with spacing, margin and edge bleed.

The layout is computed once (:func:`atlas_layout`) and is identical for every map of a
material, so an engine can sample all maps of tile ``i`` from the same rectangle.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from engine._validate import choice

__all__ = ["MAX_ATLAS_SIDE", "AtlasLayout", "atlas_layout", "render_atlas"]

MAX_ATLAS_SIDE = 16384
"""Largest atlas width or height in pixels: the texture limit of Godot 4 and of most GPUs, and
at most 2 GiB for a 16-bit RGBA atlas. Larger spacing, margin, extrusion or tile counts are
refused before any work."""


@dataclass(frozen=True, slots=True)
class AtlasLayout:
    """Where each tile sits in the atlas; identical for every map."""

    tile_w: int
    tile_h: int
    count: int
    columns: int
    rows: int
    spacing: int
    margin: int
    extrude: int
    width: int
    height: int

    def rect(self, index: int) -> tuple[int, int, int, int]:
        """(x, y, w, h) of tile ``index`` (the tile itself, extrusion excluded)."""
        r, c = divmod(index, self.columns)
        x = self.margin + c * (self.tile_w + 2 * self.extrude + self.spacing) + self.extrude
        y = self.margin + r * (self.tile_h + 2 * self.extrude + self.spacing) + self.extrude
        return x, y, self.tile_w, self.tile_h

    @property
    def tiled_margin(self) -> int:
        """Margin as Tiled/Godot see it (extrusion counts as margin)."""
        return self.margin + self.extrude

    @property
    def tiled_spacing(self) -> int:
        """Spacing as Tiled/Godot see it (extrusion of both neighbours counts as spacing)."""
        return self.spacing + 2 * self.extrude


def _nonneg_int(v, name) -> int:
    if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < 0:
        raise ValueError(f"{name} must be an integer >= 0, got {v!r}")
    return int(v)


def _default_columns(count: int) -> int:
    """About square; prefer a column count that divides ``count`` (no blank cells: Tiled
    always counts ``columns * rows`` tiles in an atlas image) if the grid stays within 1:3."""
    best = max(1, math.ceil(math.sqrt(count)))
    for c in sorted(range(1, count + 1), key=lambda c: (abs(c - best), -c)):
        if count % c == 0 and max(c, count // c) <= 3 * min(c, count // c):
            return c
    return best


def atlas_layout(
    count: int,
    tile_w: int,
    tile_h: int,
    *,
    columns: int | None = None,
    spacing: int = 0,
    margin: int = 0,
    extrude: int = 0,
) -> AtlasLayout:
    """Grid layout of ``count`` tiles; ``columns=None`` makes it as square as possible."""
    count = _nonneg_int(count, "count")
    if count < 1:
        raise ValueError("count must be >= 1")
    tile_w = _nonneg_int(tile_w, "tile_w")
    tile_h = _nonneg_int(tile_h, "tile_h")
    if tile_w < 1 or tile_h < 1:
        raise ValueError(f"tile size must be >= 1x1, got {tile_w}x{tile_h}")
    if columns is None:
        columns = _default_columns(count)
    columns = _nonneg_int(columns, "columns")
    if columns < 1:
        raise ValueError("columns must be >= 1")
    columns = min(columns, count)
    spacing = _nonneg_int(spacing, "spacing")
    margin = _nonneg_int(margin, "margin")
    extrude = _nonneg_int(extrude, "extrude")
    rows = math.ceil(count / columns)
    cw, ch = tile_w + 2 * extrude, tile_h + 2 * extrude
    width = 2 * margin + columns * cw + (columns - 1) * spacing
    height = 2 * margin + rows * ch + (rows - 1) * spacing
    if max(width, height) > MAX_ATLAS_SIDE:
        raise ValueError(
            f"the atlas would be {width}x{height} px, over the limit of {MAX_ATLAS_SIDE} px per "
            "side (the texture limit of game engines): use less spacing, margin or extrusion, "
            "or other atlas columns"
        )
    return AtlasLayout(
        tile_w, tile_h, count, columns, rows, spacing, margin, extrude, width, height
    )


def render_atlas(
    tiles: Sequence[np.ndarray], layout: AtlasLayout, *, extrude_mode: str = "edge"
) -> np.ndarray:
    """Place same-shaped (h, w[, C]) tiles (any dtype) into an atlas of that dtype, background 0.

    ``extrude_mode`` "edge" repeats the border pixels into the extrusion band
    (the usual bleed); "wrap" copies the opposite border (for tiles that wrap).
    """
    choice(extrude_mode, "extrude_mode", ("edge", "wrap"))
    if len(tiles) != layout.count:
        raise ValueError(f"got {len(tiles)} tiles for a layout of {layout.count}")
    first = np.asarray(tiles[0])
    out = np.zeros((layout.height, layout.width) + first.shape[2:], dtype=first.dtype)
    e = layout.extrude
    for i, t in enumerate(tiles):
        t = np.asarray(t)
        if t.shape != first.shape:
            raise ValueError(f"tile {i} is shaped {t.shape}, tile 0 is {first.shape}")
        x, y, w, h = layout.rect(i)
        if e:
            pad = [(e, e), (e, e)] + [(0, 0)] * (t.ndim - 2)
            t = np.pad(t, pad, mode=extrude_mode)
        out[y - e : y + h + e, x - e : x + w + e] = t
    return out
