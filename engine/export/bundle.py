"""The export bundle: every file of a tile set, built in memory and written as one folder.

:func:`export_bundle` checks everything first (tiles, options, output sizes), then builds the
files (tiles, atlases, preview, layout, Tiled, Godot, the manifest) and hands them to
:func:`engine.export.folder.write_bundle`, which swaps the folder in whole.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine._validate import as_rng, choice
from engine.bitdepth import quantize
from engine.budget import check_memory, export_bytes
from engine.export.atlas import AtlasLayout, atlas_layout, render_atlas
from engine.export.engines import godot_tres, tiled_tmx, tiled_tsx
from engine.export.folder import write_bundle
from engine.export.wang import check_wang
from engine.index_matrix import assemble_layout, check_index_matrix
from engine.jsondata import json_default
from engine.materials import NORMAL_CONVENTIONS

__all__ = [
    "BUNDLE_FORMAT",
    "BUNDLE_VERSION",
    "MAX_PREVIEW_PIXELS",
    "bundle_files",
    "export_bundle",
]

BUNDLE_FORMAT = "quilt-studio-bundle"
BUNDLE_VERSION = 1
SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")
MANIFEST_MAX_BYTES = 64 * 2**20
MAX_PREVIEW_PIXELS = 2**26
"""Largest preview assembled from the layout (8192 x 8192): a hostile or mistaken layout must
not exhaust the memory."""


@dataclass(frozen=True, slots=True)
class _Tiles:
    """The checked tiles: their maps (main map first), shapes and size."""

    maps: list[str]
    shapes: dict[str, tuple]
    tile_w: int
    tile_h: int
    count: int


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
    inputs: Sequence = (),
    wang: Mapping | None = None,
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
        Atlas options (identical for every map). The atlas must fit
        :data:`engine.export.atlas.MAX_ATLAS_SIDE` pixels per side.
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
        Replace an existing non-empty ``out_dir`` (atomically) instead of refusing; only a
        folder holding nothing but earlier bundles' files (as their manifests list them).
    inputs : list of paths
        Files the export was made from (the project): a folder holding one is refused.
    wang : dict or None
        A Wang set: ``{"colours": K, "tiles": [{"n", "e", "s", "w"}, ...]}`` (one edge
        signature per tile). The manifest lists each tile's ``wang``, the ``.tsx`` gets an
        edge Wang set and the ``.tres`` a "Match sides" terrain set (:mod:`engine.export.wang`).
    """
    out = Path(os.fspath(out_dir))
    name = _check_name(name, "name")
    choice(normal_convention, "normal_convention", NORMAL_CONVENTIONS)
    choice(extrude_mode, "extrude_mode", ("edge", "wrap"))
    choice(tile_format, "tile_format", ("png", "tif"))
    t = _check_tiles(tiles)
    source_bit_depth, bit_depth, dither = _bit_depths(
        tiles, t.maps, bit_depth, source_bit_depth, dither
    )
    lay = atlas_layout(
        t.count, t.tile_w, t.tile_h, columns=columns, spacing=spacing, margin=margin,
        extrude=extrude,
    )  # fmt: skip
    mat = check_index_matrix(index_matrix, t.count) if index_matrix is not None else None
    if preview is None and mat is not None:
        _check_preview_size(mat, t)
    weights = _check_weights(weights, t.count)
    if preview is not None and (not isinstance(preview, Mapping) or set(preview) - set(t.maps)):
        raise ValueError(f"preview must be a dict whose keys are among the maps {t.maps}")
    extra, per_tile = _split_extra(manifest_extra, t.count)
    if wang is not None:
        wang = check_wang(wang, t.count)
        per_tile["wangs"] = wang["tiles"]  # each tile entry gets its "wang"
    _check_memory(t, lay, mat, preview, bit_depth)
    if godot_path_prefix is None:
        godot_path_prefix = f"res://{out.name}/" if out.name else "res://"

    # -------- build everything in memory (cheap checks failed above, before the disk)
    gen = as_rng(rng)
    q_tiles = [
        {m: quantize(tile[m], bit_depth, dither=dither, rng=gen) for m in t.maps} for tile in tiles
    ]
    files: dict[str, object] = {}  # relative name -> uint array (image) or str (text)
    tile_entries = _tile_files(files, q_tiles, t, name, tile_format, lay, per_tile, weights)
    atlases = {}
    for m in t.maps:
        atlases[m] = f"{name}_atlas_{m}.png"
        files[atlases[m]] = render_atlas([qt[m] for qt in q_tiles], lay, extrude_mode=extrude_mode)
    if preview is None and mat is not None:
        preview = {m: assemble_layout([qt[m] for qt in q_tiles], mat) for m in t.maps}
    previews = {}
    for m, img in (preview or {}).items():
        previews[m] = f"{name}_preview_{m}.{tile_format}"
        files[previews[m]] = quantize(img, bit_depth, dither=dither, rng=gen)
    layout_files = _layout_files(files, name, mat, t, lay) if mat is not None else {}
    main_atlas = atlases[t.maps[0]]
    files[f"{name}.tsx"] = tiled_tsx(
        name=name, image=main_atlas, layout=lay, weights=weights, wang=wang
    )
    files[f"{name}.tres"] = godot_tres(
        image_path=godot_path_prefix + main_atlas, layout=lay, wang=wang
    )
    manifest = {
        "format": BUNDLE_FORMAT,
        "version": BUNDLE_VERSION,
        "name": name,
        "tile_w": t.tile_w,
        "tile_h": t.tile_h,
        "tile_count": t.count,
        "bit_depth": bit_depth,
        "source_bit_depth": source_bit_depth,
        "dithered": bool(dither and bit_depth < source_bit_depth),
        "maps": [
            {"name": m, "channels": int(t.shapes[m][2]) if len(t.shapes[m]) == 3 else 1}
            for m in t.maps
        ],
        "main_map": t.maps[0],
        "normal_convention": normal_convention,
        "tiles": tile_entries,
        "atlas": _atlas_entry(lay, extrude_mode, atlases),
        "layout": _layout_entry(mat, layout_files),
        "preview": previews,
        "tiled": {
            "tsx": f"{name}.tsx",
            "tmx": f"{name}.tmx" if mat is not None else None,
            "margin": lay.tiled_margin,
            "spacing": lay.tiled_spacing,
            "firstgid": 1,
        },
        "godot": {"tres": f"{name}.tres", "texture_path": godot_path_prefix + main_atlas},
        "parameters": extra.pop("parameters", {}),
        "seeds": extra.pop("seeds", {}),
        "scores": extra.pop("scores", None),
        "source_rects": extra.pop("source_rects", None),
        "extra": extra,
        "wang": None if wang is None else {"type": "edge", "colours": wang["colours"]},
        "frames": _frames(tile_entries, t.maps[0]),
        "meta": _meta(t, lay, bit_depth, main_atlas),
    }
    manifest["files"] = sorted([*files, f"{name}.json"])
    files[f"{name}.json"] = json.dumps(manifest, indent=1) + "\n"
    write_bundle(out, files, owned=bundle_files, overwrite=overwrite, inputs=inputs)
    return manifest


