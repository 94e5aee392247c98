"""Wang sets in the export bundle: manifest, Tiled's edge Wang set (the real Tiled reads it),
Godot's "match sides" terrain set."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from engine.export import export_bundle
from engine.export.wang import check_wang
from engine.png import decode_png
from engine.tiles.wang import canonical_signatures
from engine.tiles.wang_layout import layout_mismatches, wang_layout
from tests.engine.test_tiled_roundtrip import RASTERIZER, TILED, tiled


def wang_tiles(k: int, size: int = 8, seed: int = 0):
    g = np.random.default_rng(seed)
    sigs = canonical_signatures(k)
    tiles = [{"albedo": g.random((size, size, 3)).astype(np.float32)} for _ in sigs]
    wang = {"colours": k, "tiles": [dict(zip("nesw", s, strict=True)) for s in sigs]}
    return sigs, tiles, wang


def test_manifest_lists_every_tiles_wang_and_godot_has_a_match_sides_terrain_set(tmp_path):
    sigs, tiles, wang = wang_tiles(2)
    cells = wang_layout(sigs, 4, 6, rng=1)
    man = export_bundle(tmp_path / "b", name="w", tiles=tiles, index_matrix=cells, wang=wang)
    assert man["wang"] == {"type": "edge", "colours": 2}
    assert [t["wang"] for t in man["tiles"]] == wang["tiles"]
    tres = (tmp_path / "b" / "w.tres").read_text()
    head, atlas, res = tres.partition("[resource]")[0], tres, tres.partition("[resource]")[2]
    assert "terrain_set_0/mode = 2" in res
    assert re.findall(r'terrain_set_0/terrain_(\d)/name = "edge \d"', res) == ["0", "1"]
    columns = man["atlas"]["columns"]
    for i, s in enumerate(sigs):
        cell = f"{i % columns}:{i // columns}/0"
        block = re.findall(rf"^{re.escape(cell)}/(\S+) = (\S+)$", head, re.M)
        assert block[0] == ("terrain_set", "0")  # the set before its bits
        bits = dict(block[1:])
        assert bits == {
            "terrains_peering_bit/top_side": str(s[0]),
            "terrains_peering_bit/right_side": str(s[1]),
            "terrains_peering_bit/bottom_side": str(s[2]),
            "terrains_peering_bit/left_side": str(s[3]),
        }
    assert atlas.count("[sub_resource") == 1


@pytest.mark.parametrize("k", [2, 3])
def test_tiled_reads_the_wang_set_and_the_map(tmp_path, k):
    if TILED is None or RASTERIZER is None:
        pytest.skip("Tiled is not installed (Debian package 'tiled'; .ci/run installs it)")
    sigs, tiles, wang = wang_tiles(k)
    cells = wang_layout(sigs, 6, 8, rng=k)
    out = tmp_path / "b"
    man = export_bundle(out, name="w", tiles=tiles, index_matrix=cells, wang=wang, spacing=1)
    tiled("--export-tileset", "json", str(out / "w.tsx"), str(tmp_path / "ts.json"), cwd=tmp_path)
    tiled("--export-map", "json", str(out / "w.tmx"), str(tmp_path / "m.json"), cwd=tmp_path)
    ts = json.loads((tmp_path / "ts.json").read_text())
    (ws,) = ts["wangsets"]
    assert ws["type"] == "edge" and len(ws["colors"]) == k
    got = {t["tileid"]: t["wangid"] for t in ws["wangtiles"]}
    assert sorted(got) == list(range(len(sigs)))  # one wang tile per tile
    for i, (n, e, s, w) in enumerate(sigs):
        assert got[i] == [n + 1, 0, e + 1, 0, s + 1, 0, w + 1, 0]
    mp = json.loads((tmp_path / "m.json").read_text())
    gids = np.array(mp["layers"][0]["data"]).reshape(cells.shape) - 1
    np.testing.assert_array_equal(gids, cells)
    # Tiled's own idea of the map: every facing pair of edges has one colour
    wid = {i: got[i] for i in got}
    for r in range(cells.shape[0]):
        for c in range(cells.shape[1]):
            if c + 1 < cells.shape[1]:
                assert wid[cells[r, c]][2] == wid[cells[r, c + 1]][6]
            if r + 1 < cells.shape[0]:
                assert wid[cells[r, c]][4] == wid[cells[r + 1, c]][0]
    png = tmp_path / "m.png"
    tiled(str(out / "w.tmx"), str(png), cwd=tmp_path, program=RASTERIZER)
    drawn = decode_png(png.read_bytes())
    preview = decode_png((out / man["preview"]["albedo"]).read_bytes())
    assert np.array_equal(drawn[..., :3], preview)
    assert layout_mismatches(sigs, cells) == 0


def test_bad_wang_data_is_refused(tmp_path):
    _, tiles, wang = wang_tiles(2)
    with pytest.raises(ValueError, match="one signature per tile"):
        export_bundle(tmp_path / "b", name="w", tiles=tiles[:3], wang=wang)
    bad = {"colours": 2, "tiles": [dict(t) for t in wang["tiles"]]}
    bad["tiles"][5]["e"] = 2
    with pytest.raises(ValueError, match=r"wang\['tiles'\]\[5\]\['e'\] must be a colour 0..1"):
        export_bundle(tmp_path / "b", name="w", tiles=tiles, wang=bad)
    with pytest.raises(TypeError, match="wang must be a mapping"):
        check_wang([1, 2], 2)
    assert not (tmp_path / "b").exists()
