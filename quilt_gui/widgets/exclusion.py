"""Excluded source pixels: painted or picked by colour on an image canvas, drawn over it.

The document holds one painted mask (:attr:`Document.exclude_painted`) and one colour range
(the ``exclude_color`` / ``exclude_tolerance`` parameters). Together they are the pixels the
template search, the candidates and quilting never use (:func:`quilt_gui.pipeline.
excluded_mask`). An :class:`ExclusionPainter` edits them on a canvas showing the source
(the Source tab, the Quilting tab's sample): Shift+drag paints with the brush radius,
Shift+right-drag erases, Ctrl+Shift+click excludes the colour under the cursor. One stroke
is one undo step.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QEvent, QObject, Qt, Slot

from engine.io import to_rgb
from quilt_gui.document import Document
from quilt_gui.job_bodies import excluded_mask
from quilt_gui.widgets.canvas import ImageCanvas, ImageItem

#: Tolerance set when a colour is picked while none is set (per channel, in [0, 1]).
PICK_TOLERANCE = 0.08
EXCLUSION_KEYS = frozenset({"exclude_color", "exclude_tolerance"})
HINT = "Shift+drag: paint pixels never to use · Shift+right-drag: erase"
MOUSE = frozenset(
    {QEvent.Type.MouseButtonPress, QEvent.Type.MouseMove, QEvent.Type.MouseButtonRelease}
)


class MaskBrush(QObject):
    """A brush that paints a (H, W) bool mask of the source on ``canvas``, shown as a
    translucent ``color`` overlay; one stroke is one undo step. Subclasses say which presses
    start a stroke (:meth:`wants`), which mask is painted (:meth:`current_mask`) and where a
    finished stroke goes (:meth:`commit`)."""

    COLOR = (255, 40, 40, 150)
    Z = 15

    def __init__(self, doc: Document, canvas: ImageCanvas) -> None:
        super().__init__(canvas)
        self.doc = doc
        self.canvas = canvas
        self.overlay = ImageItem()
        self.overlay.setZValue(self.Z)
        self.overlay.hide()
        canvas.add_item(self.overlay)
        self._stroke: np.ndarray | None = None  # the mask being painted
        self._value = True  # paint (True) or erase
        self._last: tuple[int, int] | None = None
        self._viewport = canvas.viewport()
        self._viewport.installEventFilter(self)
        doc.source_changed.connect(self.refresh)

    # ------------------------------------------------------------------ subclass hooks
    def wants(self, event) -> bool:
        """Does this press start a stroke? (right button: erase)"""
        raise NotImplementedError

    def current_mask(self) -> np.ndarray | None:
        raise NotImplementedError

    def commit(self, mask: np.ndarray | None, painting: bool) -> None:
        raise NotImplementedError

    def shown_mask(self, painted: np.ndarray | None) -> np.ndarray | None:
        """What the overlay shows, given the painted mask (or the stroke)."""
        return painted

    # ------------------------------------------------------------------ drawing
    @Slot()
    def refresh(self) -> None:
        """Redraw the overlay (the stroke while one is painted)."""
        painted = self._stroke if self._stroke is not None else self.current_mask()
        mask = None if self.doc.source is None else self.shown_mask(painted)
        if mask is None or not mask.any():
            self.overlay.hide()
            return
        rgba = np.zeros(mask.shape + (4,), np.uint8)
        rgba[mask] = self.COLOR
        self.overlay.set_array(rgba)

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt API
        kind = event.type()
        if kind not in MOUSE or obj is not self._viewport or self.doc.source is None:
            return False  # (no canvas call here: it may be being destroyed)
        if kind == QEvent.Type.MouseButtonPress:
            return self._press(event)
        if kind == QEvent.Type.MouseMove and self._stroke is not None:
            px = self.canvas.pixel_at(event.position())
            self.canvas.hovered.emit(px)  # the canvas does not see this move: the status bar
            if px is not None:
                self._paint(self._last or px, px)
                self._last = px
            return True
        if kind == QEvent.Type.MouseButtonRelease and self._stroke is not None:
            stroke, self._stroke, self._last = self._stroke, None, None
            self.commit(stroke if stroke.any() else None, self._value)
            return True
        return False

    def _press(self, event) -> bool:
        if not self.wants(event):
            return False
        px = self.canvas.pixel_at(event.position())
        if px is None:
            return False
        self.canvas.hovered.emit(px)
        current = self.current_mask()
        self._stroke = np.zeros(self.doc.source.shape, bool) if current is None else current.copy()
        self._value = event.button() != Qt.MouseButton.RightButton
        self._last = px
        self._paint(px, px)
        return True

    def _paint(self, a: tuple[int, int], b: tuple[int, int]) -> None:
        """Stamp the brush along the segment a -> b (pixels (row, col))."""
        r = int(self.doc.params["brush"])
        H, W = self._stroke.shape
        steps = max(abs(b[0] - a[0]), abs(b[1] - a[1]), 1)
        for t in np.linspace(0.0, 1.0, steps + 1):
            cy, cx = a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t
            r0, r1 = max(0, int(cy) - r), min(H, int(cy) + r + 1)
            c0, c1 = max(0, int(cx) - r), min(W, int(cx) + r + 1)
            yy, xx = np.mgrid[r0:r1, c0:c1]
            disk = (yy - cy) ** 2 + (xx - cx) ** 2 <= r * r
            self._stroke[r0:r1, c0:c1][disk] = self._value
        self.refresh()


class ExclusionPainter(MaskBrush):
    """Paints the document's exclusion on ``canvas`` (Shift+drag, Shift+right-drag erases,
    Ctrl+Shift+click picks a colour) and shows it, with the colour range, in red."""

    def __init__(self, doc: Document, canvas: ImageCanvas) -> None:
        super().__init__(doc, canvas)
        doc.exclusion_changed.connect(self.refresh)
        doc.params_changed.connect(self._on_params_changed)
        self.refresh()

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        if keys & EXCLUSION_KEYS:
            self.refresh()

    def current_mask(self) -> np.ndarray | None:
        return self.doc.exclude_painted

    def shown_mask(self, painted):
        p = self.doc.params
        return excluded_mask(
            self.doc.source.main, p["exclude_color"], p["exclude_tolerance"], painted
        )

    def wants(self, event) -> bool:
        return bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier)

    def _press(self, event) -> bool:
        mods = event.modifiers()
        if mods & Qt.KeyboardModifier.ShiftModifier and mods & Qt.KeyboardModifier.ControlModifier:
            px = self.canvas.pixel_at(event.position())  # Ctrl+Shift+click: a colour
            if px is not None and event.button() == Qt.MouseButton.LeftButton:
                self.pick_colour(px)
            return px is not None
        return super()._press(event)

    def commit(self, mask, painting: bool) -> None:
        self.doc.set_painted(mask, text="Paint exclusion" if painting else "Erase exclusion")

    def pick_colour(self, px: tuple[int, int]) -> None:
        """Exclude the colour of source pixel ``px`` (row, col): one undo step."""
        r, c = px
        rgb = to_rgb(self.doc.source.main[r : r + 1, c : c + 1])[0, 0]
        color = "#" + "".join(f"{int(round(float(v) * 255)):02x}" for v in rgb)
        values = {"exclude_color": color}
        if self.doc.params["exclude_tolerance"] <= 0:
            values["exclude_tolerance"] = PICK_TOLERANCE
        self.doc.set_params(values, text="Exclude a colour")

    def clear_painted(self) -> None:
        if self.doc.exclude_painted is not None:
            self.doc.set_painted(None, text="Clear painted exclusion")
