"""The Wang tab's small gaps after session 12 (polish13): the stopped banner follows the set
shown, the Grid and Seams boxes are remembered, a heal undone gives the pixels back, and the
tiles are drawn one at a time as they come (not the whole set again for each)."""

from __future__ import annotations

from PySide6.QtGui import QImage

from tests.gui.helpers import WAIT_MS, make_window, open_sample
from tests.gui.test_wang_view import generate, wait_wang


def test_the_stopped_banner_follows_the_set_undo_and_redo_show(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, colours=1)
    w, bar = win.doc.wang, win.message_bar
    win.wang_view.colours.setValue(2)
    win.wang_view.generate().stop()  # the status bar's Cancel, before the engine's first check
    wait_wang(qtbot, win)
    assert not w.complete and bar.text.startswith("Wang set stopped")
    win.doc.undo_stack.undo()  # the complete set before is back: the banner goes
    wait_wang(qtbot, win)
    assert w.colours == 1 and w.complete and "stopped" not in bar.text
    win.doc.undo_stack.redo()  # the stopped set again: said again
    wait_wang(qtbot, win)
    assert w.colours == 2 and not w.complete
    assert bar.text.startswith(f"Wang set stopped: {len(w.tiles)} of {w.count} tiles made")
    # mend15a: the hint was read inside the redo, before the stack's index moved
    assert bar.text.endswith("(Edit ▸ Undo, Ctrl+Z, brings back the set before)."), bar.text
    win.wang_view.generate()  # Generate makes it: the old stop is not news any more
    assert "stopped" not in bar.text
    wait_wang(qtbot, win)
    assert w.complete and "stopped" not in bar.text


def test_the_grid_and_seams_boxes_are_remembered_at_the_next_start(qtbot):
    win = make_window(qtbot)
    view = win.wang_view
    assert view.seams_box.isChecked() and not view.grid_box.isChecked()  # the defaults
    view.seams_box.setChecked(False)
    view.grid_box.setChecked(True)
    win.close()
    again = make_window(qtbot).wang_view
    assert not again.seams_box.isChecked() and again.grid_box.isChecked()


def test_a_heal_undone_gives_the_pixels_back_and_an_older_set_is_not_made_again(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, tile_size=48)
    w, doc = win.doc.wang, win.doc
    tiles = dict(w.tiles)  # the 48 px set, made from the photo's pixels
    generate(qtbot, win, tile_size=40)
    win.tabs.setCurrentWidget(win.source_view)  # a heal is a Source tab edit
    doc.heal({**doc.source.maps, doc.source.main_name: 1 - doc.source.main})
    wait_wang(qtbot, win)  # the 40 px set made again from the healed pixels
    doc.undo_stack.undo()  # the heal undone: the photo's pixels back...
    wait_wang(qtbot, win)  # (the 40 px set made again from them)
    win.tabs.setCurrentWidget(win.wang_view)
    doc.undo_stack.undo()  # ...so the 48 px set comes back as it was, nothing to rebuild
    assert w.options["tile_size"] == 48 and w.complete and not win.wang_runner.stale
    assert all(w.tiles[k] is t for k, t in tiles.items())
    doc.undo_stack.redo()  # the 40 px set, made again from the photo: back as it was too
    assert w.options["tile_size"] == 40 and w.complete and not win.wang_runner.stale


def test_a_tile_made_again_redraws_its_own_marks_only(qtbot):
    """Every tile streamed in redrew the marks of every tile made so far (a 3-colour set of
    128 px tiles: about 10 s of the editor's time)."""
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    w, scene = win.doc.wang, view.tiles.scene()
    view.seams_box.setChecked(True)
    before = set(scene.items())
    w.set_tile(w.tiles[5])  # tile 5 again, as a rebuild delivers it
    after = set(scene.items())
    assert len(after) == len(before)
    assert 0 < len(after - before) <= 6  # tile 5's edge bars and cuts, the others kept


def test_a_set_put_back_is_drawn_once(qtbot, monkeypatch):
    """Ctrl+Z put a set back tile by tile, the whole arrangement drawn again for each (a
    3-colour set of 128 px tiles froze the editor for 10-15 s)."""
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    generate(qtbot, win, colours=1)
    drawn = []
    real = view.tiles.set_image
    monkeypatch.setattr(view.tiles, "set_image", lambda *a, **k: (drawn.append(1), real(*a, **k)))
    win.doc.undo_stack.undo()  # the 16 tiles of the 2-colour set back
    assert win.doc.wang.complete and len(win.doc.wang.tiles) == 16
    assert view.tiles.array.shape[:2] == (4 * 48, 4 * 48)
    assert len(drawn) <= 2  # cleared, then the set


