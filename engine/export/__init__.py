"""Export a tile set as a bundle folder, and quantize pixels to 8 or 16 bits.

:func:`export_bundle` writes, for tiles ``0..N-1`` and maps ``m`` (albedo,
normal, ...), into ``out_dir``:

- ``{name}_{index:03}_{m}.png``: every tile of every map;
- ``{name}_atlas_{m}.png``: one atlas per map, all with the identical layout
  (``columns``, ``spacing`` between cells, ``margin`` around, ``extrude``
  pixels of edge bleed around every tile);
- ``{name}.json``: the manifest (tiles, maps, atlas rectangles, source
  rectangles, parameters, seeds, scores, normal convention) with
  TexturePacker-style ``frames``/``meta``;
- ``{name}_layout.csv`` and ``{name}_layout.json``: the index matrix
  (``{"tile_w","tile_h","cols","rows","cells"}``, -1 = empty cell);
- ``{name}.tsx`` / ``{name}.tmx``: a Tiled tileset (single-image atlas of the
  main map) and a map of the layout (CSV layer, gid = firstgid + tile id);
- ``{name}.tres``: a Godot 4 ``TileSet`` text resource;
- ``{name}_preview_{m}.png``: the synthesized preview.

PNGs are written by the exact codec of :mod:`engine.export._png` (8 or 16 bits
per channel, gray / gray+alpha / RGB / RGBA, deterministic bytes).

Everything is written into a temporary sibling folder which is renamed into
place at the end, so a failure leaves nothing half-written and raises
:class:`ExportError` naming the folder and the reason.
"""

from __future__ import annotations

import csv
import errno
import io
import json
import math
import numbers
import os
import re
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from engine._fs import umask
from engine._validate import as_rng, choice
from engine.export._png import encode_png
from engine.materials import NORMAL_CONVENTIONS

__all__ = [
    "AtlasLayout",
    "ExportError",
    "assemble_layout",
    "atlas_layout",
    "export_bundle",
    "quantize",
    "render_atlas",
    "tiled_tsx",
    "tiled_tmx",
    "godot_tres",
]

BUNDLE_FORMAT = "quilt-studio-bundle"
BUNDLE_VERSION = 1
_SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")
MAX_PREVIEW_PIXELS = 2**26
"""Largest preview assembled from the layout (8192 x 8192): a hostile or mistaken layout must
not exhaust the memory."""


class ExportError(OSError):
    """The bundle could not be written; nothing was left behind. The message says where and why.

    ``errno`` holds the underlying error number (e.g. ``ENOSPC``) when there is one.
    """

    def __init__(self, code: int | None, message: str):
        super().__init__(message)
        self.errno = code

    def __str__(self) -> str:
        return self.args[0]


# ---------------------------------------------------------------- bit depth


def quantize(pixels, bit_depth: int, *, dither: bool = True, rng=None) -> np.ndarray:
    """Float [0, 1] (or uint8/uint16) pixels -> uint8 or uint16 at ``bit_depth``.

    Values already on the target grid (e.g. an 8-bit source exported at 8 bits,
    a 16-bit source at 16 bits) are copied exactly. Other values are rounded; with
    ``dither=True`` triangular (TPDF, +-1 LSB) noise is added before rounding so a
    smooth 16-bit gradient reduced to 8 bits shows no banding and keeps its local
    mean. ``rng`` seeds the noise (int or Generator).
    """
    if bit_depth not in (8, 16) or isinstance(bit_depth, bool):
        raise ValueError(f"bit_depth must be 8 or 16, got {bit_depth!r}")
    raw = np.asarray(pixels)
    if raw.dtype == np.uint8 and bit_depth == 8:
        return raw.copy()
    if raw.dtype == np.uint16 and bit_depth == 16:
        return raw.copy()
    if raw.dtype == np.uint8 and bit_depth == 16:
        return raw.astype(np.uint16) * np.uint16(257)
    gen = as_rng(rng)
    if raw.dtype == bool:
        a = raw.astype(np.float64)
    elif np.issubdtype(raw.dtype, np.integer):
        info = np.iinfo(raw.dtype)
        if info.min < 0:
            raise TypeError(f"pixels must be float in [0, 1] or unsigned integers, got {raw.dtype}")
        a = raw.astype(np.float64) / info.max
    elif np.issubdtype(raw.dtype, np.floating):
        a = raw.astype(np.float64)
        if not np.all(np.isfinite(a)):
            raise ValueError("pixels contains NaN or infinite values")
    else:
        raise TypeError(f"pixels must be a numeric array, got dtype {raw.dtype}")
    top = 255.0 if bit_depth == 8 else 65535.0
    x = np.clip(a, 0.0, 1.0) * top
    r = np.round(x)
    if dither:
        off = np.abs(x - r) > 1e-2  # float32 k/65535 is off the grid by up to ~0.004 LSB
        if off.any():
            n = gen.random(int(off.sum())) - gen.random(int(off.sum()))
            r[off] = np.round(x[off] + n)
    return np.clip(r, 0, top).astype(np.uint8 if bit_depth == 8 else np.uint16)


