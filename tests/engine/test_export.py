"""Export bundle: files, atlas layout, manifest, Tiled/Godot text, bit depth, atomic writes."""

from __future__ import annotations

import csv
import errno
import json
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import engine.export.folder
import engine.io
from engine.bitdepth import quantize
from engine.export import (
    ExportError,
    atlas_layout,
    export_bundle,
    godot_tres,
    render_atlas,
)
from engine.index_matrix import assemble_layout
from engine.png import decode_png, encode_png


def read_png(path) -> np.ndarray:
    return decode_png(Path(path).read_bytes())


def make_tiles(n=6, h=12, w=10, rng=0, maps=("albedo", "height")):
    g = np.random.default_rng(rng)
    chans = {"albedo": 3, "height": 1, "normal": 3, "rgba": 4}
    return [{m: g.random((h, w, chans[m])).astype(np.float32) for m in maps} for _ in range(n)]


# ------------------------------------------------------------------ PNG codec


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("c", [1, 2, 3, 4])
def test_png_codec_round_trip_exact(dtype, c):
    a = np.random.default_rng(c).integers(0, np.iinfo(dtype).max + 1, (9, 7, c)).astype(dtype)
    b = decode_png(encode_png(a))
    assert b.dtype == dtype and np.array_equal(a, b)


def test_png_decoder_reads_pillow_filters_and_refuses_huge_declared_size(tmp_path):
    from PIL import Image

    a = np.random.default_rng(1).integers(0, 256, (40, 30, 3)).astype(np.uint8)
    a[10:] = a[10]
    Image.fromarray(a).save(tmp_path / "p.png", optimize=True)  # adaptive filters (sub/avg/paeth)
    assert np.array_equal(read_png(tmp_path / "p.png"), a)
    with pytest.raises(ValueError, match="over the limit"):
        decode_png(encode_png(np.zeros((100, 100), np.uint8)), max_pixels=9999)


# ------------------------------------------------------------------ quantize


def test_quantize_is_exact_on_the_target_grid_even_with_dither():
    k8 = np.arange(256, dtype=np.uint8)
    assert np.array_equal(quantize(k8.astype(np.float32) / 255, 8, dither=True, rng=0), k8)
    k16 = np.arange(0, 65536, 7, dtype=np.uint16)
    assert np.array_equal(quantize(k16.astype(np.float32) / 65535, 16, dither=True, rng=0), k16)
    assert np.array_equal(quantize(k16, 16), k16)
    assert np.array_equal(quantize(k8, 16), k8.astype(np.uint16) * 257)


def test_dither_16_to_8_keeps_the_mean_where_rounding_bands():
    # a flat 16-bit value a third of the way between two 8-bit levels
    v = (100 + 1 / 3) / 255
    flat = np.full((128, 128), v, np.float32)
    rounded = quantize(flat, 8, dither=False)
    dithered = quantize(flat, 8, dither=True, rng=0)
    assert np.all(rounded == 100)  # rounding: the whole area drops to one level (banding)
    assert abs(dithered.mean() - (100 + 1 / 3)) < 0.02  # dither keeps the local mean
    assert set(np.unique(dithered)) <= {99, 100, 101, 102}
    # a slow 16-bit ramp: rounding makes long flat bands, dithering does not
    ramp = np.tile(np.linspace(0.40, 0.41, 512, dtype=np.float32), (64, 1))
    err_round = np.abs(quantize(ramp, 8, dither=False).mean(axis=0) - ramp[0] * 255).max()
    err_dith = np.abs(quantize(ramp, 8, dither=True, rng=1).mean(axis=0) - ramp[0] * 255).max()
    assert err_round > 0.45 and err_dith < 0.3
    assert np.array_equal(quantize(ramp, 8, rng=5), quantize(ramp, 8, rng=5))  # seeded


def test_quantize_validates():
    with pytest.raises(ValueError, match="bit_depth"):
        quantize(np.zeros((2, 2)), 12)
    with pytest.raises(ValueError, match="NaN"):
        quantize(np.array([0.5, np.nan]), 8)
    with pytest.raises(TypeError, match="unsigned"):
        quantize(np.array([1, -1]), 8)
    assert np.array_equal(
        quantize(np.array([0, 257 * 3, 65535], np.uint16), 8, dither=False), [0, 3, 255]
    )
    assert quantize(np.zeros((2, 3, 4, 5), np.float32), 16).shape == (2, 3, 4, 5)


