"""A rectangle on pixel edges that can be moved and resized with handles."""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QPainter, QPainterPath
from PySide6.QtWidgets import QGraphicsItem, QGraphicsObject

from quilt_gui.commands import new_merge_id
from quilt_gui.widgets.canvas import cosmetic_pen

HANDLE_PX = 9  # handle side in screen pixels


class EditableRect(QGraphicsObject):
    """An (x, y, w, h) rectangle in source pixels with 8 resize handles.

    Emits ``edited(rect, merge_id)`` while the user drags (every change of one drag shares
    the merge id, so the document records one undo step) and ``drag_finished()``.
    """

    edited = Signal(object, int)
    drag_finished = Signal()

    def __init__(
        self, color="#ffd23f", *, min_size: int = 4, resizable: bool = True, parent=None
    ) -> None:
        super().__init__(parent)
        self._rect = (0, 0, 1, 1)
        self._color = QColor(color)
        self.min_size = min_size
        self.resizable = resizable
        self.bounds: tuple[int, int] | None = None  # (H, W) the rectangle must stay inside
        self.extra = 0  # footprint extends this far right and down (overlap)
        self._drag = None  # (mode, press scene pos, rect at press, merge id)
        self._scale = 1.0
        self.setAcceptHoverEvents(True)
        self.setZValue(40)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsFocusable, False)

    # ------------------------------------------------------------------ geometry
    @property
    def rect(self) -> tuple[int, int, int, int]:
        return self._rect

    def set_rect(self, rect) -> None:
        rect = tuple(int(v) for v in rect)
        if rect != self._rect:
            self.prepareGeometryChange()
            self._rect = rect
            self.update()

    def set_view_scale(self, scale: float) -> None:
        """The view's zoom (handles keep a constant size on screen)."""
        if scale != self._scale:
            self.prepareGeometryChange()
            self._scale = scale

    def _qrect(self) -> QRectF:
        x, y, w, h = self._rect
        return QRectF(x, y, w, h)

    def _handle_size(self) -> float:
        return HANDLE_PX / max(self._scale, 1e-6)

    def _handles(self) -> dict[str, QRectF]:
        if not self.resizable:
            return {}
        r = self._qrect()
        s = self._handle_size()
        xs = {"l": r.left(), "c": r.center().x(), "r": r.right()}
        ys = {"t": r.top(), "c": r.center().y(), "b": r.bottom()}
        out = {}
        for ky, yv in ys.items():
            for kx, xv in xs.items():
                if kx == "c" and ky == "c":
                    continue
                out[ky + kx] = QRectF(xv - s / 2, yv - s / 2, s, s)
        return out

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        m = self._handle_size()
        x, y, w, h = self._rect
        e = self.extra
        return QRectF(x, y, w + e, h + e).adjusted(-m, -m, m, m)

    def shape(self) -> QPainterPath:
        path = QPainterPath()
        path.addRect(self._qrect())
        for hr in self._handles().values():
            path.addRect(hr)
        return path

    def paint(self, painter: QPainter, option, widget=None) -> None:
        self._scale = painter.worldTransform().m11() or self._scale
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, False)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.setPen(cosmetic_pen(QColor(0, 0, 0, 160), 3))
        painter.drawRect(self._qrect())
        painter.setPen(cosmetic_pen(self._color, 1))
        painter.drawRect(self._qrect())
        if self.extra:
            x, y, w, h = self._rect
            painter.setPen(cosmetic_pen(self._color, 1, Qt.PenStyle.DotLine))
            painter.drawRect(QRectF(x, y, w + self.extra, h + self.extra))
        painter.setPen(cosmetic_pen(QColor(0, 0, 0), 1))
        painter.setBrush(QBrush(self._color))
        for hr in self._handles().values():
            painter.drawRect(hr)

    # ------------------------------------------------------------------ interaction
    def hit(self, pos: QPointF) -> str | None:
        """ "move", a handle name ("tl", "cr", ...) or None."""
        for name, hr in self._handles().items():
            if hr.contains(pos):
                return name
        if self._qrect().contains(pos):
            return "move"
        return None

    def hoverMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        mode = self.hit(event.pos())
        cursors = {
            "move": Qt.CursorShape.SizeAllCursor,
            "tl": Qt.CursorShape.SizeFDiagCursor,
            "br": Qt.CursorShape.SizeFDiagCursor,
            "tr": Qt.CursorShape.SizeBDiagCursor,
            "bl": Qt.CursorShape.SizeBDiagCursor,
            "tc": Qt.CursorShape.SizeVerCursor,
            "bc": Qt.CursorShape.SizeVerCursor,
            "cl": Qt.CursorShape.SizeHorCursor,
            "cr": Qt.CursorShape.SizeHorCursor,
        }
        if mode in cursors:
            self.setCursor(cursors[mode])
        else:
            self.unsetCursor()

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        mode = self.hit(event.pos()) if event.button() == Qt.MouseButton.LeftButton else None
        if mode is None:
            event.ignore()
            return
        self._drag = (mode, event.scenePos(), self._rect, new_merge_id())
        event.accept()

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drag is None:
            event.ignore()
            return
        mode, start, (x, y, w, h), merge = self._drag
        d = event.scenePos() - start
        dx, dy = int(round(d.x())), int(round(d.y()))
        if mode == "move":
            new = (x + dx, y + dy, w, h)
        else:
            x0, y0, x1, y1 = x, y, x + w, y + h
            if "l" in mode:
                x0 = min(x0 + dx, x1 - self.min_size)
            if "r" in mode:
                x1 = max(x1 + dx, x0 + self.min_size)
            if mode[0] == "t":
                y0 = min(y0 + dy, y1 - self.min_size)
            if mode[0] == "b":
                y1 = max(y1 + dy, y0 + self.min_size)
            new = (x0, y0, x1 - x0, y1 - y0)
        new = self.clamp(new)
        if new != self._rect:
            self.set_rect(new)
            self.edited.emit(new, merge)
        event.accept()

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drag is not None:
            self._drag = None
            self.drag_finished.emit()
            event.accept()
        else:
            event.ignore()

    def clamp(self, rect) -> tuple[int, int, int, int]:
        """``rect`` kept inside ``bounds`` (footprint included), size kept when moving."""
        x, y, w, h = rect
        if self.bounds is None:
            return x, y, w, h
        H, W = self.bounds
        e = self.extra
        w, h = max(self.min_size, min(w, W - e)), max(self.min_size, min(h, H - e))
        x, y = min(max(0, x), W - e - w), min(max(0, y), H - e - h)
        return x, y, w, h
