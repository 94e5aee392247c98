"""The export dialog as a keyboard user meets it (issue 13 item 5)."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QPushButton

from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample


def test_enter_in_the_reopened_export_dialog_exports(qtbot, tmp_path):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    w.act_export.trigger()
    dlg = w._export_dialog
    qtbot.waitExposed(dlg)
    close = dlg.buttons.button(dlg.buttons.StandardButton.Close)
    qtbot.mouseClick(close, Qt.MouseButton.LeftButton)
    assert not dlg.isVisible()
    w.act_export.trigger()  # reopened
    qtbot.waitExposed(dlg)
    dlg.folder.setText(str(tmp_path / "bundle"))
    dlg.folder.setFocus()
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        qtbot.keyClick(dlg.folder, Qt.Key.Key_Return)
    assert dlg.isVisible()  # Enter exported and left the dialog open with its report
    assert (tmp_path / "bundle").is_dir() and "Exported 3 tiles" in dlg.status.text()
    browse = next(b for b in dlg.findChildren(QPushButton) if b.text() == "Browse…")
    browse.setFocus()  # Enter exports wherever the focus is (not Browse's file dialog)
    dlg.folder.setText(str(tmp_path / "bundle2"))
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        qtbot.keyClick(browse, Qt.Key.Key_Return)
    assert (tmp_path / "bundle2").is_dir()