# ---------------------------------------------------------------- earlier bundles


def bundle_files(folder: Path) -> set[str]:
    """Names of the files the bundle manifests in ``folder`` say an export wrote there: with
    ``overwrite``, a folder is replaced only if these are all it holds, so the project, a
    user's notes or another program's files are never deleted."""
    owned: set[str] = set()
    for entry in os.scandir(folder):
        if not entry.name.endswith(".json") or not entry.is_file(follow_symlinks=False):
            continue
        try:
            if entry.stat().st_size > MANIFEST_MAX_BYTES:
                continue
            doc = json.loads(Path(entry.path).read_text("utf-8"))
        except (OSError, ValueError, RecursionError):
            continue
        owned |= _manifest_files(doc, entry.name)
    return owned


def _manifest_files(doc, manifest_name: str) -> set[str]:
    """The files a bundle manifest lists (every key that names one, for manifests written
    before the ``files`` list), restricted to names beginning with the bundle's name."""
    if not isinstance(doc, dict) or doc.get("format") != BUNDLE_FORMAT:
        return set()
    name = doc.get("name")
    if not isinstance(name, str) or manifest_name != f"{name}.json":
        return set()
    listed = [manifest_name, *_strings(doc.get("files"))]
    for tile in doc.get("tiles") or []:
        listed += _strings(tile.get("files") if isinstance(tile, dict) else None)
    for key, sub in (("atlas", "images"), ("layout", "files")):
        part = doc.get(key)
        listed += _strings(part.get(sub) if isinstance(part, dict) else None)
    listed += _strings(doc.get("preview"))
    for key, subs in (("tiled", ("tsx", "tmx")), ("godot", ("tres",))):
        part = doc.get(key)
        if isinstance(part, dict):
            listed += _strings([part.get(s) for s in subs])
    return {f for f in listed if SAFE_NAME.match(f) and f.startswith(name)}


