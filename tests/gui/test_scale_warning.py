"""The template search's structure-scale warning reaches the editor's banner (issue 10, item 6)."""

from PIL import Image

from benchmarks.evalset import shelves
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
