"""Zoomable, pannable image view with pixel-aligned overlays.

Scene coordinates are source pixels: pixel (row, col) covers the square
[col, col + 1) x [row, row + 1). Overlays use cosmetic pens (one device pixel wide at
any zoom) and sit on pixel edges, so they stay aligned at 400 % and beyond.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QPainter, QPainterPath, QPen, QTransform
from PySide6.QtWidgets import (
    QGraphicsItem,
    QGraphicsPathItem,
    QGraphicsPixmapItem,
    QGraphicsRectItem,
    QGraphicsScene,
    QGraphicsView,
)

from quilt_gui.imaging import forget_display, heat_rgba, pixel_text, to_pixmap, to_qimage

#: Zoom steps: integer factors above 100 % so that magnified pixels stay square.
ZOOM_STEPS = (
    1 / 16,
    1 / 12,
    1 / 8,
    1 / 6,
    1 / 4,
    1 / 3,
    1 / 2,
    2 / 3,
    1.0,
    2.0,
    3.0,
    4.0,
    6.0,
    8.0,
    12.0,
    16.0,
    24.0,
    32.0,
    48.0,
    64.0,
)


def cosmetic_pen(color, width: float = 1.0, style=Qt.PenStyle.SolidLine) -> QPen:
    pen = QPen(QColor(color), width, style)
    pen.setCosmetic(True)
    pen.setJoinStyle(Qt.PenJoinStyle.MiterJoin)
    return pen


def pixel_path(points, offset=(0, 0)) -> QPainterPath:
    """The union of unit squares of ``points`` (row, col), shifted by ``offset`` (x, y).

    Each run of horizontally adjacent pixels is one rectangle (a control-point seam's row is
    one run): fewer shapes to build and paint while seams stream in."""
    path = QPainterPath()
    pts = np.unique(np.asarray(points, dtype=np.int64).reshape(-1, 2), axis=0)  # row-major
    if not len(pts):
        return path
    r, c = pts[:, 0], pts[:, 1]
    start = np.ones(len(pts), dtype=bool)
    start[1:] = (r[1:] != r[:-1]) | (c[1:] != c[:-1] + 1)
    first = np.flatnonzero(start)
    length = np.diff(np.append(first, len(pts)))
    ox, oy = offset
    for k, n in zip(first.tolist(), length.tolist(), strict=True):
        path.addRect(QRectF(float(c[k] + ox), float(r[k] + oy), float(n), 1.0))
    return path


class PixelSetItem(QGraphicsPathItem):
    """A set of pixels (a seam path) filled and outlined with a cosmetic pen."""

    def __init__(self, color, parent=None) -> None:
        super().__init__(parent)
        c = QColor(color)
        self.setPen(cosmetic_pen(c, 1.0))
        fill = QColor(c)
        fill.setAlpha(150)
        self.setBrush(QBrush(fill))
        self.setZValue(30)
        self.points = np.zeros((0, 2), dtype=np.int64)

    def set_points(self, points, offset=(0, 0)) -> None:
        self.points = np.asarray(points, dtype=np.int64).reshape(-1, 2)
        self.setPath(pixel_path(self.points, offset))


class ImageItem(QGraphicsPixmapItem):
    """A raster layer placed on integer pixel coordinates, nearest-neighbour when magnified."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setShapeMode(QGraphicsPixmapItem.ShapeMode.BoundingRectShape)
        self.array: np.ndarray | None = None

    def set_array(self, pixels: np.ndarray | None, pos=(0, 0)) -> None:
        self.array = pixels
        if pixels is None:
            self.setPixmap(to_pixmap(np.zeros((1, 1, 4), np.uint8)))
            self.hide()
            return
        self.setPixmap(to_pixmap(pixels))
        self.setPos(float(pos[0]), float(pos[1]))
        self.show()

    def paste(self, pixels: np.ndarray, x: int, y: int) -> None:
        """Put ``pixels`` into the shown array at column ``x``, row ``y`` and draw only them
        (a part of a large image changed: no conversion of the whole)."""
        h, w = pixels.shape[:2]
        self.array[y : y + h, x : x + w] = pixels
        forget_display(self.array)  # its remembered display copy is out of date
        pm = self.pixmap()
        p = QPainter(pm)
        p.setCompositionMode(QPainter.CompositionMode.CompositionMode_Source)
        p.drawImage(x, y, to_qimage(pixels))
        p.end()
        self.setPixmap(pm)