# ------------------------------------------------------------------ atlas


@pytest.mark.parametrize(
    "count,columns,spacing,margin,extrude", [(6, 3, 2, 1, 1), (5, None, 0, 0, 0), (7, 2, 3, 4, 2)]
)
def test_atlas_rects_do_not_overlap_and_follow_the_tiled_formula(
    count, columns, spacing, margin, extrude
):
    lay = atlas_layout(
        count, 10, 12, columns=columns, spacing=spacing, margin=margin, extrude=extrude
    )
    occupied = np.zeros((lay.height, lay.width), int)
    for i in range(count):
        x, y, w, h = lay.rect(i)
        r, c = divmod(i, lay.columns)
        # Tiled / Godot: tile (c, r) starts at margin + c * (tile + spacing), in their terms
        assert x == lay.tiled_margin + c * (10 + lay.tiled_spacing)
        assert y == lay.tiled_margin + r * (12 + lay.tiled_spacing)
        occupied[y - extrude : y + h + extrude, x - extrude : x + w + extrude] += 1
    assert occupied.max() == 1
    assert lay.width == 2 * margin + lay.columns * (10 + 2 * extrude) + (lay.columns - 1) * spacing


def test_atlas_extrusion_repeats_edge_pixels():
    tiles = [np.arange(12, dtype=np.uint8).reshape(3, 4) + 20 * i for i in range(3)]
    lay = atlas_layout(3, 4, 3, columns=3, spacing=1, margin=2, extrude=2)
    atlas = render_atlas(tiles, lay)
    for i, t in enumerate(tiles):
        x, y, w, h = lay.rect(i)
        assert np.array_equal(atlas[y : y + h, x : x + w], t)
        assert np.array_equal(
            atlas[y - 2 : y + h + 2, x - 2 : x + w + 2], np.pad(t, 2, mode="edge")
        )
    wrapped = render_atlas(tiles, lay, extrude_mode="wrap")
    x, y, w, h = lay.rect(1)
    assert np.array_equal(
        wrapped[y - 2 : y + h + 2, x - 2 : x + w + 2], np.pad(tiles[1], 2, mode="wrap")
    )
    assert atlas[0, 0] == 0 and atlas[:, :2].max() == 0  # the margin stays empty


def test_assemble_layout():
    tiles = [np.full((2, 3), i + 1, np.uint8) for i in range(3)]
    img = assemble_layout(tiles, [[0, 2], [-1, 1]])
    assert img.shape == (4, 6)
    assert (
        np.array_equal(img[:2, 3:], tiles[2])
        and img[2:, :3].max() == 0
        and np.all(img[2:, 3:] == 2)
    )
    with pytest.raises(ValueError, match="index_matrix"):
        assemble_layout(tiles, [[0, 3]])


# ------------------------------------------------------------------ bundle