# ---------------------------------------------------------------- atlas


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


def assemble_layout(tiles: Sequence[np.ndarray], index_matrix) -> np.ndarray:
    """The preview image: tile ``index_matrix[r, c]`` at cell (r, c); -1 cells stay 0."""
    m = _index_matrix(index_matrix, len(tiles))
    first = np.asarray(tiles[0])
    h, w = first.shape[:2]
    out = np.zeros((m.shape[0] * h, m.shape[1] * w) + first.shape[2:], dtype=first.dtype)
    for (r, c), k in np.ndenumerate(m):
        if k >= 0:
            out[r * h : (r + 1) * h, c * w : (c + 1) * w] = tiles[k]
    return out


def _index_matrix(index_matrix, count: int) -> np.ndarray:
    m = np.asarray(index_matrix)
    if m.ndim != 2 or m.size == 0:
        raise ValueError(
            f"index_matrix must be a non-empty 2-D (rows, cols) array, got shape {m.shape}"
        )
    if not np.issubdtype(m.dtype, np.integer) and (
        not np.issubdtype(m.dtype, np.floating) or not np.all(m == np.round(m))
    ):
        raise TypeError(f"index_matrix must hold integers, got dtype {m.dtype}")
    m = m.astype(np.int64)
    if m.min() < -1 or m.max() >= count:
        raise ValueError(
            f"index_matrix values must be tile ids in [0, {count - 1}] or -1 (empty), "
            f"got range [{m.min()}, {m.max()}]"
        )
    return m


# ---------------------------------------------------------------- Tiled / Godot text


def tiled_tsx(
    *, name: str, image: str, layout: AtlasLayout, weights: Sequence[float] | None = None
) -> str:
    """Tiled tileset XML: one image (the atlas) with Tiled's margin/spacing, optional "
    "probabilities."""
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<tileset version="1.8" tiledversion="1.8.2" name={quoteattr(name)} '
        f'tilewidth="{layout.tile_w}" '
        f'tileheight="{layout.tile_h}" spacing="{layout.tiled_spacing}" '
        f'margin="{layout.tiled_margin}" '
        f'tilecount="{layout.count}" columns="{layout.columns}">',
        f' <image source={quoteattr(image)} width="{layout.width}" height="{layout.height}"/>',
    ]
    if weights is not None:
        for i, wgt in enumerate(weights):
            lines.append(f' <tile id="{i}" probability="{float(wgt):.6g}"/>')
    lines.append("</tileset>")
    return "\n".join(lines) + "\n"


def tiled_tmx(*, tsx: str, layout: AtlasLayout, index_matrix: np.ndarray, firstgid: int = 1) -> str:
    """Tiled map XML of the layout: one CSV tile layer, gid = firstgid + tile id, 0 = empty."""
    m = np.asarray(index_matrix)
    rows, cols = m.shape
    gids = np.where(m >= 0, m + firstgid, 0)
    body = ",\n".join(",".join(str(int(g)) for g in row) for row in gids)
    return (
        "\n".join(
            [
                '<?xml version="1.0" encoding="UTF-8"?>',
                '<map version="1.8" tiledversion="1.8.2" orientation="orthogonal" '
                'renderorder="right-down" '
                f'width="{cols}" height="{rows}" tilewidth="{layout.tile_w}" '
                f'tileheight="{layout.tile_h}" '
                f'infinite="0" nextlayerid="2" nextobjectid="1">',
                f' <tileset firstgid="{firstgid}" source={quoteattr(tsx)}/>',
                f' <layer id="1" name="layout" width="{cols}" height="{rows}">',
                '  <data encoding="csv">',
                body,
                "</data>",
                " </layer>",
                "</map>",
            ]
        )
        + "\n"
    )


