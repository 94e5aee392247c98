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


def test_dither_is_offered_only_where_16_bits_are_written_as_8(qtbot, tmp_path):
    import imageio.v3 as iio
    import numpy as np

    from resources import sample_path

    w = make_window(qtbot)
    open_sample(qtbot, w)  # 8-bit: nothing to dither, whatever the bit depth chosen
    generate(qtbot, w, n=2)
    w.export_dialog()
    dlg = w._export_dialog
    for i in range(3):
        dlg.bit_depth.setCurrentIndex(i)
        assert not dlg.dither.isEnabled()
        assert dlg.dither.isChecked()  # greyed out but checked, as it is by default
        assert dlg.options()["dither"] is None  # ... and nothing is dithered
    path = tmp_path / "brick16.png"
    iio.imwrite(path, iio.imread(sample_path("brick")).astype(np.uint16) * 257)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    generate(qtbot, w, n=2)
    w.export_dialog()
    assert [dlg.bit_depth.setCurrentIndex(i) or dlg.dither.isEnabled() for i in range(3)] == [
        False,
        True,
        False,
    ]
    dlg.bit_depth.setCurrentIndex(1)  # 16-bit source written as 8 bits: dithered if asked
    assert dlg.options()["dither"] is True
    dlg.dither.setChecked(False)
    assert dlg.options()["dither"] is False
