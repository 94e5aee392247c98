"""The wrap-around view: the seamless tile (or the preview) repeated without end, panned and
zoomed across its edges, as Krita's wrap-around mode shows a texture being painted.

It opens at 100 % with a tile corner in the middle of the view, where the wrap joints meet, so
a seam is in front of the eye at once. Drag (or Space+drag, middle-drag) pans; the wheel zooms
about the cursor; the pixel readout gives coordinates inside the tile.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Slot
from PySide6.QtGui import QColor, QPainter, QPixmap
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QGraphicsItem,
    QHBoxLayout,
    QLabel,
    QRadioButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from quilt_gui.imaging import to_pixmap
from quilt_gui.widgets.canvas import ImageCanvas, cosmetic_pen

#: how many tiles the scene reaches in every direction (pannable far enough for any use)
REACH = 400


class WrapItem(QGraphicsItem):
    """A pixmap repeated over the whole scene; only the exposed part is painted."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.pixmap = QPixmap()
        self.borders = False
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemUsesExtendedStyleOption, True)

    def set_pixmap(self, pixmap: QPixmap) -> None:
        self.prepareGeometryChange()
        self.pixmap = pixmap
        self.update()

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        w, h = max(1, self.pixmap.width()), max(1, self.pixmap.height())
        return QRectF(-REACH * w, -REACH * h, 2 * REACH * w, 2 * REACH * h)

    def paint(self, painter: QPainter, option, widget=None) -> None:
        if self.pixmap.isNull():
            return
        w, h = self.pixmap.width(), self.pixmap.height()
        r = option.exposedRect.intersected(self.boundingRect())
        x0, y0 = np.floor(r.left() / w) * w, np.floor(r.top() / h) * h
        area = QRectF(x0, y0, r.right() - x0 + w, r.bottom() - y0 + h)
        painter.drawTiledPixmap(area, self.pixmap)
        if self.borders:
            painter.setPen(cosmetic_pen(QColor(255, 255, 255, 140), 1, Qt.PenStyle.DashLine))
            x = x0
            while x <= area.right():
                painter.drawLine(QPointF(x, area.top()), QPointF(x, area.bottom()))
                x += w
            y = y0
            while y <= area.bottom():
                painter.drawLine(QPointF(area.left(), y), QPointF(area.right(), y))
                y += h


class WrapCanvas(ImageCanvas):
    """An :class:`ImageCanvas` whose image repeats in every direction."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.image_item.hide()  # holds the array (pixel readout); the wrap item draws
        self.wrap = WrapItem()
        self.add_item(self.wrap)
        self.hide_scrollbars()
        self.setViewportUpdateMode(self.ViewportUpdateMode.FullViewportUpdate)
        self._fit_pending = False  # opens at 100 %, not fitted
        self._home_pending = False

    def set_image(self, pixels: np.ndarray | None, *, fit: bool = False) -> None:
        first = self.image_item.array is None
        self.image_item.array = pixels
        self.wrap.set_pixmap(QPixmap() if pixels is None else to_pixmap(pixels))
        self.wrap.setVisible(pixels is not None)
        if pixels is None:
            return
        self.setSceneRect(self.wrap.boundingRect())
        if fit or first:
            self._home_pending = not self.isVisible()  # a hidden view centres when shown
            if not self._home_pending:
                self.home()

    def image_rect(self) -> QRectF:
        a = self.image_item.array
        return QRectF() if a is None else QRectF(0, 0, a.shape[1], a.shape[0])

    def home(self) -> None:
        """100 %, a tile corner (where the wrap joints cross) in the middle of the view."""
        self._home_pending = False
        self.set_zoom(1.0)
        self.centerOn(QPointF(0.0, 0.0))

    def showEvent(self, event) -> None:  # noqa: N802 - Qt API
        super().showEvent(event)
        if self._home_pending:
            self.home()

    def fit(self) -> None:
        """Fit shows 2 x 2 tiles around a corner (the whole of an endless image never fits)."""
        a = self.image_item.array
        if a is None:
            return
        super().fit()
        vp = self.viewport().rect()
        z = min((vp.width() - 8) / (2 * a.shape[1]), (vp.height() - 8) / (2 * a.shape[0]))
        self.set_zoom(float(int(z)) if z >= 1 else z)
        self.centerOn(QPointF(0.0, 0.0))
        self.fitted = True

    def pixel_at(self, view_pos: QPointF) -> tuple[int, int] | None:
        """(row, col) inside the tile under a view position (the image repeats)."""
        a = self.image_item.array
        if a is None:
            return None
        p = self.mapToScene(view_pos.toPoint())
        return int(np.floor(p.y())) % a.shape[0], int(np.floor(p.x())) % a.shape[1]


class WrapView(QWidget):
    """The wrap-around tab: the seamless tile or the picked-tile preview, endless."""

    def __init__(self, doc, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.canvas = WrapCanvas()
        self.choice = QButtonGroup(self)
        bar = QHBoxLayout()
        bar.setContentsMargins(4, 2, 4, 2)
        bar.addWidget(QLabel("Repeat:"))
        for i, text in enumerate(("Seamless tile", "Preview")):
            b = QRadioButton(text)
            b.setChecked(i == 0)
            self.choice.addButton(b, i)
            bar.addWidget(b)
        self.choice.idClicked.connect(self._refresh)
        self.borders = QCheckBox("Tile borders")
        self.borders.setToolTip("Dashed lines where the image repeats")
        self.borders.toggled.connect(self._set_borders)
        bar.addWidget(self.borders)
        self.info = QLabel()
        self.info.setWordWrap(True)  # long texts must not widen the window
        self.info.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        bar.addWidget(self.info, 1)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(self.canvas, 1)
        doc.tileset.seamless_changed.connect(self._refresh)
        doc.tileset.preview_changed.connect(self._refresh)
        self._shape = None
        self._refresh()

    @property
    def showing_preview(self) -> bool:
        return self.choice.checkedId() == 1

    def shown_image(self) -> np.ndarray | None:
        ts = self.doc.tileset
        if self.showing_preview:
            return ts.preview
        return None if ts.seamless is None else np.asarray(ts.seamless.tile)

    @Slot()
    def _refresh(self, *_args) -> None:
        img = self.shown_image()
        shape = None if img is None else img.shape
        self.canvas.set_image(img, fit=shape is not None and shape != self._shape)
        self._shape = shape
        if img is None:
            what = "picked tiles (Candidates)" if self.showing_preview else "a seamless tile"
            self.info.setText(f"Nothing to repeat yet: make {what} first.")
        else:
            h, w = img.shape[:2]
            self.info.setText(
                f"{w}×{h} repeated without end — drag to pan across its edges, wheel to zoom, "
                "Ctrl+1: 100 %"
            )

    @Slot(bool)
    def _set_borders(self, on: bool) -> None:
        self.canvas.wrap.borders = bool(on)
        self.canvas.viewport().update()