def test_a_tile_streamed_in_is_drawn_alone_into_the_arrangement(qtbot, monkeypatch):
    """Each tile streamed in converted the whole arrangement for the screen (a 4-colour set
    of 128 px tiles: 2048 px square, 0.1 s per tile, most of the editor's time)."""
    import dataclasses

    import numpy as np

    from quilt_gui.imaging import to_uint8
    from quilt_gui.widgets import canvas

    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    w = win.doc.wang
    whole = []
    real = canvas.to_pixmap
    monkeypatch.setattr(canvas, "to_pixmap", lambda a: (whole.append(a.shape), real(a))[1])
    new = dataclasses.replace(w.tiles[5], tile=np.ascontiguousarray(1 - w.tiles[5].tile))
    w.set_tile(new)  # tile 5 made again (inverted here, to be seen)
    assert not [s for s in whole if s[:2] == (4 * 48, 4 * 48)]  # not the whole arrangement
    y, x = 1 * 48, 1 * 48  # tile 5: row 1, column 1 of 4
    np.testing.assert_array_equal(view.tiles.array[y : y + 48, x : x + 48], new.tile)
    img = view.tiles.image_item.pixmap().toImage().convertToFormat(QImage.Format.Format_RGB888)
    shown = np.array(img.constBits(), np.uint8).reshape(img.height(), img.bytesPerLine())
    shown = shown[:, : 3 * img.width()].reshape(img.height(), img.width(), 3)
    np.testing.assert_array_equal(shown[y : y + 48, x : x + 48], to_uint8(new.tile))
    np.testing.assert_array_equal(shown[:48, :48], to_uint8(w.tiles[0].tile))  # the others kept


def test_re_roll_layout_and_export_wait_for_a_whole_set(qtbot):
    """Both were offered before any set (each click answered by a warning)."""
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = win.wang_view
    buttons = (view.reroll_layout_button, view.export_button)
    assert not any(b.isEnabled() for b in buttons)  # no set yet
    generate(qtbot, win, colours=1)
    assert all(b.isEnabled() for b in buttons)
    view.colours.setValue(2)
    view.generate().stop()  # a part of a set
    wait_wang(qtbot, win)
    assert not win.doc.wang.complete and not any(b.isEnabled() for b in buttons)
    win.doc.undo_stack.undo()  # the whole set before
    assert all(b.isEnabled() for b in buttons)


def test_the_tiles_waiting_for_a_rebuild_are_veiled_until_they_come(qtbot):
    """A moved sample's tiles showed their old pixels, like the finished ones, until rebuilt."""
    from engine.tiles.wang import WangSample

    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    w = win.doc.wang
    assert view._veils == {}
    y, x = w.sample("h", 0).origin
    w.set_sample(WangSample("h", 0, (y + 2, x + 2)))  # as a drag does: its tiles wait
    users = set(w.users("h", 0))
    assert set(view._veils) == users == w.stale
    assert all(item.scene() is view.tiles.scene() for item in view._veils.values())
    wait_wang(qtbot, win)
    assert w.complete and not w.stale and view._veils == {}  # each one lifted as it came


def test_the_zoom_keys_work_on_the_wang_and_quilting_tabs_away_from_a_canvas(qtbot):
    """With the keyboard focus on a button, View ▸ Fit / Actual size / Zoom raised
    AttributeError in the event loop (the tab had no main canvas) and did nothing."""
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=1)
    view.generate_button.setFocus()
    assert win.current_canvas() is view.preview  # the layout
    win.act_zoom_in.trigger()
    assert not view.preview.fitted
    win.act_fit.trigger()
    assert view.preview.fitted
    win.tabs.setCurrentWidget(win.quilt_view)
    assert win.current_canvas() is win.quilt_view.output  # (empty: nothing to zoom yet)
    for act in (win.act_fit, win.act_100, win.act_zoom_in, win.act_zoom_out):
        act.trigger()


def test_ctrl_r_and_ctrl_g_on_the_wang_tab_act_on_the_wang_set(qtbot):
    """They re-rolled the tile set's hidden preview (an undo step on the tile set's history,
    out of Ctrl+Z's reach on the Wang tab) and made tile set candidates."""
    from PySide6.QtCore import Qt

    from tests.gui.helpers import generate as tileset_generate

    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    tileset_generate(qtbot, win, n=6)
    win.doc.tileset.set_picks([0, 1, 2])
    view = generate(qtbot, win, colours=1)
    win.activateWindow()
    qtbot.waitUntil(win.isActiveWindow, timeout=5000)
    view.seed.setFocus()
    tileset_steps, seed = win.doc.tileset.undo_stack.count(), win.doc.wang.layout_seed
    qtbot.keyClick(view.seed, Qt.Key.Key_R, Qt.KeyboardModifier.ControlModifier)
    # (a button's shortcut clicks it as animated: a moment later)
    qtbot.waitUntil(lambda: win.doc.wang.layout_seed == seed + 1, timeout=WAIT_MS)
    assert win.doc.tileset.undo_stack.count() == tileset_steps  # not the tile set's
    view.colours.setValue(2)
    qtbot.keyClick(view.seed, Qt.Key.Key_G, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: win.doc.wang.colours == 2, timeout=WAIT_MS)  # a new Wang set
    assert win.jobs.get("candidates") is None  # no tile set candidates
    wait_wang(qtbot, win)
    win.tabs.setCurrentWidget(win.source_view)  # the tile set's own keys again there
    assert win.act_reroll_layout.shortcut().toString() == "Ctrl+R"
    assert win.act_generate.shortcut().toString() == "Ctrl+G"
