"""A Wang tile size that holds whole periods (``--tile-size auto``, the note's suggestion)."""

import json
import warnings

import numpy as np
import pytest

from benchmarks.evalset import planks
from engine.bitdepth import to_float
from engine.tiles.scale import Scale
from engine.tiles.wang_size import SNAP_RANGE, auto_tile_size, source_fits, whole_period_size
from tests.engine.helpers import blob_texture


def test_the_nearest_size_holding_whole_periods_on_every_periodic_axis():
    boards = Scale(25.6, 48.0, (False, True))  # planks: 128 px holds 2.67 boards
    assert whole_period_size(boards, 128) == 144  # 96 and 144 as near: the larger
    assert whole_period_size(boards, 100) == 96
    assert whole_period_size(boards, 144) is None  # already whole
    assert whole_period_size(boards, 128, fits=lambda n: n < 140) == 96
    grid = Scale(40.0, 40.0, (True, True))
    assert whole_period_size(grid, 128) == 120
    lids = Scale(116.0, 58.2, (True, True))  # one period tall, two wide
    assert whole_period_size(lids, 128) == 116
    # no square size near 128 holds 71 px rows and 60 px columns whole: left alone
    assert whole_period_size(Scale(70.9, 60.0, (True, True)), 128) is None
    assert whole_period_size(Scale(4.0, 4.0, (False, False)), 128) is None  # no period
    far = whole_period_size(Scale(30.0, 90.0, (False, True)), 128)  # 90 or 180: too far
    assert far is None and 128 * (1 - SNAP_RANGE) > 90 and 128 * (1 + SNAP_RANGE) < 180


def test_source_fits_is_the_wang_setups_size_check():
    from engine.tiles.wang import WangSetup

    S = np.random.default_rng(0).random((100, 90, 3))
    for T in (16, 40, 60, 70, 90, 100):
        try:
            WangSetup(S, tile_size=T)
            ok = True
        except ValueError:
            ok = False
        assert source_fits(S.shape, T) == ok, T


def test_a_planks_set_names_the_size_to_use_and_auto_takes_it():
    S = to_float(planks(256))  # boards every 48 px
    n, what = auto_tile_size(S, 64)  # the default of a 256 px source: 1.33 boards
    assert n == 48 and "48 px instead of 64 px" in what and "48 px wide" in what
    assert auto_tile_size(S, 48) == (48, "48 px (holds whole periods of 48 px wide)")
    from engine.tiles.wang import wang_set

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ws = wang_set(S, tile_size=64, rng=0)
    assert ws.suggested_size == 48
    note = [str(w.message) for w in caught if "whole periods" in str(w.message)]
    assert note and note[0].endswith(": 48 px (--tile-size 48, or Tile size in the editor)")
    assert ws.suggested_note == note[0] and ws.suggested_note in ws.notes
    assert wang_set(S, tile_size=48, rng=0).suggested_size is None


def test_the_suggested_size_takes_the_runs_band_and_patch_overlap():
    from engine.tiles.wang import WangSetup

    S = to_float(planks(256))  # boards every 48 px; 64 px tiles suggest 48 by default
    setup = WangSetup(S, tile_size=64, band=14)  # 4 x 14 > 48: 48 px tiles refuse band 14
    setup.phase()
    assert setup.suggested_size is None and setup.suggested_note is None
    setup = WangSetup(S, tile_size=64, patch_overlap=30)  # 2 x 30 > 48
    setup.phase()
    assert setup.suggested_size is None
    assert not source_fits(S.shape, 48, band=14) and not source_fits(S.shape, 48, patch_overlap=30)


@pytest.fixture(scope="module")
def planks_png(tmp_path_factory):
    from PIL import Image

    path = tmp_path_factory.mktemp("planks") / "planks.png"
    Image.fromarray(planks(256)).save(path)
    return path


def test_cli_tile_size_auto(tmp_path, planks_png, capsys):
    from engine.cli import main

    out = tmp_path / "w"
    argv = ["tileset", str(planks_png), "--out", str(out), "--wang", "2", "--tile-size", "auto"]
    assert main(argv) == 0
    man = json.loads((out / "manifest.json").read_text())
    assert man["wang"]["tile_size"] == 48 and man["resolved"]["tile_min"] == [48, 48]
    assert man["tile_size_auto"]["from"] == 64 and man["tile_size_auto"]["used"] == 48
    assert not any("whole periods" in w for w in man["warnings"])
    assert "tile size (auto): 48 px instead of 64 px" in capsys.readouterr().err
    # a Somol set keeps whole periods by its range
    assert main(["tileset", str(planks_png), "--out", str(tmp_path / "s"), "--tile-size", "auto"])
    assert "--tile-size auto is for --wang sets" in capsys.readouterr().err


def _stop_at_the_set(monkeypatch):
    """Record the settings the tileset command's Wang run starts with, and stop it there."""
    import engine.tiles.wang_pipeline as pipeline

    seen = []

    def stop(source, settings, **kwargs):
        seen.append(settings)
        raise ValueError("stopped before the set")

    monkeypatch.setattr(pipeline, "iter_wang_tileset", stop)
    return seen


