"""Export the seamless tile alone (issue 13 item 13): engine.export.seamless and
``quilt-studio export PROJECT --out DIR --seamless``."""

from __future__ import annotations

import numpy as np
import pytest

from engine.cli import main
from engine.export.seamless import export_seamless, seamless_paths
from engine.io import load_image
from engine.project import project_from_tileset, save_project


def material(bit_depth=16):
    g = np.random.default_rng(1)
    top, dt = (65535, np.uint16) if bit_depth == 16 else (255, np.uint8)
    src = {
        "albedo": g.integers(0, top + 1, (40, 40, 3)).astype(dt),
        "height": g.integers(0, top + 1, (40, 40, 1)).astype(dt),
    }
    template = {m: a[4:20, 6:26] for m, a in src.items()}
    return src, template


def test_every_map_is_written_beside_the_main_one_at_its_bit_depth(tmp_path):
    _, template = material()
    maps = {m: a.astype(np.float32) / 65535 for m, a in template.items()}
    written = export_seamless(maps, tmp_path / "tile.png", bit_depth=16)
    assert [p.name for p in written] == ["tile.png", "tile_height.png"]
    for m, p in zip(template, written, strict=True):
        back = load_image(p)
        assert back.bit_depth == 16
        np.testing.assert_array_equal(np.round(back.pixels * 65535), template[m].astype(float))
    eight = export_seamless(maps, tmp_path / "t8.png", bit_depth=8, source_bit_depth=16)
    assert load_image(eight[0]).bit_depth == 8
    assert seamless_paths(maps, tmp_path / "x.tif")["height"].name == "x_height.tif"
    with pytest.raises(ValueError, match="no seamless tile"):
        export_seamless({}, tmp_path / "none.png")


def test_cli_export_seamless_writes_the_tile_per_map(tmp_path, capsys):
    src, template = material()
    project = project_from_tileset(
        sources=src,
        tiles=[template],
        template=template,
        template_rect=(6, 4, 20, 16),
        name="rock",
        bit_depth=16,
    )
    path = save_project(tmp_path / "rock.quiltproj", project)
    out = tmp_path / "out"
    assert main(["export", str(path), "--out", str(out), "--seamless"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "rock_seamless.png",
        "rock_seamless_height.png",
    ]
    tile = load_image(out / "rock_seamless.png")
    assert tile.bit_depth == 16 and tile.pixels.shape == (16, 20, 3)
    np.testing.assert_array_equal(np.round(tile.pixels * 65535), template["albedo"].astype(float))
    assert "seamless tile" in capsys.readouterr().err
    assert main(["export", str(path), "--out", str(out), "--seamless"]) == 1  # no overwrite
    assert "--overwrite" in capsys.readouterr().err
    rc = main(
        ["export", str(path), "--out", str(out), "--seamless", "--overwrite", "--bit-depth", "8"]
    )
    assert rc == 0 and load_image(out / "rock_seamless.png").bit_depth == 8
    bare = project_from_tileset(sources=src, tiles=[template], name="bare")
    bpath = save_project(tmp_path / "bare.quiltproj", bare)
    assert main(["export", str(bpath), "--out", str(tmp_path / "b"), "--seamless"]) == 1
    assert "no seamless tile" in capsys.readouterr().err
