"""Text resources for game engines and map editors: a Tiled tileset (``.tsx``) and map
(``.tmx``) of the layout, and a Godot 4 ``TileSet`` (``.tres``), all over the main map's atlas."""

from __future__ import annotations

import json
from collections.abc import Sequence
from xml.sax.saxutils import quoteattr

import numpy as np

from engine.export.atlas import AtlasLayout
from engine.export.wang import godot_terrain_lines, godot_tile_terrain, tiled_wangset_lines

__all__ = ["godot_tres", "tiled_tmx", "tiled_tsx"]


def tiled_tsx(
    *,
    name: str,
    image: str,
    layout: AtlasLayout,
    weights: Sequence[float] | None = None,
    wang: dict | None = None,
) -> str:
    """Tiled tileset XML: one image (the atlas) with Tiled's margin and spacing, the tiles'
    probabilities if ``weights`` are given, and an edge Wang set for a checked ``wang``
    (:func:`engine.export.wang.check_wang`)."""
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
    if wang is not None:
        lines += tiled_wangset_lines(wang, name=name)
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


def godot_tres(*, image_path: str, layout: AtlasLayout, wang: dict | None = None) -> str:
    """Godot 4 TileSet text resource with one TileSetAtlasSource over the atlas; with a
    checked ``wang``, a "Match sides" terrain set and every tile's peering bits."""

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
        if wang is not None:
            lines += godot_tile_terrain(wang["tiles"][i], f"{c}:{r}/0")
    lines += ["", "[resource]", f"tile_size = Vector2i({layout.tile_w}, {layout.tile_h})"]
    if wang is not None:
        lines += godot_terrain_lines(wang)
    lines.append('sources/0 = SubResource("TileSetAtlasSource_1")')
    return "\n".join(lines) + "\n"