def test_cli_tile_size_auto_takes_a_wang_manifest_and_the_patch_overlap(
    tmp_path, planks_png, capsys, monkeypatch
):
    from engine.cli import main

    seen = _stop_at_the_set(monkeypatch)
    manifest = tmp_path / "manifest.json"
    manifest.write_text(json.dumps({"settings": {"wang": 2}}))  # a Wang manifest
    argv = ["tileset", str(planks_png), "--settings", str(manifest), "--tile-size", "auto"]
    assert main([*argv, "--out", str(tmp_path / "a")]) != 0
    assert "stopped before the set" in capsys.readouterr().err  # not refused: a Wang set
    assert seen[-1].wang == 2 and seen[-1].tile_min == (48, 48)
    # 2 x 30 px of patch overlap does not fit 48 px tiles: auto keeps the 64 px default
    assert main([*argv, "--patch-overlap", "30", "--out", str(tmp_path / "b")]) != 0
    assert "tile size (auto): 64 px" in capsys.readouterr().err
    assert seen[-1].tile_min == (64, 64)


def test_auto_and_the_fixed_size_warning_judge_whole_periods_alike():
    from engine.reference_crops import phase_axes
    from engine.tiles.scale import STRUCTURES_PER_TILE, whole_structure_range

    def warned(scale, n) -> bool:
        notes = whole_structure_range(scale, (n, n), (n, n))[2]
        return any("no tile of the requested size holds" in t for t in notes)

    for T in (128, 256):
        for p in np.arange(20.0, 130.0, 0.25):
            scale = Scale(p, p, (True, True))
            n = whole_period_size(scale, T) or T  # the editor's Auto
            if n >= STRUCTURES_PER_TILE * p * 0.95:  # not "too few per tile" instead
                assert warned(scale, n) != all(phase_axes(scale, (n, n))), (T, p, n)
    # a 21 px period at 128 px: 6.10 per tile, 2 px from 126 (within 2 %): whole for both
    assert whole_period_size(Scale(21.0, 21.0, (True, True)), 128) is None
    assert not warned(Scale(21.0, 21.0, (True, True)), 128)


def test_large_structures_are_named_with_a_tile_size_that_holds_them():
    from engine.tiles.wang_size import STRUCTURE_FRACTION, large_structure_note

    assert large_structure_note(Scale(40.0, 40.0), 128, (512, 512)) == (None, None)
    note, size = large_structure_note(Scale(30.0, 90.0), 128, (3000, 4000))
    assert size == 270 and "90 px wide" in note and "tall" not in note
    assert "--tile-size 270" in note and "a photo scaled down to about 1896x1422 or less" in note
    # a period the tile holds (whole or not) is the whole-period note's; one larger warns
    assert large_structure_note(Scale(100.0, 100.0, (True, True)), 128, (512, 512))[0] is None
    note, size = large_structure_note(Scale(10.0, 150.0, (False, True)), 128, (1000, 1000))
    assert size == 450 and "150 px wide (a period)" in note
    # a source that takes no such tile: the largest that stops the warning, else a photo
    fits = lambda n: n <= 200  # noqa: E731
    _, size = large_structure_note(Scale(90.0, 90.0), 128, (300, 300), fits)
    assert size == 200 and STRUCTURE_FRACTION * 200 >= 90
    note, size = large_structure_note(Scale(90.0, 90.0), 128, (300, 300), lambda n: n < 150)
    assert size is None and "takes no tile that holds them: use a photo scaled down" in note


def test_a_set_of_tiles_smaller_than_its_blobs_warns_and_names_a_size():
    from engine.tiles.scale import structure_scale
    from engine.tiles.wang import WangSetup

    S = blob_texture()
    assert max(structure_scale(S).size) > 0.6 * 32  # the estimate of the tile set
    setup = WangSetup(S, tile_size=32)
    setup.phase()
    [note] = [n for n in setup.notes if "too large for 32 px Wang tiles" in n]
    assert setup.suggested_note == note and setup.suggested_size > 32
    assert f"--tile-size {setup.suggested_size}" in note
    assert source_fits(S.shape, setup.suggested_size)
    setup = WangSetup(S, tile_size=setup.suggested_size)  # the named size: no warning
    setup.phase()
    assert not any("too large" in n for n in setup.notes)
    assert setup.suggested_size is None


@pytest.mark.parametrize("name", ["gravel", "grass"])
def test_a_fine_texture_is_not_warned_about(name):
    from benchmarks import evalset
    from engine.tiles.wang import WangSetup

    setup = WangSetup(to_float(evalset.load(name)), tile_size=128)
    setup.phase()
    assert not any("too large" in n for n in setup.notes)


def test_no_public_evaluation_texture_is_warned_about_at_the_benchmarks_size():
    """All 15 at 128 px (text and page: 96, the largest they take); 14 meet every line of the
    Wang quality table and planks' fault is its period (the whole-period note), not its size."""
    from benchmarks import evalset
    from benchmarks.wang import tile_for
    from engine.tiles.scale import structure_scale
    from engine.tiles.wang_size import large_structure_note

    for name in evalset.PUBLIC:
        S = to_float(evalset.load(name))
        assert large_structure_note(structure_scale(S), tile_for(S, 128), S.shape) == (None, None)


def test_cli_wang_set_of_tiles_inside_blobs_warns(tmp_path, capsys):
    from PIL import Image

    from engine.cli import main

    src = tmp_path / "stones.png"
    Image.fromarray(np.round(blob_texture() * 255).astype(np.uint8)).save(src)
    argv = ["tileset", str(src), "--out", str(tmp_path / "w"), "--wang", "2", "--tile-size", "32"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "warning: the texture's structures measure about" in err
    man = json.loads((tmp_path / "w" / "manifest.json").read_text())
    assert any("too large for 32 px Wang tiles" in w for w in man["warnings"])
