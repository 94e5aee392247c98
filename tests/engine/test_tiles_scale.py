"""The texture's structure scale and the template search's preference for whole structures
(issue 10, item 6)."""

import json
import warnings

import numpy as np
import pytest

from benchmarks import evalset
from engine.settings import TilesetSettings
from engine.tiles.scale import Scale, structure_scale, whole_structure_range
from engine.tiles.template import find_template


def close(value, true, tol=0.15):
    return abs(value - true) <= tol * true


def as_float(a):
    return np.asarray(a, dtype=np.float32) / 255.0


@pytest.mark.parametrize(
    ("name", "height", "width"),
    [("bricks", 32, 72), ("shelves", 64, None), ("planks", None, 48), ("weave", 48, 48)],
)
def test_the_period_of_procedural_textures_is_found(name, height, width):
    # bricks: courses 32 px, bricks 72 px long; shelves every 64 px; planks 48 px wide; the
    # weave's over-under cell repeats every 2 strands of 24 px. All under a lighting gradient.
    s = structure_scale(as_float(evalset.load(name)))
    if height is not None:
        assert s.periodic[0] and close(s.height, height), s
    if width is not None:
        assert s.periodic[1] and close(s.width, width), s


@pytest.mark.parametrize("period", [(20, 45), (37, 26)])
def test_a_generated_grid_of_blobs_under_light_gives_its_periods(period):
    rng = np.random.default_rng(3)
    py, px = period
    yy, xx = np.mgrid[0:300, 0:360].astype(float)
    blobs = np.cos(2 * np.pi * yy / py) * np.cos(2 * np.pi * xx / px) > 0.3
    img = 0.3 + 0.4 * blobs + 0.05 * rng.standard_normal(yy.shape)
    img *= 0.6 + 0.8 * xx / xx.max()  # a strong lighting gradient
    s = structure_scale(img)
    assert s.periodic == (True, True)
    assert close(s.height, py) and close(s.width, px), s


def test_noise_has_a_small_scale_and_a_flat_image_none():
    rng = np.random.default_rng(0)
    s = structure_scale(rng.random((200, 200)))
    assert s.height < 3 and s.width < 3 and s.periodic == (False, False)
    assert structure_scale(np.full((64, 64), 0.5)).size == (0.0, 0.0)


def test_the_range_holds_whole_periods_or_warns():
    sc = Scale(64.0, 30.0, (True, False))
    lo, hi, notes = whole_structure_range(sc, (128, 128), (256, 256))
    assert lo == (191, 128) and hi == (193, 256) and notes == []  # 3 x 64 +- 1 %; x: no period
    lo, hi, notes = whole_structure_range(sc, (64, 64), (96, 96))
    assert (lo[0], hi[0]) == (64, 65) and (lo[1], hi[1]) == (64, 96)  # one period: 64 +- 1
    assert len(notes) == 1
    assert "every 64 px tall" in notes[0] and "third of the largest tile 96x96" in notes[0]
    assert "try a tile of at least 96x192" in notes[0]
    lo, hi, notes = whole_structure_range(Scale(16.0, 16.0, (True, True)), (128, 128), (256, 256))
    assert lo == (128, 128) and hi == (129, 129) and not notes  # 8 periods, +- 1 px


def test_the_search_prefers_tiles_that_hold_three_shelves():
    S = as_float(evalset.load("shelves"))  # shelves every 64 px
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t = find_template(S, tile_min=128, tile_max=256)
    assert not [w for w in caught if "structures" in str(w.message)]  # the range can hold them
    assert abs(t.rect[3] - 192) <= 1 and close(t.scale.height, 64)  # three shelves
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = find_template(S, tile_min=128, tile_max=256, whole_structures=False)
    assert plain.scale is None


def test_a_too_small_requested_tile_is_warned_about_in_words():
    S = as_float(evalset.load("shelves"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t = find_template(S, tile_min=80, tile_max=80)
    assert [w for w in caught if "repeats about every 64 px tall" in str(w.message)]
    assert any("Wang set" in w for w in t.warnings)  # the editor's banner shows these
    assert t.rect[2:] == (80, 80)


def test_the_setting_reaches_the_search():
    assert TilesetSettings().whole_structures is True
    s = TilesetSettings.from_dict({"whole_structures": False})
    assert s.to_dict()["whole_structures"] is False


def test_the_cli_reports_the_scale_and_warns_about_a_small_tile(tmp_path, capsys):
    from engine.cli import main
    from engine.png import encode_png

    (tmp_path / "s.png").write_bytes(encode_png(evalset.shelves(192, seed=5)))
    out = tmp_path / "o"
    args = ["tileset", str(tmp_path / "s.png"), "--out", str(out), "--candidates", "2"]
    assert main([*args, "--tile-min", "40"]) == 0
    err = capsys.readouterr().err
    assert "structure scale: 64 px tall (period)" in err
    assert "warning: the texture repeats about every 64 px tall" in err
    man = json.loads((out / "manifest.json").read_text())
    assert man["scale"]["periodic"]["y"] and abs(man["scale"]["height"] - 64) < 64 * 0.15
    assert any("repeats about every 64 px" in w for w in man["warnings"])
    assert main([*args, "--tile-min", "40", "--cut-structures"]) == 0
    assert "structure scale" not in capsys.readouterr().err
    assert json.loads((out / "manifest.json").read_text())["scale"] is None


def test_a_requested_size_between_whole_periods_is_warned_about():
    planks = Scale(25.0, 48.0, (False, True))
    lo, hi, notes = whole_structure_range(planks, (160, 160), (160, 160))
    assert lo == hi == (160, 160) and len(notes) == 1  # the size is kept, and said
    assert "48 px wide (3.33 per tile; 144 or 192 px hold whole ones)" in notes[0]
    assert "(--tile-min/--tile-max, or Tile size in the editor)" in notes[0]
    assert "3.12-3.54 per tile" in whole_structure_range(planks, (150, 150), (170, 170))[2][0]
    for size in (144, 192):
        assert whole_structure_range(planks, (size, size), (size, size))[2] == []
    assert whole_structure_range(planks, (128, 128), (256, 256))[2] == []  # it narrows it
    S = as_float(evalset.load("planks"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = find_template(S, tile_min=160, tile_max=160)
    assert any("144 or 192 px hold whole ones" in w for w in t.warnings)  # the banner's
