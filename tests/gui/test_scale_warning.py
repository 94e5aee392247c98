"""The template search's structure-scale warning reaches the editor's banner (issue 10, item 6)."""

import numpy as np
from PIL import Image

from benchmarks.evalset import shelves
from engine.tiles.scale import Scale
from quilt_gui import params
from tests.gui.helpers import WAIT_MS, make_window, wait_idle


def test_a_tile_smaller_than_three_periods_is_warned_about_on_the_banner(qtbot, tmp_path):
    path = tmp_path / "shelves.png"
    Image.fromarray(shelves(256, seed=3)).save(path)  # shelves every 64 px
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    w.doc.set_params({"tile_size": "64"})
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (64, 64)
    banner = w.message_bar.label.text()
    assert w.message_bar.level == "warning"
    assert "The texture repeats about every 64 px tall" in banner  # a sentence
    assert "Wang set" in banner and any("Best tile" in text for _, text in w.messages)
    assert "(Tile size)" in banner and "--tile-max" not in banner  # the editor's words


def test_auto_keeps_whole_boards_and_a_size_between_them_is_warned_about(qtbot, tmp_path):
    from benchmarks.evalset import planks

    path = tmp_path / "planks.png"
    Image.fromarray(planks(384)).save(path)  # boards every 48 px
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    assert w.doc.params["tile_size"] == "auto"  # the default: 128 px would hold 2.67 boards
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (144, 144)  # three boards
    assert w.doc.tileset.settings().tile_size == (144, 144)  # what every job runs with
    w.doc.set_params({"tile_size": "256"})  # 5.33 boards: kept as asked, and said
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (256, 256)
    banner = w.message_bar.label.text()
    assert "48 px wide (5.33 per tile; 240 or 288 px hold whole ones)" in banner
    assert "(Tile size)" in banner and "--tile-min" not in banner  # the editor's words


def test_the_auto_tile_size_moves_to_the_nearest_whole_number_of_periods():
    planks, bricks = Scale(25.0, 48.0, (False, True)), Scale(32.0, 72.0, (True, True))
    assert params.auto_tile_size((512, 512)) == 256  # without the scale: the power of two
    assert params.auto_tile_size((512, 512), planks) == 240  # 5 boards, not 5.33
    assert params.auto_tile_size((300, 300), planks) == 144  # 3 boards, not 2.67
    assert params.auto_tile_size((512, 512), bricks) == 288  # 9 courses and 4 bricks
    assert params.auto_tile_size((300, 300), bricks) == 128  # none within reach fits 300 px
    assert params.auto_tile_size((512, 512), Scale(64.0, 32.0, (True, True))) == 256  # whole
    assert params.auto_tile_size((512, 512), Scale(40.0, 50.0, (False, False))) == 256
    p = dict(params.DEFAULTS, tile_size=params.AUTO)
    assert params.tileset_settings(p, (512, 512), planks).tile_size == (240, 240)
    p[params.KEPT] = {"whole_structures": False}  # --cut-structures: the size as it was
    assert params.tileset_settings(p, (512, 512), planks).tile_size == (256, 256)


def test_the_best_tile_line_says_in_words_when_auto_moved_the_tile_size(qtbot, tmp_path):
    from benchmarks.evalset import planks

    path = tmp_path / "planks.png"
    Image.fromarray(planks(384)).save(path)  # boards every 48 px: Auto 128 -> 144
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    w.act_find.trigger()
    wait_idle(qtbot, w)
    said = "Auto tile size 144 px, not 128: it holds whole periods of the texture (3 × 48 px wide"
    line = next(text for _, text in reversed(w.messages) if text.startswith("Best tile"))
    assert said in line
    shown = (w.statusBar().currentMessage(), w.message_bar.label.text())
    assert all(said in text for text in shown)  # where the user looks, banner and status
    w.doc.set_params({"tile_size": "128"})  # asked for: kept (and warned), Auto said nothing
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert "Auto tile size" not in w.last_message()
    assert "Auto tile size" not in w.statusBar().currentMessage()


def test_the_auto_size_note_names_every_axis_it_keeps_whole():
    planks, bricks = Scale(25.0, 48.0, (False, True)), Scale(32.0, 72.0, (True, True))
    note = params.auto_size_note((512, 512), planks, 240)
    assert note.startswith("Auto tile size 240 px, not 256: it holds whole periods of the texture")
    assert "(5 × 48 px wide, measured)" in note
    note = params.auto_size_note((512, 512), bricks, 288)
    assert "(9 × 32 px tall, 4 × 72 px wide, measured)" in note
    note = params.auto_size_note((512, 512), Scale(48.0, 48.0, (True, True)), 240)  # weave
    assert "(5 × 48 px each way, measured)" in note
    assert params.auto_size_note((512, 512), planks, 256) is None  # the power of two kept
    assert params.auto_size_note((512, 512), None, 240) is None


def test_auto_square_gives_a_square_tile_on_an_image_under_128_px(qtbot, tmp_path):
    """ux13: Auto (square) searched a range on a 40×30 photo and found a 15×8 tile; it is the
    largest square of that range now, and a photo too small for any square says so."""
    assert params.auto_tile_size((30, 40)) == 15 and params.auto_tile_size((10, 10)) == 8
    assert params.auto_tile_size((9, 12)) is None  # an 8 px tile and its 2 px overlap: 10 px
    rng = np.random.default_rng(0)
    w = make_window(qtbot)
    for shape in ((30, 40), (9, 12)):
        path = tmp_path / f"tiny{shape[0]}.png"
        Image.fromarray((rng.random((*shape, 3)) * 255).astype(np.uint8)).save(path)
        with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
            w.files.open_path(str(path), confirm=False)
        wait_idle(qtbot, w)
        assert w.doc.params["tile_size"] == params.AUTO
        w.act_find.trigger()
        wait_idle(qtbot, w)
    best = [text for _, text in w.messages if text.startswith("Best tile")]
    assert len(best) == 1 and best[0].startswith("Best tile: 15x15 at")
    assert w.last_message() == (
        "No square tile fits this 12×9 image: “Tile size” Auto (square) needs 10 px each way "
        "(the smallest tile, 8 px, and its overlap). Open a larger image."
    )