def godot_tres(*, image_path: str, layout: AtlasLayout) -> str:
    """Godot 4 TileSet text resource with one TileSetAtlasSource over the atlas."""

    def s(v):
        return json.dumps(v)  # a double-quoted string with escapes, as Godot writes them

    lines = [
        '[gd_resource type="TileSet" load_steps=3 format=3]',
        "",
        f'[ext_resource type="Texture2D" path={s(image_path)} id="1_atlas"]',
        "",
        '[sub_resource type="TileSetAtlasSource" id="TileSetAtlasSource_1"]',
        'texture = ExtResource("1_atlas")',
        f"margins = Vector2i({layout.tiled_margin}, {layout.tiled_margin})",
        f"separation = Vector2i({layout.tiled_spacing}, {layout.tiled_spacing})",
        f"texture_region_size = Vector2i({layout.tile_w}, {layout.tile_h})",
    ]
    for i in range(layout.count):
        r, c = divmod(i, layout.columns)
        lines.append(f"{c}:{r}/0 = 0")
    lines += [
        "",
        "[resource]",
        f"tile_size = Vector2i({layout.tile_w}, {layout.tile_h})",
        'sources/0 = SubResource("TileSetAtlasSource_1")',
    ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- bundle


def _check_name(value, what: str) -> str:
    if not isinstance(value, str) or not _SAFE_NAME.match(value) or len(value) > 100:
        raise ValueError(
            f"{what} must be a simple file-name part (letters, digits, . _ -), got {value!r}"
        )
    return value


def _jsonable(value, what: str):
    try:
        return json.loads(json.dumps(value, allow_nan=False, default=_json_default))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must be JSON-serialisable: {exc}") from None


def _json_default(o):
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (tuple, set, frozenset)):
        return list(o)
    raise TypeError(f"{type(o).__name__} is not JSON-serialisable")