def test_bundle_files_manifest_and_identical_atlas_layout(tmp_path):
    tiles = make_tiles(6)
    mat = np.array([[0, 1, 2, 3], [5, 4, -1, 0], [2, 2, 1, 5]])
    scores = [0.5, 0.1, 0.2, 0.3, 0.4, 0.6]
    rects = [[i, 2 * i, 10, 12] for i in range(6)]
    out = tmp_path / "bundle"
    man = export_bundle(
        out,
        name="rock",
        tiles=tiles,
        index_matrix=mat,
        columns=3,
        spacing=2,
        margin=1,
        extrude=1,
        manifest_extra={
            "parameters": {"n": 6, "method": "dp"},
            "seeds": {"tileset": 7},
            "scores": scores,
            "source_rects": rects,
            "note": "hi",
        },
        normal_convention="directx",
        weights=[1, 1, 2, 2, 1, 1],
    )
    names = sorted(os.listdir(out))
    expected = {f"rock_{i:03}_{m}.png" for i in range(6) for m in ("albedo", "height")}
    expected |= {
        "rock_atlas_albedo.png",
        "rock_atlas_height.png",
        "rock.json",
        "rock_layout.csv",
        "rock_layout.json",
        "rock.tsx",
        "rock.tmx",
        "rock.tres",
        "rock_preview_albedo.png",
        "rock_preview_height.png",
    }
    assert set(names) == expected
    assert json.loads((out / "rock.json").read_text()) == man
    assert man["normal_convention"] == "directx" and man["bit_depth"] == 8
    assert man["parameters"] == {"n": 6, "method": "dp"} and man["seeds"] == {"tileset": 7}
    assert man["scores"] == scores and man["extra"] == {"note": "hi"}
    assert [t["source_rect"] for t in man["tiles"]] == rects
    atlases = {m: read_png(out / man["atlas"]["images"][m]) for m in ("albedo", "height")}
    assert (
        atlases["albedo"].shape[:2]
        == atlases["height"].shape[:2]
        == (man["atlas"]["height"], man["atlas"]["width"])
    )
    for i, t in enumerate(man["tiles"]):
        r = t["atlas_rect"]
        for m in ("albedo", "height"):
            tile_png = read_png(out / t["files"][m])
            assert np.array_equal(
                tile_png, quantize(tiles[i][m], 8, dither=False)
            )  # 8-bit source: rounded
            assert np.array_equal(
                atlases[m][r["y"] : r["y"] + r["h"], r["x"] : r["x"] + r["w"]], tile_png
            )
        fr = man["frames"][t["files"]["albedo"]]["frame"]
        assert fr == r
    lay_json = json.loads((out / "rock_layout.json").read_text())
    assert lay_json == {"tile_w": 10, "tile_h": 12, "cols": 4, "rows": 3, "cells": mat.tolist()}
    with open(out / "rock_layout.csv", newline="") as f:
        assert [[int(v) for v in row] for row in csv.reader(f)] == mat.tolist()
    prev = read_png(out / "rock_preview_albedo.png")
    assert np.array_equal(
        prev, assemble_layout([quantize(t["albedo"], 8, dither=False) for t in tiles], mat)
    )


def test_tsx_and_tmx_are_valid_xml_matching_the_manifest(tmp_path):
    tiles = make_tiles(6, maps=("albedo",))
    mat = np.array([[0, 1, -1], [5, 4, 3]])
    man = export_bundle(
        tmp_path / "b",
        name="t",
        tiles=tiles,
        index_matrix=mat,
        columns=3,
        spacing=3,
        margin=2,
        extrude=1,
        weights=[1, 2, 3, 4, 5, 6],
    )
    ts = ET.parse(tmp_path / "b" / "t.tsx").getroot()
    assert ts.tag == "tileset"
    assert {
        k: int(ts.get(k))
        for k in ("tilewidth", "tileheight", "tilecount", "columns", "spacing", "margin")
    } == {
        "tilewidth": 10,
        "tileheight": 12,
        "tilecount": 6,
        "columns": 3,
        "spacing": 5,
        "margin": 3,
    }
    img = ts.find("image")
    assert img.get("source") == man["atlas"]["images"]["albedo"]
    assert (int(img.get("width")), int(img.get("height"))) == (
        man["atlas"]["width"],
        man["atlas"]["height"],
    )
    assert [float(t.get("probability")) for t in ts.findall("tile")] == [1, 2, 3, 4, 5, 6]
    mp = ET.parse(tmp_path / "b" / "t.tmx").getroot()
    assert mp.find("tileset").get("source") == "t.tsx" and mp.find("tileset").get("firstgid") == "1"
    data = mp.find("layer/data")
    assert data.get("encoding") == "csv"
    gids = [int(v) for v in data.text.replace("\n", "").split(",")]
    assert gids == [1, 2, 0, 6, 5, 4]


