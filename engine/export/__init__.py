"""Export a tile set as a bundle folder.

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

PNGs are written by :mod:`engine.png` (libpng; 8 or 16 bits per channel, gray /
gray+alpha / RGB / RGBA, deterministic bytes).

Everything is written into a temporary sibling folder which is renamed into
place at the end, so a failure leaves nothing half-written and raises
:class:`ExportError` naming the folder and the reason. An existing folder is
replaced (``overwrite``) only if it holds nothing but files of earlier bundles.

Modules: :mod:`~engine.export.bundle` (the files and the manifest),
:mod:`~engine.export.atlas`, :mod:`~engine.export.engines` (Tiled, Godot),
:mod:`~engine.export.folder` (writing the folder).
"""

from engine.export.atlas import MAX_ATLAS_SIDE, AtlasLayout, atlas_layout, render_atlas
from engine.export.bundle import (
    BUNDLE_FORMAT,
    BUNDLE_VERSION,
    MAX_PREVIEW_PIXELS,
    bundle_files,
    export_bundle,
)
from engine.export.engines import godot_tres, tiled_tmx, tiled_tsx
from engine.export.folder import ExportError

__all__ = [
    "BUNDLE_FORMAT",
    "BUNDLE_VERSION",
    "MAX_ATLAS_SIDE",
    "MAX_PREVIEW_PIXELS",
    "AtlasLayout",
    "ExportError",
    "atlas_layout",
    "bundle_files",
    "export_bundle",
    "godot_tres",
    "render_atlas",
    "tiled_tmx",
    "tiled_tsx",
]