def export_bundle(
    out_dir,
    *,
    name: str,
    tiles: Sequence[Mapping[str, np.ndarray]],
    bit_depth: int | None = None,
    index_matrix=None,
    preview: Mapping[str, np.ndarray] | None = None,
    columns: int | None = None,
    spacing: int = 0,
    margin: int = 0,
    extrude: int = 0,
    extrude_mode: str = "edge",
    manifest_extra: Mapping | None = None,
    normal_convention: str = "opengl",
    weights: Sequence[float] | None = None,
    source_bit_depth: int | None = None,
    dither: bool | None = None,
    rng=0,
    godot_path_prefix: str | None = None,
    tile_format: str = "png",
    overwrite: bool = False,
) -> dict:
    """Write the export bundle of ``tiles`` into the folder ``out_dir``; returns the manifest.

    Parameters
    ----------
    tiles : list of {map name: (h, w[, C]) array}
        Every tile has the same maps (the first map is the main map, used for the
        Tiled/Godot atlas) and every map the same size. Float [0, 1], uint8 or uint16.
    bit_depth : 8, 16 or None
        Output bits per channel. None: ``source_bit_depth``.
    source_bit_depth : 8, 16 or None
        Bit depth of the source the tiles come from. None: 16 if any input array
        is uint16, else 8.
    dither : bool or None
        Dither when rounding (seeded by ``rng``). None (default): only when
        reducing a 16-bit source to 8 bits; otherwise values are rounded (values
        already on the output grid, i.e. copied source pixels, are always exact).
    index_matrix : (rows, cols) int array or None
        Tile ids of the previewed layout, -1 = empty.
    preview : {map: image} or None
        The synthesized preview; None assembles it from ``index_matrix`` if given.
    columns, spacing, margin, extrude, extrude_mode
        Atlas options (identical for every map).
    manifest_extra : dict or None
        Copied into the manifest: ``parameters``, ``seeds`` (any JSON), ``scores``,
        ``source_rects`` (lists with one entry per tile, also copied into each tile
        entry), and any other JSON keys under ``extra``.
    weights : list of float or None
        Per-tile probabilities, written as Tiled ``probability``.
    godot_path_prefix : str or None
        Prefix of the atlas path in the ``.tres`` (default ``res://<out_dir name>/``).
    tile_format : "png" or "tif"
        Format of the per-tile and preview files (atlases are always PNG, which
        Tiled and Godot read). Both keep 16 bits.
    overwrite : bool
        Replace an existing non-empty ``out_dir`` (atomically) instead of refusing.
    """
    out = Path(os.fspath(out_dir))
    name = _check_name(name, "name")
    choice(normal_convention, "normal_convention", NORMAL_CONVENTIONS)
    if bit_depth is not None and (isinstance(bit_depth, bool) or bit_depth not in (8, 16)):
        raise ValueError(f"bit_depth must be 8, 16 or None, got {bit_depth!r}")
    if not isinstance(tiles, Sequence) or isinstance(tiles, (str, bytes)) or len(tiles) == 0:
        raise ValueError("tiles must be a non-empty list of {map name: image} dicts")
    maps = None
    shapes: dict[str, tuple] = {}
    for i, t in enumerate(tiles):
        if not isinstance(t, Mapping) or not t:
            raise TypeError(f"tiles[{i}] must be a non-empty dict of map name -> image")
        if maps is None:
            maps = list(t)
            for m in maps:
                _check_name(m, f"map name in tiles[{i}]")
        elif list(t) != maps:
            raise ValueError(f"tiles[{i}] has maps {list(t)}, tiles[0] has {maps}")
        for m in maps:
            shp = np.shape(t[m])
            shapes.setdefault(m, shp)
            if shp != shapes[m]:
                raise ValueError(
                    f"tiles[{i}][{m!r}] is shaped {shp}, tiles[0][{m!r}] is {shapes[m]}"
                )
    th, tw = shapes[maps[0]][:2]
    for m in maps:
        if shapes[m][:2] != (th, tw):
            raise ValueError(
                f"map {m!r} tiles are {shapes[m][1]}x{shapes[m][0]}, main map tiles are {tw}x{th}"
            )
    if source_bit_depth is None:
        source_bit_depth = (
            16 if any(np.asarray(t[m]).dtype == np.uint16 for t in tiles for m in maps) else 8
        )
    elif isinstance(source_bit_depth, bool) or source_bit_depth not in (8, 16):
        raise ValueError(f"source_bit_depth must be 8, 16 or None, got {source_bit_depth!r}")
    if bit_depth is None:
        bit_depth = source_bit_depth
    if dither is None:
        dither = bit_depth < source_bit_depth
    n = len(tiles)
    lay = atlas_layout(n, tw, th, columns=columns, spacing=spacing, margin=margin, extrude=extrude)
    choice(extrude_mode, "extrude_mode", ("edge", "wrap"))
    choice(tile_format, "tile_format", ("png", "tif"))
    mat = _index_matrix(index_matrix, n) if index_matrix is not None else None
    if weights is not None:
        weights = [float(w) for w in weights]
        if len(weights) != n or not all(math.isfinite(w) and w >= 0 for w in weights):
            raise ValueError(f"weights must be {n} finite numbers >= 0")
    if preview is not None and (not isinstance(preview, Mapping) or set(preview) - set(maps)):
        raise ValueError(f"preview must be a dict whose keys are among the maps {maps}")
    extra = dict(_jsonable(dict(manifest_extra or {}), "manifest_extra"))
    per_tile = {}
    for key in ("scores", "source_rects"):
        if key in extra and extra[key] is not None:
            if not isinstance(extra[key], list) or len(extra[key]) != n:
                raise ValueError(
                    f"manifest_extra[{key!r}] must be a list with one entry per tile ({n})"
                )
            per_tile[key] = extra[key]
    if godot_path_prefix is None:
        godot_path_prefix = f"res://{out.name}/" if out.name else "res://"

    # -------- build everything in memory first (cheap checks fail before touching the disk)
    gen = as_rng(rng)
    q_tiles = [{m: quantize(t[m], bit_depth, dither=dither, rng=gen) for m in maps} for t in tiles]
    files: dict[str, object] = {}  # relative name -> uint array (image) or str (text)
    tile_entries = []
    frames = {}
    for i, qt in enumerate(q_tiles):
        entry = {"id": i, "files": {}, "atlas_rect": dict(zip("xywh", lay.rect(i), strict=True))}
        for m in maps:
            fname = f"{name}_{i:03}_{m}.{tile_format}"
            files[fname] = qt[m]
            entry["files"][m] = fname
        for key, values in per_tile.items():
            entry[key[:-1]] = values[i]
        if weights is not None:
            entry["weight"] = weights[i]
        x, y, w, h = lay.rect(i)
        frames[entry["files"][maps[0]]] = {
            "frame": {"x": x, "y": y, "w": w, "h": h},
            "rotated": False,
            "trimmed": False,
            "spriteSourceSize": {"x": 0, "y": 0, "w": w, "h": h},
            "sourceSize": {"w": w, "h": h},
        }
        tile_entries.append(entry)
    atlases = {}
    for m in maps:
        fname = f"{name}_atlas_{m}.png"
        files[fname] = render_atlas([qt[m] for qt in q_tiles], lay, extrude_mode=extrude_mode)
        atlases[m] = fname
    previews = {}
    if preview is None and mat is not None:
        px = mat.shape[0] * th * mat.shape[1] * tw
        if px > MAX_PREVIEW_PIXELS:
            raise ValueError(
                f"the layout preview would be {mat.shape[1] * tw}x{mat.shape[0] * th} px, over "
                f"the limit of {MAX_PREVIEW_PIXELS:,} pixels: use a smaller layout or pass a "
                "preview image"
            )
        preview = {m: assemble_layout([qt[m] for qt in q_tiles], mat) for m in maps}
    for m, img in (preview or {}).items():
        fname = f"{name}_preview_{m}.{tile_format}"
        files[fname] = quantize(img, bit_depth, dither=dither, rng=gen)
        previews[m] = fname
    layout_files = {}
    if mat is not None:
        cells = mat.tolist()
        files[f"{name}_layout.json"] = (
            json.dumps(
                {
                    "tile_w": tw,
                    "tile_h": th,
                    "cols": int(mat.shape[1]),
                    "rows": int(mat.shape[0]),
                    "cells": cells,
                },
                indent=1,
            )
            + "\n"
        )
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(cells)
        files[f"{name}_layout.csv"] = buf.getvalue()
        layout_files = {"csv": f"{name}_layout.csv", "json": f"{name}_layout.json"}
        files[f"{name}.tmx"] = tiled_tmx(tsx=f"{name}.tsx", layout=lay, index_matrix=mat)
    files[f"{name}.tsx"] = tiled_tsx(name=name, image=atlases[maps[0]], layout=lay, weights=weights)
    files[f"{name}.tres"] = godot_tres(image_path=godot_path_prefix + atlases[maps[0]], layout=lay)
    manifest = {
        "format": BUNDLE_FORMAT,
        "version": BUNDLE_VERSION,
        "name": name,
        "tile_w": tw,
        "tile_h": th,
        "tile_count": n,
        "bit_depth": bit_depth,
        "source_bit_depth": source_bit_depth,
        "dithered": bool(dither and bit_depth < source_bit_depth),
        "maps": [
            {"name": m, "channels": int(shapes[m][2]) if len(shapes[m]) == 3 else 1} for m in maps
        ],
        "main_map": maps[0],
        "normal_convention": normal_convention,
        "tiles": tile_entries,
        "atlas": {
            "columns": lay.columns,
            "rows": lay.rows,
            "spacing": lay.spacing,
            "margin": lay.margin,
            "extrude": lay.extrude,
            "extrude_mode": extrude_mode,
            "width": lay.width,
            "height": lay.height,
            "images": atlases,
        },
        "layout": (
            {
                "cols": int(mat.shape[1]),
                "rows": int(mat.shape[0]),
                "cells": mat.tolist(),
                "files": layout_files,
            }
            if mat is not None
            else None
        ),
        "preview": previews,
        "tiled": {
            "tsx": f"{name}.tsx",
            "tmx": f"{name}.tmx" if mat is not None else None,
            "margin": lay.tiled_margin,
            "spacing": lay.tiled_spacing,
            "firstgid": 1,
        },
        "godot": {"tres": f"{name}.tres", "texture_path": godot_path_prefix + atlases[maps[0]]},
        "parameters": extra.pop("parameters", {}),
        "seeds": extra.pop("seeds", {}),
        "scores": extra.pop("scores", None),
        "source_rects": extra.pop("source_rects", None),
        "extra": extra,
        "frames": frames,
        "meta": {
            "app": "Quilt Studio",
            "version": str(BUNDLE_VERSION),
            "image": atlases[maps[0]],
            "format": ("RGBA" if shapes[maps[0]][2:] == (4,) else "RGB")
            + str(bit_depth * (4 if shapes[maps[0]][2:] == (4,) else 3)),
            "size": {"w": lay.width, "h": lay.height},
            "scale": "1",
        },
    }
    files[f"{name}.json"] = json.dumps(manifest, indent=1) + "\n"
    _write_atomically(out, files, bit_depth, overwrite=overwrite)
    return manifest


