"""The preview: picked tiles assembled by the random index matrix, with its grid score."""

from __future__ import annotations

from PySide6.QtCore import QLineF, Qt, Slot
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QGraphicsLineItem,
    QHBoxLayout,
    QLabel,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from quilt_gui import settings
from quilt_gui.document import Document
from quilt_gui.widgets.canvas import ImageCanvas, cosmetic_pen


class PreviewView(QWidget):
    """Canvas of ``doc.tileset.preview`` with an optional tile grid and the grid score."""

    def __init__(self, doc: Document, reroll_action=None, grid_action=None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.canvas = ImageCanvas()
        self.grid = settings.get("preview_grid")
        self._lines: list[QGraphicsLineItem] = []
        bar = QHBoxLayout()
        bar.setContentsMargins(4, 2, 4, 2)
        if reroll_action is not None:
            b = QToolButton()
            b.setDefaultAction(reroll_action)
            b.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
            bar.addWidget(b)
        self.grid_box = QCheckBox("Grid overlay")
        self.grid_box.setToolTip("Draw the tile borders over the preview (G)")
        self.grid_box.setChecked(self.grid)
        self.grid_box.toggled.connect(self.set_grid)
        bar.addWidget(self.grid_box)
        self.grid_action = grid_action  # the window's toggle (shortcut G), kept in step
        if grid_action is not None:
            grid_action.setChecked(self.grid)
            grid_action.toggled.connect(self.set_grid)
        self.info = QLabel()
        self.info.setWordWrap(True)  # long texts must not widen the window
        self.info.setToolTip(
            "Grid score: autocorrelation at one tile period minus the source's "
            "own (0 = no visible grid; one tile repeated scores about 1)."
        )
        bar.addWidget(self.info, 1)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(self.canvas, 1)
        self._shape = None
        doc.tileset.preview_changed.connect(self._on_preview_changed)
        self._on_preview_changed()

    @Slot(bool)
    def set_grid(self, on: bool) -> None:
        self.grid = bool(on)
        settings.set("preview_grid", self.grid)
        self.grid_box.setChecked(self.grid)
        if self.grid_action is not None:
            self.grid_action.setChecked(self.grid)
        self._draw_grid()

    @Slot()
    def _on_preview_changed(self) -> None:
        img = self.doc.tileset.preview
        fit = img is None or self._shape != (None if img is None else img.shape)
        self._shape = None if img is None else img.shape
        self.canvas.set_image(img, fit=fit)
        self.canvas.setVisible(img is not None)
        if img is None:
            self.info.setText("Pick tiles in the Candidates gallery to see them assembled here.")
        else:
            lay = self.doc.tileset.layout
            n = len(self.doc.tileset.picks)
            score = self.doc.tileset.grid_score
            s = "n/a" if score is None else f"{score:.3f}"
            rows, cols = lay.shape if lay is not None else (0, 0)
            self.info.setText(
                f"grid score {s} · {rows}×{cols} cells from {n} picked tile{'s' if n != 1 else ''}"
            )
        self._draw_grid()

    def _draw_grid(self) -> None:
        for item in self._lines:
            self.canvas.scene().removeItem(item)
        self._lines = []
        lay, picks = self.doc.tileset.layout, self.doc.tileset.picked_entries()
        if not self.grid or self.doc.tileset.preview is None or lay is None or not picks:
            return
        th, tw = picks[0].tile.shape[:2]
        self._lines = grid_items(self.canvas, *lay.shape, th, tw)


def grid_items(canvas, rows: int, cols: int, th: int, tw: int) -> list[QGraphicsLineItem]:
    """Dashed lines along the tile borders of a rows x cols layout of th x tw tiles, added to
    ``canvas``'s scene; returns them (to remove them later)."""
    pen = cosmetic_pen(QColor(255, 255, 255, 150), 1, Qt.PenStyle.DashLine)
    lines = [QLineF(c * tw, 0, c * tw, rows * th) for c in range(1, cols)]
    lines += [QLineF(0, r * th, cols * tw, r * th) for r in range(1, rows)]
    items = []
    for line in lines:
        item = QGraphicsLineItem(line)
        item.setPen(pen)
        item.setZValue(10)
        canvas.scene().addItem(item)
        items.append(item)
    return items
