"""The template search's sweep drawn on the source while it runs.

The search (ALGORITHMS §1.6) scores every tile width at every column in its horizontal phase,
then every height at every row with the columns fixed (vertical phase), then redoes both on the
chosen rows (refinement). With ``sweep`` it streams a sample of the rectangles it has just
scored (:class:`engine.tiles.TemplateSweep`); :class:`SweepItem` draws the recent ones faintly
(blue: horizontal phase, pink: vertical; each phase replaces the last), the phase's best so
far in white, and names the phase. The engine samples, so drawing costs the search
little (``benchmarks/template_sweep.py`` measures it); the item keeps at most :data:`KEEP`
rectangles and redraws at most every :data:`REDRAW_MS` milliseconds.
"""

from __future__ import annotations

from collections import deque

from PySide6.QtCore import QRectF, Qt, QTimer
from PySide6.QtGui import QColor, QPainterPath
from PySide6.QtWidgets import (
    QGraphicsItem,
    QGraphicsPathItem,
    QGraphicsRectItem,
    QGraphicsSimpleTextItem,
)

from quilt_gui.widgets.canvas import cosmetic_pen

#: rectangles kept on screen (the most recent ones)
KEEP = 400
#: milliseconds between redraws of the sweep at least: each repaints the whole source view,
#: work the GUI thread would otherwise take from the search (benchmarks/template_sweep.py)
REDRAW_MS = 100
PHASE_COLORS = {"horizontal": "#3fc1ff", "vertical": "#ff5fd2"}
BEST_COLOR = "#ffffff"

__all__ = ["KEEP", "SweepItem"]


class SweepItem(QGraphicsPathItem):
    """Faint rectangles of the running template search, its best so far and its phase."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setZValue(25)
        self.recent: deque = deque(maxlen=KEEP)  # (phase, (x, y, w, h))
        self.paths = {k: QGraphicsPathItem(self) for k in PHASE_COLORS}
        for phase, item in self.paths.items():
            c = QColor(PHASE_COLORS[phase])
            c.setAlpha(45)
            item.setPen(cosmetic_pen(c, 1.0))
        self.best = QGraphicsPathItem(self)
        self.best.setPen(cosmetic_pen(BEST_COLOR, 2.0, Qt.PenStyle.DashLine))
        self.label_box = QGraphicsRectItem(self)  # a dark box keeps the text readable
        self.label_box.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        self.label_box.setBrush(QColor(0, 0, 0, 170))
        self.label_box.setPen(Qt.PenStyle.NoPen)
        self.label = QGraphicsSimpleTextItem(self.label_box)
        self.label.setBrush(QColor(BEST_COLOR))
        self.events = 0  # TemplateSweep events received since the search started
        self._last = None
        self._redraw = QTimer()  # one rebuild per REDRAW_MS, however many events came
        self._redraw.setSingleShot(True)
        self._redraw.setInterval(REDRAW_MS)
        self._redraw.timeout.connect(self._rebuild)
        self.hide()

    def clear(self) -> None:
        self._redraw.stop()
        self.recent.clear()
        self.events = 0
        self._last = None
        for item in (*self.paths.values(), self.best):
            item.setPath(QPainterPath())
        self._set_label("")

    def start(self) -> None:
        self.clear()
        self.show()

    def stop(self) -> None:
        self.clear()
        self.hide()

    def add_event(self, event) -> None:
        """A :class:`engine.tiles.TemplateSweep` of the running search (drawn with the rest of
        its batch)."""
        if not self.isVisible():
            return
        if self._last is not None and _phase(self._last) != _phase(event):
            self.recent.clear()  # each phase's sweep on its own
        self.recent.extend((event.phase, tuple(r)) for r in event.rects.tolist())
        self.events += 1
        self._last = event
        if not self._redraw.isActive():
            self._redraw.start()

    def _rebuild(self) -> None:
        last = self._last
        if last is None:
            return
        paths = {k: QPainterPath() for k in self.paths}
        for phase, (x, y, w, h) in self.recent:
            paths[phase].addRect(QRectF(x, y, w + last.overlap, h + last.overlap))
        for phase, item in self.paths.items():
            item.setPath(paths[phase])
        x, y, w, h = last.best
        best = QPainterPath()
        best.addRect(QRectF(x, y, w, h))
        self.best.setPath(best)
        step = "search" if last.round == 0 else f"refinement {last.round}"
        coarse = ", reduced image" if last.coarse else ""
        scored = "widths at every column" if last.phase == "horizontal" else "heights at every row"
        self._set_label(
            f"{step}: {last.phase} phase{coarse} — {scored}; best so far {w}x{h} at ({x}, {y}), "
            f"cost {last.best_cost:.4f}"
        )

    def _set_label(self, text: str) -> None:
        self.label.setText(text)
        self.label_box.setRect(self.label.boundingRect().adjusted(-4, -2, 4, 2))
        self.label_box.setVisible(bool(text))


def _phase(event) -> tuple:
    return event.phase, event.round, event.coarse