def _reason(exc: BaseException) -> str:
    if isinstance(exc, OSError):
        if exc.errno == errno.ENOSPC:
            return "the disk is full"
        if exc.errno in (errno.EACCES, errno.EPERM):
            return "permission denied (read-only folder?)"
        if exc.errno == errno.EROFS:
            return "read-only file system"
        return exc.strerror or str(exc)
    return str(exc) or type(exc).__name__


def _write_file(path: Path, content, bit_depth: int) -> None:
    if isinstance(content, str):
        _write_bytes(path, content.encode("utf-8"))
        return
    q = np.asarray(content)
    if path.suffix == ".tif":
        import tifffile

        buf = io.BytesIO()
        tifffile.imwrite(
            buf,
            q[:, :, 0] if q.ndim == 3 and q.shape[2] == 1 else q,
            photometric="minisblack" if q.ndim == 2 or q.shape[2] < 3 else "rgb",
            extrasamples=("unassalpha",) if q.ndim == 3 and q.shape[2] in (2, 4) else None,
            compression="zlib",
            metadata=None,
        )
        _write_bytes(path, buf.getvalue())
        return
    _write_bytes(path, encode_png(q))


def _write_bytes(path: Path, data: bytes) -> None:
    """Every byte of the bundle goes through here (tests simulate a full disk on it)."""
    with open(path, "wb") as f:
        f.write(data)


