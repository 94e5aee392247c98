"""Issue 13's polish list, one check each."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QImage, QPalette

from quilt_gui.files import default_folder
from quilt_gui.theme import apply_theme
from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample, wait_idle


def test_no_scrollbars_when_the_image_fits(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    wait_idle(qtbot, w)
    v = w.source_view
    v.fit()
    qtbot.wait(50)
    h, vbar = v.horizontalScrollBar(), v.verticalScrollBar()
    assert not h.isVisible() and not vbar.isVisible()  # the margin to pan into brings none
    v.set_zoom(4.0)  # 512 px at 400 % does not fit: both bars
    qtbot.waitUntil(lambda: h.isVisible() and vbar.isVisible(), timeout=WAIT_MS)
    v.fit()
    qtbot.waitUntil(lambda: not h.isVisible() and not vbar.isVisible(), timeout=WAIT_MS)


def mean_colour(widget) -> np.ndarray:
    img = widget.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    w, h = img.width(), img.height()
    a = np.frombuffer(img.constBits(), np.uint8, img.bytesPerLine() * h)
    return a.reshape(h, img.bytesPerLine())[:, : w * 3].reshape(h, w, 3).mean(axis=(0, 1))


def test_the_active_repeat_button_stands_out_in_the_dark_theme(qtbot, qapp):
    style, palette = qapp.style().name(), QPalette(qapp.palette())
    apply_theme(qapp, "dark")
    try:
        w = make_window(qtbot)
        buttons = w.tile_view.repeat_buttons
        on = buttons.checkedButton()
        off = next(b for b in buttons.buttons() if b is not on)
        assert np.abs(mean_colour(on) - mean_colour(off)).max() > 40  # not a shade: a colour
        basic = w.params_panel.view_buttons.checkedButton()
        other = next(b for b in w.params_panel.view_buttons.buttons() if b is not basic)
        assert np.abs(mean_colour(basic) - mean_colour(other)).max() > 40
    finally:
        qapp.setStyleSheet("")
        qapp.setStyle(style)
        qapp.setPalette(palette)


def test_the_empty_previews_toolbar_is_at_the_top(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.tabs.setCurrentWidget(w.preview_view)
    qtbot.wait(50)
    p = w.preview_view
    assert w.doc.tileset.preview is None and not p.canvas.isVisible()
    assert p.grid_box.geometry().bottom() < 60 < p.height() / 2  # not in the middle of the tab


def test_non_square_thumbnails_leave_no_gaps(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3, rect=(100, 100, 192, 64))  # a 3:1 strip
    wait_idle(qtbot, w)
    view = w.gallery
    cell = view.visualRect(view.model().index(0, 0))
    thumb = view.model().index(0, 0).data(Qt.ItemDataRole.DecorationRole)
    tw, th = thumb.deviceIndependentSize().width(), thumb.deviceIndependentSize().height()
    assert tw > 2.5 * th
    assert cell.height() <= th + 40 and cell.width() <= tw + 20  # the strip's shape, no square


def test_save_and_export_start_in_the_same_folder_beside_the_source(qtbot, tmp_path, monkeypatch):
    from PIL import Image
    from PySide6.QtWidgets import QFileDialog

    folder = tmp_path / "photos"
    folder.mkdir()
    src = folder / "bark.png"
    Image.fromarray((np.random.default_rng(1).random((64, 64, 3)) * 255).astype(np.uint8)).save(src)
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(src), confirm=False)
    starts = []
    monkeypatch.setattr(
        QFileDialog,
        "getSaveFileName",
        lambda parent, cap, start, *a: starts.append(start) or ("", ""),
    )
    w.files.ask_image_path("Save output", "bark_quilted.png")
    w.files.ask_save_path()
    assert [str(Path(s).parent) for s in starts] == [str(folder)] * 2
    assert default_folder(w.doc, "last_export_dir") == str(folder)  # the export dialog's rule