def parse_tres(text: str):
    """Parse Godot 4 text resource syntax: [section attrs] headers and key = value lines."""
    sections = []
    head_re = re.compile(r'^\[(\w+)((?:\s+\w+=(?:"[^"]*"|[^\s\]]+))*)\]$')
    attr_re = re.compile(r'(\w+)=("[^"]*"|[^\s\]]+)')
    line_re = re.compile(r"^([\w:/]+) = (.+)$")
    value_re = re.compile(
        r'^(-?\d+|"[^"]*"|true|false|Vector2i\(-?\d+, -?\d+\)|(Ext|Sub)Resource\("[^"]+"\))$'
    )
    for raw in text.splitlines():
        if not raw.strip():
            continue
        m = head_re.match(raw)
        if m:
            sections.append(
                (m.group(1), {k: v.strip('"') for k, v in attr_re.findall(m.group(2))}, {})
            )
            continue
        m = line_re.match(raw)
        assert m and sections, f"not Godot resource syntax: {raw!r}"
        assert value_re.match(m.group(2)), f"bad value {m.group(2)!r}"
        sections[-1][2][m.group(1)] = m.group(2)
    return sections


def test_godot_tres_structure(tmp_path):
    tiles = make_tiles(5, maps=("albedo",))
    man = export_bundle(
        tmp_path / "tex", name="g", tiles=tiles, columns=2, spacing=1, margin=2, extrude=1
    )
    sec = parse_tres((tmp_path / "tex" / "g.tres").read_text())
    kinds = [s[0] for s in sec]
    assert kinds == ["gd_resource", "ext_resource", "sub_resource", "resource"]
    head = sec[0][1]
    assert head["type"] == "TileSet" and head["format"] == "3" and int(head["load_steps"]) == 3
    ext = sec[1][1]
    assert (
        ext["type"] == "Texture2D"
        and ext["path"] == "res://tex/" + man["atlas"]["images"]["albedo"]
    )
    sub_attrs, sub = sec[2][1], sec[2][2]
    assert sub_attrs["type"] == "TileSetAtlasSource"
    assert sub["texture"] == f'ExtResource("{ext["id"]}")'
    assert sub["texture_region_size"] == "Vector2i(10, 12)"
    assert sub["margins"] == "Vector2i(3, 3)" and sub["separation"] == "Vector2i(3, 3)"
    coords = sorted(k for k in sub if k.endswith("/0"))
    assert coords == sorted(["0:0/0", "1:0/0", "0:1/0", "1:1/0", "0:2/0"])
    assert all(sub[k] == "0" for k in coords)
    res = sec[3][2]
    assert res["tile_size"] == "Vector2i(10, 12)"
    assert res["sources/0"] == f'SubResource("{sub_attrs["id"]}")'
    # the atlas regions Godot computes (margins + coord * (size + separation)) hold the tiles
    atlas = read_png(tmp_path / "tex" / man["atlas"]["images"]["albedo"])
    for i, t in enumerate(man["tiles"]):
        c, r = i % 2, i // 2
        x, y = 3 + c * (10 + 3), 3 + r * (12 + 3)
        assert np.array_equal(
            atlas[y : y + 12, x : x + 10], read_png(tmp_path / "tex" / t["files"]["albedo"])
        )
    assert godot_tres(image_path='res://a "b".png', layout=atlas_layout(1, 2, 2)).count('\\"') == 2