def _strings(v) -> list[str]:
    if isinstance(v, dict):
        v = list(v.values())
    return [s for s in v if isinstance(s, str)] if isinstance(v, list) else []


# ---------------------------------------------------------------- checks


def _check_name(value, what: str) -> str:
    if not isinstance(value, str) or not SAFE_NAME.match(value) or len(value) > 100:
        raise ValueError(
            f"{what} must be a simple file-name part (letters, digits, . _ -), got {value!r}"
        )
    return value


def _check_tiles(tiles) -> _Tiles:
    """Every tile a dict of the same maps, every map one shape, all maps one size."""
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
    return _Tiles(maps, shapes, tw, th, len(tiles))


def _bit_depths(tiles, maps, bit_depth, source_bit_depth, dither) -> tuple[int, int, bool]:
    """(source bit depth, output bit depth, dither) with their defaults resolved."""
    if bit_depth is not None and (isinstance(bit_depth, bool) or bit_depth not in (8, 16)):
        raise ValueError(f"bit_depth must be 8, 16 or None, got {bit_depth!r}")
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
    return source_bit_depth, bit_depth, bool(dither)


def _check_preview_size(mat: np.ndarray, t: _Tiles) -> None:
    px = mat.shape[0] * t.tile_h * mat.shape[1] * t.tile_w
    if px > MAX_PREVIEW_PIXELS:
        raise ValueError(
            f"the layout preview would be {mat.shape[1] * t.tile_w}x{mat.shape[0] * t.tile_h} px, "
            f"over the limit of {MAX_PREVIEW_PIXELS:,} pixels: use a smaller layout or pass a "
            "preview image"
        )


def _check_memory(t: _Tiles, lay: AtlasLayout, mat, preview, bit_depth: int) -> None:
    """The bundle is built in memory: refuse one that does not fit before building it."""
    if preview is not None:
        first = next(iter(preview.values()), None)
        preview_hw = np.shape(first)[:2] if first is not None else None
    elif mat is not None:
        preview_hw = (mat.shape[0] * t.tile_h, mat.shape[1] * t.tile_w)
    else:
        preview_hw = None
    channels = [s[2] if len(s) == 3 else 1 for s in t.shapes.values()]
    check_memory(
        export_bytes(
            t.count,
            (t.tile_h, t.tile_w),
            channels,
            atlas_hw=(lay.height, lay.width),
            preview_hw=preview_hw,
            bit_depth=bit_depth,
        ),
        what=f"an export of {t.count} tiles of {t.tile_w}x{t.tile_h}",
        way_out="export fewer tiles, at 8 bits, or with a smaller layout",
    )


def _check_weights(weights, n: int) -> list[float] | None:
    if weights is None:
        return None
    try:
        out = [float(w) for w in weights]
    except (TypeError, ValueError, OverflowError):
        out = []
    if len(out) != n or not all(math.isfinite(w) and w >= 0 for w in out):
        raise ValueError(f"weights must be {n} finite numbers >= 0")
    return out


