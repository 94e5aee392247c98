"""The Wang tab's small gaps after session 12 (polish13): the stopped banner follows the set
shown, the Grid and Seams boxes are remembered, a heal undone gives the pixels back."""

from __future__ import annotations

from tests.gui.helpers import make_window, open_sample
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