def test_sixteen_bit_tiles_are_exact_copies_of_source_pixels(tmp_path):
    g = np.random.default_rng(3)
    src16 = g.integers(0, 65536, (40, 40, 3)).astype(np.uint16)
    gray16 = g.integers(0, 65536, (40, 40)).astype(np.uint16)
    (tmp_path / "gray16.png").write_bytes(encode_png(gray16))
    loaded = engine.io.load_image(tmp_path / "gray16.png")
    assert loaded.bit_depth == 16
    srcf = src16.astype(np.float32) / 65535  # what a 16-bit load gives the engine
    # a tile cut from the source with a feathered blend band in the middle columns
    r1, r2 = srcf[:16, :16], srcf[20:36, 20:36]
    h1, h2 = loaded.pixels[:16, :16], loaded.pixels[20:36, 20:36]
    alpha = np.clip((10 - np.arange(16)) / 4, 0, 1)[None, :].repeat(16, 0).astype(np.float32)
    from engine.materials import apply_cut

    cut = apply_cut({"albedo": r1, "height": h1}, {"albedo": r2, "height": h2}, alpha)
    man = export_bundle(tmp_path / "b16", name="s", tiles=[cut], source_bit_depth=16)
    assert man["bit_depth"] == 16
    out = read_png(tmp_path / "b16" / "s_000_albedo.png")
    outh = read_png(tmp_path / "b16" / "s_000_height.png")[:, :, 0]
    assert out.dtype == np.uint16 and outh.dtype == np.uint16
    keep1, keep2 = alpha == 1, alpha == 0
    assert keep1.sum() > 50 and keep2.sum() > 50
    assert np.array_equal(out[keep1], src16[:16, :16][keep1]) and np.array_equal(
        out[keep2], src16[20:36, 20:36][keep2]
    )
    assert np.array_equal(outh[keep1], gray16[:16, :16][keep1]) and np.array_equal(
        outh[keep2], gray16[20:36, 20:36][keep2]
    )
    # uint16 input auto-selects 16-bit; 8-bit only on request, dithered
    assert (
        export_bundle(tmp_path / "auto", name="a", tiles=[{"m": src16[:8, :8]}])["bit_depth"] == 16
    )
    man8 = export_bundle(tmp_path / "eight", name="e", tiles=[{"m": src16[:8, :8]}], bit_depth=8)
    assert read_png(tmp_path / "eight" / "e_000_m.png").dtype == np.uint8 and man8["bit_depth"] == 8
    assert man8["dithered"] and man8["source_bit_depth"] == 16


# ------------------------------------------------------------------ validation


def test_bundle_validates_inputs(tmp_path):
    tiles = make_tiles(2)
    with pytest.raises(ValueError, match="name"):
        export_bundle(tmp_path / "x", name="../evil", tiles=tiles)
    with pytest.raises(ValueError, match="maps"):
        export_bundle(tmp_path / "x", name="a", tiles=[tiles[0], {"albedo": tiles[1]["albedo"]}])
    with pytest.raises(ValueError, match="index_matrix"):
        export_bundle(tmp_path / "x", name="a", tiles=tiles, index_matrix=[[0, 2]])
    with pytest.raises(ValueError, match="scores"):
        export_bundle(tmp_path / "x", name="a", tiles=tiles, manifest_extra={"scores": [1]})
    with pytest.raises(ValueError, match="JSON"):
        export_bundle(
            tmp_path / "x", name="a", tiles=tiles, manifest_extra={"parameters": {"f": object()}}
        )
    with pytest.raises(ValueError, match="spacing"):
        export_bundle(tmp_path / "x", name="a", tiles=tiles, spacing=-1)
    # a layout whose preview would not fit in memory (here 12 000 x 10 800 px) is refused
    with pytest.raises(ValueError, match="layout preview would be 12000x10800 px"):
        export_bundle(tmp_path / "x", name="a", tiles=tiles, index_matrix=np.zeros((900, 1200)))
    assert not (tmp_path / "x").exists()


# ------------------------------------------------------------------ atomicity


def leftovers(parent: Path, name: str):
    return [p.name for p in parent.iterdir() if p.name.startswith(f".{name}.")]


