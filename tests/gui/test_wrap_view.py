"""The wrap-around view (issue 13 item 14): the tile repeated without end at 100 %."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, QPointF, Qt

from quilt_gui.imaging import to_uint8
from tests.gui.helpers import make_window, open_sample, template, wait_idle


def grabbed(canvas) -> np.ndarray:
    img = canvas.viewport().grab().toImage().convertToFormat(img_format())
    a = np.frombuffer(img.constBits(), np.uint8).reshape(img.height(), img.bytesPerLine())
    return a[:, : img.width() * 4].reshape(img.height(), img.width(), 4)[:, :, :3].copy()


def img_format():
    from PySide6.QtGui import QImage

    return QImage.Format.Format_RGBA8888


def expected_at(canvas, tile: np.ndarray, shape) -> np.ndarray:
    """What the view must show: tile pixel (scene y mod h, scene x mod w) at every view pixel."""
    h, w = tile.shape[:2]
    origin = canvas.mapToScene(QPoint(0, 0))
    rows = (np.floor(origin.y()).astype(int) + np.arange(shape[0])) % h
    cols = (np.floor(origin.x()).astype(int) + np.arange(shape[1])) % w
    return tile[np.ix_(rows, cols)]


def test_the_wrap_view_repeats_the_tile_at_100_and_pans_across_its_edges(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    template(qtbot, w, (150, 120, 96, 80))
    w.tile_view.wrap_requested.emit()  # the tile dock's "Wrap-around…" button
    assert w.tabs.currentWidget() is w.wrap_view
    canvas = w.wrap_view.canvas
    qtbot.waitExposed(canvas)
    wait_idle(qtbot, w)
    assert canvas.zoom == 1.0
    tile = to_uint8(np.asarray(w.doc.tileset.seamless.tile))[:, :, :3]
    for step in (None, (-137, 61), (2 * 96 + 13, -3 * 80 - 7)):  # across several edges
        before = canvas.mapToScene(QPoint(0, 0))
        if step is not None:
            start = QPointF(canvas.viewport().rect().center())
            qtbot.mousePress(canvas.viewport(), Qt.MouseButton.LeftButton, pos=start.toPoint())
            end = start + QPointF(*step)
            qtbot.mouseMove(canvas.viewport(), end.toPoint())
            qtbot.mouseRelease(canvas.viewport(), Qt.MouseButton.LeftButton, pos=end.toPoint())
            moved = before - canvas.mapToScene(QPoint(0, 0))
            assert (round(moved.x()), round(moved.y())) == step  # the drag panned 1:1
        shot = grabbed(canvas)
        want = expected_at(canvas, tile, shot.shape[:2])
        assert shot.shape[0] > 2 * 80 and shot.shape[1] > 2 * 96  # more than 2 x 2 tiles
        np.testing.assert_array_equal(shot, want)
    # the pixel readout gives coordinates inside the tile
    r, c = canvas.pixel_at(QPointF(canvas.viewport().rect().center()))
    assert 0 <= r < 80 and 0 <= c < 96
    # zoom keeps repeating; the preview can be repeated too
    canvas.zoom_out()
    assert canvas.zoom < 1.0 and canvas.wrap.isVisible()
    w.wrap_view.choice.button(1).click()
    assert "Nothing to repeat" in w.wrap_view.info.text()
