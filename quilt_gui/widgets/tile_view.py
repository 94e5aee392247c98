"""The seamless tile shown wrapped 1x1 / 3x3 / 5x5 with grid lines and its quality figures."""

from __future__ import annotations

import threading
import weakref

import numpy as np
from PySide6.QtCore import QLineF, Qt, Signal, Slot
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QGraphicsLineItem,
    QHBoxLayout,
    QLabel,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from quilt_gui import jobs, settings
from quilt_gui.document import Document
from quilt_gui.widgets.canvas import ImageCanvas, cosmetic_pen

REPEATS = (1, 3, 5)


_source_detail: dict[int, tuple[weakref.ref, float]] = {}
_source_lock = threading.Lock()


def source_detail(source: np.ndarray) -> float:
    """``laplacian_variance(source)``, remembered while ``source`` lives (worker threads).

    The tile's figure changes on every rectangle move, the source's never.
    """
    from engine.metrics import laplacian_variance

    with _source_lock:  # concurrent jobs on one source compute it once
        hit = _source_detail.get(id(source))
        if hit is not None and hit[0]() is source:
            return hit[1]
        value = float(laplacian_variance(source))
        _source_detail[id(source)] = (weakref.ref(source), value)
        return value


def tile_metrics(tile: np.ndarray, source: np.ndarray, *, cancel=None) -> dict:
    """Wrap border ratio and detail ratio of a tile (engine.metrics), for the label:
    detail ratio = laplacian_variance(tile) / laplacian_variance(source), the latter cached.
    """
    from engine.metrics import laplacian_variance, wrap_border_ratio

    vs = source_detail(source)
    detail = float(laplacian_variance(tile)) / vs if vs > 0 else float("nan")
    return {"wrap": float(wrap_border_ratio(tile)), "detail": detail}


class TiledImageView(QWidget):
    """An image repeated n x n with optional grid lines (shared by the tile and candidates)."""

    repeats_changed = Signal(int)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.canvas = ImageCanvas()
        self.canvas.hide_scrollbars()
        self.tile: np.ndarray | None = None
        self.repeats = settings.get("tile_repeats")
        if self.repeats not in REPEATS:
            self.repeats = 3
        self.grid = settings.get("tile_grid_lines")
        self._lines: list[QGraphicsLineItem] = []
        bar = self.bar = QHBoxLayout()
        bar.setContentsMargins(0, 0, 0, 0)
        self.repeat_buttons = QButtonGroup(self)
        for n in REPEATS:
            b = QToolButton()
            b.setText(f"{n}×{n}")
            b.setCheckable(True)
            b.setChecked(n == self.repeats)
            b.setToolTip(f"Show the tile repeated {n}×{n}")
            self.repeat_buttons.addButton(b, n)
            bar.addWidget(b)
        self.repeat_buttons.idClicked.connect(self.set_repeats)
        self.grid_box = QCheckBox("Grid lines")
        self.grid_box.setToolTip("Draw the tile borders")
        self.grid_box.setChecked(self.grid)
        self.grid_box.toggled.connect(self.set_grid)
        bar.addWidget(self.grid_box)
        bar.addStretch(1)
        self.info = QLabel()
        self.info.setWordWrap(True)  # long texts must not widen the window
        lay = QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        lay.addLayout(bar)
        lay.addWidget(self.canvas, 1)
        lay.addWidget(self.info)

    @Slot(int)
    def set_repeats(self, n: int) -> None:
        self.repeats = int(n)
        self.repeat_buttons.button(self.repeats).setChecked(True)
        settings.set("tile_repeats", self.repeats)
        self._redraw(fit=True)
        self.repeats_changed.emit(self.repeats)

    @Slot(bool)
    def set_grid(self, on: bool) -> None:
        self.grid = bool(on)
        settings.set("tile_grid_lines", self.grid)
        self._redraw_lines()

    def set_tile(self, tile: np.ndarray | None) -> None:
        refit = self.tile is None or tile is None or self.tile.shape != tile.shape
        self.tile = tile
        self._redraw(fit=refit)

    def shown_image(self) -> np.ndarray | None:
        """What the canvas shows: the tile repeated ``repeats`` times each way."""
        if self.tile is None:
            return None
        return np.tile(self.tile, (self.repeats, self.repeats, 1))

    def _redraw(self, fit: bool = False) -> None:
        self.canvas.set_image(self.shown_image(), fit=fit)
        self._redraw_lines()

    def _redraw_lines(self) -> None:
        for item in self._lines:
            self.canvas.scene().removeItem(item)
        self._lines = []
        if not self.grid or self.tile is None:
            return
        h, w = self.tile.shape[:2]
        n = self.repeats
        pen = cosmetic_pen(QColor(255, 255, 255, 140), 1, Qt.PenStyle.DashLine)
        for k in range(1, n):
            for line in (QLineF(k * w, 0, k * w, n * h), QLineF(0, k * h, n * w, k * h)):
                item = QGraphicsLineItem(line)
                item.setPen(pen)
                item.setZValue(10)
                self.canvas.scene().addItem(item)
                self._lines.append(item)


class TileView(TiledImageView):
    """The document's seamless tile, with its wrap border ratio and detail ratio."""

    wrap_requested = Signal()  # show the tile in the large wrap-around view

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        large = QToolButton()
        large.setText("Wrap-around…")
        large.setToolTip("Pan across the tile's edges at 100 % in the Wrap-around tab")
        large.clicked.connect(self.wrap_requested)
        self.bar.insertWidget(self.bar.count() - 1, large)
        self.metrics: dict | None = None
        self.info.setToolTip(
            "Wrap border ratio: joint across the tile's wrap vs. the texture "
            "itself (1.0 = invisible).\nDetail ratio: Laplacian variance of the "
            "tile vs. the source (below 0.95 means blur)."
        )
        doc.tileset.seamless_changed.connect(self._on_seamless_changed)
        self._on_seamless_changed()

    @Slot()
    def _on_seamless_changed(self) -> None:
        s = self.doc.tileset.seamless
        self.set_tile(None if s is None else np.asarray(s.tile))
        self.metrics = None
        if s is None or self.doc.source is None:
            self.info.setText("No seamless tile yet.")
            return
        h, w = s.tile.shape[:2]
        self.info.setText(f"{w}×{h} tile — measuring...")
        jobs.start(
            "tile_metrics",
            tile_metrics,
            np.asarray(s.tile),
            self.doc.source.main,
            label="Measuring the tile",
            on_done=self._on_metrics,
        )

    def _on_metrics(self, m: dict) -> None:
        self.metrics = m
        h, w = self.tile.shape[:2] if self.tile is not None else (0, 0)
        self.info.setText(
            f"{w}×{h} tile — wrap border ratio {m['wrap']:.2f} · detail ratio {m['detail']:.2f}"
        )
