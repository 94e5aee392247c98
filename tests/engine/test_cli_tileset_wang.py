"""End to end: ``quilt-studio tileset SOURCE --out DIR --wang K --tile-size N`` and its project."""

import json

import numpy as np
import pytest

from engine.cli import main
from engine.png import decode_png, encode_png
from engine.project import export_project, load_project
from engine.tiles.wang_layout import layout_mismatches
from tests.engine.helpers import smooth_texture


@pytest.fixture(scope="module")
def src(tmp_path_factory):
    d = tmp_path_factory.mktemp("src")
    S = smooth_texture((100, 104), 3, seed=9, sigma=1.5)
    rgb16 = np.round(S * 65535).astype(np.uint16)
    rgb16[::3, ::5] += 1  # values 8 bits cannot hold
    paths = {"rgb16": d / "rgb16.png", "height": d / "height.png"}
    paths["rgb16"].write_bytes(encode_png(rgb16))
    paths["height"].write_bytes(encode_png(np.round(S[:, :, 1] * 255).astype(np.uint8)))
    return paths, rgb16


def test_wang_set_files_manifest_layout_and_project(tmp_path, src):
    paths, rgb16 = src
    out = tmp_path / "w"
    proj = tmp_path / "w.quiltproj"
    argv = ["tileset", str(paths["rgb16"]), "--out", str(out), "--wang", "2"]
    argv += ["--tile-size", "32", "--seed", "4", "--preview", "4x6", "--project", str(proj)]
    assert main([*argv, "--map", f"height={paths['height']}"]) == 0
    man = json.loads((out / "manifest.json").read_text())
    assert man["kind"] == "wang" and man["resolved"]["wang"] == 2
    assert len(man["tiles"]) == 16
    sigs = [tuple(t["wang"][k] for k in "nesw") for t in man["tiles"]]
    assert len(set(sigs)) == 16
    assert len(man["wang"]["samples"]) == 4
    cells = np.array(json.loads((out / "layout.json").read_text())["cells"])
    assert cells.shape == (4, 6) and layout_mismatches(sigs, cells) == 0
    tile = decode_png((out / man["tiles"][0]["file"]).read_bytes())
    assert tile.dtype == np.uint16 and tile.shape == (32, 32, 3)
    assert (out / man["tiles"][0]["maps"]["height"]).exists()
    # 16-bit exact: the north edge row is the sample's source row
    oy, ox = man["wang"]["samples"][sigs[0][0]]["origin"]
    np.testing.assert_array_equal(tile[0], rgb16[oy, ox : ox + 32])
    preview = decode_png((out / man["preview"]["file"]).read_bytes())
    assert preview.shape == (4 * 32, 6 * 32, 3)

    p = load_project(proj)
    assert p.wang["colours"] == 2 and len(p.wang["samples"]) == 4 and not p.candidates
    assert [tuple(c.params["wang"][k] for k in "nesw") for c in p.wang_tiles] == sigs
    np.testing.assert_array_equal(p.wang["layout"], cells)
    np.testing.assert_array_equal(np.round(p.wang_tiles[0].tile * 65535).astype(np.uint16), tile)

    bundle = tmp_path / "b"
    assert main(["export", str(proj), "--out", str(bundle)]) == 0
    bman = json.loads((bundle / "tileset.json").read_text())
    assert bman["wang"] == {"type": "edge", "colours": 2}
    assert [tuple(t["wang"][k] for k in "nesw") for t in bman["tiles"]] == sigs
    assert bman["atlas"]["columns"] == 4  # the canonical 4x4 arrangement
    tsx = (bundle / "tileset.tsx").read_text()
    assert tsx.count("<wangtile ") == 16 and 'type="edge"' in tsx

    p.wang["pending"] = [3, 7]  # saved by the editor while two tiles waited for a rebuild
    with pytest.raises(ValueError, match="2 of the project's Wang tiles were saved while"):
        export_project(p, tmp_path / "b2")
    assert not (tmp_path / "b2").exists()


def test_wang_flags_are_checked(tmp_path, src, capsys):
    paths, _ = src
    base = ["tileset", str(paths["rgb16"]), "--out", str(tmp_path / "x"), "--wang", "2"]
    assert main([*base, "--tile-min", "24", "--tile-max", "32"]) == 1
    assert "Wang tiles are square and of one size" in capsys.readouterr().err
    assert main([*base, "--tile-size", "32", "--pick", "1,2"]) == 1
    assert "--pick belongs to the template workflow" in capsys.readouterr().err
    # it was taken, the set made from the photo as it is and the manifest said flatten: true
    assert main([*base, "--tile-size", "32", "--flatten"]) == 1
    assert "--flatten is not available for Wang sets" in capsys.readouterr().err
    assert main([*base, "--tile-size", "96"]) == 1
    assert "too small for 96 px Wang tiles" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_project_checks_the_wang_record(tmp_path, src):
    from engine.candidate import CandidateTile
    from engine.project import project_from_tileset

    paths, rgb16 = src
    good = {"colours": 1, "samples": [{"axis": "h", "colour": 0, "origin": [40, 0]}]}
    good["samples"].append({"axis": "v", "colour": 0, "origin": [0, 40]})
    t = np.zeros((32, 32, 3), np.float32)
    tile = CandidateTile(0, t, params={"wang": {"n": 0, "e": 0, "s": 0, "w": 0}})
    p = project_from_tileset(sources=rgb16, tiles=[], wang=good, wang_tiles=[tile, tile])
    assert p.wang == good and len(p.wang_tiles) == 2
    with pytest.raises(ValueError, match="wang.samples must list 2 samples"):
        project_from_tileset(
            sources=rgb16, tiles=[], wang={**good, "samples": good["samples"][:1]},
            wang_tiles=[tile],
        )  # fmt: skip
    with pytest.raises(ValueError, match="the Wang tiles' signatures"):
        project_from_tileset(sources=rgb16, tiles=[], wang=good, wang_tiles=[CandidateTile(0, t)])
    with pytest.raises(ValueError, match="wang.layout must be a valid layout"):
        project_from_tileset(
            sources=rgb16, tiles=[], wang={**good, "layout": [[0, 5]]}, wang_tiles=[tile]
        )
