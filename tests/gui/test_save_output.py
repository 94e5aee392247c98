"""Quilting and transfer results get out (issue 13 item 1): Save output from the File menu,
the output's context menu and Ctrl+Shift+S on the Quilting tab; kept in the project file; an
unsaved one is not replaced without asking."""

from __future__ import annotations

import numpy as np
from PIL import Image
from PySide6.QtGui import QKeySequence

from engine.io import load_image
from tests.gui.helpers import WAIT_MS, make_window, wait_idle


def open_small(qtbot, w, tmp_path):
    src = tmp_path / "sample.png"
    rng = np.random.default_rng(2)
    Image.fromarray((rng.random((48, 40, 3)) * 255).astype(np.uint8)).save(src)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(src), confirm=False)
    w.doc.set_param("block", 16)


def test_save_output_from_the_menu_the_context_menu_and_ctrl_shift_s(qtbot, tmp_path):
    w = make_window(qtbot)
    open_small(qtbot, w, tmp_path)
    assert not w.act_save_output.isEnabled()
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    out = w.doc.quilting.output
    assert w.act_save_output.isEnabled() and w.doc.quilting.unsaved and w.doc.modified
    file_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&File")
    assert w.act_save_output in file_menu.actions()
    assert w.act_save_output in w.quilt_view.output.actions()  # the output's context menu
    save_as = QKeySequence(QKeySequence.StandardKey.SaveAs)
    assert w.act_save_output.shortcut() == save_as and w.act_save_as.shortcut().isEmpty()
    target = tmp_path / "quilted.png"
    w.files.ask_image_path = lambda caption, name: str(target)
    w.act_save_output.trigger()
    wait_idle(qtbot, w)
    saved = load_image(target).pixels
    assert saved.shape == out.shape and np.abs(saved - out).max() <= 0.5 / 255 + 1e-6
    assert not w.doc.quilting.unsaved and "Saved the 80×96 output" in w.last_message()
    w.tabs.setCurrentWidget(w.source_view)  # elsewhere Ctrl+Shift+S is Save project as
    assert w.act_save_as.shortcut() == save_as and w.act_save_output.shortcut().isEmpty()


def test_the_output_is_kept_in_the_project_and_not_replaced_without_asking(qtbot, tmp_path):
    w = make_window(qtbot)
    open_small(qtbot, w, tmp_path)
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    out = w.doc.quilting.output.copy()
    asked = []
    w.files.ask_discard_output = lambda: asked.append(1) or False
    w.act_quilt.trigger()  # unsaved: asks, and keeps it on Cancel
    wait_idle(qtbot, w)
    assert asked and np.array_equal(w.doc.quilting.output, out)
    path = tmp_path / "q.quiltproj"
    assert w.files.save_to(str(path), wait=True)
    assert not w.doc.quilting.unsaved
    w.act_quilt.trigger()  # saved in the project: no question
    wait_idle(qtbot, w)
    assert len(asked) == 1
    again = make_window(qtbot)
    with qtbot.waitSignal(again.doc.path_changed, timeout=WAIT_MS):
        again.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, again)
    kept = again.doc.quilting.finished_output
    assert kept is not None and np.abs(kept - out).max() <= 0.5 / 255 + 1e-6
    assert again.act_save_output.isEnabled()
    assert "kept in the project" in again.quilt_view.counter.text()
    np.testing.assert_array_equal(again.quilt_view.output.array, kept)