def _split_extra(manifest_extra, n: int) -> tuple[dict, dict]:
    """(manifest extras as plain JSON, the per-tile lists among them)."""
    try:
        extra = json.loads(
            json.dumps(dict(manifest_extra or {}), allow_nan=False, default=json_default)
        )
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"manifest_extra must be JSON-serialisable: {exc}") from None
    per_tile = {}
    for key in ("scores", "source_rects"):
        if key in extra and extra[key] is not None:
            if not isinstance(extra[key], list) or len(extra[key]) != n:
                raise ValueError(
                    f"manifest_extra[{key!r}] must be a list with one entry per tile ({n})"
                )
            per_tile[key] = extra[key]
    return extra, per_tile


# ---------------------------------------------------------------- files and manifest parts


def _tile_files(files, q_tiles, t: _Tiles, name, tile_format, lay, per_tile, weights) -> list:
    """Add every tile of every map to ``files``; returns the manifest's tile entries."""
    entries = []
    for i, qt in enumerate(q_tiles):
        entry = {"id": i, "files": {}, "atlas_rect": dict(zip("xywh", lay.rect(i), strict=True))}
        for m in t.maps:
            fname = f"{name}_{i:03}_{m}.{tile_format}"
            files[fname] = qt[m]
            entry["files"][m] = fname
        for key, values in per_tile.items():
            entry[key[:-1]] = values[i]
        if weights is not None:
            entry["weight"] = weights[i]
        entries.append(entry)
    return entries


def _layout_files(files, name: str, mat: np.ndarray, t: _Tiles, lay: AtlasLayout) -> dict:
    """The index matrix as JSON and CSV, and the Tiled map of it."""
    cells = mat.tolist()
    doc = {"tile_w": t.tile_w, "tile_h": t.tile_h, "cols": int(mat.shape[1])}
    doc.update({"rows": int(mat.shape[0]), "cells": cells})
    files[f"{name}_layout.json"] = json.dumps(doc, indent=1) + "\n"
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(cells)
    files[f"{name}_layout.csv"] = buf.getvalue()
    files[f"{name}.tmx"] = tiled_tmx(tsx=f"{name}.tsx", layout=lay, index_matrix=mat)
    return {"csv": f"{name}_layout.csv", "json": f"{name}_layout.json"}


def _atlas_entry(lay: AtlasLayout, extrude_mode: str, atlases: dict) -> dict:
    return {
        "columns": lay.columns,
        "rows": lay.rows,
        "spacing": lay.spacing,
        "margin": lay.margin,
        "extrude": lay.extrude,
        "extrude_mode": extrude_mode,
        "width": lay.width,
        "height": lay.height,
        "images": atlases,
    }


def _layout_entry(mat, layout_files: dict) -> dict | None:
    if mat is None:
        return None
    return {
        "cols": int(mat.shape[1]),
        "rows": int(mat.shape[0]),
        "cells": mat.tolist(),
        "files": layout_files,
    }


def _frames(tile_entries: list, main: str) -> dict:
    """TexturePacker-style frames of the main map's atlas."""
    frames = {}
    for entry in tile_entries:
        r = entry["atlas_rect"]
        w, h = r["w"], r["h"]
        frames[entry["files"][main]] = {
            "frame": dict(r),
            "rotated": False,
            "trimmed": False,
            "spriteSourceSize": {"x": 0, "y": 0, "w": w, "h": h},
            "sourceSize": {"w": w, "h": h},
        }
    return frames


def _meta(t: _Tiles, lay: AtlasLayout, bit_depth: int, image: str) -> dict:
    rgba = t.shapes[t.maps[0]][2:] == (4,)
    return {
        "app": "Quilt Studio",
        "version": str(BUNDLE_VERSION),
        "image": image,
        "format": ("RGBA" if rgba else "RGB") + str(bit_depth * (4 if rgba else 3)),
        "size": {"w": lay.width, "h": lay.height},
        "scale": "1",
    }