def _write_atomically(
    out: Path, files: Mapping[str, object], bit_depth: int, *, overwrite: bool
) -> None:
    parent = out.parent if str(out.parent) else Path(".")
    if out.exists() and not out.is_dir():
        raise ExportError(errno.EEXIST, f"cannot export to {out}: it exists and is not a folder")
    replace = out.is_dir() and any(out.iterdir())
    if replace and not overwrite:
        raise ExportError(
            errno.EEXIST,
            f"cannot export to {out}: the folder is not empty (pass overwrite=True or --overwrite "
            "to replace it)",
        )
    try:
        parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f".{out.name}.tmp-"))
    except OSError as exc:
        raise ExportError(
            exc.errno or errno.EIO, f"cannot export to {out}: {_reason(exc)}; nothing was written"
        ) from exc
    old = None
    try:
        for rel, content in files.items():
            _write_file(tmp / rel, content, bit_depth)
        os.chmod(tmp, 0o777 & ~umask())
        if out.is_dir():
            if replace:
                old = Path(tempfile.mkdtemp(dir=parent, prefix=f".{out.name}.old-"))
                os.replace(out, old / "bundle")
            else:
                out.rmdir()
        os.replace(tmp, out)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if old is not None and (old / "bundle").exists() and not out.exists():
            os.replace(old / "bundle", out)
            shutil.rmtree(old, ignore_errors=True)
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            raise
        err = exc.errno if isinstance(exc, OSError) and exc.errno else errno.EIO
        raise ExportError(
            err, f"cannot export to {out}: {_reason(exc)}; nothing was written"
        ) from exc
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
