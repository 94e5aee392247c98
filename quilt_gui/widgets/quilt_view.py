"""Quilting mode: the output grows block by block; click a block to inspect its cut.

Left: the sample, with the source window of the selected block and the excluded pixels.
Right: the output, painted block by block as the engine places them (only the new block's
pixels are converted, so the GUI stays responsive on large outputs). Below: the selected
block's sample window, its placed pixels and its overlap error map, with the seam on each.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QEvent, QRectF, Qt, QTimer, Signal, Slot
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
from quilt_gui.pipeline import excluded_mask
from quilt_gui.widgets.canvas import ImageCanvas, ImageItem, ShadeItem
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
        self.excluded = ImageItem()
        self.excluded.setZValue(15)
        self.excluded.hide()
        self.sample.add_item(self.excluded)
        self.inspector = OverlapView("#7dff5f")
        self.inspector.setToolTip(
            "The selected block: its sample window, the pixels placed, and "
            "the overlap error map, with the cut on each"
        )
        self.info = QLabel(
            "Press Synthesize (Ctrl+Return) to quilt the source into a larger texture."
        )
        self.info.setWordWrap(True)
        self.selected: int | None = None
        self._stroke: np.ndarray | None = None  # the mask being painted (Shift+drag)
        self._stroke_value = True
        self._last_px: tuple[int, int] | None = None
        self.sample.viewport().installEventFilter(self)
        self.sample.setToolTip(
            "Ctrl+click: exclude this colour · Shift+drag: paint pixels "
            "never to copy · Shift+right-drag: erase"
        )
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
        doc.quilt_reset.connect(self._on_reset)
        doc.block_placed.connect(self._on_block_placed)
        doc.quilt_finished.connect(self._on_finished)
        doc.quilt_iteration.connect(self._on_iteration)
        doc.target_changed.connect(self._on_target_changed)
        doc.params_changed.connect(self._on_params_changed)
        doc.exclusion_changed.connect(self._update_exclusion)
        self._on_source_changed()

    # ------------------------------------------------------------------ document -> view
    @Slot()
    def _on_source_changed(self) -> None:
        src = self.doc.source
        self.sample.set_image(None if src is None else src.main, fit=True)
        self._update_exclusion()
        self._on_reset()

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        if keys & {"exclude_color", "exclude_tolerance"}:
            self._update_exclusion()

    def _update_exclusion(self) -> None:
        src = self.doc.source
        p = self.doc.params
        painted = self._stroke if self._stroke is not None else self.doc.exclude_painted
        mask = (
            None
            if src is None
            else excluded_mask(src.main, p["exclude_color"], p["exclude_tolerance"], painted)
        )
        if mask is None or not mask.any():
            self.excluded.hide()
            return
        rgba = np.zeros(mask.shape + (4,), np.uint8)
        rgba[mask] = (255, 40, 40, 150)
        self.excluded.set_array(rgba)

    @Slot()
    def _on_reset(self) -> None:
        out = self.doc.quilt_output
        self.select(None)
        if out is None:
            self.output.set_image(None)
            self.raster.reset(0, 0)
            self.counter.setText("")
            return
        h, w = out.shape[:2]
        fit = self.output.array is None or self.output.array.shape != out.shape
        self.output.set_image(out, fit=fit)
        self.raster.reset(h, w)
        self.counter.setText("quilting…")

    @Slot(int)
    def _on_block_placed(self, index: int) -> None:
        out = self.doc.quilt_output
        rec = self.doc.quilt_blocks[index]
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
        out = self.doc.quilt_output
        self.output.set_image(out)
        self.raster.reset(0, 0)
        self.block_rect.hide()
        res = self.doc.quilt_result
        h, w = out.shape[:2]
        passes = getattr(res, "iterations", ())
        how = (
            f"{len(passes)} transfer passes, correspondence error "
            f"{passes[-1].correspondence_error:.4f}"
            if passes
            else f"{res.select}, {res.seam} seams"
        )
        self.counter.setText(f"{w}×{h} from {len(res.blocks)} blocks ({how})")
        self.select(len(self.doc.quilt_blocks) - 1 if self.doc.quilt_blocks else None)

    @Slot(int)
    def _on_iteration(self, iteration: int) -> None:
        """A transfer pass ended: show its image; the next pass paints over it."""
        self.output.set_image(self.doc.quilt_output)
        self.raster.reset(*self.doc.quilt_output.shape[:2])
        self.select(None)
        self.counter.setText(f"transfer pass {iteration} of {self.doc.params['iterations']} done")

    @Slot()
    def _on_target_changed(self) -> None:
        self.target.set_image(self.doc.transfer_target, fit=True)
        if self.doc.transfer_target is not None:
            self.inputs.setCurrentWidget(self.target)

    # ------------------------------------------------------------------ painted exclusion
    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt API
        """Shift+drag on the sample paints the exclusion mask (right button erases)."""
        if obj is not self.sample.viewport() or self.doc.source is None:
            return False
        kind = event.type()
        if (
            kind == QEvent.Type.MouseButtonPress
            and event.modifiers() & Qt.KeyboardModifier.ShiftModifier
        ):
            px = self.sample.pixel_at(event.position())
            if px is None:
                return False
            current = self.doc.exclude_painted
            self._stroke = (
                np.zeros(self.doc.source.shape, bool) if current is None else current.copy()
            )
            self._stroke_value = event.button() != Qt.MouseButton.RightButton
            self._last_px = px
            self._paint(px, px)
            return True
        if kind == QEvent.Type.MouseMove and self._stroke is not None:
            px = self.sample.pixel_at(event.position())
            if px is not None:
                self._paint(self._last_px or px, px)
                self._last_px = px
            return True
        if kind == QEvent.Type.MouseButtonRelease and self._stroke is not None:
            stroke, self._stroke, self._last_px = self._stroke, None, None
            text = "Paint exclusion" if self._stroke_value else "Erase exclusion"
            self.doc.set_painted(stroke if stroke.any() else None, text=text)
            return True
        return False

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
            self._stroke[r0:r1, c0:c1][disk] = self._stroke_value
        self._update_exclusion()

    @Slot()
    def clear_painted(self) -> None:
        if self.doc.exclude_painted is not None:
            self.doc.set_painted(None, text="Clear painted exclusion")

    # ------------------------------------------------------------------ inspection
    @Slot()
    def _inspect_newest(self) -> None:
        if self.doc.quilt_blocks and self.doc.quilt_result is None:
            self.select(len(self.doc.quilt_blocks) - 1)

    @Slot(object, object)
    def _on_output_clicked(self, px, _modifiers) -> None:
        self.select(self.doc.block_at(*px))

    @Slot(object, object)
    def _on_sample_clicked(self, px, modifiers) -> None:
        if not modifiers & Qt.KeyboardModifier.ControlModifier or self.doc.source is None:
            return
        rgb = self.doc.source.main[px[0], px[1]]
        rgb = np.repeat(rgb[:1], 3) if rgb.shape[0] < 3 else rgb[:3]
        color = "#" + "".join(f"{int(round(float(v) * 255)):02x}" for v in rgb)
        values = {"exclude_color": color}
        if self.doc.params["exclude_tolerance"] <= 0:
            values["exclude_tolerance"] = 0.08
        self.doc.set_params(values, text="Exclude a colour")

    def select(self, index: int | None) -> None:
        """Show block ``index`` in the inspector (None clears it)."""
        self.selected = index
        if index is None or not 0 <= index < len(self.doc.quilt_blocks):
            self.selected = None
            self.inspector.clear()
            self.source_rect.hide()
            self.selection_changed.emit()
            return
        rec = self.doc.quilt_blocks[index]
        out = self.doc.quilt_output
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
        if len(rec.path):
            seam = f"seam criterion {rec.criterion:.3f}, peak {rec.peak:.3f}"
        elif any(rec.arms):
            seam = "straight overlap (no cut)"
        else:
            seam = "no overlap (first block)"
        match = (
            ""
            if np.isnan(rec.match_error)
            else f" · match error {rec.match_error:.4g} (best {rec.best_error:.4g})"
        )
        self.info.setText(
            f"Block #{rec.index + 1} at row {r}, col {c} ({w}×{h}) from sample ({x}, {y}) · "
            f"overlaps top {t}, left {left}{', bottom ' + str(b) if b else ''}"
            f"{', right ' + str(rt) if rt else ''} · {seam}{match} · chosen among "
            f"{rec.candidates} windows"
        )
        self.selection_changed.emit()

    def selected_block(self):
        """The engine record of the inspected block, or None."""
        i = self.selected
        return None if i is None or i >= len(self.doc.quilt_blocks) else self.doc.quilt_blocks[i]