def test_full_disk_midway_leaves_nothing(tmp_path, monkeypatch):
    calls = {"n": 0}
    real = engine.export.folder._write_bytes

    def flaky(path, data):
        calls["n"] += 1
        if calls["n"] == 4:
            real(path, data[: len(data) // 2])  # half a file, then the disk is full
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, data)

    monkeypatch.setattr(engine.export.folder, "_write_bytes", flaky)
    with pytest.raises(ExportError, match="disk is full") as info:
        export_bundle(tmp_path / "b", name="a", tiles=make_tiles(3), index_matrix=[[0, 1, 2]])
    assert info.value.errno == errno.ENOSPC and "nothing was written" in str(info.value)
    assert calls["n"] == 4
    assert not (tmp_path / "b").exists() and leftovers(tmp_path, "b") == []


def test_failure_while_replacing_keeps_the_old_bundle(tmp_path, monkeypatch):
    out = tmp_path / "b"
    export_bundle(out, name="a", tiles=make_tiles(2, rng=1))
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    with pytest.raises(ExportError, match="not empty"):
        export_bundle(out, name="a", tiles=make_tiles(2, rng=2))

    def broken(path, data):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(engine.export.folder, "_write_bytes", broken)
    with pytest.raises(ExportError, match="Input/output error"):
        export_bundle(out, name="a", tiles=make_tiles(2, rng=2), overwrite=True)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert leftovers(tmp_path, "b") == []
    monkeypatch.undo()
    export_bundle(out, name="a", tiles=make_tiles(2, rng=2), overwrite=True)
    after = {p.name: p.read_bytes() for p in out.iterdir()}
    assert set(after) == set(before) and after != before and leftovers(tmp_path, "b") == []


def test_read_only_folder_simulated(tmp_path, monkeypatch):
    import tempfile

    def denied(*a, **k):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(tempfile, "mkdtemp", denied)
    with pytest.raises(ExportError, match="permission denied"):
        export_bundle(tmp_path / "b", name="a", tiles=make_tiles(1))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() == 0,
    reason="running as root: file permissions do not stop root from writing",
)
def test_read_only_folder_real(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(ExportError, match="cannot export"):
            export_bundle(ro / "b", name="a", tiles=make_tiles(1))
        assert list(ro.iterdir()) == []
    finally:
        ro.chmod(0o755)


@pytest.mark.skipif(
    not Path("/sys/fs").is_dir(),
    reason="needs Linux sysfs (a folder nobody, not even root, can write)",
)
def test_unwritable_system_folder_real():
    with pytest.raises(ExportError, match="cannot export to /sys/fs/quilt_bundle") as info:
        export_bundle("/sys/fs/quilt_bundle", name="a", tiles=make_tiles(1))
    assert "nothing was written" in str(info.value)
    assert not Path("/sys/fs/quilt_bundle").exists()


def test_real_full_disk_and_read_only_file_system(tmpfs):
    tiles = make_tiles(12, h=64, w=64)  # ~300 kB of PNGs
    full = tmpfs("full", "size=128k")
    with pytest.raises(ExportError, match="disk is full") as info:
        export_bundle(full / "b", name="a", tiles=tiles, index_matrix=np.zeros((3, 4), int))
    assert info.value.errno == errno.ENOSPC and list(full.iterdir()) == []
    # replacing a bundle that fits by one that does not keeps the old one, byte for byte
    export_bundle(full / "b", name="a", tiles=make_tiles(2, h=8, w=8))
    before = {p.name: p.read_bytes() for p in (full / "b").iterdir()}
    with pytest.raises(ExportError, match="disk is full"):
        export_bundle(full / "b", name="a", tiles=tiles, overwrite=True)
    assert {p.name: p.read_bytes() for p in (full / "b").iterdir()} == before
    assert [p.name for p in full.iterdir()] == ["b"]
    ro = tmpfs("ro", "size=128k,ro")
    with pytest.raises(ExportError, match="read-only file system"):
        export_bundle(ro / "b", name="a", tiles=make_tiles(1))
    assert list(ro.iterdir()) == []


@pytest.mark.parametrize("maps", [("albedo", "height"), ("rgba",)])
def test_tiff_tiles_keep_16_bits(tmp_path, maps):
    import tifffile

    g = np.random.default_rng(9)
    chans = {"albedo": 3, "height": 1, "rgba": 4}
    tiles = [
        {m: g.integers(0, 65536, (6, 5, chans[m])).astype(np.uint16) for m in maps}
        for _ in range(2)
    ]
    man = export_bundle(
        tmp_path / "t", name="t", tiles=tiles, tile_format="tif", index_matrix=[[0, 1]]
    )
    for i, entry in enumerate(man["tiles"]):
        for m in maps:
            assert entry["files"][m].endswith(".tif")
            back = tifffile.imread(tmp_path / "t" / entry["files"][m])
            assert back.dtype == np.uint16 and np.array_equal(
                back.reshape(tiles[i][m].shape), tiles[i][m]
            )
    assert man["atlas"]["images"][maps[0]].endswith(".png") and man["preview"][maps[0]].endswith(
        ".tif"
    )
