"""Undo per workflow (issue 13 item 7) and Ctrl+Y (polish)."""

from __future__ import annotations

from PySide6.QtGui import QKeySequence

from tests.gui.helpers import make_window, open_sample


def test_undo_on_one_tab_never_changes_the_other_tabs_parameters(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    doc = w.doc
    w.tabs.setCurrentWidget(w.quilt_view)
    doc.set_param("block", 40)  # a quilting edit
    w.tabs.setCurrentWidget(w.source_view)
    doc.set_param("rho", 7)  # then a tile-set edit
    w.tabs.setCurrentWidget(w.quilt_view)
    assert w.act_undo.text() == "&Undo Change Block size"  # says what it undoes
    w.act_undo.trigger()
    assert doc.params["block"] == 48 and doc.params["rho"] == 7
    assert not w.act_undo.isEnabled()  # nothing more to undo in quilting
    w.tabs.setCurrentWidget(w.source_view)
    assert w.act_undo.text() == "&Undo Change Blend softness"
    w.act_undo.trigger()
    assert doc.params["rho"] == 3 and doc.params["block"] == 48
    w.act_redo.trigger()
    assert doc.params["rho"] == 7
    assert doc.modified  # either history counts
    # an edit both workflows share goes to the history of the tab in front
    w.tabs.setCurrentWidget(w.quilt_view)
    doc.set_param("exclude_tolerance", 0.2)
    w.tabs.setCurrentWidget(w.source_view)
    w.act_undo.trigger()
    assert doc.params["exclude_tolerance"] == 0.2 and doc.params["rho"] == 3


def test_ctrl_y_and_ctrl_shift_z_both_redo_whatever_the_keymap(qtbot):
    w = make_window(qtbot)
    keys = [k.toString() for k in w.act_redo.shortcuts()]
    for k in ("Ctrl+Y", "Ctrl+Shift+Z", QKeySequence(QKeySequence.StandardKey.Redo).toString()):
        assert QKeySequence(k).toString() in keys, (k, keys)