class HeatItem(ImageItem):
    """An error map shown as a translucent heat overlay."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setZValue(20)
        self.setOpacity(0.75)

    def set_error(self, error: np.ndarray | None, pos=(0, 0), vmax: float | None = None) -> None:
        self.set_array(None if error is None else heat_rgba(error, vmax=vmax), pos)
        self.error = error


class ShadeItem(QGraphicsRectItem):
    """A translucent rectangle on pixel edges (an overlap region)."""

    def __init__(self, color, parent=None) -> None:
        super().__init__(parent)
        c = QColor(color)
        fill = QColor(c)
        fill.setAlpha(60)
        self.setBrush(QBrush(fill))
        self.setPen(cosmetic_pen(c, 1.0, Qt.PenStyle.DashLine))
        self.setZValue(10)

    def set_rect(self, x: int, y: int, w: int, h: int) -> None:
        self.setRect(QRectF(float(x), float(y), float(w), float(h)))


class ImageCanvas(QGraphicsView):
    """The source (or any image) with wheel zoom about the cursor and drag to pan.

    Space+drag and middle-drag pan in every canvas, as in image editors; a plain drag pans
    too unless the canvas gives it another job (the source view draws the tile rectangle).
    """

    zoom_changed = Signal(float)
    hovered = Signal(object)  # (row, col) inside the image, or None
    pixel_clicked = Signal(object, object)  # (row, col), Qt.KeyboardModifiers: a click, no drag

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.image_item = ImageItem()
        self.image_item.setZValue(0)
        self.scene().addItem(self.image_item)
        self.setDragMode(QGraphicsView.DragMode.ScrollHandDrag)
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.SmartViewportUpdate)
        self.setMouseTracking(True)
        self.setBackgroundBrush(QBrush(QColor(24, 24, 26)))
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        # files dropped on an image go to the window (open them); a QGraphicsView accepts
        # drops for its scene by default and would swallow them
        self.setAcceptDrops(False)
        self.viewport().setAcceptDrops(False)
        self._zoom = 1.0
        self._fit_pending = True  # fit as soon as the view has its real size
        self.fitted = False  # showing the whole image, not zoomed by the user: refit on resize
        self._fit_size = None  # the view's size at the last fit
        self._press_pos = None
        self._pan_from = None  # (view pos, scroll values) while Space/middle-panning
        self.space_down = False
        self._scrollbars = True  # shown when the image does not fit (hide_scrollbars: never)
        self._apply_zoom_hints()

    # ------------------------------------------------------------------ image
    @property
    def array(self) -> np.ndarray | None:
        return self.image_item.array

    def set_image(self, pixels: np.ndarray | None, *, fit: bool = False) -> None:
        """Show ``pixels``; ``fit`` (or a first image) fits it into the view."""
        first = self.image_item.array is None
        self.image_item.set_array(pixels)
        if pixels is None:
            return
        h, w = pixels.shape[:2]
        margin = max(w, h) * 0.5
        self.setSceneRect(QRectF(-margin, -margin, w + 2 * margin, h + 2 * margin))
        if fit or first:
            self._fit_pending = True
            self.fit()
        self._update_scrollbars()

    def image_rect(self) -> QRectF:
        a = self.image_item.array
        if a is None:
            return QRectF()
        return QRectF(0, 0, a.shape[1], a.shape[0])

    # ------------------------------------------------------------------ zoom
    @property
    def zoom(self) -> float:
        return self._zoom

    def set_zoom(self, zoom: float, anchor: QPointF | None = None) -> None:
        """Scale to ``zoom`` keeping the scene point under view position ``anchor`` fixed."""
        zoom = float(min(max(zoom, ZOOM_STEPS[0]), ZOOM_STEPS[-1]))
        self.fitted = self._fit_pending = False
        if anchor is None:
            anchor = QPointF(self.viewport().rect().center())
        scene_pt = self.mapToScene(anchor.toPoint())
        self._zoom = zoom
        self.setTransform(QTransform.fromScale(zoom, zoom))
        self._update_scrollbars()  # before the correction: bars coming or going move the view
        # scroll so that scene_pt is again under anchor
        now = self.mapFromScene(scene_pt)
        delta = now - anchor.toPoint()
        self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() + delta.x())
        self.verticalScrollBar().setValue(self.verticalScrollBar().value() + delta.y())
        self._apply_zoom_hints()
        self.zoom_changed.emit(zoom)

    def _apply_zoom_hints(self) -> None:
        smooth = self._zoom < 1.0
        self.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, smooth)
        mode = (
            Qt.TransformationMode.SmoothTransformation
            if smooth
            else Qt.TransformationMode.FastTransformation
        )
        for item in self.scene().items():
            if isinstance(item, QGraphicsPixmapItem):
                item.setTransformationMode(mode)

    def zoom_step(self, steps: int, anchor: QPointF | None = None) -> None:
        z = self._zoom
        if steps > 0:
            bigger = [s for s in ZOOM_STEPS if s > z * 1.001]
            target = bigger[min(steps, len(bigger)) - 1] if bigger else ZOOM_STEPS[-1]
        else:
            smaller = [s for s in ZOOM_STEPS if s < z / 1.001]
            target = smaller[max(len(smaller) + steps, 0)] if smaller else ZOOM_STEPS[0]
        self.set_zoom(target, anchor)

    def zoom_in(self) -> None:
        self.zoom_step(1)

    def zoom_out(self) -> None:
        self.zoom_step(-1)

    def actual_size(self) -> None:
        """100 %, centred on what was at the centre."""
        self.set_zoom(1.0)

    def fit(self) -> None:
        """Zoom so the whole image is visible, centred (and keep it so on resizes).

        A hidden view (another tab) does not know its size yet: it fits when shown.
        """
        r = self.image_rect()
        if r.isEmpty():
            return
        vp = self.viewport().rect()
        if not self.isVisible() or vp.width() < 10 or vp.height() < 10:
            self._fit_pending = True
            return
        z = min((vp.width() - 8) / r.width(), (vp.height() - 8) / r.height())
        if z >= 1:
            z = float(int(z))  # integer magnification keeps pixels square
        self._zoom = float(min(max(z, ZOOM_STEPS[0]), ZOOM_STEPS[-1]))
        self.setTransform(QTransform.fromScale(self._zoom, self._zoom))
        self.centerOn(r.center())
        self._fit_pending = False
        self.fitted = True
        self._fit_size = self.size()
        self._apply_zoom_hints()
        self._update_scrollbars()
        self.zoom_changed.emit(self._zoom)

    def center_on_pixel(self, row: float, col: float) -> None:
        self.centerOn(QPointF(col, row))

    # ------------------------------------------------------------------ events
    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt API
        delta = event.angleDelta().y()
        if delta == 0:
            return
        self.zoom_step(1 if delta > 0 else -1, event.position())
        event.accept()

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt API
        super().resizeEvent(event)
        # the view's own size, not the viewport's: scroll bars coming and going must not
        # make a fit -> resize -> fit loop
        if self._fit_pending or (self.fitted and self.size() != self._fit_size):
            self.fit()
        else:
            self._update_scrollbars()

    def showEvent(self, event) -> None:  # noqa: N802 - Qt API
        super().showEvent(event)
        if self._fit_pending:
            self.fit()

    def pan_starts(self, event) -> bool:
        """A press that pans: the middle button, or the left one with Space held."""
        b = event.button()
        return b == Qt.MouseButton.MiddleButton or (
            b == Qt.MouseButton.LeftButton and self.space_down
        )

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self.pan_starts(event):
            bars = (self.horizontalScrollBar().value(), self.verticalScrollBar().value())
            self._pan_from = (event.position(), bars, event.button())
            self.viewport().setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        self._press_pos = event.position() if event.button() == Qt.MouseButton.LeftButton else None
        super().mousePressEvent(event)

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt API
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self.space_down = True
            self.viewport().setCursor(Qt.CursorShape.OpenHandCursor)
            event.accept()
            return
        super().keyPressEvent(event)

    def keyReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self.space_down = False
            self.viewport().unsetCursor()
            event.accept()
            return
        super().keyReleaseEvent(event)

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._pan_from is not None:
            if event.button() == self._pan_from[2]:
                self._pan_from = None
                if self.space_down:
                    self.viewport().setCursor(Qt.CursorShape.OpenHandCursor)
                else:
                    self.viewport().unsetCursor()
            event.accept()
            return
        super().mouseReleaseEvent(event)
        start, self._press_pos = self._press_pos, None
        if start is None or event.button() != Qt.MouseButton.LeftButton:
            return
        d = event.position() - start
        if abs(d.x()) + abs(d.y()) <= 4:
            px = self.pixel_at(event.position())
            if px is not None:
                self.pixel_clicked.emit(px, event.modifiers())

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._pan_from is not None:
            start, (h, v), _ = self._pan_from
            d = event.position() - start
            self.horizontalScrollBar().setValue(h - round(d.x()))
            self.verticalScrollBar().setValue(v - round(d.y()))
            event.accept()
            return
        super().mouseMoveEvent(event)
        self.hovered.emit(self.pixel_at(event.position()))

    def leaveEvent(self, event) -> None:  # noqa: N802 - Qt API
        super().leaveEvent(event)
        self.hovered.emit(None)

    def hover_text(self, px, bit_depth: int = 8) -> str:
        """The status bar's words for the pixel ``px`` (row, col) under the mouse ("" off the
        image): its position and value in the file's integer range."""
        a = self.array
        if px is None or a is None:
            return ""
        r, c = px
        return f"x {c}, y {r} = ({pixel_text(a, r, c, bit_depth)})"

    def pixel_at(self, view_pos: QPointF) -> tuple[int, int] | None:
        """(row, col) of the image pixel under a view position, or None outside."""
        a = self.image_item.array
        if a is None:
            return None
        p = self.mapToScene(view_pos.toPoint())
        r, c = int(np.floor(p.y())), int(np.floor(p.x()))
        if 0 <= r < a.shape[0] and 0 <= c < a.shape[1]:
            return r, c
        return None

    def view_pos_of_pixel(self, row: float, col: float) -> QPointF:
        """View coordinates of the centre of pixel (row, col) (for tests and tooltips)."""
        return QPointF(self.mapFromScene(QPointF(col + 0.5, row + 0.5)))

    def hide_scrollbars(self) -> None:
        """For small panels: pan by dragging only."""
        self._scrollbars = False
        self._update_scrollbars()

    def _update_scrollbars(self) -> None:
        """Scroll bars only where the image at this zoom is wider / taller than the view
        (the scene has a margin to pan into, which alone must not bring scroll bars)."""
        r, room = self.image_rect(), self.maximumViewportSize()
        off, needed = Qt.ScrollBarPolicy.ScrollBarAlwaysOff, Qt.ScrollBarPolicy.ScrollBarAsNeeded
        wide = self._scrollbars and r.width() * self._zoom > room.width()
        tall = self._scrollbars and r.height() * self._zoom > room.height()
        self.setHorizontalScrollBarPolicy(needed if wide else off)
        self.setVerticalScrollBarPolicy(needed if tall else off)

    def add_item(self, item: QGraphicsItem) -> QGraphicsItem:
        self.scene().addItem(item)
        if isinstance(item, QGraphicsPixmapItem):
            self._apply_zoom_hints()
        return item
