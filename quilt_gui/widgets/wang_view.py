"""The Wang tab: a Wang tile set made from the source, its edge samples, tiles and preview.

* **Source** — every edge sample drawn as its diamond (the square rotated by 45° whose
  diagonal is the tile edge it sits on), in its colour: solid for the north/south colours,
  dashed for the east/west ones. Click one to select it, drag it to re-choose it: every tile
  that shows it is rebuilt in the background (one undo step per drag).
* **Tiles** — the set in its canonical arrangement (a valid tiling that also wraps), each
  edge marked with its colour, the corner cuts and the interior's closed cut drawn.
* **Preview** — a random valid 8x8 layout; re-roll it, show the tile grid.
"""

from __future__ import annotations

from functools import partial

import numpy as np
from PySide6.QtCore import QLineF, QPointF, Qt, Signal, Slot
from PySide6.QtGui import QBrush, QColor, QPainterPath, QPolygonF
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGraphicsItem,
    QGraphicsLineItem,
    QGraphicsPathItem,
    QGraphicsPolygonItem,
    QGraphicsRectItem,
    QGraphicsSimpleTextItem,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSpinBox,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from engine.export.wang import PALETTE
from quilt_gui import settings
from quilt_gui.widgets.canvas import ImageCanvas, cosmetic_pen
from quilt_gui.widgets.preview import grid_items

__all__ = ["WangView"]

CUT_COLOR = "#ff4d4d"  # corner cuts
PATCH_COLOR = "#7dff5f"  # the interior's closed cut


def colour_of(c: int) -> QColor:
    return QColor(PALETTE[c % len(PALETTE)])


def arrangement_shape(doc_wang) -> tuple[int, int, int] | None:
    """The shape of :func:`arrangement`, None before the first tile."""
    w = doc_wang
    if not w.tiles:
        return None
    T, _, C = next(iter(w.tiles.values())).tile.shape
    n = w.colours**2
    return n * int(w.options["variants"]) * T, n * T, C


def arrangement(doc_wang) -> np.ndarray | None:
    """The tiles in their canonical arrangement (K² x K² per variant, variants stacked),
    black where a tile is still missing; None before the first tile."""
    w = doc_wang
    shape = arrangement_shape(w)
    if shape is None:
        return None
    first = next(iter(w.tiles.values())).tile
    T, n = first.shape[0], w.colours**2
    out = np.zeros(shape, first.dtype)
    for k, t in w.tiles.items():
        r, c = divmod(k, n)
        out[r * T : (r + 1) * T, c * T : (c + 1) * T] = t.tile
    return out


class SampleItem(QGraphicsPolygonItem):
    """One edge sample's diamond; drag it (whole pixels) to move the sample."""

    def __init__(self, view: WangView, axis: str, colour: int) -> None:
        super().__init__()
        self.view, self.axis, self.colour = view, axis, colour
        col = colour_of(colour)
        style = Qt.PenStyle.SolidLine if axis == "h" else Qt.PenStyle.DashLine
        self._pen = cosmetic_pen(col, 2, style)
        self._pen_selected = cosmetic_pen(QColor("#ffffff"), 3, style)
        self.setPen(self._pen)
        fill = QColor(col)
        fill.setAlpha(45)
        self.setBrush(QBrush(fill))
        self.setZValue(40)
        self.setCursor(Qt.CursorShape.OpenHandCursor)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsFocusable, False)
        # the name, white on a chip of the colour: readable on any texture (red on bricks was not)
        self.label = QGraphicsRectItem(self)
        self.label.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        chip = QColor(col)
        chip.setAlpha(215)
        self.label.setBrush(QBrush(chip))
        self.label.setPen(Qt.PenStyle.NoPen)
        text = QGraphicsSimpleTextItem(f"{axis}{colour}", self.label)
        text.setBrush(QBrush(QColor("#ffffff")))
        box = text.boundingRect()
        text.setPos(3, 0)
        self.label.setRect(0, 0, box.width() + 6, box.height())
        self._drag = None  # (press scene pos, origin at press)
        self.origin = (0, 0)
        self.tile = 1

    def place(self, sample, tile: int) -> None:
        self.origin, self.tile = tuple(sample.origin), tile
        self.setPos(0, 0)
        pts = [QPointF(x, y) for x, y in sample.diamond(tile)]
        self.setPolygon(QPolygonF(pts))
        self.label.setPos(pts[0] + QPointF(2, 2))

    def set_selected(self, on: bool) -> None:
        self.setPen(self._pen_selected if on else self._pen)

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        if event.button() != Qt.MouseButton.LeftButton:
            event.ignore()
            return
        self._drag = (event.scenePos(), self.origin)
        self.setCursor(Qt.CursorShape.ClosedHandCursor)
        self.view.select_sample(self.axis, self.colour)
        event.accept()

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drag is None:
            return
        d = event.scenePos() - self._drag[0]
        self.setPos(round(d.x()), round(d.y()))

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drag is None:
            return
        self.setCursor(Qt.CursorShape.OpenHandCursor)
        (oy, ox), dx, dy = self._drag[1], int(self.pos().x()), int(self.pos().y())
        self._drag = None
        if dx or dy:
            self.view.sample_dropped.emit(self.axis, self.colour, (oy + dy, ox + dx))
        self.setPos(0, 0)  # the document redraws it where the sample really is


