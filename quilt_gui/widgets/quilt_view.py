"""Quilting mode: the output grows block by block; click a block to inspect its cut.

Left: the sample, with the source window of the selected block and the excluded pixels
(:mod:`quilt_gui.widgets.exclusion`: the same exclusion as the tile set's).
Right: the output, painted block by block as the engine places them (only the new block's
pixels are converted, so the GUI stays responsive on large outputs). Below: the selected
block's sample window, its placed pixels and its overlap error map, with the seam on each.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QRectF, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QColor, QImage, QPainter
from PySide6.QtWidgets import (
    QGraphicsItem,
    QHBoxLayout,
    QLabel,
    QSplitter,
    QTabWidget,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from quilt_gui.document import Document
from quilt_gui.imaging import to_qimage
from quilt_gui.widgets.canvas import ImageCanvas, ShadeItem
from quilt_gui.widgets.exclusion import HINT, ExclusionPainter
from quilt_gui.widgets.overlap_panel import OverlapView


class RasterItem(QGraphicsItem):
    """A QImage the size of the output; blocks are painted into it region by region."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.image = QImage()
        self.setZValue(5)

    def reset(self, h: int, w: int) -> None:
        self.prepareGeometryChange()
        self.image = QImage(w, h, QImage.Format.Format_RGBA8888)
        self.image.fill(QColor(0, 0, 0, 0))
        self.update()

    def paste(self, pixels: np.ndarray, x: int, y: int) -> None:
        """Draw ``pixels`` with their top-left corner at output pixel (x, y)."""
        p = QPainter(self.image)
        p.setCompositionMode(QPainter.CompositionMode.CompositionMode_Source)
        p.drawImage(x, y, to_qimage(pixels).convertToFormat(QImage.Format.Format_RGBA8888))
        p.end()
        self.update(QRectF(x, y, pixels.shape[1], pixels.shape[0]))

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        return QRectF(0, 0, self.image.width(), self.image.height())

    def paint(self, painter: QPainter, option, widget=None) -> None:
        if not self.image.isNull():
            painter.drawImage(QRectF(0, 0, self.image.width(), self.image.height()), self.image)


START_TEXT = "Press Synthesize (Ctrl+Return) to quilt the source into a larger texture."
PICK_TEXT = "Click a block of the output to see its overlap, error map and cut."


def wrapped_pieces(start: int, size: int, total: int) -> list[tuple[int, int]]:
    """(output start, length) of the pieces of a span that wraps around at ``total``."""
    first = min(size, total - start)
    return [(start, first)] + ([(0, size - first)] if first < size else [])


