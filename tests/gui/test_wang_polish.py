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