class WangView(QWidget):
    """The Wang tab of ``doc`` (a :class:`quilt_gui.document.Document`), run by ``runner``."""

    sample_dropped = Signal(str, int, object)  # axis, colour, new origin (row, col)
    export_requested = Signal()

    def __init__(self, doc, runner, parent=None) -> None:
        super().__init__(parent)
        self.doc, self.runner = doc, runner
        self.samples: dict[tuple[str, int], SampleItem] = {}
        self._tile_items: dict[int, list] = {}  # tile index -> its edge bars and cuts
        self._veils: dict[int, QGraphicsRectItem] = {}  # over the tiles waiting for a rebuild
        self._grid_items: list = []
        self._shape = None
        self._make_controls()
        self.source = ImageCanvas()
        self.tiles = ImageCanvas()
        self.preview = ImageCanvas()
        right = QSplitter(Qt.Orientation.Vertical)
        right.addWidget(self._titled("Tiles (canonical arrangement)", self.tiles))
        right.addWidget(self._titled("Random valid layout", self.preview))
        right.setSizes([500, 500])
        split = QSplitter(Qt.Orientation.Horizontal)
        split.addWidget(self._titled("Source and edge samples", self.source))
        split.addWidget(right)
        split.setSizes([500, 600])
        self.info = QLabel()
        self.info.setWordWrap(True)
        self.info.setAlignment(Qt.AlignmentFlag.AlignTop)
        self.info.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        side = QWidget()  # the controls, in a narrow column left of the canvases
        col = QVBoxLayout(side)
        col.setContentsMargins(0, 0, 0, 0)
        col.addLayout(self.bar)
        col.addWidget(self.info, 1)
        side.setMaximumWidth(210)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(side)
        lay.addWidget(split, 1)
        w = doc.wang
        doc.source_changed.connect(self._on_source_changed)
        w.reset.connect(self._on_reset)
        w.samples_changed.connect(self._draw_samples)
        w.tile_changed.connect(self._on_tile_changed)
        w.tiles_replaced.connect(self._draw_tiles)
        w.stale_changed.connect(self._draw_veils)
        w.layout_changed.connect(self._draw_preview)
        w.selection_changed.connect(self._on_selection_changed)
        self.sample_dropped.connect(runner.move_sample)
        self._on_source_changed()

    @property
    def canvas(self) -> ImageCanvas:
        """The canvas the View menu's zoom acts on when none has the keyboard focus: the
        layout."""
        return self.preview

    @Slot(int)
    def keep_clear_of(self, height: int) -> None:
        """End the canvases ``height`` px above the bottom (the window's banner floats there:
        it must not cover the layout's last rows); 0 when it is gone."""
        self.layout().setContentsMargins(0, 0, 0, max(0, int(height)))

    # ------------------------------------------------------------------ construction
    @staticmethod
    def _titled(title: str, canvas: ImageCanvas) -> QWidget:
        box = QWidget()
        v = QVBoxLayout(box)
        v.setContentsMargins(2, 2, 2, 2)
        label = QLabel(f"<b>{title}</b>")
        label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        v.addWidget(label)
        v.addWidget(canvas, 1)
        return box

    def _spin(self, lo, hi, value, tip) -> QSpinBox:
        s = QSpinBox()
        s.setRange(lo, hi)
        s.setValue(value)
        s.setToolTip(tip)
        return s

    def _make_controls(self) -> None:
        o = self.doc.wang.options
        self.colours = self._spin(1, 4, o["colours"], "Colours per edge direction K: K⁴ tiles")
        self.tile_size = self._spin(8, 1024, o["tile_size"], "Tile size in pixels (square)")
        self.tile_size.setSingleStep(8)
        self.variants = self._spin(1, 8, o["variants"], "Tiles per edge signature")
        self.interior = QComboBox()
        self.interior.addItems(["patch", "diamonds"])
        self.interior.setToolTip(
            "patch: a matched source window inside each tile (only a thin edge ring is shared);"
            " diamonds: Cohen's four edge diamonds alone"
        )
        self.seed = self._spin(0, 2**31 - 1, o["seed"], "Seed of the set")
        self.generate_button = QPushButton("Generate")
        self.generate_button.setToolTip("Make the Wang set from the source (Ctrl+G)")
        self.generate_button.setShortcut("Ctrl+G")  # on this tab (the tile set's elsewhere)
        self.generate_button.clicked.connect(self.generate)
        self.reroll_sample_button = QPushButton("Re-roll sample")
        self.reroll_sample_button.setToolTip(
            "Choose the selected edge sample again (click a diamond on the source to select)"
        )
        self.reroll_sample_button.clicked.connect(self.reroll_selected)
        self.reroll_layout_button = QPushButton("Re-roll layout")
        self.reroll_layout_button.setToolTip("Another valid layout of the Wang tiles (Ctrl+R)")
        self.reroll_layout_button.setShortcut("Ctrl+R")
        self.reroll_layout_button.clicked.connect(self.runner.reroll_layout)
        self.seams_box = QCheckBox("Seams")
        self.seams_box.setChecked(settings.get("wang_seams"))
        self.seams_box.setToolTip("Draw the corner cuts (red) and the interiors' cuts (green)")
        self.seams_box.toggled.connect(partial(settings.set, "wang_seams"))
        self.seams_box.toggled.connect(self._draw_tile_overlays)
        self.grid_box = QCheckBox("Grid")
        self.grid_box.setChecked(settings.get("wang_grid"))
        self.grid_box.setToolTip("Draw the tile borders over the preview")
        self.grid_box.toggled.connect(partial(settings.set, "wang_grid"))
        self.grid_box.toggled.connect(self._draw_grid)
        self.export_button = QPushButton("Export…")
        self.export_button.setToolTip("Write the set for Tiled (Wang set) and Godot (terrains)")
        self.export_button.clicked.connect(self.export_requested)
        form = QFormLayout()
        form.setContentsMargins(4, 4, 4, 4)
        for label, widget in (
            ("Colours", self.colours),
            ("Tile size", self.tile_size),
            ("Variants", self.variants),
            ("Interior", self.interior),
            ("Seed", self.seed),
        ):
            form.addRow(label, widget)
        form.addRow(self.generate_button)
        form.addRow(self.reroll_sample_button)
        form.addRow(self.reroll_layout_button)
        checks = QHBoxLayout()
        checks.addWidget(self.seams_box)
        checks.addWidget(self.grid_box)
        form.addRow(checks)
        form.addRow(self.export_button)
        self.bar = form

    # ------------------------------------------------------------------ actions
    def options(self) -> dict:
        return {
            "colours": self.colours.value(),
            "tile_size": self.tile_size.value(),
            "variants": self.variants.value(),
            "interior": self.interior.currentText(),
            "seed": self.seed.value(),
        }

    @Slot()
    def generate(self):
        return self.runner.generate(self.options())

    @Slot()
    def reroll_selected(self):
        sel = self.doc.wang.selected
        if sel is None:
            self.runner.message.emit(
                "warning", "Select an edge sample first: click its diamond on the source."
            )
            return None
        return self.runner.reroll_sample(*sel)

    def select_sample(self, axis: str, colour: int) -> None:
        self.doc.wang.select((axis, colour))

    # ------------------------------------------------------------------ drawing
    @Slot()
    def _on_source_changed(self) -> None:
        src = self.doc.source
        self.source.set_image(None if src is None else src.main, fit=True)
        top = self.runner.largest_tile()
        self.generate_button.setEnabled(top is not None)
        if top is not None:
            self.tile_size.setMaximum(top)  # a tiny source takes tiles below 16 px only

    @Slot()
    def _on_reset(self) -> None:
        o = self.doc.wang.options
        for spin, key in (
            (self.colours, "colours"),
            (self.tile_size, "tile_size"),
            (self.variants, "variants"),
            (self.seed, "seed"),
        ):
            spin.blockSignals(True)
            spin.setValue(int(o[key]))
            spin.blockSignals(False)
        self.interior.setCurrentText(o["interior"])
        self._draw_samples()
        self._draw_tiles(fit=True)
        self._draw_preview()

    @Slot()
    def _draw_samples(self) -> None:
        w = self.doc.wang
        for item in self.samples.values():
            self.source.scene().removeItem(item)
        self.samples = {}
        if w.samples is None:
            self._update_info()
            return
        T = int(w.options["tile_size"])
        for s in w.samples:
            item = SampleItem(self, s.axis, s.colour)
            item.place(s, T)
            self.source.add_item(item)
            self.samples[(s.axis, s.colour)] = item
        self._on_selection_changed()
        self._update_info()

    @Slot()
    def _on_selection_changed(self) -> None:
        sel = self.doc.wang.selected
        for key, item in self.samples.items():
            item.set_selected(key == sel)
        self.reroll_sample_button.setEnabled(sel is not None)
        self._update_info()

    @Slot(int)
    def _on_tile_changed(self, index: int) -> None:
        if self._paste_tile(index):
            self._draw_tile_marks(index)
            self._update_info()
        else:
            self._draw_tiles(fit=self.tiles.fitted, index=index)
        if self.doc.wang.layout is not None:
            self._draw_preview()

    def _paste_tile(self, k: int) -> bool:
        """Draw tile ``k`` alone into the arrangement shown, if it has its place there (a
        2048 px arrangement converted whole took 0.1 s per tile streamed in)."""
        w, shown = self.doc.wang, self.tiles.array
        t = w.tiles.get(k)
        if t is None or shown is None or shown.shape != arrangement_shape(w):
            return False
        if t.tile.shape != (shown.shape[1] // w.colours**2,) * 2 + shown.shape[2:]:
            return False
        T = t.tile.shape[0]
        r, c = divmod(k, w.colours**2)
        self.tiles.image_item.paste(t.tile, c * T, r * T)
        return True

    @Slot()
    def _draw_tiles(self, *, fit: bool = False, index: int | None = None) -> None:
        """The arrangement; the marks of tile ``index`` only when it is the one changed (each
        tile streamed in redrew every tile's marks: quadratic, seconds for 81 tiles)."""
        img = arrangement(self.doc.wang)
        shape = None if img is None else img.shape
        fit = fit or img is None or self._shape != shape
        every = index is None or self._shape != shape
        self._shape = shape
        self.tiles.set_image(img, fit=fit)
        if every:
            self._draw_tile_overlays()
        else:
            self._draw_tile_marks(index)
        self._update_info()

    @Slot()
    def _draw_tile_overlays(self, *_args) -> None:
        """The marks of every tile."""
        for k in set(self._tile_items) | set(self.doc.wang.tiles):
            self._draw_tile_marks(k)

    def _draw_tile_marks(self, k: int) -> None:
        """Tile ``k``'s edge bars and (Seams) its corner cuts and interior's cut."""
        scene = self.tiles.scene()
        for item in self._tile_items.pop(k, ()):
            scene.removeItem(item)
        w = self.doc.wang
        t = w.tiles.get(k)
        if t is None:
            self._veil(k)
            return
        T = t.tile.shape[0]
        r, c = divmod(k, w.colours**2)
        y0, x0 = r * T, c * T
        items = self._edge_markers(t.signature, x0, y0, T)
        if self.seams_box.isChecked():
            cuts, loops = QPainterPath(), QPainterPath()
            for name, p in t.paths.items():
                path = loops if name == "patch" else cuts
                pts = np.asarray(p)
                if len(pts) < 2:
                    continue
                if name == "patch":
                    pts = np.vstack([pts, pts[:1]])
                path.moveTo(x0 + pts[0, 1] + 0.5, y0 + pts[0, 0] + 0.5)
                for rr, cc in pts[1:]:
                    path.lineTo(x0 + cc + 0.5, y0 + rr + 0.5)
            for path, color in ((cuts, CUT_COLOR), (loops, PATCH_COLOR)):
                item = QGraphicsPathItem(path)
                item.setPen(cosmetic_pen(color, 1))
                item.setZValue(30)
                scene.addItem(item)
                items.append(item)
        self._tile_items[k] = items
        self._veil(k)

    @Slot()
    def _draw_veils(self) -> None:
        """A dark veil over every tile waiting for a rebuild (it still shows old pixels)."""
        for k in set(self._veils) | set(self.doc.wang.stale):
            self._veil(k)
        self._update_info()

    def _veil(self, k: int) -> None:
        w = self.doc.wang
        t = w.tiles.get(k)
        if t is None or k not in w.stale:
            item = self._veils.pop(k, None)
            if item is not None:
                self.tiles.scene().removeItem(item)
            return
        if k not in self._veils:
            T = t.tile.shape[0]
            r, c = divmod(k, w.colours**2)
            item = QGraphicsRectItem(c * T, r * T, T, T)
            item.setBrush(QBrush(QColor(0, 0, 0, 140)))
            item.setPen(Qt.PenStyle.NoPen)
            item.setZValue(25)  # under the marks
            item.setToolTip("Waiting for its rebuild: it still shows its old pixels")
            self.tiles.scene().addItem(item)
            self._veils[k] = item

    def _edge_markers(self, signature, x0: int, y0: int, T: int) -> list:
        """A thick bar in the edge's colour along the middle third of each edge (the items)."""
        items = []
        a, b = T / 3, 2 * T / 3
        inset = max(1.5, T / 40)
        lines = {
            0: QLineF(x0 + a, y0 + inset, x0 + b, y0 + inset),
            1: QLineF(x0 + T - inset, y0 + a, x0 + T - inset, y0 + b),
            2: QLineF(x0 + a, y0 + T - inset, x0 + b, y0 + T - inset),
            3: QLineF(x0 + inset, y0 + a, x0 + inset, y0 + b),
        }
        for side, line in lines.items():
            item = QGraphicsLineItem(line)
            style = Qt.PenStyle.SolidLine if side in (0, 2) else Qt.PenStyle.DashLine
            item.setPen(cosmetic_pen(colour_of(signature[side]), 4, style))
            item.setZValue(35)
            self.tiles.scene().addItem(item)
            items.append(item)
        return items

    @Slot()
    def _draw_preview(self) -> None:
        from engine.tiles.layout import assemble

        w = self.doc.wang
        img = None
        if w.layout is not None and w.complete:
            img = assemble(w.tile_list(), w.layout)
        first = img is not None and (self.preview.array is None or self.preview.fitted)
        self.preview.set_image(img, fit=first)  # empty (not hidden: its title stays on top)
        self._draw_grid()
        self._update_info()

    @Slot()
    def _draw_grid(self, *_args) -> None:
        scene = self.preview.scene()
        for item in self._grid_items:
            scene.removeItem(item)
        self._grid_items = []
        w = self.doc.wang
        if not self.grid_box.isChecked() or w.layout is None or not w.complete:
            return
        T = w.tile_list()[0].tile.shape[0]
        self._grid_items = grid_items(self.preview, *w.layout.shape, T, T)

    def _update_info(self) -> None:
        w = self.doc.wang
        for button in (self.reroll_layout_button, self.export_button):
            button.setEnabled(w.complete)  # a layout and an export need the whole set
        if self.doc.source is None:
            self.info.setText("Open a source image to make a Wang tile set.")
            return
        if not self.generate_button.isEnabled():
            self.info.setText("This source is too small for Wang tiles.")
            return
        if w.samples is None and not w.tiles:
            self.info.setText(
                "Generate makes K⁴ tiles whose touching edges always match: each edge colour is "
                "a diamond of the source, drawn here; drag one to move it."
            )
            return
        K = w.colours
        made = len(w.tiles)
        text = f"{made} of {w.count} tiles · {K} colours per edge direction"
        if self.runner.stale:
            text += f" · rebuilding {len(self.runner.stale)}"
        if w.selected is not None:
            a, c = w.selected
            s = w.sample(a, c)
            users = len(w.users(a, c))
            text += f" · sample {a}{c} at (row {s.origin[0]}, col {s.origin[1]}), on {users} tiles"
        self.info.setText(text)