class QuiltView(QWidget):
    """Sample | output, and the block inspector."""

    selection_changed = Signal()  # the inspected block changed (``selected``)

    def __init__(self, doc: Document, actions=(), parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.sample = ImageCanvas()
        self.target = ImageCanvas()
        self.output = ImageCanvas()
        self.raster = RasterItem()
        self.output.add_item(self.raster)
        self.source_rect = ShadeItem("#ffd23f")
        self.source_rect.hide()
        self.sample.add_item(self.source_rect)
        self.block_rect = ShadeItem("#ffd23f")
        self.block_rect.setZValue(40)
        self.block_rect.hide()
        self.output.add_item(self.block_rect)
        self.painter = ExclusionPainter(doc, self.sample)
        self.excluded = self.painter.overlay
        self.inspector = OverlapView("#7dff5f", names=("sample window", "placed", "error"))
        self.inspector.setToolTip(
            "The selected block: its sample window, the pixels placed, and "
            "the overlap error map, with the cut on each"
        )
        self.info = QLabel(START_TEXT)
        self.info.setWordWrap(True)
        self.selected: int | None = None
        self.sample.setToolTip(f"Ctrl+click: exclude this colour · {HINT}")
        self._inspect_timer = QTimer(self)
        self._inspect_timer.setSingleShot(True)
        self._inspect_timer.setInterval(0)
        self._inspect_timer.timeout.connect(self._inspect_newest)
        bar = QHBoxLayout()
        bar.setContentsMargins(4, 2, 4, 2)
        for action in actions:
            b = QToolButton()
            b.setDefaultAction(action)
            b.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
            bar.addWidget(b)
        self.counter = QLabel()
        bar.addWidget(self.counter, 1)
        top = QSplitter(Qt.Orientation.Horizontal)
        self.inputs = QTabWidget()
        self.inputs.setDocumentMode(True)
        self.inputs.addTab(self.sample, "Sample")
        self.inputs.addTab(self.target, "Transfer target")
        self.inputs.setTabToolTip(
            0, "The texture blocks are copied from (Ctrl+click: exclude a colour)"
        )
        self.inputs.setTabToolTip(1, "Texture transfer imitates this image's layout")
        top.addWidget(self.inputs)
        box = QWidget()
        bl = QVBoxLayout(box)
        bl.setContentsMargins(0, 0, 0, 0)
        bl.addWidget(QLabel("<b>Output</b>"))
        bl.addWidget(self.output, 1)
        top.addWidget(box)
        top.setSizes([350, 650])
        bottom = QWidget()
        bb = QVBoxLayout(bottom)
        bb.setContentsMargins(0, 0, 0, 0)
        bb.addWidget(QLabel("<b>Selected block</b>: sample window | placed | overlap error"))
        bb.addWidget(self.inspector, 1)
        bb.addWidget(self.info)
        split = QSplitter(Qt.Orientation.Vertical)
        split.addWidget(top)
        split.addWidget(bottom)
        split.setSizes([640, 260])
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(split, 1)
        self.output.pixel_clicked.connect(self._on_output_clicked)
        self.sample.pixel_clicked.connect(self._on_sample_clicked)
        doc.source_changed.connect(self._on_source_changed)
        doc.pixels_changed.connect(self._on_pixels_changed)
        doc.quilting.reset.connect(self._on_reset)
        doc.quilting.block_placed.connect(self._on_block_placed)
        doc.quilting.finished.connect(self._on_finished)
        doc.quilting.restored.connect(self._on_restored)
        doc.quilting.iteration_finished.connect(self._on_iteration)
        doc.quilting.target_changed.connect(self._on_target_changed)
        self._on_source_changed()

    # ------------------------------------------------------------------ document -> view
    @Slot()
    def _on_source_changed(self) -> None:
        src = self.doc.source
        self.sample.set_image(None if src is None else src.main, fit=True)
        self._on_reset()

    @Slot()
    def _on_pixels_changed(self) -> None:
        self.sample.set_image(self.doc.source.main)

    @Slot()
    def _on_reset(self) -> None:
        out = self.doc.quilting.output
        self.select(None)
        if out is None:
            self.output.set_image(None)
            self.raster.reset(0, 0)
            self.counter.setText("")
            return
        h, w = out.shape[:2]
        fit = self.output.array is None or self.output.array.shape != out.shape
        # the output starts black and blocks are painted into the raster above it: show an
        # 8-bit black image (converting the float zeros stalled the GUI ~0.1 s at 1536 px)
        self.output.set_image(np.zeros(out.shape, np.uint8), fit=fit)
        self.raster.reset(h, w)
        self.counter.setText("quilting…")

    @Slot()
    def _on_restored(self) -> None:
        """An output read from a project: shown as it was saved (its blocks are not kept)."""
        self.select(None)
        self.raster.reset(0, 0)
        self.block_rect.hide()
        out = self.doc.quilting.output
        self.output.set_image(out, fit=True)
        if out is not None:
            h, w = out.shape[:2]
            self.counter.setText(f"{w}×{h} output kept in the project (its blocks are not)")

    @property
    def canvas(self) -> ImageCanvas:
        """The canvas the View menu's zoom acts on when none has the keyboard focus: the
        output."""
        return self.output

    def set_output_actions(self, actions) -> None:
        """The output's context menu (right-click): Save output… and the like."""
        self.output.setContextMenuPolicy(Qt.ContextMenuPolicy.ActionsContextMenu)
        self.output.addActions(list(actions))

    @Slot(int)
    def _on_block_placed(self, index: int) -> None:
        out = self.doc.quilting.output
        rec = self.doc.quilting.blocks[index]
        H, W = out.shape[:2]
        (r, c), (h, w) = rec.position, rec.size
        for rr, nh in wrapped_pieces(r, h, H):
            for cc, nw in wrapped_pieces(c, w, W):
                self.raster.paste(out[rr : rr + nh, cc : cc + nw], cc, rr)
        self.block_rect.set_rect(c, r, w, h)  # the newest block
        self.block_rect.show()
        self.counter.setText(f"{index + 1} blocks placed")
        self._inspect_timer.start()  # the inspector follows the newest block, once per frame

    @Slot()
    def _on_finished(self) -> None:
        out = self.doc.quilting.output
        self.output.set_image(out)
        self.raster.reset(0, 0)
        self.block_rect.hide()
        res = self.doc.quilting.result
        h, w = out.shape[:2]
        from engine.transfer import TransferResult

        if isinstance(res, TransferResult) and res.iterations:
            passes = res.iterations
            how = (
                f"{len(passes)} transfer passes, correspondence error "
                f"{passes[-1].correspondence_error:.4f}"
            )
        else:
            how = f"{res.select}, {res.seam.method} seams"
        self.counter.setText(f"{w}×{h} from {len(res.blocks)} blocks ({how})")
        self.select(len(self.doc.quilting.blocks) - 1 if self.doc.quilting.blocks else None)

    @Slot(int)
    def _on_iteration(self, iteration: int) -> None:
        """A transfer pass ended: show its image; the next pass paints over it."""
        self.output.set_image(self.doc.quilting.output)
        self.raster.reset(*self.doc.quilting.output.shape[:2])
        self.select(None)
        self.counter.setText(f"transfer pass {iteration} of {self.doc.params['iterations']} done")

    @Slot()
    def _on_target_changed(self) -> None:
        self.target.set_image(self.doc.quilting.target, fit=True)
        if self.doc.quilting.target is not None:
            self.inputs.setCurrentWidget(self.target)

    # ------------------------------------------------------------------ inspection
    @Slot()
    def _inspect_newest(self) -> None:
        if self.doc.quilting.blocks and self.doc.quilting.result is None:
            self.select(len(self.doc.quilting.blocks) - 1)

    @Slot(object, object)
    def _on_output_clicked(self, px, _modifiers) -> None:
        self.select(self.doc.quilting.block_at(*px))

    @Slot(object, object)
    def _on_sample_clicked(self, px, modifiers) -> None:
        """Ctrl+click on the sample excludes its colour (Ctrl+Shift+click, as on the Source
        tab, is the painter's)."""
        if modifiers & Qt.KeyboardModifier.ControlModifier and self.doc.source is not None:
            self.painter.pick_colour(px)

    @Slot()
    def clear_painted(self) -> None:
        self.painter.clear_painted()

    def select(self, index: int | None) -> None:
        """Show block ``index`` in the inspector (None clears it)."""
        self.selected = index
        if index is None or not 0 <= index < len(self.doc.quilting.blocks):
            self.selected = None
            self.inspector.clear()
            self.source_rect.hide()
            self.block_rect.hide()  # no block's caption or frame left from an earlier output
            self.info.setText(PICK_TEXT if self.doc.quilting.blocks else START_TEXT)
            self.selection_changed.emit()
            return
        rec = self.doc.quilting.blocks[index]
        out = self.doc.quilting.output
        H, W = out.shape[:2]
        (r, c), (h, w) = rec.position, rec.size
        x, y, sw, sh = rec.source
        window = self.doc.source.main[y : y + sh, x : x + sw][:h, :w]
        placed = out[np.ix_((r + np.arange(h)) % H, (c + np.arange(w)) % W)]
        error = np.zeros((h, w), np.float32) if rec.error is None else np.asarray(rec.error)
        self.inspector.show_overlap(window, placed, error, stacked=False)
        self.inspector.set_path(np.asarray(rec.path) if len(rec.path) else None)
        self.source_rect.set_rect(x, y, sw, sh)
        self.source_rect.show()
        self.block_rect.set_rect(c, r, w, h)
        self.block_rect.show()
        t, left, b, rt = rec.arms
        seam = seam_text(rec)
        match = (
            ""
            if np.isnan(rec.match_error)
            else f" · match error {rec.match_error:.4g} (best {rec.best_error:.4g})"
        )
        self.info.setText(
            f"Block #{rec.index + 1} at row {r}, col {c} ({w}×{h}) from sample ({x}, {y}) · "
            f"overlaps top {t}, left {left}{', bottom ' + str(b) if b else ''}"
            f"{', right ' + str(rt) if rt else ''} · {seam}{match} · chosen among "
            f"{rec.candidates} window{'s' if rec.candidates != 1 else ''}"
        )
        self.selection_changed.emit()

    def selected_block(self):
        """The engine record of the inspected block, or None."""
        i = self.selected
        return (
            None if i is None or i >= len(self.doc.quilting.blocks) else self.doc.quilting.blocks[i]
        )


def seam_text(rec) -> str:
    """How block ``rec`` met its neighbours, for the inspector's caption."""
    if len(rec.path):
        return f"seam criterion {rec.criterion:.3f}, peak {rec.peak:.3f}"
    if not any(rec.arms):
        return "no overlap (first block)"
    if rec.error is not None and not np.any(rec.error):
        # the engine searches no cut where old and new agree exactly (a continued copy)
        return "no cut needed: the sample continues its neighbours exactly (overlap error 0)"
    return "straight overlap (no cut)"
